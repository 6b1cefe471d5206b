// Dense linear algebra of the linearised plant (src/mechanics/dense.hpp).
#include "mechanics/dense.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

namespace gmasim::dense {

std::vector<std::complex<double>> eigenvalues(const Eigen::MatrixXd& A) {
  const Eigen::EigenSolver<Eigen::MatrixXd> es(A, false);
  return {es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size()};
}

Eigen::MatrixXd exponential(const Eigen::MatrixXd& A) { return A.exp(); }

}  // namespace gmasim::dense
