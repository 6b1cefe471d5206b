// The step's laws over the number type (gmasim/physics/laws-inl.h), instantiated for double in
// gmasim::physics: what the scalar step calls. The lanes instantiate the same text for their
// SIMD number type (src/lanes/number_lanes-inl.h).
#pragma once

#include <cmath>

#include "gmasim/physics/number.hpp"
#include "gmasim/physics/oscillator_closed_form.hpp"

namespace gmasim::physics {

// cos(pi m / 2) by libm (cos_half_pi beyond |m| = 1).
struct CosHalfPiLibm {
  double operator()(double m) const { return std::cos(1.5707963267948966 * m); }
};

// The closed form where `where` holds, e1 and ed1 kept elsewhere (oscillator_step beyond the
// series' caps; the lanes' overload applies it lane by lane).
inline void oscillator_free_closed_form_where(bool where, double m, double c, double k, double h,
                                              double e0, double ed0, double &e1, double &ed1) {
  if (where) oscillator_free_closed_form(m, c, k, h, e0, ed0, e1, ed1);
}

#define GMASIM_LAW_INLINE [[gnu::always_inline]] inline
#define GMASIM_LAW_RARE inline
#include "gmasim/physics/laws-inl.h"  // IWYU pragma: export
// after laws-inl.h, whose series and anchors it uses (a block of its own: clang-format keeps it)
#include "gmasim/physics/ja_law-inl.h"  // IWYU pragma: export
#undef GMASIM_LAW_INLINE
#undef GMASIM_LAW_RARE

using ExpPoint = ExpPointT<double>;
inline constexpr ExpPoint kNoExpPoint{__builtin_nan(""), 0.0};
using OscillatorPropagator = OscillatorPropagatorT<double>;
using DeltaETerms = DeltaETermsT<double>;
using RodMechanics = RodMechanicsT<double>;
using LangevinValue = LangevinValueT<double>;
using LagWeightsSlope = LagWeightsSlopeT<double>;
using JaCoefficients = JaCoefficientsT<double>;
using JaMoveStart = JaMoveStartT<double>;
using JaExpPoints = JaExpPointsT<double>;
using JaEvaluation = JaEvaluationT<double>;
using JaSlopeTerms = JaSlopeTermsT<double>;

}  // namespace gmasim::physics
