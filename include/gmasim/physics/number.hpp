// The number type of the step's laws (docs/lanes.md, "One physics"). The laws that the step
// calls per rod and step -- the short series, the Delta-E modulus, the magnetostriction, the
// oscillator update -- are written once, as templates over a number type T:
//   T = double                the scalar step (model/step.cpp): one simulation;
//   T = lanes::Lanes<D>       the SIMD lanes (src/lanes/number_lanes-inl.h): W simulations in one
//                             Highway vector, each lane one simulation.
// A law uses + - * / and the comparisons of T (IEEE, exact the same on every target: the lanes
// are built without contraction into FMA, -ffp-contract=off, and so is the library), and these
// primitives, which this header gives for double and number_lanes-inl.h for the lanes:
//   Mask<T>            what a comparison gives (bool for double)
//   select(m, a, b)    a where m holds, b elsewhere (a branch becomes a select)
//   any(m), all(m), none(m), true_mask(x) (every lane)
//   abs(x), sqrt(x)    exact in IEEE arithmetic
//   pow2i(n)           2^n for an integer n in [-1022, 1023] (exact: the Preisach law's exp)
//   table_at(t, j)     t[j] for an integer j (a gather over the lanes: the same element)
//   each(f, x, m)      a scalar function f (libm's std::exp, std::cos) applied to each lane
//                      where m holds (x kept elsewhere):
//                      the lanes call the scalar step's own algorithm, so that no lane differs
//                      from the scalar step in its last digits (why not Highway's Exp: it
//                      rounds differently from libm, and the scalar step's outputs, its
//                      references and its calibration would all move).
// Every value a lane computes is therefore the scalar instance's value bit for bit, by
// construction (tests/test_number.cpp checks it on every target this machine runs).
// A branch that the scalar step takes rarely is written `if (any(m)) { ... select ... }`: the
// scalar instance does the work only where it is needed, the lanes where one lane needs it.
#pragma once

#include <bit>
#include <cmath>
#include <utility>

namespace gmasim::physics {

template <class T>
using Mask = decltype(std::declval<T>() < std::declval<T>());

inline double select(bool m, double a, double b) { return m ? a : b; }
inline bool any(bool m) { return m; }
inline bool all(bool m) { return m; }
inline bool none(bool m) { return !m; }
inline bool true_mask(double) { return true; }  // every lane (the one)
inline double abs(double x) { return std::fabs(x); }
inline double sqrt(double x) { return std::sqrt(x); }
inline double table_at(const double* t, double j) { return t[static_cast<long long>(j)]; }
// 2^n as its bits: the exponent field n + 1023 over a zero mantissa (as the lanes build it).
inline double pow2i(double n) {
  return std::bit_cast<double>(static_cast<unsigned long long>(static_cast<long long>(n) + 1023)
                               << 52);
}
template <class F>
inline double each(F f, double x, bool where) {
  return where ? f(x) : x;
}

// libm's exponential and cosine as the scalar functions each() applies.
struct LibmExp {
  double operator()(double x) const { return std::exp(x); }
};

}  // namespace gmasim::physics
