// A small dense complex solve A x = b by LU with partial pivoting, in the operations and order
// of Eigen 3.4's PartialPivLU<MatrixXcd>::solve for n <= kSmallLuMax (unblocked LU, one
// triangular panel), so that it gives the same bits; without its heap allocations, its l1
// norm (9 std::abs for a 3 x 3 matrix, used only by rcond()) and its expression overhead, it
// costs about half as much. SmallSignalModel::response() solves one such 3 x 3 system per
// frequency: 4000 of them in every identify evaluation of a first-resonance target.
// tests/test_small_lu.cpp compares it with Eigen bit for bit.
#pragma once

#include <complex>

namespace gmasim::mechanics_detail {

inline constexpr int kSmallLuMax = 8;  // Eigen's triangular panel width: one panel up to here

// Solves in place: a is n x n, column-major (overwritten by its LU factors), b (length n)
// becomes x. n in [1, kSmallLuMax]. A singular A gives what Eigen gives (inf / nan).
void small_lu_solve(std::complex<double>* a, std::complex<double>* b, int n);

}  // namespace gmasim::mechanics_detail
