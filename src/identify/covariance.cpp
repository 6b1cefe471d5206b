// Confidence intervals and correlations from the Jacobian of the normalised residuals at the
// optimum: theta = p (linear) or ln|p| (log parameters), cov = s^2 (J^T J)^-1 with
// s^2 = sum r^2 / (m - n), 95 % interval = 1.96 sigma (log: multiplicative).
#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "internal.hpp"

namespace gmasim::identify_detail {

void fill_covariance(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u,
                     double h, IdentifyResult& out) {
  const std::size_t n = obj.dim(), m = obj.residual_count();
  const auto p = obj.to_params(u);
  const auto dtheta = obj.theta_per_unit();
  const auto& fit = obj.fit();
  out.parameters.clear();
  for (std::size_t j = 0; j < n; ++j) {
    FittedParameter fp;
    fp.name = obj.names()[j];
    fp.unit = obj.units()[j];
    fp.scale = fit.parameters[j].scale;
    fp.lower = fit.parameters[j].lower;
    fp.upper = fit.parameters[j].upper;
    fp.value = p[j];
    fp.at_bound = u[j] < 1e-6 || u[j] > 1.0 - 1e-6;
    fp.std_error = std::numeric_limits<double>::infinity();
    fp.ci_low = -std::numeric_limits<double>::infinity();
    fp.ci_high = std::numeric_limits<double>::infinity();
    fp.determined = false;
    out.parameters.push_back(fp);
  }
  out.correlation.assign(n, std::vector<double>(n, 0.0));
  out.residual_count = m;
  std::vector<double> r, Jv;
  if (!jacobian(obj, ev, u, h, r, Jv)) {
    out.covariance_ok = false;
    out.covariance_note = "the model cannot be evaluated at the optimum";
    return;
  }
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Ju(
      Jv.data(), static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(n));
  Eigen::MatrixXd J = Ju;
  for (std::size_t j = 0; j < n; ++j) J.col(static_cast<Eigen::Index>(j)) /= dtheta[j];
  double ss = 0.0;
  for (double v : r) ss += v * v;
  const double dof = static_cast<double>(m) - static_cast<double>(n);
  const double s2 = dof > 0 ? ss / dof : 0.0;
  out.residual_sigma = std::sqrt(s2);

  // Column scaling for conditioning; pseudo-inverse with a relative eigenvalue cut.
  Eigen::MatrixXd A = J.transpose() * J;
  Eigen::VectorXd d(static_cast<Eigen::Index>(n));
  for (Eigen::Index j = 0; j < d.size(); ++j) d(j) = A(j, j) > 0 ? 1.0 / std::sqrt(A(j, j)) : 0.0;
  const Eigen::MatrixXd As = d.asDiagonal() * A * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(As);
  const Eigen::VectorXd lam = es.eigenvalues();
  const Eigen::MatrixXd V = es.eigenvectors();
  const double lmax = lam.maxCoeff();
  const double cut = 1e-12 * std::max(lmax, 1e-300);
  Eigen::MatrixXd inv =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  Eigen::VectorXd null_weight = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  int rank_deficiency = 0;
  for (Eigen::Index k = 0; k < lam.size(); ++k) {
    if (lam(k) > cut) {
      inv += V.col(k) * V.col(k).transpose() / lam(k);
    } else {
      ++rank_deficiency;
      null_weight += V.col(k).cwiseAbs2();
    }
  }
  const Eigen::MatrixXd cov = s2 * (d.asDiagonal() * inv * d.asDiagonal());
  out.covariance_ok = true;
  const double cond =
      lam.minCoeff() > 0 ? lmax / lam.minCoeff() : std::numeric_limits<double>::infinity();
  out.covariance_note = fmt::format(
      "{} residuals, {} parameters; residual variance from the fit (m - n degrees of freedom: "
      "RMS sqrt(m / (m - n)) = {:.4g} %); condition number of the column-scaled J^T J {:.3g}",
      m, n, out.residual_sigma * std::sqrt(static_cast<double>(m)), cond);
  if (rank_deficiency > 0) {
    out.covariance_note += fmt::format(
        "; J^T J is rank-deficient by {}: some parameter "
        "combinations are not determined by the data",
        rank_deficiency);
  }
  for (std::size_t j = 0; j < n; ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    auto& fp = out.parameters[j];
    if (d(jj) == 0.0 || null_weight(jj) > 1e-2) continue;  // not determined: infinite interval
    const double sd = std::sqrt(std::max(cov(jj, jj), 0.0));
    if (fp.scale == ParamScale::Log) {
      const double a = fp.value * std::exp(-1.96 * sd), b = fp.value * std::exp(1.96 * sd);
      fp.ci_low = std::min(a, b);
      fp.ci_high = std::max(a, b);
      fp.std_error = std::fabs(fp.value) * sd;
    } else {
      fp.ci_low = fp.value - 1.96 * sd;
      fp.ci_high = fp.value + 1.96 * sd;
      fp.std_error = sd;
    }
    fp.determined = std::isfinite(sd) && (fp.ci_high - fp.ci_low) < (fp.upper - fp.lower);
    for (std::size_t k = 0; k < n; ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      const double den = std::sqrt(cov(jj, jj) * cov(kk, kk));
      out.correlation[j][k] = den > 0 ? cov(jj, kk) / den : 0.0;
    }
  }
}

}  // namespace gmasim::identify_detail
