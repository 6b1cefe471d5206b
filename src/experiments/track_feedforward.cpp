// The inverse feed-forward against plants that differ from its model (issue 20): the PID
// alone, with the temperature feed-forward and with the inverse feed-forward, on the 16
// mismatched plants of plant_mismatches(). gmasim/experiments/feedforward.hpp; docs/experiments.md,
// "Inverse-model feed-forward".
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>
#include <utility>

#include "experiments/parallel.hpp"
#include "experiments/request_meta.hpp"
#include "experiments/track_loop.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/feedforward.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {
namespace {

constexpr std::pair<TrackController, const char*> kControllerNames[] = {
    {TrackController::Pid, "pid"},
    {TrackController::PidTemperature, "pid_temperature"},
    {TrackController::PidInverse, "pid_inverse"},
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct FeedforwardJob {
  std::size_t T, A, f, mismatch, controller;  // indices into the request's lists
};

// RMS(pid) / RMS(c) over the mismatches of each grid point, for every controller c but pid.
std::vector<FeedforwardRatio> ratios(const FeedforwardEvaluationRequest& r,
                                     const std::vector<FeedforwardJob>& jobs,
                                     const std::vector<FeedforwardRun>& runs) {
  std::map<std::tuple<std::size_t, std::size_t, std::size_t, std::size_t>, double> pid;
  for (std::size_t i = 0; i < jobs.size(); ++i)
    if (runs[i].controller == TrackController::Pid)
      pid[{jobs[i].T, jobs[i].A, jobs[i].f, jobs[i].mismatch}] = runs[i].point.error_rms_um;
  std::map<std::tuple<std::size_t, std::size_t, std::size_t, std::size_t>, std::vector<double>> by;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const FeedforwardJob& j = jobs[i];
    if (runs[i].controller == TrackController::Pid) continue;
    const auto it = pid.find({j.T, j.A, j.f, j.mismatch});
    auto& v = by[{j.T, j.A, j.f, j.controller}];
    const double q = it == pid.end() ? std::nan("") : it->second / runs[i].point.error_rms_um;
    if (std::isfinite(q)) v.push_back(q);
  }
  std::vector<FeedforwardRatio> out;
  for (const auto& [key, v] : by) {
    FeedforwardRatio q;
    q.temperature_C = r.track.temperatures_C[std::get<0>(key)];
    q.amplitude_um = r.track.amplitudes_um[std::get<1>(key)];
    q.frequency_Hz = r.track.frequencies_Hz[std::get<2>(key)];
    q.controller = r.controllers[std::get<3>(key)];
    q.combinations = static_cast<int>(v.size());
    if (!v.empty()) {
      q.median = median(v);
      q.min = *std::min_element(v.begin(), v.end());
      q.max = *std::max_element(v.begin(), v.end());
    }
    out.push_back(q);
  }
  return out;
}

void check_evaluation(const FeedforwardEvaluationRequest& r) {
  detail::check_track_request(r.track);
  fields::check_request_fields(r);
  if (r.mismatches.empty())
    throw InputError("feed-forward evaluation: no plant mismatch given: give at least one");
  if (r.controllers.empty())
    throw InputError("feed-forward evaluation: no controller given (--controllers)");
  const double runs = static_cast<double>(r.track.temperatures_C.size()) *
                      static_cast<double>(r.track.amplitudes_um.size()) *
                      static_cast<double>(r.track.frequencies_Hz.size()) *
                      static_cast<double>(r.mismatches.size()) *
                      static_cast<double>(r.controllers.size());
  if (runs > kMaxGridRuns)
    throw InputError(fmt::format("feed-forward evaluation of {:.4g} runs: too many (limit {:g})",
                                 runs, kMaxGridRuns));
}

}  // namespace

const char* track_controller_name(TrackController c) {
  for (const auto& [mode, name] : kControllerNames)
    if (mode == c) return name;
  return "?";
}

std::vector<std::string> track_controller_names(const std::vector<TrackController>& cs) {
  std::vector<std::string> out;
  for (TrackController c : cs) out.emplace_back(track_controller_name(c));
  return out;
}

TrackController parse_track_controller(const std::string& name) {
  for (const auto& [mode, n] : kControllerNames)
    if (name == n) return mode;
  throw InputError("controller '" + clip_for_message(name) +
                   "': must be pid, pid_temperature or pid_inverse");
}

std::vector<PlantMismatch> plant_mismatches(double fraction, double offset_C) {
  std::vector<PlantMismatch> out;
  for (int t = 0; t < 2; ++t)
    for (int bits = 0; bits < 8; ++bits) {
      const double sMs = (bits & 4) ? -1.0 : 1.0, sk = (bits & 2) ? -1.0 : 1.0,
                   sl = (bits & 1) ? -1.0 : 1.0, dT = t == 0 ? offset_C : -offset_C;
      auto sign = [](double s) { return s > 0.0 ? '+' : '-'; };
      out.push_back({fmt::format("Ms{} k{} ls{} T{:+g}", sign(sMs), sign(sk), sign(sl), dT),
                     1.0 + sMs * fraction, 1.0 + sk * fraction, 1.0 + sl * fraction, dT});
    }
  return out;
}

PlantMismatch perfect_plant() { return {"none", 1.0, 1.0, 1.0, 0.0}; }

std::vector<PlantMismatch> parse_plant_mismatches(const std::string& word) {
  if (word == "all") return plant_mismatches();
  if (word == "none") return {perfect_plant()};
  if (word == "both") {
    auto v = plant_mismatches();
    v.insert(v.begin(), perfect_plant());
    return v;
  }
  throw InputError("mismatch '" + clip_for_message(word) +
                   "': must be all (the 16 combinations), none (the plant is the model) or both");
}

Model mismatched_plant(const Model& m, const PlantMismatch& x) {
  ModelSpec spec = m.spec;
  auto scale = [&](const std::string& key, double f) { spec.set(key, spec.get(key) * f); };
  scale("material.Ms_A_per_m", x.Ms_factor);
  scale("material.lambda_s", x.lambda_s_factor);
  // k+/-: the parameter that sets the loop's width, the law's own (JA k0, Preisach H_c0)
  const std::string width = with_magnetisation_law(m.options.magnetisation_law, [](auto law) {
    return std::string(decltype(law)::loop_width_key);
  });
  for (const auto& rod : spec.rods) scale(rod + "." + width, x.k_factor);
  spec.source = m.spec.source + " (plant " + x.label + ")";
  return compile(spec);
}

FeedforwardEvaluation run_feedforward_evaluation(const Model& m,
                                                 const FeedforwardEvaluationRequest& r,
                                                 const ProgressFn& progress) {
  check_evaluation(r);
  const auto wall0 = std::chrono::steady_clock::now();
  const TrackRequest& tr = r.track;
  FeedforwardEvaluation res;
  // The plants, their conditions at every loop temperature, the plant steps per frequency.
  std::vector<Model> plants;
  for (const auto& x : r.mismatches) plants.push_back(mismatched_plant(m, x));
  std::vector<std::vector<Conditions>> plant_c(plants.size());
  for (std::size_t k = 0; k < plants.size(); ++k)
    for (double T : tr.temperatures_C)
      plant_c[k].push_back(make_conditions(plants[k], T + r.mismatches[k].temperature_offset_C));
  std::vector<long> sub;
  for (double f : tr.frequencies_Hz) {
    TrackRequest one = tr;
    one.frequencies_Hz = {f};
    sub.push_back(detail::track_substeps(one));
  }
  // One request per controller.
  std::vector<TrackRequest> req(r.controllers.size(), tr);
  const InverseFeedforwardSettings inv{tr.bias_A, tr.current_limit_A, tr.sample_rate_Hz,
                                       tr.inverse.band_Hz, tr.inverse.dynamic};
  for (std::size_t c = 0; c < r.controllers.size(); ++c) {
    req[c].feedforward = {};
    req[c].inverse.enabled = r.controllers[c] == TrackController::PidInverse;
    if (r.controllers[c] == TrackController::PidTemperature) {
      if (!res.temperature_feedforward.enabled()) {
        CompensateRequest cq;
        cq.frequency_Hz = r.schedule_frequency_Hz;
        res.temperature_feedforward = loop_temperature_feedforward(m, cq, tr);
      }
      req[c].feedforward = res.temperature_feedforward;
    }
  }
  const bool any_inverse = std::find(r.controllers.begin(), r.controllers.end(),
                                     TrackController::PidInverse) != r.controllers.end();
  if (any_inverse)
    for (double T : tr.temperatures_C)
      res.inverses.push_back(fit_linear_inverse(m, make_conditions(m, T), tr.bias_A, inv.band_Hz));

  std::vector<FeedforwardJob> jobs;
  for (std::size_t T = 0; T < tr.temperatures_C.size(); ++T)
    for (std::size_t A = 0; A < tr.amplitudes_um.size(); ++A)
      for (std::size_t f = 0; f < tr.frequencies_Hz.size(); ++f)
        for (std::size_t x = 0; x < r.mismatches.size(); ++x)
          for (std::size_t c = 0; c < r.controllers.size(); ++c) jobs.push_back({T, A, f, x, c});
  res.runs.resize(jobs.size());
  res.threads = resolve_thread_count(tr.threads, jobs.size());
  detail::parallel_for(
      jobs.size(), res.threads,
      [&](std::size_t i) {
        const FeedforwardJob& j = jobs[i];
        const double T = tr.temperatures_C[j.T];
        std::optional<InverseFeedforward> ff;
        if (req[j.controller].inverse.enabled) ff.emplace(m, T, inv, &res.inverses[j.T]);
        const detail::TrackPlant plant{plants[j.mismatch], plant_c[j.mismatch][j.T],
                                       ff ? &*ff : nullptr};
        FeedforwardRun& run = res.runs[i];
        run.mismatch = r.mismatches[j.mismatch].label;
        run.controller = r.controllers[j.controller];
        run.plant_temperature_C = T + r.mismatches[j.mismatch].temperature_offset_C;
        detail::track_run(plant, req[j.controller],
                          {T, tr.amplitudes_um[j.A], tr.frequencies_Hz[j.f]}, sub[j.f],
                          tr.noise_seed + i, run.point, nullptr);
      },
      progress);
  res.ratios = ratios(r, jobs, res.runs);
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

Report feedforward_report(const Model& m, const FeedforwardEvaluationRequest& req,
                          const FeedforwardEvaluation& res) {
  Report r;
  r.experiment = "track";
  r.meta.emplace_back("model", m.spec.source);
  r.meta.emplace_back("feedforward", "inverse");
  const TrackRequest& t = req.track;
  fields::add_request_meta(r, req);  // its table (gmasim/experiments/experiment_fields.hpp)
  r.meta.emplace_back("mismatch",
                      "the plant: M_s, k (every rod), lambda_s times (1 +- 0.1); its temperature "
                      "the loop's +- 10 degC; the feed-forward's model at the loop's temperature");
  r.meta.emplace_back("goal",
                      "at 100 Hz, 20 um, 20 and 70 degC: RMS(pid)/RMS(pid_inverse) "
                      "median >= 5 and min >= 2 over the 16 combinations (issue 20)");
  r.meta.emplace_back("threads", res.threads);
  r.meta.emplace_back("wall_time_s", res.wall_time_s);
  Table runs{"runs",
             {"temperature_C", "frequency_Hz", "amplitude_um", "mismatch", "controller",
              "plant_temperature_C", "rms_error_um", "peak_error_um", "rms_error_pct_of_amplitude",
              "current_min_A", "current_max_A", "feedforward_min_A", "feedforward_max_A",
              "saturated", "status", "error"},
             {}};
  for (const auto& x : res.runs) {
    const TrackPoint& p = x.point;
    runs.rows.push_back({p.temperature_C, p.frequency_Hz, p.amplitude_um, x.mismatch,
                         track_controller_name(x.controller), x.plant_temperature_C, p.error_rms_um,
                         p.error_peak_um, p.error_rms_pct, p.current_min_A, p.current_max_A,
                         p.feedforward_min_A, p.feedforward_max_A, p.saturated,
                         p.diverged ? "diverged" : "ok", p.error});
  }
  Table ratio{"ratios",
              {"temperature_C", "frequency_Hz", "amplitude_um", "controller", "combinations",
               "ratio_median", "ratio_min", "ratio_max"},
              {}};
  for (const auto& q : res.ratios)
    ratio.rows.push_back({q.temperature_C, q.frequency_Hz, q.amplitude_um,
                          track_controller_name(q.controller), q.combinations, q.median, q.min,
                          q.max});
  Table inv{"inverse",
            {"temperature_C", "a1_s", "a2_s2", "a3_s3", "band_Hz", "max_residual",
             "static_gain_um_per_A"},
            {}};
  for (std::size_t i = 0; i < res.inverses.size(); ++i) {
    const LinearInverse& l = res.inverses[i];
    inv.rows.push_back({t.temperatures_C[i], l.a[0], l.a[1], l.a[2], l.band_Hz, l.max_residual,
                        l.static_gain_um_per_A});
  }
  r.tables = {std::move(runs), std::move(ratio), std::move(inv)};
  return r;
}

}  // namespace gmasim
