// What the sensitivities say about identifiability (gmasim/experiments/sensitivity.hpp): the
// Jacobian in units of each quantity's tolerance, its singular directions, and the correlations of
// the parameters a fit to the quantities would have. docs/experiments.md, "Sensitivity".
#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "common/numbers.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/sensitivity.hpp"

namespace gmasim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Singular values of the column-normalised Jacobian below this fraction of the largest are
// raised to it for the covariance (identify's pseudo-inverse cuts eigenvalues of J^T J at
// 1e-12, the same level): a direction no quantity sees keeps a large, finite variance, so a
// pair that enters only as a product shows correlation -1, as a nearly degenerate pair does.
constexpr double kFloor = 1e-6;
// A parameter with more than this weight in the floored directions is not determined.
constexpr double kNullWeight = 1e-2;

// Singular values (padded with zeros to n) and the full right singular vectors of A.
struct Svd {
  Eigen::VectorXd s;
  Eigen::MatrixXd V;
};
Svd svd_full(const Eigen::MatrixXd& A) {
  const auto n = A.cols();
  Svd out;
  out.s = Eigen::VectorXd::Zero(n);
  if (A.rows() == 0) {
    out.V = Eigen::MatrixXd::Identity(n, n);
    return out;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  out.s.head(svd.singularValues().size()) = svd.singularValues();
  out.V = svd.matrixV();
  return out;
}

std::vector<Direction> directions_of(const Eigen::MatrixXd& J, double ratio) {
  const Svd d = svd_full(J);
  const double smax = d.s.size() ? d.s.maxCoeff() : 0.0;
  std::vector<Direction> out;
  for (Eigen::Index k = 0; k < d.s.size(); ++k) {
    Direction dir;
    dir.singular_value = d.s(k);
    dir.ratio = smax > 0 ? d.s(k) / smax : 0.0;
    dir.near_null = dir.ratio < ratio;
    dir.weak = d.s(k) < 1.0;
    Eigen::VectorXd v = d.V.col(k);
    Eigen::Index big = 0;
    v.cwiseAbs().maxCoeff(&big);
    if (v(big) < 0) v = -v;  // sign convention: the largest component positive
    dir.components.assign(v.data(), v.data() + v.size());
    out.push_back(std::move(dir));
  }
  return out;  // JacobiSVD sorts decreasing; the padded zeros come last
}

// Correlations and standard deviations from C = D (A^T A)^-1 D, A = J D.
void covariance(const Eigen::MatrixXd& J, const Eigen::VectorXd& norm, Identifiability& id) {
  const auto n = J.cols();
  Eigen::VectorXd D = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) D(j) = norm(j) > 0 ? 1.0 / norm(j) : 0.0;
  const Svd d = svd_full(J * D.asDiagonal());
  const double smax = d.s.size() ? d.s.maxCoeff() : 0.0;
  id.correlation.assign(static_cast<std::size_t>(n), std::vector<double>(n, kNaN));
  id.std_dev.assign(static_cast<std::size_t>(n), kNaN);
  id.condition = kInf;
  if (!(smax > 0)) return;
  const double floor = kFloor * smax;
  Eigen::MatrixXd Cn = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd null_weight = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double s = std::max(d.s(k), floor);
    Cn += d.V.col(k) * d.V.col(k).transpose() / (s * s);
    if (d.s(k) < floor) null_weight += d.V.col(k).cwiseAbs2();
  }
  const double smin = d.s.minCoeff();
  id.condition = smin > 0 ? smax / smin : kInf;
  const Eigen::MatrixXd C = D.asDiagonal() * Cn * D.asDiagonal();
  for (Eigen::Index j = 0; j < n; ++j) {
    if (D(j) == 0.0) continue;  // no quantity sees parameter j
    const auto jj = static_cast<std::size_t>(j);
    id.std_dev[jj] = null_weight(j) > kNullWeight ? kInf : std::sqrt(std::max(C(j, j), 0.0));
    for (Eigen::Index k = 0; k < n; ++k) {
      if (D(k) == 0.0) continue;
      const double den = std::sqrt(C(j, j) * C(k, k));
      id.correlation[jj][static_cast<std::size_t>(k)] = den > 0 ? C(j, k) / den : kNaN;
    }
  }
}

}  // namespace

Identifiability analyse_identifiability(const std::vector<std::string>& quantities,
                                        const std::vector<double>& scales,
                                        const std::vector<std::vector<double>>& scaled_jacobian,
                                        std::size_t parameters, double near_null_ratio) {
  if (quantities.size() != scales.size() || quantities.size() != scaled_jacobian.size())
    throw InputError("identifiability: quantities, scales and Jacobian rows differ in number");
  const auto m = static_cast<Eigen::Index>(quantities.size());
  const auto n = static_cast<Eigen::Index>(parameters);
  Eigen::MatrixXd J(m, n);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& row = scaled_jacobian[static_cast<std::size_t>(i)];
    const double sc = scales[static_cast<std::size_t>(i)];
    if (row.size() != parameters || !(std::isfinite(sc) && sc > 0))
      throw InputError(
          fmt::format("identifiability: quantity {}: needs {} finite entries and a "
                      "scale > 0",
                      quantities[static_cast<std::size_t>(i)], parameters));
    for (Eigen::Index j = 0; j < n; ++j) {
      const double v = row[static_cast<std::size_t>(j)];
      if (!std::isfinite(v))
        throw InputError(fmt::format("identifiability: quantity {}: entry {} is not finite",
                                     quantities[static_cast<std::size_t>(i)], j));
      J(i, j) = v / sc;
    }
  }
  Identifiability id;
  id.quantities = quantities;
  id.jacobian.assign(static_cast<std::size_t>(m), std::vector<double>(parameters));
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      id.jacobian[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = J(i, j);
  const Eigen::VectorXd norm = J.colwise().norm().transpose();
  id.column_norm.assign(norm.data(), norm.data() + norm.size());
  id.directions = directions_of(J, near_null_ratio);
  for (const auto& d : id.directions) id.rank += d.near_null ? 0 : 1;
  covariance(J, norm, id);
  return id;
}

std::string direction_text(const Direction& d, const std::vector<ParameterInfo>& params) {
  std::vector<std::size_t> order(d.components.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return std::fabs(d.components[a]) > std::fabs(d.components[b]);
  });
  std::string s;
  for (std::size_t j : order) {
    const double c = d.components[j];
    if (std::fabs(c) < 0.1 || j >= params.size()) continue;
    const ParameterInfo& p = params[j];
    const std::string term = p.step == StepKind::Log ? fmt::format("ln({})", p.name)
                                                     : fmt::format("({}/{:.3g})", p.name, p.scale);
    s += fmt::format("{}{:+.2f} {}", s.empty() ? "" : " ", c, term);
  }
  return s;
}

}  // namespace gmasim
