// Local refinement of the GA champion: Levenberg-Marquardt (Ceres) on the normalised
// residuals, in u-space with the bounds [0, 1]. The Jacobian is a central difference whose
// 2n + 1 evaluations run as one batch over the threads and MPI ranks (BatchEvaluator); every
// rank runs the same solver on bit-identical numbers, so they stay in lockstep.
#include <ceres/ceres.h>
#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "internal.hpp"

namespace gmasim::identify_detail {

bool jacobian(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u, double h,
              std::vector<double>& r, std::vector<double>& J, int fixed) {
  const std::size_t n = obj.dim(), m = obj.residual_count();
  // Points: the centre, then u + h e_j and u - h e_j for every free column (clipped to the
  // bounds: one-sided there). A fixed column (a profile) is not differentiated.
  std::vector<std::vector<double>> pts{u};
  std::vector<std::size_t> cols;
  std::vector<double> up(n), um(n);
  for (std::size_t j = 0; j < n; ++j) {
    if (static_cast<int>(j) == fixed) continue;
    auto p = u, q = u;
    up[j] = p[j] = std::min(1.0, u[j] + h);
    um[j] = q[j] = std::max(0.0, u[j] - h);
    pts.push_back(std::move(p));
    pts.push_back(std::move(q));
    cols.push_back(j);
  }
  std::vector<std::vector<double>> res;
  const auto ok = ev.run(pts, res);
  if (!ok[0]) return false;
  r = res[0];
  J.assign(m * n, 0.0);
  for (std::size_t k = 0; k < cols.size(); ++k) {
    const std::size_t j = cols[k];
    const bool okp = ok[1 + 2 * k] != 0, okm = ok[2 + 2 * k] != 0;
    const std::vector<double>* a = okp ? &res[1 + 2 * k] : &res[0];
    const std::vector<double>* b = okm ? &res[2 + 2 * k] : &res[0];
    const double da = okp ? up[j] : u[j], db = okm ? um[j] : u[j];
    if (da == db) continue;  // neither side evaluates: no information on this column
    for (std::size_t i = 0; i < m; ++i) J[i * n + j] = ((*a)[i] - (*b)[i]) / (da - db);
  }
  return true;
}

namespace {

class FdCost final : public ceres::CostFunction {
 public:
  FdCost(const Objective& obj, BatchEvaluator& ev, double h, int fixed = -1)
      : obj_(obj), ev_(ev), h_(h), fixed_(fixed) {
    set_num_residuals(static_cast<int>(obj.residual_count()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(obj.dim()));
  }
  // Ceres asks for the Jacobian at an accepted point twice (and for residuals at points it
  // has seen): the last point's residuals and Jacobian are kept and reused, since each
  // Jacobian costs 2n + 1 model evaluations. Ceres calls this from one thread.
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const std::size_t n = obj_.dim(), m = obj_.residual_count();
    const std::vector<double> u(parameters[0], parameters[0] + n);
    const bool want_j = jacobians && jacobians[0];
    if (!(u == last_u_ && (last_has_j_ || !want_j))) {
      if (want_j) {
        if (!jacobian(obj_, ev_, u, h_, last_r_, last_J_, fixed_)) return false;
      } else {
        std::vector<std::vector<double>> res;
        const auto ok = ev_.run({u}, res);
        if (!ok[0]) return false;
        last_r_ = std::move(res[0]);
      }
      last_u_ = u;
      last_has_j_ = want_j;
    }
    std::copy(last_r_.begin(), last_r_.begin() + static_cast<std::ptrdiff_t>(m), residuals);
    if (want_j) std::copy(last_J_.begin(), last_J_.end(), jacobians[0]);  // row-major m x n
    return true;
  }

 private:
  const Objective& obj_;
  BatchEvaluator& ev_;
  double h_;
  int fixed_;
  mutable std::vector<double> last_u_, last_r_, last_J_;
  mutable bool last_has_j_ = false;
};

class Callback final : public ceres::IterationCallback {
 public:
  Callback(const IdentifyOptions& o, Collective& comm,
           const std::function<void(int, double)>& on_iteration, const BatchEvaluator& ev,
           long eval_cap)
      : o_(o), comm_(comm), on_iteration_(on_iteration), ev_(ev), eval_cap_(eval_cap) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (on_iteration_) on_iteration_(s.iteration, std::sqrt(2.0 * s.cost));
    if (any_rank(comm_, o_.stop && o_.stop->load())) {
      interrupted = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;  // keeps the last accepted point
    }
    // The evaluation budget (the same count on every rank: they stay in lockstep).
    if (eval_cap_ >= 0 && ev_.evaluations() > eval_cap_) {
      capped = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    // Stall: the last kStall successful steps together lowered the cost by less than
    // kStallTol (relative). With noisy data LM otherwise crawls along flat valleys of
    // undetermined parameters for many iterations without a visible gain.
    if (s.iteration == 0 || s.step_is_successful) accepted_.push_back(s.cost);
    const std::size_t k = accepted_.size();
    if (k > kStall &&
        accepted_[k - 1 - kStall] - accepted_[k - 1] <= kStallTol * accepted_[k - 1]) {
      stalled = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool interrupted = false, stalled = false, capped = false;
  static constexpr std::size_t kStall = 4;
  static constexpr double kStallTol = 1e-4;

 private:
  const IdentifyOptions& o_;
  Collective& comm_;
  const std::function<void(int, double)>& on_iteration_;
  const BatchEvaluator& ev_;
  long eval_cap_;
  std::vector<double> accepted_;
};

}  // namespace

RefineOutcome refine_lm(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u0,
                        const IdentifyOptions& o, Collective& comm,
                        const std::function<void(int, double)>& on_iteration, int fixed,
                        int max_iterations, long eval_cap) {
  const std::size_t n = obj.dim();
  std::vector<double> u = u0;
  for (double& v : u) v = std::clamp(v, 0.0, 1.0);
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  problem.AddResidualBlock(new FdCost(obj, ev, o.fd_step, fixed), nullptr, u.data());
  if (fixed >= 0) {
    if (n == 1) {
      problem.SetParameterBlockConstant(u.data());
    } else {
      problem.SetManifold(u.data(), new ceres::SubsetManifold(static_cast<int>(n), {fixed}));
    }
  }
  for (std::size_t j = 0; j < n; ++j) {
    problem.SetParameterLowerBound(u.data(), static_cast<int>(j), 0.0);
    problem.SetParameterUpperBound(u.data(), static_cast<int>(j), 1.0);
  }
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = max_iterations >= 0 ? max_iterations : o.refine_iterations;
  so.function_tolerance = 1e-7;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-8;
  // With the bounds Ceres runs a projected Armijo line search along every step; its default
  // cubic interpolation asks for the gradient at each trial point, a full finite-difference
  // Jacobian (2n + 1 evaluations) here. The quadratic interpolation needs the values only.
  so.line_search_interpolation_type = ceres::QUADRATIC;
  so.num_threads = 1;  // parallelism is inside the Jacobian batch
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  Callback cb(o, comm, on_iteration, ev, eval_cap);
  so.callbacks.push_back(&cb);
  so.update_state_every_iteration = true;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  RefineOutcome out;
  out.u = u;
  out.f = std::sqrt(2.0 * summary.final_cost);
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.interrupted = cb.interrupted;
  out.capped = cb.capped;
  out.summary = fmt::format(
      "Ceres Levenberg-Marquardt: {} iterations, RMS {:.4g} % -> {:.4g} %, {}", out.iterations,
      std::sqrt(2.0 * summary.initial_cost), out.f,
      cb.stalled ? "converged (the RMS changed by < 0.005 % over 4 steps)" : summary.message);
  if (!summary.IsSolutionUsable()) {
    out.u = u0;
    out.f = std::sqrt(2.0 * summary.initial_cost);
  }
  return out;
}

}  // namespace gmasim::identify_detail
