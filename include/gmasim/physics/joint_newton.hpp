// The consistent magnetic state's joint Newton solve and commit (gmasim/physics/joint_newton-inl.h)
// instantiated for double in gmasim::physics: what the scalar step (src/model/step.cpp) calls.
// The lanes instantiate the same text over their SIMD number type (src/lanes/step_kernel-inl.h).
#pragma once

#include "gmasim/physics/laws.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim::physics {

#define GMASIM_LAW_INLINE [[gnu::always_inline]] inline
#include "gmasim/physics/joint_newton-inl.h"  // IWYU pragma: export
#undef GMASIM_LAW_INLINE

using RodMagnetic = RodMagneticT<double>;

}  // namespace gmasim::physics
