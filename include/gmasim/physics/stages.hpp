// The step's stages written once over the number type, instantiated for double in
// gmasim::physics: what the scalar step (src/model/step.cpp) calls. The consistent magnetic
// state's joint Newton solve and commit (gmasim/physics/joint_newton-inl.h) and the mechanical
// stages (gmasim/physics/mechanics_stage-inl.h), the rods' circuit system (rod_circuit-inl.h: the
// netlist's low-rank solve), and their order (stage_order-inl.h). The lanes
// instantiate the same texts over their SIMD number type (src/lanes/number_lanes-inl.h).
#pragma once

#include "gmasim/physics/laws.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim::physics {

#define GMASIM_LAW_INLINE [[gnu::always_inline]] inline
#include "gmasim/physics/joint_newton-inl.h"  // IWYU pragma: export
#include "gmasim/physics/rod_circuit-inl.h"   // IWYU pragma: export
// after laws-inl.h, whose mechanics laws it calls
#include "gmasim/physics/mechanics_stage-inl.h"  // IWYU pragma: export
#include "gmasim/physics/stage_order-inl.h"      // IWYU pragma: export
#undef GMASIM_LAW_INLINE

using RodMagnetic = RodMagneticT<double>;
using RodStrain = RodStrainT<double>;
using RodOscillator = RodOscillatorT<double>;
using RodMechanicsInputs = RodMechanicsInputsT<double>;
using MountState = MountStateT<double>;

}  // namespace gmasim::physics
