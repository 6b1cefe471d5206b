// Bindings of the experiments: each returns the experiment's report (the same tables the
// CLI writes as CSV) as {"meta": {...}, "<table>": {column: ndarray or list of str}}.
#include "gmasim/experiments/experiments.hpp"

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/feedforward.hpp"
#include "gmasim/experiments/reproduce.hpp"

namespace py = pybind11;

namespace gmasim::py_bind {
namespace {

py::object cell_value(const Cell& c) {
  if (c.is_bool) return py::bool_(c.text == "true");
  if (c.is_text) return py::str(c.text);
  return py::float_(c.number);
}

py::dict report_dict(const Report& r) {
  py::dict out, meta;
  for (const auto& [k, v] : r.meta) meta[py::str(k)] = cell_value(v);
  out["meta"] = meta;
  for (const auto& t : r.tables) {
    py::dict cols;
    for (std::size_t j = 0; j < t.columns.size(); ++j) {
      bool numeric = true;
      for (const auto& row : t.rows) numeric = numeric && !row[j].is_text;
      if (numeric) {
        std::vector<double> v;
        v.reserve(t.rows.size());
        for (const auto& row : t.rows) v.push_back(row[j].number);
        cols[py::str(t.columns[j])] = to_numpy(v);
      } else {
        py::list l;
        for (const auto& row : t.rows) l.append(cell_value(row[j]));
        cols[py::str(t.columns[j])] = l;
      }
    }
    out[py::str(t.name)] = cols;
  }
  return out;
}

template <class F>
auto without_gil(F&& f) {
  py::gil_scoped_release release;
  return f();
}

// sweep(): temperature x current x frequency (Fig. 12-14).
void bind_sweep(py::module_& mod) {
  mod.def(
      "sweep",
      [](const Model& m, std::vector<double> temperatures_C, std::vector<double> currents_pp_A,
         std::vector<double> frequencies_Hz, double reference_temperature_C, double periods,
         double dt_s, int threads, const std::vector<std::string>& freeze) {
        SweepRequest r;
        r.temperatures_C = std::move(temperatures_C);
        r.currents_pp_A = std::move(currents_pp_A);
        r.frequencies_Hz = std::move(frequencies_Hz);
        r.reference_temperature_C = reference_temperature_C;
        r.periods = periods;
        r.dt_s = dt_s;
        r.threads = threads;
        r.freeze = parse_freeze(freeze);
        const SweepResult res = without_gil([&] { return run_sweep(m, r); });
        return report_dict(sweep_report(m, r, res));
      },
      py::arg("model"), py::arg("temperatures_C") = SweepRequest{}.temperatures_C,
      py::arg("currents_pp_A") = SweepRequest{}.currents_pp_A,
      py::arg("frequencies_Hz") = SweepRequest{}.frequencies_Hz,
      py::arg("reference_temperature_C") = 20.0, py::arg("periods") = 3.0, py::arg("dt_s") = 0.0,
      py::arg("threads") = 0, py::arg("freeze") = std::vector<std::string>{},
      "Temperature x current x frequency grid (Fig. 12-14). Returns {'meta', 'points': {column: "
      "array}, ...}");
}

// frf(): the frequency response (Fig. 15).
void bind_frf(py::module_& mod) {
  mod.def(
      "frf",
      [](const Model& m, std::vector<double> temperatures_C, double f_min_Hz, double f_max_Hz,
         int points, double bias_A, double amplitude_A, bool stepped_sine, bool small_signal,
         int peak_refinements, int threads) {
        FrfRequest r;
        r.temperatures_C = std::move(temperatures_C);
        r.f_min_Hz = f_min_Hz;
        r.f_max_Hz = f_max_Hz;
        r.points = points;
        r.bias_A = bias_A;
        r.amplitude_A = amplitude_A;
        r.stepped_sine = stepped_sine;
        r.small_signal = small_signal;
        r.peak_refinements = peak_refinements;
        r.threads = threads;
        const FrfResult res = without_gil([&] { return run_frf(m, r); });
        return report_dict(frf_report(m, r, res));
      },
      py::arg("model"), py::arg("temperatures_C") = FrfRequest{}.temperatures_C,
      py::arg("f_min_Hz") = 1.0, py::arg("f_max_Hz") = 5000.0, py::arg("points") = 40,
      py::arg("bias_A") = 1.0, py::arg("amplitude_A") = FrfRequest{}.amplitude_A,
      py::arg("stepped_sine") = true, py::arg("small_signal") = true,
      py::arg("peak_refinements") = FrfRequest{}.peak_refinements, py::arg("threads") = 0,
      "Frequency response current -> displacement (Fig. 15): stepped sine and small-signal, modes "
      "of eq. 15. peak_refinements: extra stepped-sine points refining its peak (0: the grid "
      "only).");
}

// track(): closed-loop PID tracking (Fig. 16); with feedforward="inverse" the inverse-model
// feed-forward evaluated against mismatched plants (gmasim/experiments/feedforward.hpp).
py::dict track_feedforward(const Model& m, const TrackRequest& r, const std::string& feedforward,
                           const std::string& mismatch,
                           const std::vector<std::string>& controllers) {
  if (feedforward != "inverse" && feedforward != "inverse_static")
    throw InputError("feedforward '" + feedforward + "': must be none, inverse or inverse_static");
  FeedforwardEvaluationRequest q;
  q.track = r;
  q.track.inverse.dynamic = feedforward == "inverse";
  q.mismatches = parse_plant_mismatches(mismatch);
  q.controllers.clear();
  for (const auto& c : controllers) q.controllers.push_back(parse_track_controller(c));
  const FeedforwardEvaluation res = without_gil([&] { return run_feedforward_evaluation(m, q); });
  return report_dict(feedforward_report(m, q, res));
}

void bind_track(py::module_& mod) {
  mod.def(
      "track",
      [](const Model& m, std::vector<double> temperatures_C, std::vector<double> amplitudes_um,
         std::vector<double> frequencies_Hz, double kp, double ki, double kd, double sample_rate_Hz,
         double bias_A, double sensor_noise_um, double periods, int threads,
         double amplifier_A_per_unit, const std::string& feedforward, const std::string& mismatch,
         const std::vector<std::string>& controllers, double feedforward_band_Hz) {
        TrackRequest r;
        r.amplifier_A_per_unit = amplifier_A_per_unit;
        r.temperatures_C = std::move(temperatures_C);
        r.amplitudes_um = std::move(amplitudes_um);
        r.frequencies_Hz = std::move(frequencies_Hz);
        r.gains = {kp, ki, kd};
        r.sample_rate_Hz = sample_rate_Hz;
        r.bias_A = bias_A;
        r.sensor_noise_um = sensor_noise_um;
        r.periods = periods;
        r.threads = threads;
        r.inverse.band_Hz = feedforward_band_Hz;
        if (feedforward != "none")
          return track_feedforward(m, r, feedforward, mismatch, controllers);
        const TrackResult res = without_gil([&] { return run_track(m, r); });
        return report_dict(track_report(m, r, res));
      },
      py::arg("model"), py::arg("temperatures_C") = TrackRequest{}.temperatures_C,
      py::arg("amplitudes_um") = TrackRequest{}.amplitudes_um,
      py::arg("frequencies_Hz") = TrackRequest{}.frequencies_Hz, py::arg("kp") = 0.2,
      py::arg("ki") = 0.03, py::arg("kd") = 0.007, py::arg("sample_rate_Hz") = 10000.0,
      py::arg("bias_A") = 1.0, py::arg("sensor_noise_um") = 0.0, py::arg("periods") = 4.0,
      py::arg("threads") = 0, py::arg("amplifier_A_per_unit") = TrackRequest{}.amplifier_A_per_unit,
      py::arg("feedforward") = "none", py::arg("mismatch") = "all",
      py::arg("controllers") = std::vector<std::string>{"pid", "pid_temperature", "pid_inverse"},
      py::arg("feedforward_band_Hz") = InverseFeedforwardRequest{}.band_Hz,
      "Closed-loop tracking with the discrete PID (Fig. 16); gains' units in docs/experiments.md.\n"
      "feedforward='inverse' (or 'inverse_static': the quasi-static inverse alone) adds the "
      "inverse-model feed-forward and evaluates it against plants that differ from the model "
      "(mismatch='all': M_s, k, lambda_s x (1 +- 0.1) and the temperature +-10 degC, 16 plants; "
      "'none': the model itself; 'both'), for each of `controllers` (pid, pid_temperature, "
      "pid_inverse): tables 'runs' (one row per run, rms_error_um), 'ratios' (RMS(pid) / "
      "RMS(controller) over the plants: median, min, max) and 'inverse' (the linear part's "
      "fitted inverse per temperature). docs/experiments.md, 'Inverse-model feed-forward'");
}

// compensate(): the drive schedule that restores the stroke, and its tracking.
void bind_compensate(py::module_& mod) {
  mod.def(
      "compensate",
      [](const Model& m, std::vector<double> temperatures_C, double reference_temperature_C,
         double reference_current_pp_A, double current_min_A, double target_stroke_um,
         double frequency_Hz, const std::string& adjust, double max_current_A, double tolerance_um,
         bool track, std::vector<double> track_amplitudes_um,
         std::vector<double> track_frequencies_Hz, double bias_A, int threads) {
        CompensateRequest r;
        r.temperatures_C = std::move(temperatures_C);
        r.reference_temperature_C = reference_temperature_C;
        r.reference_current_pp_A = reference_current_pp_A;
        r.current_min_A = current_min_A;
        r.target_stroke_um = target_stroke_um;
        r.frequency_Hz = frequency_Hz;
        r.adjust = parse_compensation_adjust(adjust);
        r.max_current_A = max_current_A;
        r.tolerance_um = tolerance_um;
        r.threads = threads;
        return report_dict(without_gil([&] {
          const CompensateResult res = run_compensate(m, r);
          if (!track) return compensate_report(m, r, res);
          TrackRequest t;
          t.temperatures_C = r.temperatures_C;
          t.amplitudes_um = track_amplitudes_um;
          t.frequencies_Hz = track_frequencies_Hz;
          t.bias_A = bias_A;
          t.threads = threads;
          const CompensatedTrack ct = run_compensated_track(m, r, t);
          return compensate_report(m, r, res, &ct);
        }));
      },
      py::arg("model"), py::arg("temperatures_C") = CompensateRequest{}.temperatures_C,
      py::arg("reference_temperature_C") = 20.0, py::arg("reference_current_pp_A") = 8.0,
      py::arg("current_min_A") = -3.0, py::arg("target_stroke_um") = 0.0,
      py::arg("frequency_Hz") = 10.0, py::arg("adjust") = "amplitude",
      py::arg("max_current_A") = 30.0, py::arg("tolerance_um") = 1e-3, py::arg("track") = false,
      py::arg("track_amplitudes_um") = std::vector<double>{10.0},
      py::arg("track_frequencies_Hz") = std::vector<double>{10.0}, py::arg("bias_A") = 1.0,
      py::arg("threads") = 0,
      "Temperature compensation: the drive restoring the target stroke at each temperature "
      "(table 'schedule'), and with track=True PID tracking plain vs with temperature "
      "feed-forward (table 'track'). docs/experiments.md");
}

// The temperature laws: ablate() (Fig. 20), params_vs_temperature() (Fig. 18-19) and
// thermal_expansion() (eq. 21).
void bind_temperature_laws(py::module_& mod) {
  mod.def(
      "ablate",
      [](const Model& m, double temperature_C, std::vector<double> frequencies_Hz,
         double current_pp_A) {
        AblateRequest r;
        r.temperature_C = temperature_C;
        r.frequencies_Hz = std::move(frequencies_Hz);
        r.current_pp_A = current_pp_A;
        const AblateResult res = without_gil([&] { return run_ablate(m, r); });
        return report_dict(ablate_report(m, r, res));
      },
      py::arg("model"), py::arg("temperature_C") = 70.0,
      py::arg("frequencies_Hz") = AblateRequest{}.frequencies_Hz, py::arg("current_pp_A") = 6.0,
      "Freeze one temperature law at 20 degC at a time (Fig. 20)");
  mod.def(
      "params_vs_temperature",
      [](const Model& m, std::vector<double> temperatures_C, double current_pp_A,
         double frequency_Hz) {
        ParamsVsTemperatureRequest r;
        r.temperatures_C = std::move(temperatures_C);
        r.current_pp_A = current_pp_A;
        r.frequency_Hz = frequency_Hz;
        const ParamsVsTemperatureResult res =
            without_gil([&] { return run_params_vs_temperature(m, r); });
        return report_dict(params_report(m, r, res));
      },
      py::arg("model"), py::arg("temperatures_C") = ParamsVsTemperatureRequest{}.temperatures_C,
      py::arg("current_pp_A") = 8.0, py::arg("frequency_Hz") = 10.0,
      "mu_G, rho_G, M_G, E_G, E_t against temperature (Fig. 19) and stroke retention (Fig. 18)");
  mod.def(
      "thermal_expansion",
      [](const Model& m) {
        return report_dict(thermal_report(m, thermal_expansion_coefficient(m)));
      },
      py::arg("model"), "Eq. (21): the stack's thermal expansion in um/degC");
}

// claims(): the whole study scored on the paper's claims.
void bind_claims(py::module_& mod) {
  mod.def(
      "claims",
      [](const Model& m, bool quick) {
        ReproduceOptions o;
        o.quick = quick;
        const ReproduceResult res = without_gil([&] { return run_reproduce(m, o); });
        return report_dict(claims_report(res.claims));
      },
      py::arg("model"), py::arg("quick") = false,
      "The whole study's claims table (as `gmasim reproduce`)");
}

}  // namespace

void bind_experiments(py::module_& mod) {
  bind_sweep(mod);
  bind_frf(mod);
  bind_track(mod);
  bind_compensate(mod);
  bind_temperature_laws(mod);
  bind_claims(mod);
}

}  // namespace gmasim::py_bind
