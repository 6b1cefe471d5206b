// small_lu.hpp: Eigen 3.4's partial-pivoting LU solve of a small complex system, operation for
// operation (Eigen/src/LU/PartialPivLU.h, unblocked_lu and _solve_impl;
// Eigen/src/Core/products/TriangularSolverVector.h, one panel), without its heap.
#include "mechanics/small_lu.hpp"

#include <cmath>
#include <utility>

namespace gmasim::mechanics_detail {
namespace {

using cd = std::complex<double>;

// Eigen's packet product of complex doubles (pmul<Packet1cd>): re = ar br - ai bi,
// im = ar bi + ai br, without std::complex's NaN recovery (the same bits for finite values).
cd mul(cd a, cd b) {
  return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}

// Eigen's packet quotient (pdiv<Packet1cd>, used by the LU's column scaling): a conj(b) / |b|^2.
cd div_packet(cd a, cd b) {
  const double re = a.real() * b.real() + a.imag() * b.imag();
  const double im = a.imag() * b.real() - a.real() * b.imag();
  const double s = b.real() * b.real() + b.imag() * b.imag();
  return {re / s, im / s};
}

}  // namespace

void small_lu_solve(cd* a, cd* b, int n) {
  auto A = [&](int i, int j) -> cd& { return a[j * n + i]; };
  int swap_with[kSmallLuMax];
  for (int k = 0; k < n; ++k) {
    // The pivot: the first largest |a_ik| (Eigen's score and maxCoeff) in column k, i >= k.
    int p = k;
    double best = std::abs(A(k, k));
    for (int i = k + 1; i < n; ++i) {
      const double s = std::abs(A(i, k));
      if (s > best) {
        best = s;
        p = i;
      }
    }
    swap_with[k] = p;
    if (best != 0.0) {
      if (p != k)
        for (int j = 0; j < n; ++j) std::swap(A(k, j), A(p, j));
      const cd pivot = A(k, k);
      for (int i = k + 1; i < n; ++i) A(i, k) = div_packet(A(i, k), pivot);
    }
    // The rank-one update of the trailing block, column by column (Eigen's outer product).
    for (int j = k + 1; j < n; ++j) {
      const cd r = A(k, j);
      for (int i = k + 1; i < n; ++i) A(i, j) -= mul(r, A(i, k));
    }
  }
  for (int k = 0; k < n; ++k) std::swap(b[k], b[swap_with[k]]);  // P b
  for (int i = 0; i < n; ++i) {  // L (unit diagonal), forward; a zero entry skips its column
    if (b[i] == cd(0.0)) continue;
    for (int s = i + 1; s < n; ++s) b[s] -= mul(b[i], A(s, i));
  }
  for (int i = n - 1; i >= 0; --i) {  // U, backward: std::complex's quotient, as Eigen's
    if (b[i] == cd(0.0)) continue;
    b[i] /= A(i, i);
    for (int s = 0; s < i; ++s) b[s] -= mul(b[i], A(s, i));
  }
}

}  // namespace gmasim::mechanics_detail
