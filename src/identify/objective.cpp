// The identification objective: normalised residuals of simulated vs measured displacement
// (and optionally flux density) at every compared sample, plus scalar targets. The sum of
// squares of the residuals is the square of the weighted RMS error in % of peak-to-peak.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <set>
#include <span>

#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/validate.hpp"
#include "identify/objective_impl.hpp"

namespace gmasim {
// =======================================================================================
// Construction: the settings, the parameters and their start point, the records, the
// targets, the run lengths, the residual layout.
namespace {

using identify_detail::CondData;
using identify_detail::Param;
using identify_detail::ResonanceRun;
using identify_detail::SineRun;
using identify_detail::TargetData;

void check_settings(const ObjectiveSettings& settings, const MeasurementSet& data,
                    const FitSpec& fit) {
  validate(settings);
  if (fit.parameters.empty()) throw InputError(located(fit.source, 0, "no parameter to fit"));
  if (data.items.empty() && fit.targets.empty()) {
    throw InputError(
        "nothing to fit against: give measurements (--data) or [[target]] entries "
        "in the fit spec");
  }
}

}  // namespace

void validate(const ObjectiveSettings& settings) {
  if (!(settings.steps_per_period >= 8.0))
    throw InputError(fmt::format("steps per period {:g} (--steps-per-period): must be >= 8",
                                 settings.steps_per_period));
  if (!(settings.dt_s >= 0.0) || !std::isfinite(settings.dt_s))
    throw InputError(fmt::format("dt {:g} s (--dt): must be >= 0", settings.dt_s));
  if (settings.dt_s > 0.0 && (settings.dt_s < kMinStepDt_s || settings.dt_s > kMaxStepDt_s))
    throw InputError(fmt::format("dt {:g} s (--dt): must be in [{:g}, {:g}] s, or 0", settings.dt_s,
                                 kMinStepDt_s, kMaxStepDt_s));
  if (!(settings.flux_weight >= 0.0))
    throw InputError(
        fmt::format("flux weight {:g} (--flux-weight): must be >= 0", settings.flux_weight));
  if (!(settings.target_periods >= 1.0))
    throw InputError(fmt::format("target periods {:g} (--target-periods): must be >= 1",
                                 settings.target_periods));
  require_in(settings.steps_per_period, 8.0, 1e6, "steps per period");
  require_in(settings.target_periods, 1.0, 1e4, "target periods");
  require_in(settings.flux_weight, 0.0, 1e6, "flux weight");
  require_in(settings.quasi_static_increments, 10.0, 1e6, "quasi-static increments per range");
}

namespace {

// One fitted parameter: its full key, unit, scale and bounds (both valid model values).
Param make_param(const ModelSpec& start, const FitSpec& fit, const FitParameter& fp,
                 std::set<std::string>& seen) {
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
  p.unit = start.unit_of(key);
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
  return p;
}

// Every fitted name the start model does not know (an old unit-less spelling, a typo), all of
// them in one message rather than the first alone (issue 41).
void check_parameter_names(const Objective::Impl& I) {
  std::vector<std::string> bad;
  for (const auto& fp : I.fit.parameters) {
    try {
      (void)I.start.key_of(fp.name);
    } catch (const InputError& e) {
      bad.push_back(located(I.fit.source, fp.line, e.what()));
    }
  }
  if (bad.size() == 1) throw InputError(bad.front());
  if (bad.size() > 1)
    throw InputError(fmt::format("{} of the fit's {} parameter names are not the model's:\n  {}",
                                 bad.size(), I.fit.parameters.size(), fmt::join(bad, "\n  ")));
}

void add_parameters(Objective::Impl& I) {
  check_parameter_names(I);
  std::set<std::string> seen;
  for (const auto& fp : I.fit.parameters) {
    const Param p = make_param(I.start, I.fit, fp, seen);
    I.params.push_back(p);
    I.names.push_back(p.key);
    I.units.push_back(p.unit);
  }
  for (std::size_t j = 0; j < I.params.size(); ++j) {  // the start point
    const auto& fp = I.fit.parameters[j];
    const Param& p = I.params[j];
    double v = fp.has_start ? fp.start : I.start.params.at(p.key).value;
    if (fp.has_start && v != I.start.params.at(p.key).value)
      I.notes.push_back(fmt::format("start value {} = {:g} from the fit spec (the model has {:g})",
                                    p.key, v, I.start.params.at(p.key).value));
    if (v < p.lo || v > p.hi) {
      const double c = std::clamp(v, p.lo, p.hi);
      I.notes.push_back(
          fmt::format("start value {} = {:g} lies outside [{:g}, {:g}]: moved onto the bound, "
                      "the search starts from {:g}",
                      p.key, v, p.lo, p.hi, c));
      v = c;
    }
    I.start_u.push_back(I.to_u(j, v));
  }
}

// A field record must reach fields the model's rod responds to: its largest |H| at least
// kMinFieldOverA of the rod's anhysteretic shape field a (eq. 10 at the record's temperature,
// ~6 kA/m for Terfenol-D; a loop is driven to several times a). A column in kA/m read as A/m
// is 1000 times too small and fails this rule, instead of fitting a flat loop silently.
constexpr double kMinFieldOverA = 0.05;

void check_field_magnitude(const Model& start_model, const Measurement& meas) {
  if (meas.drive_kind != DriveInput::Field) return;
  const std::size_t rod = identify_detail::record_rod(start_model, meas);
  const Conditions c = make_conditions(start_model, meas.condition.temperature_C);
  // the law's own field scale (JA: a^T; Preisach: H_c^T), named by the law
  const char* field_name = "";
  const double a = with_magnetisation_law(start_model.options.magnetisation_law, [&](auto law) {
    field_name = decltype(law)::characteristic_field_name;
    return decltype(law)::characteristic_field_A_per_m(c.rods[rod]);
  });
  double hmax = 0.0;
  for (double h : meas.drive) hmax = std::max(hmax, std::fabs(h));
  if (hmax >= kMinFieldOverA * a) return;
  const std::string col =
      meas.drive_header.empty() ? std::string(meas.drive_column()) : meas.drive_header;
  const double in_col = col == "field_kA_per_m" ? hmax / 1e3 : hmax;
  throw InputError(located(
      meas.path, 0,
      fmt::format("column {}: the largest |field| is {:g} {} = {:g} A/m, below {:g} x the "
                  "{} = {:.4g} A/m of rod '{}' at {:g} degC (the rule: a record's field must "
                  "reach {:g} times that field, or the rod barely leaves its demagnetised "
                  "state); if the values are in kA/m, name the column field_kA_per_m (read x "
                  "1000), or convert them to A/m",
                  col, in_col, col == "field_kA_per_m" ? "kA/m" : "A/m", hmax, kMinFieldOverA,
                  field_name, a, start_model.rods[rod].name, meas.condition.temperature_C,
                  kMinFieldOverA)));
}

// One record: its compared samples and peak-to-peak values; checked against the start model.
CondData make_cond(const Model& start_model, const Measurement& meas, std::size_t k,
                   const ObjectiveSettings& settings) {
  try {
    (void)make_conditions(start_model, meas.condition.temperature_C);
  } catch (const InputError& e) {  // at the line that gave the temperature, where known
    const auto& c = meas.condition;
    throw InputError(c.temperature_file.empty()
                         ? located(meas.path, 0, e.what())
                         : located(c.temperature_file, c.temperature_line, e.what()));
  }
  CondData cd;
  cd.index = k;
  const double span = meas.t_s.back() - meas.t_s.front();
  cd.compare_begin =
      static_cast<std::size_t>(std::lower_bound(meas.t_s.begin(), meas.t_s.end(),
                                                meas.condition.compare_from_s - 1e-12 * span) -
                               meas.t_s.begin());
  const std::size_t nc = meas.t_s.size() - cd.compare_begin;
  if (nc < 3) throw InputError(located(meas.path, 0, "fewer than 3 samples after compare_from_s"));
  (void)identify_detail::record_rod(start_model, meas);
  check_field_magnitude(start_model, meas);
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
    if (!(cd.ppB > 0.0))
      throw InputError(located(meas.path, 0, "flux_T does not vary: set the flux weight to 0"));
  }
  return cd;
}

// The records; returns their total weight.
double add_records(Objective::Impl& I, const Model& start_model) {
  double W = 0.0;
  for (std::size_t k = 0; k < I.data.items.size(); ++k) {
    const Measurement& meas = I.data.items[k];
    const CondData cd = make_cond(start_model, meas, k, I.settings);
    W += meas.weight * (1.0 + (cd.flux ? I.settings.flux_weight : 0.0));
    I.conds.push_back(cd);
  }
  return W;
}

// The loop measure a sine target of this kind reads (Objective::Impl::target_value).
void add_wanted(LoopMetricsWanted& w, TargetKind kind) {
  switch (kind) {
    case TargetKind::StrokeUm:
    case TargetKind::StrokeChangePct:
    case TargetKind::RetentionPct:
      w.stroke = true;
      return;
    case TargetKind::HysteresisUm:
    case TargetKind::HysteresisChangePct:
      w.hysteresis = true;
      return;
    case TargetKind::BppT:
    case TargetKind::BppChangePct:
      w.B_pp = true;
      return;
    default:
      return;
  }
}

// The targets and the runs they share; adds their weights to W.
void add_targets(Objective::Impl& I, const Model& start_model, double& W) {
  // The run of a drive (shared by the targets at it), wanting the loop measure of `kind`.
  auto sine_index = [&](const SineRun& r, TargetKind kind) {
    auto it = std::find_if(I.sine_runs.begin(), I.sine_runs.end(),
                           [&](const SineRun& o) { return o.same_drive(r); });
    if (it == I.sine_runs.end()) it = I.sine_runs.insert(it, r);
    add_wanted(it->want, kind);
    return static_cast<int>(it - I.sine_runs.begin());
  };
  for (const auto& t : I.fit.targets) {
    TargetData td;
    td.t = t;
    for (double T : {t.temperature_C, t.reference_temperature_C}) {
      try {
        (void)make_conditions(start_model, T);
      } catch (const InputError& e) {
        throw InputError(located(I.fit.source, t.line, e.what()));
      }
    }
    if (t.kind == TargetKind::ResonanceHz || t.kind == TargetKind::FrfPeakHz ||
        t.kind == TargetKind::BandwidthHz || t.kind == TargetKind::ModulusGPa) {
      const ResonanceRun rr{t.temperature_C, t.bias_A, t.kind};
      const auto it = std::find(I.res_runs.begin(), I.res_runs.end(), rr);
      td.res_run = static_cast<int>(it - I.res_runs.begin());
      if (it == I.res_runs.end()) I.res_runs.push_back(rr);
    } else {
      td.run =
          sine_index({t.temperature_C, t.current_pp_A, t.frequency_Hz, t.current_min_A}, t.kind);
      const bool change = t.kind == TargetKind::StrokeChangePct ||
                          t.kind == TargetKind::HysteresisChangePct ||
                          t.kind == TargetKind::BppChangePct || t.kind == TargetKind::RetentionPct;
      if (change) {
        td.ref_run = sine_index(
            {t.reference_temperature_C, t.current_pp_A, t.frequency_Hz, t.current_min_A}, t.kind);
      }
    }
    W += t.weight;
    I.targets.push_back(td);
  }
}

// Every simulation an evaluation will run is checked here, so that an evaluation fails only
// for its parameter values, never for the settings (issue 8).
void check_run_lengths(const Objective::Impl& I) {
  for (const SineRun& run : I.sine_runs) (void)identify_detail::sine_target_grid(run, I.settings);
  for (const auto& cd : I.conds) {
    const Measurement& meas = I.data.items[cd.index];
    const double n = identify_detail::record_step_count(meas, I.settings);
    if (n <= kMaxSteps) continue;
    if (meas.condition.quasi_static)
      throw InputError(
          located(meas.path, 0,
                  fmt::format("{:.4g} quasi-static increments over the record: too many (limit "
                              "{:g}); lower the increments per drive range",
                              n, kMaxSteps)));
    const double dt = identify_detail::objective_step(
        I.settings, meas.periodic() ? 1.0 / meas.condition.frequency_Hz : 0.0);
    throw InputError(located(
        meas.path, 0,
        fmt::format("{:.4g} steps of {:g} s over the record's {:g} s: too many (limit {:g}, "
                    "pre-cycles included); give --dt, or a frequency_Hz condition for a periodic "
                    "record",
                    n, dt, meas.t_s.back() - meas.t_s.front(), kMaxSteps)));
  }
}

// Residual layout and scales: each record's compared samples (then its flux samples), then
// the targets; every residual is scaled so that their sum of squares is the weighted RMS [%]^2.
void lay_out_residuals(Objective::Impl& I, double W) {
  std::size_t off = 0;
  for (auto& cd : I.conds) {
    const Measurement& meas = I.data.items[cd.index];
    const std::size_t nc = meas.t_s.size() - cd.compare_begin;
    cd.y_scale = 100.0 / cd.pp_um * std::sqrt(meas.weight / (W * static_cast<double>(nc)));
    cd.r_offset = off;
    off += nc;
    if (cd.flux) {
      cd.B_scale = 100.0 / cd.ppB *
                   std::sqrt(meas.weight * I.settings.flux_weight / (W * static_cast<double>(nc)));
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
}

}  // namespace

Objective::Objective(const ModelSpec& start, const MeasurementSet& data, const FitSpec& fit,
                     const ObjectiveSettings& settings) {
  auto impl = std::make_shared<Impl>();
  Impl& I = *impl;
  I.start = start;
  I.data = data;
  I.fit = fit;
  I.settings = settings;
  check_settings(settings, data, fit);
  add_parameters(I);
  const Model start_model = compile(start);
  double W = add_records(I, start_model);
  add_targets(I, start_model, W);
  check_run_lengths(I);
  for (auto& run : I.sine_runs) run.drive_A = identify_detail::sine_drive(run, I.settings);
  for (auto& cd : I.conds) {  // the records' drives on their grids (the records' lanes)
    const Measurement& meas = I.data.items[cd.index];
    if (meas.drive_kind == DriveInput::Current && !meas.condition.quasi_static)
      cd.drive_A = identify_detail::record_drive(meas, I.settings);
  }
  lay_out_residuals(I, W);
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

std::vector<char> Objective::Impl::residuals_batch(std::span<const double* const> u,
                                                   std::span<double* const> r) const {
  const std::size_t P = u.size();
  std::vector<char> ok(P, 0);
  std::deque<Model> models;         // stable addresses
  std::vector<std::size_t> shared;  // the points whose records share the lanes
  std::vector<const Model*> shared_models;
  for (std::size_t i = 0; i < P; ++i) {
    try {
      models.push_back(model_at(u[i]));
    } catch (const InputError&) {
      continue;  // residuals() fails at u[i] alike
    }
    // the points without records share the lanes of their targets' runs (targets_batch)
    const bool no_records = conds.empty() && settings.lanes && lanes_supported(models.back());
    if (records_in_lanes(models.back()) || no_records) {
      shared.push_back(i);
      shared_models.push_back(&models.back());
    } else {
      ok[i] = residuals_at(models.back(), r[i], nullptr) ? 1 : 0;
    }
  }
  std::vector<identify_detail::RecordOutputs> out;
  std::vector<char> failed;
  bool batched = shared.size() > 1;
  if (batched && conds.empty()) {
    out.resize(shared.size());
    failed.assign(shared.size(), 0);
  } else if (batched) {
    try {
      identify_detail::run_records_lanes(shared_models, record_measurements(), record_flux(),
                                         settings, out, &failed, record_drives());
    } catch (const InputError&) {  // a state at rest failed (make_states): each point alone
      batched = false;
    } catch (const DivergenceError&) {
      batched = false;
    }
  }
  // The targets of the points whose records ran: their sine runs in shared lanes too.
  std::vector<std::size_t> live;
  std::vector<const Model*> live_models;
  for (std::size_t j = 0; batched && j < shared.size(); ++j) {
    if (failed[j]) continue;
    live.push_back(j);
    live_models.push_back(shared_models[j]);
  }
  std::vector<TargetOutputs> tout;
  std::vector<char> tfailed;
  const bool targets_done = !targets.empty() && targets_batch(live_models, tout, tfailed);
  std::vector<const TargetOutputs*> tdone(shared.size(), nullptr);
  for (std::size_t q = 0; targets_done && q < live.size(); ++q) {
    if (tfailed[q]) failed[live[q]] = 1;  // its residuals() fails in its targets
    tdone[live[q]] = &tout[q];
  }
  for (std::size_t j = 0; j < shared.size(); ++j) {
    const std::size_t i = shared[j];
    if (!batched)
      ok[i] = residuals_at(*shared_models[j], r[i], nullptr) ? 1 : 0;
    else if (!failed[j])
      ok[i] = residuals_at(*shared_models[j], r[i], nullptr, &out[j], tdone[j]) ? 1 : 0;
  }
  return ok;
}

std::vector<char> Objective::residuals_batch(std::span<const double* const> u,
                                             std::span<double* const> r) const {
  if (u.size() != r.size())
    throw InputError(
        fmt::format("residuals_batch: {} points but {} residual vectors", u.size(), r.size()));
  return impl_->residuals_batch(u, r);
}

std::vector<double> Objective::rms_pct_batch(const std::vector<std::vector<double>>& u) const {
  const std::size_t P = u.size();
  std::vector<std::vector<double>> r(P, std::vector<double>(impl_->m));
  std::vector<const double*> up(P);
  std::vector<double*> rp(P);
  for (std::size_t i = 0; i < P; ++i) {
    if (u[i].size() != dim())
      throw InputError(
          fmt::format("rms_pct_batch: point {} has {} values, the fit {}", i, u[i].size(), dim()));
    up[i] = u[i].data();
    rp[i] = r[i].data();
  }
  const std::vector<char> ok = impl_->residuals_batch(up, rp);
  std::vector<double> f(P, kPenalty);
  for (std::size_t i = 0; i < P; ++i) {
    if (!ok[i]) continue;
    double ss = 0.0;
    for (double v : r[i]) ss += v * v;
    f[i] = std::sqrt(ss);
  }
  return f;
}

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

}  // namespace gmasim
