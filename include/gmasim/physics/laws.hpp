// The step's laws over the number type (gmasim/physics/laws-inl.h), instantiated for double in
// gmasim::physics: what the scalar step calls. The lanes instantiate the same text for their
// SIMD number type (src/lanes/number_lanes-inl.h).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "gmasim/physics/number.hpp"
#include "gmasim/physics/oscillator_closed_form.hpp"
#include "gmasim/physics/preisach_history.hpp"

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

// The Preisach law's stack read at x (preisach_law-inl.h; the lanes' overload reads each lane's
// stack): the base extremum a move to x continues from (preisach_base).
inline void preisach_base_at(const PreisachHistory *h, double x, double &xb, double &mub,
                             double &mcb, double &mub_u, bool &up, bool &same) {
  const PreisachBase b = preisach_base(*h, x);
  xb = b.xb;
  mub = b.mub;
  mcb = b.mcb;
  mub_u = b.mub_u;
  up = b.up;
  same = b.same;
}

// exp(-t^2) on the grid t = m/16, m = 0 .. 424 (Cody's erfc splits exp(-x^2) there:
// preisach_law-inl.h), made once by the law's own exp_nonpositive, so that every instance reads
// the same numbers.
const double *exp_minus_grid_squared();

#define GMASIM_LAW_INLINE [[gnu::always_inline]] inline
#define GMASIM_LAW_RARE inline
#include "gmasim/physics/laws-inl.h"  // IWYU pragma: export
// after laws-inl.h, whose series and anchors it uses (a block of its own: clang-format keeps it)
#include "gmasim/physics/ja_law-inl.h"  // IWYU pragma: export
// after ja_law-inl.h, whose langevin_pair it uses
#include "gmasim/physics/preisach_law-inl.h"  // IWYU pragma: export
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
inline const double *exp_minus_grid_squared() {
  static const std::array<double, 425> table = [] {
    std::array<double, 425> t{};
    for (int m = 0; m < 425; ++m) {
      const double x = m * (1.0 / 16.0);
      t[static_cast<std::size_t>(m)] = exp_nonpositive(-(x * x));
    }
    return t;
  }();
  return table.data();
}

using GaussTerms = GaussTermsT<double>;
using Everett = EverettT<double>;
using PreisachBins = PreisachBinsT<double>;
using PreisachConstants = PreisachConstantsT<double>;

}  // namespace gmasim::physics
