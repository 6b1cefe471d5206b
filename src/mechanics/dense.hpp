// Dense linear algebra of the linearised plant (src/mechanics/dense.cpp): Eigen's eigenvalue
// and matrix-exponential algorithms, each instantiated once for the state
// space (gmasim/mechanics/state_space.hpp), the PID loop's margins
// (src/experiments/loop_margins.cpp) and their tests -- they are the heaviest templates of the
// build.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <vector>

namespace gmasim::dense {

// The eigenvalues of A (Eigen::EigenSolver, values only).
std::vector<std::complex<double>> eigenvalues(const Eigen::MatrixXd& A);
// e^A (Eigen's unsupported MatrixFunctions: scaling and squaring with Pade approximants).
Eigen::MatrixXd exponential(const Eigen::MatrixXd& A);

}  // namespace gmasim::dense
