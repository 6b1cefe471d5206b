// simulate_lanes (gmasim/lanes.hpp): simulate() for many settings at once, the runs that
// share a step count advancing together in a LaneBatch. Each lane's run is simulate()'s: the
// same grid, rest state, records, checks, metrics and error texts (src/simulate/run.cpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "simulate/record.hpp"

namespace gmasim {
namespace {

struct Plan {
  double dt_s = 0, duration_s = 0;
  long steps = 0;
};

// simulate()'s grid of a periodic run (run.cpp, run_length): whole steps per period.
Plan periodic_plan(const SimulationSettings& s) {
  const auto& w = s.waveform;
  Plan p;
  const double dt0 = s.dt_s > 0.0 ? s.dt_s : auto_dt(w);
  const double per = w.period_s();
  const long n = steps_to_resolve(per / dt0, 0, "steps per period");
  p.dt_s = per / static_cast<double>(n);
  p.duration_s = s.periods * per;
  const StepGrid g =
      StepGrid::covering(0.0, p.duration_s, p.dt_s, "simulation (--dt, --duration or --periods)");
  p.dt_s = g.dt_s;
  p.steps = g.steps;
  return p;
}

// One lane's run: its conditions, its state (kept for unpacking) and its result.
struct LaneRun {
  std::size_t setting = 0;
  Conditions c;
  State st;
  bool live = false;
  long first_recorded = 0;  // metrics_only: the step before the last period's window
  MetricsWindow window;     // metrics_only: kept instead of the series
  // Rows staged before they are appended to the series column by column (LaneBatch::record_row).
  std::vector<double> rows;
  std::size_t staged = 0;
  // Appends the staged rows' first `columns` values (of `width`) to cols.
  // Written by index into the grown column (no push_back per value: its end pointer was a chain).
  void flush(std::vector<std::vector<double>>& cols, std::size_t width, std::size_t columns) {
    for (std::size_t q = 0; q < columns; ++q) {
      std::vector<double>& col = cols[q];
      const std::size_t at = col.size();
      col.resize(at + staged);
      double* o = col.data() + at;
      for (std::size_t k = 0; k < staged; ++k) o[k] = rows[k * width + q];
    }
    staged = 0;
  }
};
constexpr std::size_t kStagedRows = 64;

// The lanes' drives at one time: Waveform::current_at of a biased sine (every lane of a group is
// periodic), Waveform::biased_sine_from_cos with the cosine taken once per distinct frequency (a
// sweep's lanes share a few) -- the same operations, the same bits.
struct Drives {
  std::vector<double> freq, cosine;  // the distinct frequencies, their cos 2 pi f t
  std::vector<std::size_t> of;       // lane -> its frequency's index
  std::vector<const Waveform*> w;    // lane -> its waveform
  void add(const Waveform& wf) {
    std::size_t u = 0;
    while (u < freq.size() && !(freq[u] == wf.frequency_Hz)) ++u;
    if (u == freq.size()) freq.push_back(wf.frequency_Hz);
    of.push_back(u);
    w.push_back(&wf);
  }
  void at(double t, std::vector<double>& current) {
    constexpr double two_pi = 2.0 * physics::kPi;
    cosine.resize(freq.size());
    for (std::size_t u = 0; u < freq.size(); ++u) cosine[u] = std::cos(two_pi * freq[u] * t);
    for (std::size_t l = 0; l < w.size(); ++l)
      current[l] = w[l]->biased_sine_from_cos(cosine[of[l]]);
  }
};

void finish(const SimulationSettings& s, const Plan& p, const LaneRun& lr, bool metrics_only,
            Result& r) {
  if (r.series.rows() > 0) r.thermal_expansion_um = r.series.column("xT_um").back();
  if (r.diverged) return;
  const double t0 = p.duration_s - s.waveform.period_s(), t1 = p.duration_s;
  r.metrics = metrics_only ? lr.window.metrics(t0, t1) : compute_metrics(r.series, t0, t1);
  r.has_metrics = true;
}

// The runs' settings (idx) and conditions, and their rest states: make_state's ramp for all of
// them in lanes (make_states: equal to make_state to the lanes' rounding); none where a ramp
// fails (then each run makes its own, make_state, and its error is the run's).
std::vector<State> rest_states(const Model& m, std::span<const SimulationSettings> settings,
                               const std::vector<std::size_t>& idx, std::vector<LaneRun>& runs) {
  const std::vector<const Model*> models(runs.size(), &m);
  std::vector<const Conditions*> conds;
  std::vector<double> I0;
  for (std::size_t q = 0; q < idx.size(); ++q) {
    LaneRun& lr = runs[q];
    const SimulationSettings& s = settings[idx[q]];
    lr.setting = idx[q];
    lr.c = make_conditions(m, s.temperature_C, s.freeze);
    conds.push_back(&lr.c);
    I0.push_back(s.waveform.current_at(0.0));
  }
  try {
    return make_states(models, conds, I0);
  } catch (const DivergenceError&) {
    return {};
  }
}

// The lanes of a group: each run's rest state (rest_states), its first row (the rest state's,
// where the record starts there) and its lane; a run whose rest state fails its checks gets
// its error and no lane.
struct Lanes {
  std::vector<const Model*> models;
  std::vector<const Conditions*> conds;
  std::vector<const State*> states;
  std::vector<std::size_t> lane_of;  // lane -> run
};
Lanes start_runs(const Model& m, std::span<const SimulationSettings> settings,
                 const std::vector<std::size_t>& idx, const Plan& p, bool metrics_only,
                 std::vector<LaneRun>& runs, std::vector<Result>& out) {
  Lanes ln;
  std::vector<State> rest = rest_states(m, settings, idx, runs);
  for (std::size_t q = 0; q < idx.size(); ++q) {
    LaneRun& lr = runs[q];
    const SimulationSettings& s = settings[idx[q]];
    Result& r = out[idx[q]];
    r.dt_s = p.dt_s;
    r.thermal_expansion_start_um = r.thermal_expansion_um = lr.c.thermal_expansion_m * 1e6;
    make_columns(m, r.series,
                 metrics_only ? 0 : static_cast<std::size_t>(p.steps / s.record_every + 2));
    try {
      lr.st = rest.empty() ? make_state(m, lr.c, s.waveform.current_at(0.0)) : std::move(rest[q]);
      lr.st.energy.enabled = false;
      check_physical_validity(m, lr.c, lr.st, 0.0);
      if (metrics_only) {
        lr.window.start(p.steps, std::lround(s.waveform.period_s() / p.dt_s), s.record_every);
        lr.first_recorded = lr.window.first;
      }
      if (lr.first_recorded <= 0 && metrics_only) {
        lr.window.push(lr.st);
      } else if (lr.first_recorded <= 0) {
        record(lr.c, lr.st, r.series);
      }
      lr.live = true;
      ln.models.push_back(&m);
      ln.conds.push_back(&lr.c);
      ln.states.push_back(&lr.st);
      ln.lane_of.push_back(q);
    } catch (const DivergenceError& e) {
      r.diverged = true;
      r.error = e.what();
    }
  }
  return ln;
}

// The steps of a group's lanes, each lane's rows staged and appended: the series' columns, or,
// metrics_only, the window's (t, the current, y and B: what record() writes there).
void step_runs(const Lanes& ln, std::span<const SimulationSettings> settings, const Plan& p,
               bool metrics_only, std::vector<LaneRun>& runs, std::vector<Result>& out) {
  LaneBatch batch(ln.models, ln.conds, ln.states);
  const std::size_t n = ln.lane_of.size();
  const std::size_t width = metrics_only ? MetricsWindow::kColumns : batch.record_width();
  for (std::size_t l = 0; l < n; ++l) runs[ln.lane_of[l]].rows.resize(kStagedRows * width);
  std::vector<double> current(n), dt(n, p.dt_s), t1(n);
  std::size_t live = n;
  Drives drives;
  for (std::size_t l = 0; l < n; ++l) drives.add(settings[runs[ln.lane_of[l]].setting].waveform);
  auto columns = [&](LaneRun& lr) -> std::vector<std::vector<double>>& {
    return metrics_only ? lr.window.columns : out[lr.setting].series.columns;
  };
  // The first step any lane records: before it, a step needs the lanes only where one of them
  // stops (a lane's step count is set when it stops, or at the end).
  long first_row = p.steps;
  for (std::size_t l = 0; l < n; ++l) {
    const LaneRun& lr = runs[ln.lane_of[l]];
    first_row = std::min(first_row, std::max(lr.first_recorded, 1L));
  }
  std::size_t stopped = 0;  // the lanes diverged so far
  long k = 1;
  for (; k <= p.steps && live > 0; ++k) {
    const double t = 0.0 + static_cast<double>(k) * p.dt_s;  // the Uniform clock
    drives.at(t, current);
    std::fill(t1.begin(), t1.end(), t);
    batch.step(current, dt, t1);
    const std::size_t now_stopped = batch.diverged_count();
    if (k < first_row && now_stopped == stopped) continue;
    stopped = now_stopped;
    for (std::size_t l = 0; l < n; ++l) {
      LaneRun& lr = runs[ln.lane_of[l]];
      if (!lr.live) continue;
      Result& r = out[lr.setting];
      if (batch.diverged(l)) {
        lr.flush(columns(lr), width, width);
        r.diverged = true;
        r.error = batch.error(l);
        r.steps = k - 1;
        lr.live = false;
        --live;
        continue;
      }
      if (k < lr.first_recorded || (k % settings[lr.setting].record_every != 0 && k != p.steps))
        continue;
      double* row = lr.rows.data() + lr.staged * width;
      if (metrics_only) {  // the lane's t and current are the step's (LaneBatch::record_row)
        row[0] = t;
        row[1] = current[l];
        row[2] = batch.y_m(l) * 1e6;
        row[3] = batch.B_T(l);
      } else {
        batch.record_row(l, lr.c.thermal_expansion_m, row);
      }
      if (++lr.staged == kStagedRows || k == p.steps) lr.flush(columns(lr), width, width);
    }
  }
  for (std::size_t l = 0; l < n; ++l) {  // the runs that did not stop: every step
    const LaneRun& lr = runs[ln.lane_of[l]];
    if (lr.live) out[lr.setting].steps = k - 1;
  }
}

// The rest states, then the steps of the group in lanes.
void run_group(const Model& m, std::span<const SimulationSettings> settings,
               const std::vector<std::size_t>& idx, const Plan& p, bool metrics_only,
               std::vector<Result>& out) {
  const auto wall0 = std::chrono::steady_clock::now();
  std::vector<LaneRun> runs(idx.size());
  const Lanes ln = start_runs(m, settings, idx, p, metrics_only, runs, out);
  if (!ln.lane_of.empty()) step_runs(ln, settings, p, metrics_only, runs, out);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  for (const LaneRun& lr : runs) {
    Result& r = out[lr.setting];
    r.wall_time_s = wall / static_cast<double>(runs.size());
    finish(settings[lr.setting], p, lr, metrics_only, r);
  }
}

}  // namespace

std::vector<Result> simulate_lanes(const Model& m, std::span<const SimulationSettings> settings,
                                   bool metrics_only) {
  std::vector<Result> out(settings.size());
  const bool model_ok = lanes_supported(m);
  // A group shares the step count and the step (the lanes' time grid). Every periodic run
  // takes the lanes, whatever else is in the batch: a point's numbers never depend on which
  // other points it was run with (RunClaims.MatchesTheFullStudy).
  using Key = std::pair<long, double>;
  std::map<Key, std::vector<std::size_t>> groups;  // (step count, step) -> settings
  std::map<Key, Plan> plans;
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const SimulationSettings& s = settings[i];
    validate(s);
    if (!model_ok || s.self_heating.enabled || s.energy_ledger || !s.waveform.periodic() ||
        s.progress) {
      out[i] = metrics_only ? simulate_metrics_only(m, s) : simulate(m, s);
      continue;
    }
    const Plan p = periodic_plan(s);
    const Key key{p.steps, p.dt_s};
    plans[key] = p;
    groups[key].push_back(i);
  }
  for (const auto& [key, idx] : groups) run_group(m, settings, idx, plans[key], metrics_only, out);
  return out;
}

}  // namespace gmasim
