// The identification objective's internals (gmasim/identify/identify.hpp, Objective): its
// parameters, records and targets, and the residual evaluation, shared by objective.cpp
// (construction, evaluation) and objective_fits.cpp (the fit report's per-record and per-target
// view).
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/experiments/frf_bias.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "identify/objective_runs.hpp"
#include "identify/record_lanes.hpp"
#include "identify/record_run.hpp"

namespace gmasim {
namespace identify_detail {

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
  // A timed, current-driven record's coil current on its grid (record_drive, computed once for
  // the records' lanes); empty for the others.
  std::vector<double> drive_A;
};

struct TargetData {
  FitTarget t;
  int run = -1, ref_run = -1, res_run = -1;
  double r_scale = 0;
  std::size_t r_index = 0;
};

}  // namespace identify_detail

// The objective's data: built by the constructor (objective.cpp), read by the evaluations and
// the fit report (objective_fits.cpp).
struct Objective::Impl {
  using CondData = identify_detail::CondData;
  using Param = identify_detail::Param;
  using ResonanceRun = identify_detail::ResonanceRun;
  using SineMetrics = identify_detail::SineMetrics;
  using SineRun = identify_detail::SineRun;
  using StartCache = identify_detail::StartCache;
  using TargetData = identify_detail::TargetData;

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
    return compile(std::move(spec));
  }

  // Whether the records run in SIMD lanes at this model (identify/record_lanes.hpp).
  bool records_in_lanes(const Model& model) const {
    return settings.lanes && conds.size() > 1 && all_records_in_lanes(model);
  }

  // The records' residuals: from `done` (the records already run in lanes, a batch
  // evaluation), else run here. Throws InputError / DivergenceError.
  void record_residuals(const Model& model, StartCache& starts, double* r,
                        identify_detail::RecordOutputs* done = nullptr) const {
    std::vector<double> y, B;
    identify_detail::RecordOutputs lanes_out;
    const bool lanes = done != nullptr || records_in_lanes(model);
    if (lanes && !done) {  // every record in its own SIMD lane (identify/record_lanes.hpp)
      identify_detail::run_records_lanes(model, record_measurements(), record_flux(), settings,
                                         lanes_out.response, lanes_out.B_T, record_drives());
      done = &lanes_out;
    }
    for (std::size_t k = 0; k < conds.size(); ++k) {
      const CondData& cd = conds[k];
      const Measurement& meas = data.items[cd.index];
      if (lanes) {
        y.swap(done->response[k]);
        B.swap(done->B_T[k]);
      } else {
        identify_detail::run_record_from_start(model, starts, meas, settings, y,
                                               cd.flux ? &B : nullptr);
      }
      identify_detail::apply_offset(meas.condition.offset, meas.response, cd.compare_begin, y);
      if (cd.flux)
        identify_detail::apply_offset(meas.condition.flux_offset, meas.flux_T, cd.compare_begin, B);
      const std::size_t n = meas.t_s.size();
      for (std::size_t i = cd.compare_begin; i < n; ++i) {
        r[cd.r_offset + i - cd.compare_begin] = cd.y_scale * (y[i] - meas.response[i]);
        if (cd.flux) r[cd.rB_offset + i - cd.compare_begin] = cd.B_scale * (B[i] - meas.flux_T[i]);
      }
    }
  }

  std::vector<const Measurement*> record_measurements() const {
    std::vector<const Measurement*> recs;
    for (const auto& cd : conds) recs.push_back(&data.items[cd.index]);
    return recs;
  }
  std::vector<const std::vector<double>*> record_drives() const {
    std::vector<const std::vector<double>*> d;
    for (const auto& cd : conds) d.push_back(&cd.drive_A);
    return d;
  }
  std::vector<bool> record_flux() const {
    std::vector<bool> flux;
    for (const auto& cd : conds) flux.push_back(cd.flux);
    return flux;
  }

  bool all_records_in_lanes(const Model& model) const {
    for (const auto& cd : conds)
      if (!identify_detail::record_in_lanes(model, data.items[cd.index])) return false;
    return true;
  }

  // The simulations of the scalar targets. Throws InputError / DivergenceError.
  void target_runs(const Model& model, StartCache& starts, std::vector<SineMetrics>& sm,
                   std::vector<double>& res) const {
    const bool lanes = settings.lanes && lanes_supported(model);
    std::deque<identify_detail::BiasRamp> ramps;  // the frf targets' (lanes), per res_runs
    if (lanes) ramps = make_ramps_in_lanes(model, starts);
    if (lanes && sine_runs.size() > 1) {  // the frf targets' DC settling beside, if it fits
      sm = identify_detail::run_sines_lanes(
          model, sine_runs, settings, starts,
          identify_detail::settlings_beside_sines(model, sine_runs, settings, res_runs, ramps));
    } else {
      std::vector<double> I, yy, BB;
      sm.resize(sine_runs.size());
      for (std::size_t k = 0; k < sine_runs.size(); ++k)
        sm[k] = identify_detail::run_sine(model, sine_runs[k], settings, I, yy, BB, starts);
    }
    res.resize(res_runs.size());
    for (std::size_t k = 0; k < res_runs.size(); ++k)
      res[k] = identify_detail::lowest_resonance_Hz(model, res_runs[k], starts,
                                                    lanes ? &ramps[k] : nullptr);
  }

  // The (temperature, initial current) of every state at rest the targets start from: the sine
  // runs' (their minimum) and the modulus and resonance targets' (their bias).
  std::vector<std::pair<double, double>> target_starts() const {
    std::vector<std::pair<double, double>> k;
    for (const auto& run : sine_runs)
      k.emplace_back(run.T, biased_sine(run.pp, run.f, run.min).current_at(0.0));
    for (const auto& run : res_runs)
      if (run.kind == TargetKind::ModulusGPa || run.kind == TargetKind::ResonanceHz)
        k.emplace_back(run.T, run.bias);
    return k;
  }

  // Every quasi-static ramp of the targets in one batch of lanes: the start states
  // (target_starts, into the cache) and the frf targets' bias ramps, returned per res_runs
  // (the other targets' entries unused).
  std::deque<identify_detail::BiasRamp> make_ramps_in_lanes(const Model& model,
                                                            StartCache& starts) const {
    std::deque<identify_detail::BiasRamp> ramps;
    std::vector<const Conditions*> rc;
    std::vector<double> I0;
    std::vector<std::size_t> which;
    identify_detail::bias_ramps(model, res_runs, ramps, rc, I0, which);
    std::vector<State> st = starts.make_in_lanes(target_starts(), rc, I0);
    for (std::size_t j = 0; j < which.size(); ++j) ramps[which[j]].ramped = std::move(st[j]);
    return ramps;
  }

  bool residuals(const double* u, double* r, std::string* why = nullptr) const {
    try {
      return residuals_at(model_at(u), r, why);
    } catch (const InputError& e) {
      if (why) *why = e.what();
      return false;
    }
  }

  // What target_runs gives a point: its sine runs' metrics and its resonance targets' values.
  struct TargetOutputs {
    std::vector<SineMetrics> sm;
    std::vector<double> res;
  };

  // residuals() at a compiled model; `done`: its records' outputs, already run in lanes;
  // `targets_done`: its targets' runs, already run (targets_batch).
  bool residuals_at(const Model& model, double* r, std::string* why,
                    identify_detail::RecordOutputs* done = nullptr,
                    const TargetOutputs* targets_done = nullptr) const {
    try {
      StartCache starts(model);
      record_residuals(model, starts, r, done);
      if (!targets.empty()) {
        TargetOutputs own;
        if (!targets_done) target_runs(model, starts, own.sm, own.res);
        const TargetOutputs& t = targets_done ? *targets_done : own;
        for (const auto& td : targets) {
          const double sim = target_value(td, t.sm, t.res);
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

  // Objective::residuals_batch (objective.cpp).
  std::vector<char> residuals_batch(std::span<const double* const> u,
                                    std::span<double* const> r) const;
  // target_runs for several models at once (objective_batch.cpp), where target_runs takes the
  // lanes with more than one sine run: their start states and ramps in one make_states batch,
  // their sine runs in one batch of lanes (sine k of model c in lane k P + c), each model's
  // outputs equal to target_runs's bit for bit. failed[c] = 1 where model c's target_runs would
  // throw. Returns false (nothing computed) where the batch does not apply or a start state fails
  // (make_states throws): then each model runs target_runs alone.
  bool targets_batch(const std::vector<const Model*>& models, std::vector<TargetOutputs>& out,
                     std::vector<char>& failed) const;

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
      case TargetKind::ModulusGPa:
        return res[static_cast<std::size_t>(td.res_run)];
    }
    return 0.0;
  }
};

}  // namespace gmasim
