// The objective's records in SIMD lanes (record_lanes.hpp).
#include "identify/record_lanes.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <span>

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

// One record's run (record_run.cpp, RecordRun::run_timed), shared by its candidates' lanes:
// its grid, drive, passes and the samples' cursor (the same for every candidate: they depend on
// the record and the settings only).
struct LaneRecordRun {
  const Measurement* meas = nullptr;
  StepGrid grid;
  Waveform w;
  bool sine = false;
  long passes = 1, total = 0;
  double I0 = 0;
  long kk = 0, pass = 0;           // the step within its pass (1 .. steps), and the pass
  double grid_prev = 0, t = 0;     // the grid's previous time and the step's (t_k)
  double t_prev = 0;               // the samples' interpolation: the previous step's time
  std::size_t j = 0, table_j = 1;  // the next sample; the drive table's interval
  const std::vector<double>* drive = nullptr;  // record_drive's currents, if computed

  // The record's drive at t (record_run.cpp, TableDrive: forward-moving linear interpolation).
  double current_at(double tt) {
    if (sine) return w.current_at(tt);
    const auto& ts = meas->t_s;
    const auto& v = meas->drive;
    if (tt <= ts.front()) return v.front();
    if (tt >= ts.back()) return v.back();
    while (table_j + 1 < ts.size() && ts[table_j] < tt) ++table_j;
    while (table_j > 1 && ts[table_j - 1] > tt) --table_j;
    const double f = (tt - ts[table_j - 1]) / (ts[table_j] - ts[table_j - 1]);
    return v[table_j - 1] + f * (v[table_j] - v[table_j - 1]);
  }
  bool last() const { return pass + 1 == passes; }
};

// One lane's outputs: the record's response (and B) of one candidate, and the values of the step
// before (the samples' interpolation).
struct LaneRecordOut {
  std::vector<double>* response = nullptr;
  std::vector<double>* B = nullptr;
  std::size_t rod = 0;
  bool strain = false;
  double length_m = 1, r_prev = 0, B_prev = 0;

  double si(const State& x) const { return strain ? x.rods[rod].x_m / length_m : x.y_m; }
  double si(const LaneBatch& b, std::size_t lane) const {
    return strain ? b.x_m(lane, static_cast<int>(rod)) / length_m : b.y_m(lane);
  }
};

// The record's grid, drive and passes (as run_timed sets them up).
void set_up_record(LaneRecordRun& rr, const ObjectiveSettings& s) {
  const Measurement& meas = *rr.meas;
  const auto& cond = meas.condition;
  rr.I0 = record_initial_current(meas);
  rr.sine = cond.current_source == "sine";
  if (rr.sine) rr.w = biased_sine(cond.current_pp_A, cond.frequency_Hz, cond.current_min_A);
  const double t0 = meas.t_s.front(), t1 = meas.t_s.back();
  const double dt_target = objective_step(s, meas.periodic() ? 1.0 / cond.frequency_Hz : 0.0);
  const std::string what = meas.path + ": steps over the record";
  rr.grid = StepGrid::spanning(t0, t1, steps_to_resolve((t1 - t0) / dt_target, 1, what), what);
  rr.passes = 1 + cond.precycles;
  rr.total = rr.passes * rr.grid.steps;
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

// The lanes of a batch: record k of candidate c in lane k P + c.
struct RecordLanes {
  std::size_t P = 0;
  std::vector<LaneRecordRun> rec;
  std::vector<LaneRecordOut> out;
  std::vector<char>* failed = nullptr;
  std::vector<double> frac;  // the step's samples' interpolation fractions
  std::size_t stopped = 0;   // the lanes diverged so far (LaneBatch::diverged_count)
};

// The samples at or before t0 of a pass (from the state the pass starts at: the rest state or
// the lane's) and the interpolation's start.
template <class Value>
void begin_pass(RecordLanes& L, std::size_t k, bool last, Value value) {
  LaneRecordRun& rr = L.rec[k];
  const auto& ts = rr.meas->t_s;
  std::size_t j = 0;
  for (; j < ts.size() && ts[j] <= ts.front(); ++j) {
    if (!last) continue;
    for (std::size_t c = 0; c < L.P; ++c) {
      LaneRecordOut& o = L.out[k * L.P + c];
      double r, B;
      value(k * L.P + c, r, B);
      (*o.response)[j] = r * 1e6;
      if (o.B) (*o.B)[j] = B;
    }
  }
  for (std::size_t c = 0; c < L.P; ++c) {
    LaneRecordOut& o = L.out[k * L.P + c];
    value(k * L.P + c, o.r_prev, o.B_prev);
  }
  rr.j = j;
  rr.table_j = 1;
  rr.t_prev = ts.front();
}

// The grid's next step of every record (StepClock::Spanning within the record's pass; a finished
// record idles at its last step), its drive computed once for the record's candidates.
void next_step(RecordLanes& L, long q, LaneBatch& batch, std::vector<double>& current,
               std::vector<double>& dt, std::vector<double>& t1) {
  for (std::size_t k = 0; k < L.rec.size(); ++k) {
    LaneRecordRun& rr = L.rec[k];
    const long steps = rr.grid.steps;
    if (q > rr.total) {
      rr.kk = steps;
    } else {
      rr.kk = rr.kk == steps ? 1 : rr.kk + 1;
      if (rr.kk == 1) {
        if (q > 1) ++rr.pass;
        rr.grid_prev = rr.grid.t0_s;
        for (std::size_t c = 0; c < L.P; ++c) batch.set_time(k * L.P + c, rr.grid.t0_s);
      }
    }
    const double t =
        rr.kk == steps ? rr.grid.t1_s : rr.grid.t0_s + static_cast<double>(rr.kk) * rr.grid.dt_s;
    const double d = q > rr.total ? rr.grid.dt_s : t - rr.grid_prev;
    rr.grid_prev = t;
    rr.t = t;
    const double I =
        rr.drive && q <= rr.total ? (*rr.drive)[static_cast<std::size_t>(rr.kk)] : rr.current_at(t);
    const std::size_t l0 = k * L.P;
    std::fill_n(current.begin() + static_cast<std::ptrdiff_t>(l0), L.P, I);
    std::fill_n(dt.begin() + static_cast<std::ptrdiff_t>(l0), L.P, d);
    std::fill_n(t1.begin() + static_cast<std::ptrdiff_t>(l0), L.P, t);
  }
}

// After a step: each live lane's samples up to the step's time, interpolated linearly (the
// fractions computed once per record), and at the end of a pass the samples after it from the
// lane's state, then the next pass's start. A lane that diverges fails its candidate (or throws).
void after_step(RecordLanes& L, long q, const LaneBatch& batch) {
  const std::size_t P = L.P;
  std::vector<char>* failed = L.failed;
  const std::size_t stopped = batch.diverged_count();
  const bool new_stops = stopped != L.stopped;  // else no lane needs its check
  L.stopped = stopped;
  for (std::size_t k = 0; k < L.rec.size(); ++k) {
    LaneRecordRun& rr = L.rec[k];
    if (q > rr.total) continue;
    for (std::size_t c = 0; new_stops && c < P; ++c) {
      if (failed && (*failed)[c]) continue;
      if (batch.diverged(k * P + c)) {
        if (!failed) throw DivergenceError(batch.error(k * P + c));
        (*failed)[c] = 1;  // the candidate's residuals() fails: its outputs are not used
      }
    }
    const bool last = rr.last();
    const auto& ts = rr.meas->t_s;
    const std::size_t n = ts.size(), j0 = rr.j;
    std::size_t j1 = j0;
    for (; last && j1 < n && ts[j1] <= rr.t; ++j1) {
      if (j1 - j0 == L.frac.size()) L.frac.push_back(0.0);
      L.frac[j1 - j0] = (ts[j1] - rr.t_prev) / (rr.t - rr.t_prev);
    }
    for (std::size_t c = 0; last && c < P; ++c) {
      if (failed && (*failed)[c]) continue;
      LaneRecordOut& o = L.out[k * P + c];
      const double r_now = o.si(batch, k * P + c), B_now = batch.B_T(k * P + c);
      for (std::size_t j = j0; j < j1; ++j) {
        const double f = L.frac[j - j0];
        (*o.response)[j] = (o.r_prev + f * (r_now - o.r_prev)) * 1e6;
        if (o.B) (*o.B)[j] = o.B_prev + f * (B_now - o.B_prev);
      }
      o.r_prev = r_now;
      o.B_prev = B_now;
    }
    rr.j = j1;
    rr.t_prev = rr.t;
    if (rr.kk != rr.grid.steps) continue;
    // The pass ends: the samples after t1 from its state, then the next pass from it.
    auto value = [&](std::size_t l, double& r, double& B) {
      r = L.out[l].si(batch, l);
      B = batch.B_T(l);
    };
    for (std::size_t c = 0; last && c < P; ++c) {
      if (failed && (*failed)[c]) continue;
      LaneRecordOut& o = L.out[k * P + c];
      double r, B;
      value(k * P + c, r, B);
      for (std::size_t j = j1; j < n; ++j) {
        (*o.response)[j] = r * 1e6;
        if (o.B) (*o.B)[j] = B;
      }
    }
    if (!last) begin_pass(L, k, rr.pass + 2 == rr.passes, value);
  }
}

// Each lane's model (the candidate's, or for a record at its own prestress a preloaded copy),
// its conditions (one per model and temperature) and its outputs.
void set_up_lanes(RecordLanes& L, std::span<const Model* const> candidates,
                  const std::vector<bool>& flux, std::vector<RecordOutputs>& out,
                  std::deque<Model>& preloaded, std::deque<Conditions>& conditions,
                  std::vector<const Model*>& models, std::vector<const Conditions*>& conds) {
  const std::size_t P = L.P, n = L.out.size();
  for (std::size_t l = 0; l < n; ++l) {
    const std::size_t k = l / P, c = l % P;
    const Measurement& meas = *L.rec[k].meas;
    const auto& cond = meas.condition;
    const Model* m = candidates[c];
    if (!std::isnan(cond.prestress_MPa)) {
      preloaded.push_back(with_record_preload(*m, cond));
      m = &preloaded.back();
    }
    const Conditions* cp = nullptr;
    for (std::size_t u = 0; u < l && !cp; ++u)  // the conditions of (model, temperature)
      if (models[u] == m && conds[u]->temperature_C == cond.temperature_C) cp = conds[u];
    if (!cp) {
      conditions.push_back(make_conditions(*m, cond.temperature_C));
      cp = &conditions.back();
    }
    models[l] = m;
    conds[l] = cp;
    LaneRecordOut& o = L.out[l];
    o.response = &out[c].response[k];
    o.B = flux[k] ? &out[c].B_T[k] : nullptr;
    o.rod = record_rod(*m, meas);
    o.strain = meas.response_kind == ResponseOutput::Strain;
    o.length_m = cp->rods[o.rod].length_m;
    o.response->resize(meas.t_s.size());
    if (o.B) o.B->resize(meas.t_s.size());
  }
}

}  // namespace

std::vector<double> record_drive(const Measurement& meas, const ObjectiveSettings& s) {
  LaneRecordRun rr;
  rr.meas = &meas;
  set_up_record(rr, s);
  const long steps = rr.grid.steps;
  if (steps > kMaxStoredDriveSteps) return {};
  std::vector<double> d(static_cast<std::size_t>(steps) + 1, 0.0);
  for (long kk = 1; kk <= steps; ++kk) {  // next_step's times, from the start of a pass
    const double t =
        kk == steps ? rr.grid.t1_s : rr.grid.t0_s + static_cast<double>(kk) * rr.grid.dt_s;
    d[static_cast<std::size_t>(kk)] = rr.current_at(t);
  }
  return d;
}

void run_records_lanes(const Model& m, const std::vector<const Measurement*>& records,
                       const std::vector<bool>& flux, const ObjectiveSettings& s,
                       std::vector<std::vector<double>>& response,
                       std::vector<std::vector<double>>& B_T,
                       const std::vector<const std::vector<double>*>& drive_A) {
  const Model* const one[1] = {&m};
  std::vector<RecordOutputs> out(1);
  run_records_lanes(one, records, flux, s, out, nullptr, drive_A);
  response = std::move(out[0].response);
  B_T = std::move(out[0].B_T);
}

void run_records_lanes(std::span<const Model* const> candidates,
                       const std::vector<const Measurement*>& records,
                       const std::vector<bool>& flux, const ObjectiveSettings& s,
                       std::vector<RecordOutputs>& out, std::vector<char>* failed,
                       const std::vector<const std::vector<double>*>& drive_A) {
  const std::size_t P = candidates.size(), R = records.size(), n = P * R;
  out.resize(P);
  for (auto& o : out) {
    o.response.resize(R);
    o.B_T.resize(R);
  }
  if (failed) failed->assign(P, 0);
  // Lane l = k P + c: record k of candidate c, so that a vector holds one record across the
  // candidates (the same drive and grid: the lanes' Newton iterations and branches agree).
  RecordLanes L;
  L.P = P;
  L.failed = failed;
  L.rec.resize(R);
  L.out.resize(n);
  long longest = 0;
  for (std::size_t k = 0; k < R; ++k) {
    L.rec[k].meas = records[k];
    set_up_record(L.rec[k], s);
    if (k < drive_A.size() && drive_A[k] && !drive_A[k]->empty()) L.rec[k].drive = drive_A[k];
    longest = std::max(longest, L.rec[k].total);
  }
  std::deque<Model> preloaded;  // stable addresses
  std::deque<Conditions> conditions;
  std::vector<const Model*> models(n);
  std::vector<const Conditions*> conds(n);
  set_up_lanes(L, candidates, flux, out, preloaded, conditions, models, conds);
  std::vector<double> I0(n);
  for (std::size_t l = 0; l < n; ++l) I0[l] = L.rec[l / P].I0;
  std::vector<std::size_t> start_of(n);
  const std::vector<State> rest = rest_states(models, conds, I0, start_of);
  std::vector<const State*> states(n);
  for (std::size_t l = 0; l < n; ++l) states[l] = &rest[start_of[l]];
  for (std::size_t k = 0; k < R; ++k)  // the first pass starts at the rest state
    begin_pass(L, k, L.rec[k].passes == 1, [&](std::size_t l, double& r, double& B) {
      r = L.out[l].si(*states[l]);
      B = states[l]->B_T;
    });
  LaneBatch batch(models, conds, states);
  std::vector<double> current(n), dt(n), t1(n);
  for (long q = 1; q <= longest; ++q) {
    next_step(L, q, batch, current, dt, t1);
    batch.step(current, dt, t1);
    after_step(L, q, batch);
  }
}

}  // namespace gmasim::identify_detail
