// Confidence intervals and correlations from the Jacobian of the normalised residuals at the
// optimum: theta = p (linear) or ln|p| (log parameters), cov = s^2 (J^T J)^-1 with
// s^2 = sum r^2 / (m - n), 95 % interval = 1.96 sigma (log: multiplicative).
#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "internal.hpp"

namespace gmasim::identify_detail {

namespace {

// Profile likelihood of one parameter at a time: the range of u_j over which the weighted
// sum of squares, minimised over the other parameters, stays within `thr` of its minimum
// `chi_opt`. Marches out from the optimum to each bound (warm-started LM with u_j held),
// then refines the crossing by two bisections and a linear interpolation. Every point is
// charged to the stage's evaluation budget (ProfileOutcome); a side the budget cuts short
// keeps its bound as the interval's edge (conservative). Remembers the lowest point seen.
class Profiler {
 public:
  Profiler(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u, double chi_opt,
           double thr, const IdentifyOptions& o, Collective& comm, ProfileOutcome& prof)
      : obj_(obj), ev_(ev), u_(u), chi_opt_(chi_opt), thr_(thr), o_(o), comm_(comm), prof_(prof) {
    prof_.lowest_f = std::sqrt(chi_opt);
    prof_.lowest_u = u;
  }

  // The interval of u_j, the k-th of n to profile, spending at most `allowance` evaluations;
  // `cut` is set when the allowance ended a side early.
  std::pair<double, double> interval(std::size_t j, std::size_t k, std::size_t n, long allowance,
                                     bool& cut) {
    k_ = k;
    n_ = n;
    end_ = allowance < 0 ? -1 : ev_.evaluations() + allowance;
    cut = false;
    double edge[2] = {0.0, 1.0};
    for (int side = 0; side < 2; ++side) {
      const double bound = side == 0 ? 0.0 : 1.0;
      if (std::fabs(u_[j] - bound) < 1e-9) continue;  // the optimum is on this bound
      const auto e = side_edge(j, side == 0 ? -1.0 : 1.0, bound);
      if (e) {
        edge[side] = *e;
      } else {
        cut = true;
      }
    }
    return {edge[0], edge[1]};
  }

 private:
  // One LM solve costs at most (2n + 1) evaluations per iteration.
  long per_iteration() const { return 2 * static_cast<long>(obj_.dim()) + 1; }

  // chi^2 at u_j = uj, the others re-fitted from `warm` (updated); nullopt when the budget
  // does not allow a converged solve.
  std::optional<double> chi_at(std::vector<double>& warm, std::size_t j, double uj) {
    constexpr int kIterations = 20;  // warm-started; the stall rule ends converged solves early
    if (end_ >= 0 && ev_.evaluations() + 2 * per_iteration() > end_) return std::nullopt;
    warm[j] = uj;
    const long cap = end_ < 0 ? -1 : end_ - per_iteration();
    const RefineOutcome ro =
        refine_lm(obj_, ev_, warm, o_, comm_, {}, static_cast<int>(j), kIterations, cap);
    warm = ro.u;
    const double chi = ro.f * ro.f;
    if (ro.f < prof_.lowest_f) {  // a point better than the optimum: kept even if capped
      prof_.lowest_f = ro.f;
      prof_.lowest_u = ro.u;
    }
    if (comm_.rank() == 0 && o_.progress) {  // the stage can take minutes: say where it is
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
      o_.progress({"profile", static_cast<int>(k_ + 1), static_cast<int>(n_), obj_.names()[j], ro.f,
                   ev_.evaluations(), 0.0, wall});
    }
    if (ro.capped) return std::nullopt;  // not minimised over the others: no profile value
    return chi;
  }

  // Where the profile crosses the threshold between the optimum and `bound` (u-space);
  // the bound if it does not; nullopt if the budget ended the march first.
  std::optional<double> side_edge(std::size_t j, double dir, double bound) {
    constexpr double kSteps[] = {0.04, 0.12, 0.3, 0.6, 1.0};
    std::vector<double> warm = u_, ok_warm = u_;
    double ok_u = u_[j], ok_d = 0.0, out_u = bound, out_d = 0.0;
    bool crossed = false;
    for (double st : kSteps) {
      const double uj = std::clamp(u_[j] + dir * st, 0.0, 1.0);
      const auto chi = chi_at(warm, j, uj);
      if (!chi) return std::nullopt;
      const double d = *chi - chi_opt_;
      if (d > thr_) {
        crossed = true;
        out_u = uj;
        out_d = d;
        break;
      }
      ok_u = uj;
      ok_d = d;
      ok_warm = warm;
      if (uj == bound) break;
    }
    if (!crossed) return bound;  // within the threshold up to the bound
    for (int b = 0; b < 2; ++b) {
      const double mid = 0.5 * (ok_u + out_u);
      std::vector<double> w = ok_warm;
      const auto chi = chi_at(w, j, mid);
      if (!chi) break;  // the crossing is between ok_u and out_u: interpolate what we have
      const double d = *chi - chi_opt_;
      if (d > thr_) {
        out_u = mid;
        out_d = d;
      } else {
        ok_u = mid;
        ok_d = d;
        ok_warm = w;
      }
    }
    // Linear interpolation of the excess between the last point inside and the first out.
    const double f = out_d > ok_d ? (thr_ - ok_d) / (out_d - ok_d) : 0.5;
    return ok_u + std::clamp(f, 0.0, 1.0) * (out_u - ok_u);
  }

  const Objective& obj_;
  BatchEvaluator& ev_;
  std::size_t k_ = 0, n_ = 0;  // the parameter being profiled, of n (progress)
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  const std::vector<double>& u_;
  double chi_opt_, thr_;
  const IdentifyOptions& o_;
  Collective& comm_;
  ProfileOutcome& prof_;
  long end_ = -1;  // ev_.evaluations() at which this parameter's allowance ends (-1: none)
};

// Parameter j at u before its interval is known: an infinite standard error, and the
// bounds as its (linearised) interval.
FittedParameter unbounded_parameter(const Objective& obj, std::size_t j, double value, double uj) {
  FittedParameter fp = fitted_parameter(obj, j, value);
  fp.at_bound = uj < 1e-6 || uj > 1.0 - 1e-6;
  fp.std_error = std::numeric_limits<double>::infinity();
  fp.ci_method = "linearised";
  fp.wald_low = -std::numeric_limits<double>::infinity();
  fp.wald_high = std::numeric_limits<double>::infinity();
  fp.determined = false;
  fp.ci_low = fp.lower;
  fp.ci_high = fp.upper;
  return fp;
}

// The Jacobian of the residuals (m x n, row-major, per unit of u) per unit of theta.
Eigen::MatrixXd jacobian_in_theta(const std::vector<double>& Jv, std::size_t m, std::size_t n,
                                  const std::vector<double>& dtheta) {
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Ju(
      Jv.data(), static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(n));
  Eigen::MatrixXd J = Ju;
  for (std::size_t j = 0; j < n; ++j) J.col(static_cast<Eigen::Index>(j)) /= dtheta[j];
  return J;
}

// cov = s^2 (J^T J)^+ in theta, through the column-scaled J^T J (for conditioning) and its
// pseudo-inverse with a relative eigenvalue cut.
struct Covariance {
  Eigen::MatrixXd cov;
  Eigen::VectorXd d;            // the column scaling 1 / sqrt((J^T J)_jj); 0: a zero column
  Eigen::VectorXd null_weight;  // each parameter's weight in the cut (null) eigenvectors
  int rank_deficiency = 0;      // eigenvalues cut
  double condition = 0.0;       // condition number of the column-scaled J^T J
};

Covariance scaled_covariance(const Eigen::MatrixXd& J, double s2) {
  const Eigen::Index n = J.cols();
  Covariance c;
  Eigen::MatrixXd A = J.transpose() * J;
  c.d.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) c.d(j) = A(j, j) > 0 ? 1.0 / std::sqrt(A(j, j)) : 0.0;
  const Eigen::MatrixXd As = c.d.asDiagonal() * A * c.d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(As);
  const Eigen::VectorXd lam = es.eigenvalues();
  const Eigen::MatrixXd V = es.eigenvectors();
  const double lmax = lam.maxCoeff();
  const double cut = 1e-12 * std::max(lmax, 1e-300);
  Eigen::MatrixXd inv = Eigen::MatrixXd::Zero(n, n);
  c.null_weight = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < lam.size(); ++k) {
    if (lam(k) > cut) {
      inv += V.col(k) * V.col(k).transpose() / lam(k);
    } else {
      ++c.rank_deficiency;
      c.null_weight += V.col(k).cwiseAbs2();
    }
  }
  c.cov = s2 * (c.d.asDiagonal() * inv * c.d.asDiagonal());
  c.condition =
      lam.minCoeff() > 0 ? lmax / lam.minCoeff() : std::numeric_limits<double>::infinity();
  return c;
}

std::string covariance_note(std::size_t m, std::size_t n, double residual_sigma,
                            const Covariance& c) {
  std::string note = fmt::format(
      "{} residuals, {} parameters; residual variance from the fit (m - n degrees of freedom: "
      "RMS sqrt(m / (m - n)) = {:.4g} %); condition number of the column-scaled J^T J {}",
      m, n, residual_sigma * std::sqrt(static_cast<double>(m)),
      std::isfinite(c.condition) ? fmt::format("{:.3g}", c.condition)
                                 : std::string("infinite (singular)"));
  if (c.rank_deficiency > 0) {
    note += fmt::format(
        "; J^T J is rank-deficient by {}: some parameter "
        "combinations are not determined by the data",
        c.rank_deficiency);
  }
  return note;
}

// The linearised 95 % interval of a parameter of standard deviation sd in theta (1.96 sd;
// multiplicative for a log parameter); it is the parameter's interval when it is narrower
// than the bounds.
void set_linearised_interval(FittedParameter& fp, double sd) {
  if (fp.scale == ParamScale::Log) {
    const double a = fp.value * std::exp(-1.96 * sd), b = fp.value * std::exp(1.96 * sd);
    fp.wald_low = std::min(a, b);
    fp.wald_high = std::max(a, b);
    fp.std_error = std::fabs(fp.value) * sd;
    fp.determined = std::isfinite(sd) && 2.0 * 1.96 * sd < std::fabs(std::log(fp.upper / fp.lower));
  } else {
    fp.wald_low = fp.value - 1.96 * sd;
    fp.wald_high = fp.value + 1.96 * sd;
    fp.std_error = sd;
    fp.determined = std::isfinite(sd) && 2.0 * 1.96 * sd < fp.upper - fp.lower;
  }
  if (fp.determined) {
    fp.ci_low = fp.wald_low;
    fp.ci_high = fp.wald_high;
  }
}

// Intervals and correlations of the parameters outside the null space of J^T J (the others
// keep their infinite interval).
void set_linearised_intervals(const Covariance& c, IdentifyResult& out) {
  const std::size_t n = out.parameters.size();
  for (std::size_t j = 0; j < n; ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    if (c.d(jj) == 0.0 || c.null_weight(jj) > 1e-2) continue;  // not determined
    set_linearised_interval(out.parameters[j], std::sqrt(std::max(c.cov(jj, jj), 0.0)));
    for (std::size_t k = 0; k < n; ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      const double den = std::sqrt(c.cov(jj, jj) * c.cov(kk, kk));
      out.correlation[j][k] = den > 0 ? c.cov(jj, kk) / den : 0.0;
    }
  }
}

// Profile likelihood where the linearisation cannot hold: a parameter on a bound (the
// optimum is not stationary there) or whose linearised interval leaves the bounds. The
// stage's budget is shared out evenly over the parameters still to profile.
void set_profile_intervals(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u,
                           double f, double dof, const IdentifyOptions& o, Collective& comm,
                           IdentifyResult& out, ProfileOutcome& prof) {
  const double chi_opt = f * f;
  const double thr = 3.841458820694124 * chi_opt / dof;  // chi^2_1(95 %) s^2
  const long ev0 = ev.evaluations();
  const auto t0 = std::chrono::steady_clock::now();
  Profiler profiler(obj, ev, u, chi_opt, thr, o, comm, prof);
  std::vector<std::size_t> todo;
  for (std::size_t j = 0; j < out.parameters.size(); ++j) {
    const auto& fp = out.parameters[j];
    const bool leaves = !(fp.wald_low >= fp.lower && fp.wald_high <= fp.upper);
    if (fp.at_bound || leaves) todo.push_back(j);
  }
  std::string names, cut_names;
  for (std::size_t k = 0; k < todo.size(); ++k) {
    const std::size_t j = todo[k];
    auto& fp = out.parameters[j];
    const long spent = ev.evaluations() - ev0;
    const long allowance =
        prof.budget < 0 ? -1
                        : std::max(0L, prof.budget - spent) / static_cast<long>(todo.size() - k);
    bool cut = false;
    const auto [ulo, uhi] = profiler.interval(j, k, todo.size(), allowance, cut);
    std::vector<double> a = u, b = u;
    a[j] = ulo;
    b[j] = uhi;
    const double pa = obj.to_params(a)[j], pb = obj.to_params(b)[j];
    fp.ci_low = std::min(pa, pb);
    fp.ci_high = std::max(pa, pb);
    fp.ci_method = "profile";
    fp.determined = !(ulo <= 1e-9 && uhi >= 1.0 - 1e-9);
    names += (names.empty() ? "" : ", ") + fp.name;
    if (cut) cut_names += (cut_names.empty() ? "" : ", ") + fp.name;
  }
  prof.evaluations = ev.evaluations() - ev0;
  prof.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  prof.budget_hit = !cut_names.empty();
  if (!names.empty()) {
    out.covariance_note += fmt::format(
        "; profile-likelihood intervals (the other parameters re-fitted, Delta chi^2 = 3.84 "
        "s^2) for {}",
        names);
  }
  if (!cut_names.empty()) {
    out.notes.push_back(fmt::format(
        "the profile stage's budget ({} evaluations, --profile-evaluations) ended the profile of "
        "{} before its crossing: that side's interval edge is the bound (conservative); raise "
        "--profile-evaluations for the exact edge",
        prof.budget, cut_names));
  }
}

}  // namespace

FittedParameter fitted_parameter(const Objective& obj, std::size_t j, double value) {
  const auto& spec = obj.fit().parameters[j];
  FittedParameter fp;
  fp.name = obj.names()[j];
  fp.unit = obj.units()[j];
  fp.scale = spec.scale;
  fp.lower = spec.lower;
  fp.upper = spec.upper;
  fp.value = value;
  return fp;
}

void fill_covariance(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u,
                     double f, const IdentifyOptions& o, Collective& comm, IdentifyResult& out,
                     ProfileOutcome& prof) {
  prof.lowest_f = f;
  prof.lowest_u = u;
  const std::size_t n = obj.dim(), m = obj.residual_count();
  const auto p = obj.to_params(u);
  out.parameters.clear();
  for (std::size_t j = 0; j < n; ++j)
    out.parameters.push_back(unbounded_parameter(obj, j, p[j], u[j]));
  out.correlation.assign(n, std::vector<double>(n, 0.0));
  out.residual_count = m;
  std::vector<double> r, Jv;
  if (!jacobian(obj, ev, u, o.fd_step, r, Jv)) {
    out.covariance_ok = false;
    out.covariance_note = "the model cannot be evaluated at the optimum";
    return;
  }
  const Eigen::MatrixXd J = jacobian_in_theta(Jv, m, n, obj.theta_per_unit());
  double ss = 0.0;
  for (double v : r) ss += v * v;
  const double dof = static_cast<double>(m) - static_cast<double>(n);
  if (!(dof > 0)) {  // no residual degrees of freedom: the scatter, and so s^2, is unknown
    out.covariance_ok = false;
    out.covariance_note = fmt::format(
        "{} residuals for {} parameters: no residual degrees of freedom, so the residual "
        "variance, and with it every interval, cannot be estimated (the fit solves its targets; "
        "`gmasim sensitivity` shows how well they pin each parameter)",
        m, n);
    return;
  }
  const double s2 = ss / dof;
  out.residual_sigma = std::sqrt(s2);
  const Covariance c = scaled_covariance(J, s2);
  out.covariance_ok = true;
  out.covariance_note = covariance_note(m, n, out.residual_sigma, c);
  set_linearised_intervals(c, out);
  if (!o.profile || !(dof > 0)) return;
  set_profile_intervals(obj, ev, u, f, dof, o, comm, out, prof);
}

}  // namespace gmasim::identify_detail
