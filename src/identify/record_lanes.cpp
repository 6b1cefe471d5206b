// The objective's records in SIMD lanes (record_lanes.hpp).
#include "identify/record_lanes.hpp"

#include <algorithm>
#include <deque>
#include <stdexcept>

#include "gmasim/errors.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "identify/record_run.hpp"

namespace gmasim::identify_detail {

bool record_in_lanes(const Model& m, const Measurement& meas) {
  const auto& c = meas.condition;
  return lanes_supported(m) && meas.drive_kind == DriveInput::Current && !c.quasi_static &&
         c.initial_state == InitialState::Demagnetised;
}

namespace {

// One record's run (record_run.cpp, RecordRun::run_timed): its grid, drive and sampling.
struct LaneRecord {
  const Measurement* meas = nullptr;
  const Model* model = nullptr;
  Conditions c;
  State st;
  StepGrid grid;
  Waveform w;
  bool sine = false;
  long passes = 1, total = 0;
  std::size_t rod = 0, j = 0, table_j = 1;
  bool strain = false;
  double length_m = 1, r_prev = 0, B_prev = 0, t_prev = 0, I0 = 0;
  std::vector<double>* response = nullptr;
  std::vector<double>* B = nullptr;

  double si(const State& x) const { return strain ? x.rods[rod].x_m / length_m : x.y_m; }
  double si(const LaneBatch& b, std::size_t lane) const {
    return strain ? b.x_m(lane, static_cast<int>(rod)) / length_m : b.y_m(lane);
  }
  // The record's drive at t (record_run.cpp, TableDrive: forward-moving linear interpolation).
  double current_at(double t) {
    if (sine) return w.current_at(t);
    const auto& ts = meas->t_s;
    const auto& v = meas->drive;
    if (t <= ts.front()) return v.front();
    if (t >= ts.back()) return v.back();
    while (table_j + 1 < ts.size() && ts[table_j] < t) ++table_j;
    while (table_j > 1 && ts[table_j - 1] > t) --table_j;
    const double f = (t - ts[table_j - 1]) / (ts[table_j] - ts[table_j - 1]);
    return v[table_j - 1] + f * (v[table_j] - v[table_j - 1]);
  }
  void store(std::size_t i, const State& x) {
    (*response)[i] = si(x) * 1e6;
    if (B) (*B)[i] = x.B_T;
  }
  // The start of a pass: the samples at or before t0 from the state, the interpolation's start.
  void begin_pass(bool last) {
    const auto& ts = meas->t_s;
    j = 0;
    table_j = 1;
    for (; j < ts.size() && ts[j] <= ts.front(); ++j)
      if (last) store(j, st);
    r_prev = si(st);
    B_prev = st.B_T;
    t_prev = ts.front();
  }
  // After a step ending at t: the samples up to t, interpolated linearly.
  void after_step(const LaneBatch& b, std::size_t lane, double t, bool last) {
    const auto& ts = meas->t_s;
    const double r_now = si(b, lane), B_now = b.B_T(lane);
    while (last && j < ts.size() && ts[j] <= t) {
      const double f = (ts[j] - t_prev) / (t - t_prev);
      (*response)[j] = (r_prev + f * (r_now - r_prev)) * 1e6;
      if (B) (*B)[j] = B_prev + f * (B_now - B_prev);
      ++j;
    }
    r_prev = r_now;
    B_prev = B_now;
    t_prev = t;
  }
  void end_pass(bool last) {
    for (; last && j < meas->t_s.size(); ++j) store(j, st);
  }
};

// The record's model, conditions, current at its start (I0), grid and outputs; its rest state
// comes after (make_states, for all the records at once).
void set_up(LaneRecord& lr, const Model& m, std::deque<Model>& preloaded,
            const ObjectiveSettings& s) {
  const Measurement& meas = *lr.meas;
  const auto& cond = meas.condition;
  const double T = cond.temperature_C;
  lr.I0 = record_initial_current(meas);
  if (std::isnan(cond.prestress_MPa)) {
    lr.model = &m;
  } else {
    preloaded.push_back(with_record_preload(m, cond));
    lr.model = &preloaded.back();
  }
  lr.c = make_conditions(*lr.model, T);
  lr.rod = record_rod(*lr.model, meas);
  lr.strain = meas.response_kind == ResponseOutput::Strain;
  lr.length_m = lr.c.rods[lr.rod].length_m;
  lr.sine = cond.current_source == "sine";
  if (lr.sine) lr.w = biased_sine(cond.current_pp_A, cond.frequency_Hz, cond.current_min_A);
  const double t0 = meas.t_s.front(), t1 = meas.t_s.back();
  const double dt_target = objective_step(s, meas.periodic() ? 1.0 / cond.frequency_Hz : 0.0);
  const std::string what = meas.path + ": steps over the record";
  lr.grid = StepGrid::spanning(t0, t1, steps_to_resolve((t1 - t0) / dt_target, 1, what), what);
  lr.passes = 1 + cond.precycles;
  lr.total = lr.passes * lr.grid.steps;
  lr.response->resize(meas.t_s.size());
  if (lr.B) lr.B->resize(meas.t_s.size());
}

// The records' rest states in lanes (make_states), one per distinct (model, temperature, I0)
// as StartCache shares them; start_of[k] is record k's.
std::vector<State> rest_states(const std::vector<const Model*>& models,
                               const std::vector<const Conditions*>& conds,
                               const std::vector<double>& I0, std::vector<std::size_t>& start_of) {
  const std::size_t n = models.size();
  std::vector<const Model*> um;
  std::vector<const Conditions*> uc;
  std::vector<double> ui;
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t u = 0;
    while (u < um.size() && !(um[u] == models[k] &&
                              uc[u]->temperature_C == conds[k]->temperature_C && ui[u] == I0[k]))
      ++u;
    if (u == um.size()) {
      um.push_back(models[k]);
      uc.push_back(conds[k]);
      ui.push_back(I0[k]);
    }
    start_of[k] = u;
  }
  return make_states(um, uc, ui);
}

// The records' steps, all lanes at once; a lane whose candidate failed is left to idle.
void step_records(std::vector<LaneRecord>& runs, const std::vector<const Model*>& models,
                  const std::vector<const Conditions*>& conds,
                  const std::vector<const State*>& states, long longest, std::size_t P,
                  std::vector<char>* failed) {
  const std::size_t n = runs.size();
  LaneBatch batch(models, conds, states);
  std::vector<double> current(n), dt(n), t1(n);
  std::vector<double> t_prev(n);
  for (std::size_t k = 0; k < n; ++k) t_prev[k] = runs[k].grid.t0_s;
  for (long q = 1; q <= longest; ++q) {
    for (std::size_t k = 0; k < n; ++k) {  // StepClock::Spanning within the lane's pass
      LaneRecord& lr = runs[k];
      const long steps = lr.grid.steps;
      const long kk = q > lr.total ? steps : (q - 1) % steps + 1;  // a finished lane idles
      if (kk == 1 && q <= lr.total) {
        t_prev[k] = lr.grid.t0_s;
        batch.set_time(k, lr.grid.t0_s);
      }
      if (k % P != 0) {  // the record's other candidates: its grid and drive, computed once
        dt[k] = dt[k - 1];
        t_prev[k] = t_prev[k - 1];
        t1[k] = t1[k - 1];
        current[k] = current[k - 1];
        continue;
      }
      const double t =
          kk == steps ? lr.grid.t1_s : lr.grid.t0_s + static_cast<double>(kk) * lr.grid.dt_s;
      dt[k] = q > lr.total ? lr.grid.dt_s : t - t_prev[k];
      t_prev[k] = t;
      t1[k] = t;
      current[k] = lr.current_at(t);
    }
    batch.step(current, dt, t1);
    for (std::size_t k = 0; k < n; ++k) {
      LaneRecord& lr = runs[k];
      if (q > lr.total) continue;
      if (failed && (*failed)[k % P]) continue;
      if (batch.diverged(k)) {
        if (!failed) throw DivergenceError(batch.error(k));
        (*failed)[k % P] = 1;  // the candidate's residuals() fails: its outputs are not used
        continue;
      }
      const long pass = (q - 1) / lr.grid.steps;
      const bool last = pass + 1 == lr.passes;
      lr.after_step(batch, k, t1[k], last);
      if (q % lr.grid.steps == 0) {  // the pass ends: its state for the samples after t1
        batch.unpack(k, lr.st);
        lr.end_pass(last);
        if (!last) lr.begin_pass(pass + 2 == lr.passes);
      }
    }
  }
}

}  // namespace

void run_records_lanes(const Model& m, const std::vector<const Measurement*>& records,
                       const std::vector<bool>& flux, const ObjectiveSettings& s,
                       std::vector<std::vector<double>>& response,
                       std::vector<std::vector<double>>& B_T) {
  const Model* const one[1] = {&m};
  std::vector<RecordOutputs> out(1);
  run_records_lanes(one, records, flux, s, out, nullptr);
  response = std::move(out[0].response);
  B_T = std::move(out[0].B_T);
}

void run_records_lanes(std::span<const Model* const> candidates,
                       const std::vector<const Measurement*>& records,
                       const std::vector<bool>& flux, const ObjectiveSettings& s,
                       std::vector<RecordOutputs>& out, std::vector<char>* failed) {
  const std::size_t P = candidates.size(), R = records.size(), n = P * R;
  out.resize(P);
  for (auto& o : out) {
    o.response.resize(R);
    o.B_T.resize(R);
  }
  if (failed) failed->assign(P, 0);
  // Lane l = k P + c: record k of candidate c, so that a vector holds one record across the
  // candidates (the same drive and grid: the lanes' Newton iterations and branches agree).
  std::vector<LaneRecord> runs(n);
  std::deque<Model> preloaded;  // stable addresses
  std::vector<const Model*> models(n);
  std::vector<const Conditions*> conds(n);
  std::vector<const State*> states(n);
  std::vector<double> I0(n);
  std::vector<std::size_t> start_of(n);
  long longest = 0;
  for (std::size_t l = 0; l < n; ++l) {
    const std::size_t k = l / P, c = l % P;
    LaneRecord& lr = runs[l];
    lr.meas = records[k];
    lr.response = &out[c].response[k];
    lr.B = flux[k] ? &out[c].B_T[k] : nullptr;
    set_up(lr, *candidates[c], preloaded, s);
    if (c > 0 && (lr.grid.steps != runs[l - c].grid.steps || lr.total != runs[l - c].total))
      throw std::logic_error("run_records_lanes: a record's grid depends on the candidate");
    models[l] = lr.model;
    conds[l] = &lr.c;
    I0[l] = lr.I0;
    longest = std::max(longest, lr.total);
  }
  const std::vector<State> rest = rest_states(models, conds, I0, start_of);
  for (std::size_t l = 0; l < n; ++l) {
    LaneRecord& lr = runs[l];
    lr.st = rest[start_of[l]];
    lr.st.t_s = lr.meas->t_s.front();
    lr.begin_pass(lr.passes == 1);
    states[l] = &lr.st;
  }
  step_records(runs, models, conds, states, longest, P, failed);
}

}  // namespace gmasim::identify_detail
