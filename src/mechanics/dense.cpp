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

std::vector<std::complex<double>> generalized_eigenvalues(const Eigen::MatrixXd& M,
                                                          const Eigen::MatrixXd& N) {
  const Eigen::GeneralizedEigenSolver<Eigen::MatrixXd> ges(M, N, false);
  std::vector<std::complex<double>> z;
  for (Eigen::Index k = 0; k < ges.alphas().size(); ++k)
    z.push_back(ges.alphas()(k) / ges.betas()(k));
  return z;
}

Eigen::MatrixXd exponential(const Eigen::MatrixXd& A) { return A.exp(); }

}  // namespace gmasim::dense
