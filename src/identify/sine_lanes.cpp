// The scalar targets' biased-sine runs in SIMD lanes (objective_runs.hpp, run_sines_lanes):
// every run advances in its own lane with what run_sine does for one of them -- the same
// start state (StartCache), grid (StepClock::Uniform, sine_target_grid), drive and last-period
// metrics -- and each held run (the frf targets' DC settling) with what its run_loop does.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "identify/objective_runs.hpp"

namespace gmasim::identify_detail {

namespace {

// One sine run's rows: the last period and its closing row.
struct LaneSineRows {
  std::vector<double> I, y, B;
};

// A sine run's drive, grid and wanted measures (the same for every point of a batch).
struct LaneSineRun {
  Waveform w;
  SineGrid g;
  LoopMetricsWanted want;
};

SineMetrics metrics_of(const LaneSineRows& ls, const LoopMetricsWanted& want) {
  const std::size_t rows = ls.I.size();
  std::vector<double> t(rows);  // uniform: only the spacing matters to the refinement
  for (std::size_t k = 0; k < rows; ++k) t[k] = static_cast<double>(k);
  const LoopMetrics L = loop_metrics(t, ls.I, ls.y, ls.B, 0, rows - 1, want);
  SineMetrics r;
  r.stroke_um = L.stroke_um;
  r.B_pp_T = L.B_pp_T;
  r.hysteresis_um = L.hysteresis_um;
  return r;
}

// The lanes of a batch: sine k of point c in lane k P + c, then every point's held runs.
struct SineLanes {
  std::size_t n = 0, P = 0;  // sine runs, points
  std::vector<LaneSineRun> run;
  std::vector<LaneSineRows> rows;        // per sine lane
  std::vector<std::size_t> held_point;   // per held lane: its point
  std::vector<const HeldRun*> held;      // per held lane
  std::vector<const Model*> models;      // per lane
  std::vector<const Conditions*> conds;  // per lane
  std::vector<const State*> states;      // per lane
  std::vector<const StepGrid*> grid;     // per lane
};

// The sine lanes' grids, start states and first rows; the held lanes after them.
void set_up_sines(SineLanes& L, std::vector<SinePoint>& points, const std::vector<SineRun>& runs,
                  const ObjectiveSettings& s) {
  const std::size_t n = runs.size(), P = points.size();
  L.n = n;
  L.P = P;
  L.run.resize(n);
  L.rows.resize(n * P);
  for (std::size_t k = 0; k < n; ++k) {
    L.run[k].w = biased_sine(runs[k].pp, runs[k].f, runs[k].min);
    L.run[k].g = sine_target_grid(runs[k], s);
    L.run[k].want = runs[k].want;
  }
  for (std::size_t l = 0; l < n * P; ++l) {
    const std::size_t k = l / P, c = l % P;
    const LaneSineRun& lr = L.run[k];
    const auto& cs = points[c].starts->get(runs[k].T, lr.w.current_at(0.0));
    L.models.push_back(points[c].m);
    L.conds.push_back(&cs.first);
    L.states.push_back(&cs.second);
    L.grid.push_back(&lr.g.grid);
    const auto nrows = static_cast<std::size_t>(lr.g.per_period) + 1;
    LaneSineRows& r = L.rows[l];
    r.I.assign(nrows, 0.0);
    r.y.assign(nrows, 0.0);
    r.B.assign(nrows, 0.0);
    if (lr.g.grid.steps == lr.g.per_period) {  // one period: its first row is the start
      r.I[0] = cs.second.current_A;
      r.y[0] = cs.second.y_m * 1e6;
      r.B[0] = cs.second.B_T;
    }
  }
  for (std::size_t c = 0; c < P; ++c)
    for (const HeldRun& h : points[c].held) {
      L.held_point.push_back(c);
      L.held.push_back(&h);
      L.models.push_back(points[c].m);
      L.conds.push_back(h.c);
      L.states.push_back(h.s);
      L.grid.push_back(&h.grid);
    }
}

// The lanes' times and drives of step q (StepClock::Uniform; a finished lane idles), each sine's
// computed once for its points.
void sine_inputs(const SineLanes& L, const std::vector<SineRun>& runs, long q,
                 std::vector<double>& current, std::vector<double>& dt, std::vector<double>& t1) {
  const std::size_t nl = L.grid.size(), ns = L.n * L.P;
  for (std::size_t k = 0; k < L.n; ++k) {
    const StepGrid& g = L.run[k].g.grid;
    const long kk = std::min(q, g.steps);
    const double t = g.t0_s + static_cast<double>(kk) * g.dt_s;
    const std::vector<double>& drive = runs[k].drive_A;  // sine_drive: the same numbers
    const double I = drive.empty() ? L.run[k].w.current_at(t) : drive[static_cast<std::size_t>(kk)];
    for (std::size_t l = k * L.P; l < (k + 1) * L.P; ++l) {
      t1[l] = t;
      dt[l] = g.dt_s;
      current[l] = I;
    }
  }
  for (std::size_t l = ns; l < nl; ++l) {
    const StepGrid& g = *L.grid[l];
    t1[l] = g.t0_s + static_cast<double>(std::min(q, g.steps)) * g.dt_s;
    dt[l] = g.dt_s;
    current[l] = L.held[l - ns]->I;
  }
}

}  // namespace

void run_sines_lanes(std::vector<SinePoint>& points, const std::vector<SineRun>& runs,
                     const ObjectiveSettings& s, bool throw_first) {
  SineLanes L;
  set_up_sines(L, points, runs, s);
  const std::size_t nl = L.grid.size(), ns = L.n * L.P;
  long longest = 0;
  for (const StepGrid* g : L.grid) longest = std::max(longest, g->steps);
  LaneBatch batch(L.models, L.conds, L.states);
  for (std::size_t l = 0; l < nl; ++l) batch.set_time(l, L.grid[l]->t0_s);
  std::vector<double> current(nl), dt(nl), t1(nl);
  std::size_t stopped = 0;  // the lanes diverged so far
  for (long q = 1; q <= longest; ++q) {
    sine_inputs(L, runs, q, current, dt, t1);
    batch.step(current, dt, t1);
    const std::size_t now_stopped = batch.diverged_count();
    const bool new_stops = now_stopped != stopped;
    stopped = now_stopped;
    for (std::size_t l = 0; l < nl; ++l) {
      const long total = L.grid[l]->steps;
      if (q > total) continue;
      SinePoint& pt = points[l < ns ? l % L.P : L.held_point[l - ns]];
      if (pt.failed) continue;
      if (new_stops && batch.diverged(l)) {
        if (throw_first) throw DivergenceError(batch.error(l));
        pt.failed = true;  // the point's residuals() fails: its metrics are not used
        continue;
      }
      if (l >= ns) {
        if (q == total) batch.unpack(l, *L.held[l - ns]->s);
        continue;
      }
      const long first = total - L.run[l / L.P].g.per_period;
      if (q < first) continue;
      const auto i = static_cast<std::size_t>(q - first);
      L.rows[l].I[i] = current[l];
      L.rows[l].y[i] = batch.y_m(l) * 1e6;
      L.rows[l].B[i] = batch.B_T(l);
    }
  }
  for (std::size_t c = 0; c < L.P; ++c) {
    if (points[c].failed) continue;
    points[c].metrics.resize(L.n);
    for (std::size_t k = 0; k < L.n; ++k)
      points[c].metrics[k] = metrics_of(L.rows[k * L.P + c], L.run[k].want);
  }
}

std::vector<SineMetrics> run_sines_lanes(const Model& m, const std::vector<SineRun>& runs,
                                         const ObjectiveSettings& s, StartCache& starts,
                                         const std::vector<HeldRun>& held) {
  std::vector<SinePoint> one(1);
  one[0].m = &m;
  one[0].starts = &starts;
  one[0].held = held;
  run_sines_lanes(one, runs, s, true);
  return std::move(one[0].metrics);
}

}  // namespace gmasim::identify_detail
