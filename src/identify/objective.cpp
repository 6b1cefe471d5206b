// The identification objective: normalised residuals of simulated vs measured displacement
// (and optionally flux density) at every compared sample, plus scalar targets. The sum of
// squares of the residuals is the square of the weighted RMS error in % of peak-to-peak.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <span>

#include "gmasim/errors.hpp"
#include "gmasim/experiments.hpp"
#include "gmasim/identify.hpp"
#include "gmasim/io.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/validate.hpp"
#include "identify/record_run.hpp"

namespace gmasim {
namespace {

struct Param {
  std::string key, unit;
  ParamScale scale = ParamScale::Linear;
  double lo = 0, hi = 0;
  double tlo = 0, thi = 0;  // theta bounds: p, or ln|p|
  double sign = 1.0;
};

struct CondData {
  std::size_t index = 0;          // in data.items
  std::size_t compare_begin = 0;  // first compared sample
  double pp_um = 0, y_scale = 0;
  bool flux = false;
  double ppB = 0, B_scale = 0;
  std::size_t r_offset = 0, rB_offset = 0;
};

struct SineRun {
  double T, pp, f, min;
  bool operator==(const SineRun&) const = default;
};
struct ResonanceRun {
  double T, bias;
  TargetKind kind;  // ResonanceHz, FrfPeakHz or BandwidthHz
  bool operator==(const ResonanceRun&) const = default;
};

struct TargetData {
  FitTarget t;
  int run = -1, ref_run = -1, res_run = -1;
  double r_scale = 0;
  std::size_t r_index = 0;
};

struct SineMetrics {
  double stroke_um = 0, hysteresis_um = 0, B_pp_T = 0;
};

// Conditions and the state at rest per (temperature, initial current): runs that share both
// (every frequency and amplitude of a biased sine starting at its -3 A minimum) share one
// make_state(), whose quasi-static ramp costs about as much as 300 steps.
class StartCache {
 public:
  explicit StartCache(const Model& m) : m_(m) {}
  const std::pair<Conditions, State>& get(double T, double I0) {
    for (const auto& e : entries_)
      if (e.T == T && e.I0 == I0) return e.cs;
    Conditions c = make_conditions(m_, T);
    State st = make_state(m_, c, I0);
    entries_.push_back({T, I0, {std::move(c), std::move(st)}});
    return entries_.back().cs;
  }

 private:
  struct Entry {
    double T, I0;
    std::pair<Conditions, State> cs;
  };
  const Model& m_;
  std::deque<Entry> entries_;
};

SineMetrics run_sine(const Model& m, const SineRun& run, const ObjectiveSettings& s,
                     std::vector<double>& I, std::vector<double>& y, std::vector<double>& B,
                     StartCache& starts) {
  const Waveform w = biased_sine(run.pp, run.f, run.min);
  const double per = w.period_s();
  const long n_per =
      std::max(8L, checked_ceil_count(per / identify_detail::objective_step(s, per), kMaxSteps, "steps per period"));
  const double dt = per / static_cast<double>(n_per);
  const long periods = std::max(1L, checked_count(s.target_periods, 1e4, "target periods"));
  const long total = periods * n_per;
  const auto& [c, st0] = starts.get(run.T, w.current_at(0.0));
  State st = st0;
  I.assign(static_cast<std::size_t>(n_per), 0.0);
  y.assign(static_cast<std::size_t>(n_per), 0.0);
  B.assign(static_cast<std::size_t>(n_per), 0.0);
  const long first = total - n_per;  // record samples k in [first, total)
  auto rec = [&](long k) {
    if (k < first || k >= total) return;
    const auto i = static_cast<std::size_t>(k - first);
    I[i] = st.current_A;
    y[i] = st.y_m * 1e6;
    B[i] = st.B_T;
  };
  rec(0);
  for (long k = 1; k <= total; ++k) {
    const double t = static_cast<double>(k) * dt;
    step(m, c, st, {w.current_at(t), dt});
    st.t_s = t;
    rec(k);
  }
  SineMetrics r;
  r.stroke_um = peak_to_peak(y);
  r.B_pp_T = peak_to_peak(B);
  r.hysteresis_um = hysteresis_width(I, y, 0, y.size());
  return r;
}

double lowest_resonance_Hz(const Model& m, const ResonanceRun& run) {
  if (run.kind != TargetKind::ResonanceHz) {  // the small-signal frequency response (Fig. 15)
    FrfRequest r;
    r.temperatures_C = {run.T};
    r.bias_A = run.bias;
    r.stepped_sine = false;
    r.threads = 1;
    const FrfResult frf = run_frf(m, r);  // kept alive: cv refers into it
    const FrfCurve& cv = frf.curves.at(0);
    return run.kind == TargetKind::FrfPeakHz ? cv.first_resonance_Hz : cv.bandwidth_3dB_Hz;
  }
  const Conditions c = make_conditions(m, run.T);
  const State st = make_state(m, c, run.bias);
  double f = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m.rod_count(); ++i) {
    const double K = oscillator_stiffness(c, st, i);
    const double mass = c.rods[static_cast<std::size_t>(i)].mass_osc_kg;
    f = std::min(f, std::sqrt(K / mass) / (2.0 * physics::kPi));
  }
  return f;
}

}  // namespace

void simulate_measurement(const Model& m, const Measurement& meas, const ObjectiveSettings& s,
                          std::vector<double>& y_um, std::vector<double>* B_T) {
  StartCache starts(m);
  const auto& [c, st] =
      starts.get(meas.condition.temperature_C, identify_detail::record_initial_current(meas));
  identify_detail::run_record(m, c, st, meas, s, y_um, B_T);
}

// =======================================================================================
struct Objective::Impl {
  ModelSpec start;
  MeasurementSet data;
  FitSpec fit;
  ObjectiveSettings settings;
  std::vector<Param> params;
  std::vector<std::string> names, units, notes;
  std::vector<double> start_u;
  std::vector<CondData> conds;
  std::vector<SineRun> sine_runs;
  std::vector<ResonanceRun> res_runs;
  std::vector<TargetData> targets;
  std::size_t m = 0;

  double to_param(std::size_t j, double u) const {
    const Param& p = params[j];
    const double th = p.tlo + u * (p.thi - p.tlo);
    return p.scale == ParamScale::Log ? p.sign * std::exp(th) : th;
  }
  double to_u(std::size_t j, double v) const {
    const Param& p = params[j];
    const double th = p.scale == ParamScale::Log ? std::log(std::fabs(v)) : v;
    return std::clamp((th - p.tlo) / (p.thi - p.tlo), 0.0, 1.0);
  }

  // Model at u; throws InputError if a value breaks a model rule.
  Model model_at(const double* u) const {
    ModelSpec spec = start;
    for (std::size_t j = 0; j < params.size(); ++j) spec.set(params[j].key, to_param(j, u[j]));
    return compile(spec);
  }

  bool residuals(const double* u, double* r, std::string* why = nullptr) const {
    try {
      const Model model = model_at(u);
      StartCache starts(model);
      std::vector<double> y, B;
      for (const auto& cd : conds) {
        const Measurement& meas = data.items[cd.index];
        const auto& [c, st] = starts.get(meas.condition.temperature_C,
                                         identify_detail::record_initial_current(meas));
        identify_detail::run_record(model, c, st, meas, settings, y, cd.flux ? &B : nullptr);
        identify_detail::apply_offset(meas.condition.offset, meas.response, cd.compare_begin, y);
        if (cd.flux)
          identify_detail::apply_offset(meas.condition.flux_offset, meas.flux_T, cd.compare_begin,
                                        B);
        const std::size_t n = meas.t_s.size();
        for (std::size_t i = cd.compare_begin; i < n; ++i) {
          r[cd.r_offset + i - cd.compare_begin] = cd.y_scale * (y[i] - meas.response[i]);
          if (cd.flux)
            r[cd.rB_offset + i - cd.compare_begin] = cd.B_scale * (B[i] - meas.flux_T[i]);
        }
      }
      if (!targets.empty()) {
        std::vector<double> I, yy, BB;
        std::vector<SineMetrics> sm(sine_runs.size());
        for (std::size_t k = 0; k < sine_runs.size(); ++k)
          sm[k] = run_sine(model, sine_runs[k], settings, I, yy, BB, starts);
        std::vector<double> res(res_runs.size());
        for (std::size_t k = 0; k < res_runs.size(); ++k)
          res[k] = lowest_resonance_Hz(model, res_runs[k]);
        for (const auto& td : targets) {
          const double sim = target_value(td, sm, res);
          r[td.r_index] = td.r_scale * (sim - td.t.value);
        }
      }
    } catch (const InputError& e) {
      if (why) *why = e.what();
      return false;
    } catch (const DivergenceError& e) {
      if (why) *why = e.what();
      return false;
    }
    for (std::size_t i = 0; i < m; ++i)
      if (!std::isfinite(r[i])) {
        if (why) *why = fmt::format("residual {} is not finite", i);
        return false;
      }
    return true;
  }

  static double target_value(const TargetData& td, const std::vector<SineMetrics>& sm,
                             const std::vector<double>& res) {
    auto change = [&](auto get) {
      const double ref = get(sm[static_cast<std::size_t>(td.ref_run)]);
      return 100.0 * (get(sm[static_cast<std::size_t>(td.run)]) / ref - 1.0);
    };
    auto stroke = [](const SineMetrics& s) { return s.stroke_um; };
    auto hyst = [](const SineMetrics& s) { return s.hysteresis_um; };
    auto bpp = [](const SineMetrics& s) { return s.B_pp_T; };
    switch (td.t.kind) {
      case TargetKind::StrokeUm:
        return sm[static_cast<std::size_t>(td.run)].stroke_um;
      case TargetKind::HysteresisUm:
        return sm[static_cast<std::size_t>(td.run)].hysteresis_um;
      case TargetKind::BppT:
        return sm[static_cast<std::size_t>(td.run)].B_pp_T;
      case TargetKind::StrokeChangePct:
        return change(stroke);
      case TargetKind::HysteresisChangePct:
        return change(hyst);
      case TargetKind::BppChangePct:
        return change(bpp);
      case TargetKind::RetentionPct:
        return 100.0 + change(stroke);
      case TargetKind::ResonanceHz:
      case TargetKind::FrfPeakHz:
      case TargetKind::BandwidthHz:
        return res[static_cast<std::size_t>(td.res_run)];
    }
    return 0.0;
  }
};

Objective::Objective(const ModelSpec& start, const MeasurementSet& data, const FitSpec& fit,
                     const ObjectiveSettings& settings) {
  auto impl = std::make_shared<Impl>();
  Impl& I = *impl;
  I.start = start;
  I.data = data;
  I.fit = fit;
  I.settings = settings;
  if (!(settings.steps_per_period >= 8.0))
    throw InputError(fmt::format("steps per period {:g}: must be >= 8", settings.steps_per_period));
  if (!(settings.dt_s >= 0.0) || !std::isfinite(settings.dt_s))
    throw InputError(fmt::format("dt {:g} s: must be >= 0", settings.dt_s));
  if (!(settings.flux_weight >= 0.0))
    throw InputError(fmt::format("flux weight {:g}: must be >= 0", settings.flux_weight));
  if (!(settings.target_periods >= 1.0))
    throw InputError(fmt::format("target periods {:g}: must be >= 1", settings.target_periods));
  require_in(settings.steps_per_period, 8.0, 1e6, "steps per period");
  require_in(settings.target_periods, 1.0, 1e4, "target periods");
  require_in(settings.flux_weight, 0.0, 1e6, "flux weight");
  require_in(settings.quasi_static_increments, 10.0, 1e6, "quasi-static increments per range");
  if (fit.parameters.empty()) throw InputError(located(fit.source, 0, "no parameter to fit"));
  if (data.items.empty() && fit.targets.empty()) {
    throw InputError(
        "nothing to fit against: give measurements (--data) or [[target]] entries "
        "in the fit spec");
  }

  // ---- parameters ----
  std::set<std::string> seen;
  for (const auto& fp : fit.parameters) {
    std::string key;
    try {
      key = start.key_of(fp.name);
    } catch (const InputError& e) {
      throw InputError(located(fit.source, fp.line, e.what()));
    }
    if (!seen.insert(key).second) {
      throw InputError(located(fit.source, fp.line,
                               fmt::format("parameter {} ({}) is listed twice", fp.name, key)));
    }
    Param p;
    p.key = key;
    p.unit = start.params.at(key).unit;
    p.scale = fp.scale;
    p.lo = fp.lower;
    p.hi = fp.upper;
    if (p.scale == ParamScale::Log) {
      p.sign = p.lo < 0 ? -1.0 : 1.0;
      p.tlo = std::log(std::fabs(p.lo));
      p.thi = std::log(std::fabs(p.hi));
    } else {
      p.tlo = p.lo;
      p.thi = p.hi;
    }
    // Both bounds must be values the model accepts.
    for (double b : {p.lo, p.hi}) {
      ModelSpec probe = start;
      try {
        probe.set(key, b);
      } catch (const InputError& e) {
        throw InputError(located(fit.source, fp.line,
                                 fmt::format("parameter {}: bound {:g} is not a valid model value "
                                             "({})",
                                             fp.name, b, e.what())));
      }
    }
    I.params.push_back(p);
    I.names.push_back(key);
    I.units.push_back(p.unit);
  }
  // ---- start point ----
  for (std::size_t j = 0; j < I.params.size(); ++j) {
    const auto& fp = fit.parameters[j];
    const Param& p = I.params[j];
    double v = fp.has_start ? fp.start : start.params.at(p.key).value;
    if (v < p.lo || v > p.hi) {
      const double c = std::clamp(v, p.lo, p.hi);
      I.notes.push_back(
          fmt::format("start value {} = {:g} lies outside [{:g}, {:g}]: the search "
                      "starts from {:g}",
                      p.key, v, p.lo, p.hi, c));
      v = c;
    }
    I.start_u.push_back(I.to_u(j, v));
  }
  // ---- measurements ----
  const Model start_model = compile(start);
  double W = 0.0;
  for (std::size_t k = 0; k < data.items.size(); ++k) {
    const Measurement& meas = data.items[k];
    try {
      (void)make_conditions(start_model, meas.condition.temperature_C);
    } catch (const InputError& e) {
      throw InputError(located(meas.path, 0, e.what()));
    }
    CondData cd;
    cd.index = k;
    const double span = meas.t_s.back() - meas.t_s.front();
    cd.compare_begin =
        static_cast<std::size_t>(std::lower_bound(meas.t_s.begin(), meas.t_s.end(),
                                                  meas.condition.compare_from_s - 1e-12 * span) -
                                 meas.t_s.begin());
    const std::size_t nc = meas.t_s.size() - cd.compare_begin;
    if (nc < 3) {
      throw InputError(located(meas.path, 0, "fewer than 3 samples after compare_from_s"));
    }
    try {
      (void)identify_detail::record_rod(start_model, meas);
    } catch (const InputError& e) {
      throw InputError(e.what());
    }
    cd.pp_um = peak_to_peak(std::span<const double>(meas.response).subspan(cd.compare_begin));
    if (!(cd.pp_um > 0.0)) {
      throw InputError(located(meas.path, 0,
                               fmt::format("the measured {} does not vary over the compared "
                                           "samples: the RMS / peak-to-peak error is undefined",
                                           meas.response_column())));
    }
    cd.flux = settings.flux_weight > 0.0 && !meas.flux_T.empty();
    if (cd.flux) {
      cd.ppB = peak_to_peak(std::span<const double>(meas.flux_T).subspan(cd.compare_begin));
      if (!(cd.ppB > 0.0)) {
        throw InputError(located(meas.path, 0, "flux_T does not vary: set the flux weight to 0"));
      }
    }
    W += meas.weight * (1.0 + (cd.flux ? settings.flux_weight : 0.0));
    I.conds.push_back(cd);
  }
  // ---- targets ----
  auto sine_index = [&](const SineRun& r) {
    const auto it = std::find(I.sine_runs.begin(), I.sine_runs.end(), r);
    if (it != I.sine_runs.end()) return static_cast<int>(it - I.sine_runs.begin());
    I.sine_runs.push_back(r);
    return static_cast<int>(I.sine_runs.size() - 1);
  };
  for (const auto& t : fit.targets) {
    TargetData td;
    td.t = t;
    for (double T : {t.temperature_C, t.reference_temperature_C}) {
      try {
        (void)make_conditions(start_model, T);
      } catch (const InputError& e) {
        throw InputError(located(fit.source, t.line, e.what()));
      }
    }
    if (t.kind == TargetKind::ResonanceHz || t.kind == TargetKind::FrfPeakHz ||
        t.kind == TargetKind::BandwidthHz) {
      const ResonanceRun rr{t.temperature_C, t.bias_A, t.kind};
      const auto it = std::find(I.res_runs.begin(), I.res_runs.end(), rr);
      td.res_run = static_cast<int>(it - I.res_runs.begin());
      if (it == I.res_runs.end()) I.res_runs.push_back(rr);
    } else {
      td.run = sine_index({t.temperature_C, t.current_pp_A, t.frequency_Hz, t.current_min_A});
      const bool change = t.kind == TargetKind::StrokeChangePct ||
                          t.kind == TargetKind::HysteresisChangePct ||
                          t.kind == TargetKind::BppChangePct || t.kind == TargetKind::RetentionPct;
      if (change) {
        td.ref_run = sine_index(
            {t.reference_temperature_C, t.current_pp_A, t.frequency_Hz, t.current_min_A});
      }
    }
    W += t.weight;
    I.targets.push_back(td);
  }
  // ---- run lengths: every simulation an evaluation will run is checked here, so that an
  // evaluation fails only for its parameter values, never for the settings (issue 8) ----
  for (const SineRun& run : I.sine_runs) {
    const double per = 1.0 / run.f;
    const double n_per = std::max(8.0, std::ceil(per / identify_detail::objective_step(settings, per) - 1e-9));
    (void)checked_count(n_per * std::round(settings.target_periods), kMaxSteps,
                        fmt::format("steps of the {:g} Hz target simulation", run.f));
  }
  for (const auto& cd : I.conds) {
    const Measurement& meas = data.items[cd.index];
    const double n = identify_detail::record_step_count(meas, settings);
    if (!(n <= kMaxSteps))
      throw InputError(located(
          meas.path, 0,
          meas.condition.quasi_static
              ? fmt::format("{:.4g} quasi-static increments over the record: too many (limit "
                            "{:g}); lower the increments per drive range",
                            n, kMaxSteps)
              : fmt::format("{:.4g} steps of {:g} s over the record's {:g} s: too many (limit "
                            "{:g}, pre-cycles included); give --dt, or a frequency_Hz "
                            "condition for a periodic record",
                            n,
                            identify_detail::objective_step(
                                settings, meas.periodic() ? 1.0 / meas.condition.frequency_Hz
                                                          : 0.0),
                            meas.t_s.back() - meas.t_s.front(), kMaxSteps)));
  }
  // ---- residual layout and scales ----
  std::size_t off = 0;
  for (auto& cd : I.conds) {
    const Measurement& meas = data.items[cd.index];
    const std::size_t nc = meas.t_s.size() - cd.compare_begin;
    cd.y_scale = 100.0 / cd.pp_um * std::sqrt(meas.weight / (W * static_cast<double>(nc)));
    cd.r_offset = off;
    off += nc;
    if (cd.flux) {
      cd.B_scale = 100.0 / cd.ppB *
                   std::sqrt(meas.weight * settings.flux_weight / (W * static_cast<double>(nc)));
      cd.rB_offset = off;
      off += nc;
    }
  }
  for (auto& td : I.targets) {
    td.r_scale = 100.0 / td.t.scale * std::sqrt(td.t.weight / W);
    td.r_index = off++;
  }
  I.m = off;
  if (I.m < I.params.size()) {
    throw InputError(
        fmt::format("{} residuals for {} parameters: the fit is underdetermined; "
                    "add data or targets, or fit fewer parameters",
                    I.m, I.params.size()));
  }
  impl_ = std::move(impl);
}

std::string Objective::failure_reason(const std::vector<double>& u) const {
  std::vector<double> r(impl_->m);
  std::string why;
  return impl_->residuals(u.data(), r.data(), &why) ? std::string() : why;
}

std::size_t Objective::dim() const { return impl_->params.size(); }
std::size_t Objective::residual_count() const { return impl_->m; }
const std::vector<std::string>& Objective::names() const { return impl_->names; }
const std::vector<std::string>& Objective::units() const { return impl_->units; }
const FitSpec& Objective::fit() const { return impl_->fit; }
const MeasurementSet& Objective::data() const { return impl_->data; }
const ObjectiveSettings& Objective::settings() const { return impl_->settings; }
const ModelSpec& Objective::start_spec() const { return impl_->start; }
const std::vector<std::string>& Objective::notes() const { return impl_->notes; }
std::vector<double> Objective::start_unit() const { return impl_->start_u; }

std::vector<double> Objective::to_params(const std::vector<double>& u) const {
  std::vector<double> p(u.size());
  for (std::size_t j = 0; j < u.size(); ++j) p[j] = impl_->to_param(j, u[j]);
  return p;
}

std::vector<double> Objective::to_unit(const std::vector<double>& p) const {
  std::vector<double> u(p.size());
  for (std::size_t j = 0; j < p.size(); ++j) u[j] = impl_->to_u(j, p[j]);
  return u;
}

std::vector<double> Objective::theta_per_unit() const {
  std::vector<double> d;
  for (const auto& p : impl_->params) d.push_back(p.thi - p.tlo);
  return d;
}

bool Objective::residuals(const double* u, double* r) const { return impl_->residuals(u, r); }

double Objective::rms_pct(const std::vector<double>& u) const {
  std::vector<double> r(impl_->m);
  if (!impl_->residuals(u.data(), r.data())) return kPenalty;
  double ss = 0.0;
  for (double v : r) ss += v * v;
  return std::sqrt(ss);
}

ModelSpec Objective::spec_at(const std::vector<double>& u) const {
  ModelSpec spec = impl_->start;
  for (std::size_t j = 0; j < impl_->params.size(); ++j)
    spec.set(impl_->params[j].key, impl_->to_param(j, u[j]));
  return spec;
}

std::vector<ConditionFit> Objective::condition_fits(const std::vector<double>& u) const {
  const Impl& I = *impl_;
  std::vector<ConditionFit> out;
  std::optional<Model> model;
  std::string model_error;
  try {
    model.emplace(I.model_at(u.data()));
  } catch (const InputError& e) {
    model_error = e.what();
  }
  for (const auto& cd : I.conds) {
    const Measurement& meas = I.data.items[cd.index];
    ConditionFit f;
    f.label = meas.condition.label;
    f.path = meas.path;
    {
      std::string safe;
      for (char ch : f.label) {
        const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                        (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' || ch == '.';
        safe += ok ? ch : '_';
      }
      std::string name = "overlay_" + safe;
      for (int k = 2;
           std::any_of(out.begin(), out.end(),
                       [&](const ConditionFit& o) { return o.overlay_file == name + ".csv"; });
           ++k)
        name = fmt::format("overlay_{}_{}", safe, k);
      f.overlay_file = name + ".csv";
    }
    f.condition = meas.condition;
    f.weight = meas.weight;
    f.samples = meas.t_s.size();
    f.compared = f.samples - cd.compare_begin;
    f.pp_um = cd.pp_um;
    f.response_unit = std::string(meas.response_unit());
    std::vector<double> y, B;
    const bool has_flux = !meas.flux_T.empty();
    try {
      if (!model) throw InputError(model_error);
      simulate_measurement(*model, meas, I.settings, y, has_flux ? &B : nullptr);
      identify_detail::apply_offset(meas.condition.offset, meas.response, cd.compare_begin, y);
      if (has_flux)
        identify_detail::apply_offset(meas.condition.flux_offset, meas.flux_T, cd.compare_begin,
                                      B);
    } catch (const std::exception& e) {
      f.failed = true;
      f.error = e.what();
      out.push_back(std::move(f));
      continue;
    }
    double ss = 0.0, ssB = 0.0;
    for (std::size_t i = cd.compare_begin; i < f.samples; ++i) {
      const double d = y[i] - meas.response[i];
      ss += d * d;
      f.max_err_um = std::max(f.max_err_um, std::fabs(d));
      if (has_flux) ssB += (B[i] - meas.flux_T[i]) * (B[i] - meas.flux_T[i]);
    }
    f.rms_um = std::sqrt(ss / static_cast<double>(f.compared));
    f.rms_pct = 100.0 * f.rms_um / f.pp_um;
    if (has_flux) {
      const double ppB =
          peak_to_peak(std::span<const double>(meas.flux_T).subspan(cd.compare_begin));
      if (ppB > 0.0) f.flux_rms_pct = 100.0 * std::sqrt(ssB / static_cast<double>(f.compared)) / ppB;
    }
    TimeSeries& ts = f.overlay;
    // Timed current/displacement records keep their historical column names; the others
    // name their own columns (sample index, field, strain).
    const std::string unit = f.response_unit;
    ts.names = {meas.condition.quasi_static ? "sample" : "t_s", std::string(meas.drive_column()),
                "measured_" + unit, "simulated_" + unit, "compared"};
    ts.columns = {meas.t_s, meas.drive, meas.response, y, std::vector<double>(f.samples, 0.0)};
    for (std::size_t i = cd.compare_begin; i < f.samples; ++i) ts.columns[4][i] = 1.0;
    if (has_flux) {
      ts.names.insert(ts.names.end(), {"measured_flux_T", "simulated_flux_T"});
      ts.columns.push_back(meas.flux_T);
      ts.columns.push_back(B);
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<TargetFit> Objective::target_fits(const std::vector<double>& u) const {
  const Impl& I = *impl_;
  std::vector<TargetFit> out;
  if (I.targets.empty()) return out;
  std::vector<SineMetrics> sm(I.sine_runs.size());
  std::vector<double> res(I.res_runs.size());
  bool failed = false;
  try {
    const Model model = I.model_at(u.data());
    StartCache starts(model);
    std::vector<double> a, b, c;
    for (std::size_t k = 0; k < I.sine_runs.size(); ++k)
      sm[k] = run_sine(model, I.sine_runs[k], I.settings, a, b, c, starts);
    for (std::size_t k = 0; k < I.res_runs.size(); ++k)
      res[k] = lowest_resonance_Hz(model, I.res_runs[k]);
  } catch (const std::exception&) {
    failed = true;
  }
  for (const auto& td : I.targets) {
    TargetFit f;
    f.label = td.t.label;
    f.kind = target_kind_name(td.t.kind);
    f.value = td.t.value;
    f.weight = td.t.weight;
    f.failed = failed;
    if (!failed) {
      f.simulated = Impl::target_value(td, sm, res);
      f.error_pct = 100.0 * (f.simulated - f.value) / td.t.scale;
    }
    out.push_back(f);
  }
  return out;
}

// =======================================================================================
MeasurementSet synthesize_measurements(const Model& truth, const SyntheticRequest& r) {
  if (r.samples_per_period < 8) throw InputError("samples per period: must be >= 8");
  if (r.precycles == 0 && !(r.periods >= 1.5))
    throw InputError("periods: must be >= 1.5 (the first is not compared)");
  if (!(r.periods >= 1.0)) throw InputError("periods: must be >= 1 (one whole loop)");
  require_in(r.periods, 1.0, kMaxPeriods, "periods");
  require_in(r.current_min_A, -kMaxCurrent_A, kMaxCurrent_A, "current minimum", "A");
  require_in(r.noise_pct, 0.0, 100.0, "noise", "%");
  require_in(r.flux_noise_pct, 0.0, 100.0, "flux noise", "%");
  require_in(r.response_offset, -1e6, 1e6, "response offset");
  if (r.precycles < 0 || r.precycles > kMaxPrecycles)
    throw InputError(fmt::format("precycles {}: must be in [0, {}]", r.precycles, kMaxPrecycles));
  for (double T : r.temperatures_C) require_finite(T, "temperature", "degC");
  for (double pp : r.currents_pp_A)
    require_in(pp, 0.0, 2.0 * kMaxCurrent_A, "current peak-to-peak", "A");
  for (double f : r.frequencies_Hz) {
    require_positive(f, "frequency", "Hz");
    require_in(f, 0.0, kMaxFrequency_Hz, "frequency", "Hz");
  }
  (void)checked_count(r.periods * r.samples_per_period, kMaxRecordedRows, "samples per record");
  (void)checked_count(static_cast<double>(r.temperatures_C.size()) *
                          static_cast<double>(r.currents_pp_A.size()) *
                          static_cast<double>(r.frequencies_Hz.size()),
                      kMaxListValues, "synthetic records");
  MeasurementSet set;
  std::uint64_t state = 0x9E3779B97F4A7C15ULL ^ r.seed;
  auto next_u01 = [&]() {  // splitmix64: the same numbers on every platform
    state += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return (static_cast<double>(z >> 11) + 0.5) * 0x1.0p-53;
  };
  auto gauss = [&]() {  // Box-Muller
    const double u1 = next_u01(), u2 = next_u01();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * physics::kPi * u2);
  };
  // A quasi-static record has no frequency: one record per (temperature, current).
  const std::vector<double> freqs =
      r.quasi_static ? std::vector<double>{1.0} : r.frequencies_Hz;
  for (double T : r.temperatures_C) {
    for (double pp : r.currents_pp_A) {
      for (double f : freqs) {
        Measurement m;
        auto& c = m.condition;
        c.temperature_C = T;
        c.quasi_static = r.quasi_static;
        c.rod = r.rod;
        c.precycles = r.precycles;
        c.offset = r.offset;
        m.response_kind = r.response;
        if (r.quasi_static) {
          c.compare_from_s = r.precycles > 0 ? 0.0 : r.samples_per_period;  // sample index
          c.label = fmt::format("T{:g}_I{:g}_qs", T, pp);
        } else {
          c.frequency_Hz = f;
          c.current_pp_A = pp;
          c.current_min_A = r.current_min_A;
          c.compare_from_s = r.precycles > 0 ? 0.0 : 1.0 / f;
          c.label = fmt::format("T{:g}_I{:g}_f{:g}", T, pp, f);
        }
        m.path = c.label + ".csv";
        const Waveform w = biased_sine(pp, f, r.current_min_A);
        const long n = std::lround(r.periods * r.samples_per_period);
        for (long k = 0; k <= n; ++k) {
          const double t = static_cast<double>(k) / (f * r.samples_per_period);
          m.t_s.push_back(r.quasi_static ? static_cast<double>(k) : t);
          m.drive.push_back(w.current_at(t));
        }
        std::vector<double> y, B, H;
        {
          const Conditions cond = make_conditions(truth, T);
          const State st0 =
              make_state(truth, cond, identify_detail::record_initial_current(m));
          identify_detail::run_record(truth, cond, st0, m, r.objective, y,
                                      r.with_flux ? &B : nullptr, &H);
        }
        if (r.drive == DriveInput::Field) {  // what a Hall probe on the rod reads
          m.drive = H;
          m.drive_kind = DriveInput::Field;
        }
        const double sy = r.noise_pct / 100.0 * peak_to_peak(y);
        m.response = y;
        for (double& v : m.response) v += sy * gauss();
        if (r.offset == OffsetMode::FirstSample) {
          const double first = m.response.front();
          for (double& v : m.response) v -= first;
        } else if (r.offset == OffsetMode::Fitted) {
          for (double& v : m.response) v += r.response_offset;
        }
        if (r.with_flux) {
          const double sb = r.flux_noise_pct / 100.0 * peak_to_peak(B);
          m.flux_T = B;
          for (double& v : m.flux_T) v += sb * gauss();
        }
        set.items.push_back(std::move(m));
      }
    }
  }
  return set;
}

}  // namespace gmasim
