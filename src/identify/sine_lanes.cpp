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

struct LaneSine {
  Waveform w;
  SineGrid g;
  LoopMetricsWanted want;
  std::vector<double> I, y, B;  // the last period and its closing row
};

SineMetrics metrics_of(const LaneSine& ls) {
  const std::size_t rows = ls.I.size();
  std::vector<double> t(rows);  // uniform: only the spacing matters to the refinement
  for (std::size_t k = 0; k < rows; ++k) t[k] = static_cast<double>(k);
  const LoopMetrics L = loop_metrics(t, ls.I, ls.y, ls.B, 0, rows - 1, ls.want);
  SineMetrics r;
  r.stroke_um = L.stroke_um;
  r.B_pp_T = L.B_pp_T;
  r.hysteresis_um = L.hysteresis_um;
  return r;
}

}  // namespace

std::vector<SineMetrics> run_sines_lanes(const Model& m, const std::vector<SineRun>& runs,
                                         const ObjectiveSettings& s, StartCache& starts,
                                         const std::vector<HeldRun>& held) {
  const std::size_t n = runs.size(), nl = n + held.size();  // the sines' lanes, then the held
  std::vector<LaneSine> ls(n);
  std::vector<const Model*> models(nl, &m);
  std::vector<const Conditions*> conds(nl);
  std::vector<const State*> states(nl);
  std::vector<const StepGrid*> grid(nl);
  long longest = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const SineRun& run = runs[k];
    ls[k].w = biased_sine(run.pp, run.f, run.min);
    ls[k].g = sine_target_grid(run, s);
    ls[k].want = run.want;
    const auto& cs = starts.get(run.T, ls[k].w.current_at(0.0));
    conds[k] = &cs.first;
    states[k] = &cs.second;
    grid[k] = &ls[k].g.grid;
    const auto rows = static_cast<std::size_t>(ls[k].g.per_period) + 1;
    ls[k].I.assign(rows, 0.0);
    ls[k].y.assign(rows, 0.0);
    ls[k].B.assign(rows, 0.0);
    if (ls[k].g.grid.steps == ls[k].g.per_period) {  // one period: its first row is the start
      ls[k].I[0] = cs.second.current_A;
      ls[k].y[0] = cs.second.y_m * 1e6;
      ls[k].B[0] = cs.second.B_T;
    }
  }
  for (std::size_t h = 0; h < held.size(); ++h) {
    conds[n + h] = held[h].c;
    states[n + h] = held[h].s;
    grid[n + h] = &held[h].grid;
  }
  for (const StepGrid* g : grid) longest = std::max(longest, g->steps);
  LaneBatch batch(models, conds, states);
  for (std::size_t k = 0; k < nl; ++k) batch.set_time(k, grid[k]->t0_s);
  std::vector<double> current(nl), dt(nl), t1(nl);
  for (long q = 1; q <= longest; ++q) {
    for (std::size_t k = 0; k < nl; ++k) {  // StepClock::Uniform; a finished lane idles
      const StepGrid& g = *grid[k];
      const long kk = std::min(q, g.steps);
      t1[k] = g.t0_s + static_cast<double>(kk) * g.dt_s;
      dt[k] = g.dt_s;
      if (k >= n) {
        current[k] = held[k - n].I;
        continue;
      }
      const std::vector<double>& drive = runs[k].drive_A;  // sine_drive: the same numbers
      current[k] = drive.empty() ? ls[k].w.current_at(t1[k]) : drive[static_cast<std::size_t>(kk)];
    }
    batch.step(current, dt, t1);
    for (std::size_t k = 0; k < nl; ++k) {
      const long total = grid[k]->steps;
      if (q > total) continue;
      if (batch.diverged(k)) throw DivergenceError(batch.error(k));
      if (k >= n) {
        if (q == total) batch.unpack(k, *held[k - n].s);
        continue;
      }
      const long first = total - ls[k].g.per_period;
      if (q < first) continue;
      const auto i = static_cast<std::size_t>(q - first);
      ls[k].I[i] = current[k];
      ls[k].y[i] = batch.y_m(k) * 1e6;
      ls[k].B[i] = batch.B_T(k);
    }
  }
  std::vector<SineMetrics> out(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = metrics_of(ls[k]);
  return out;
}

}  // namespace gmasim::identify_detail
