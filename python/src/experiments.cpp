// Bindings of the experiments: each returns the experiment's report (the same tables the
// CLI writes as CSV) as {"meta": {...}, "<table>": {column: ndarray or list of str}}.
#include "gmasim/experiments/experiments.hpp"

#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <complex>
#include <memory>

#include "bindings.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/feedforward.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "request_args.hpp"

namespace py = pybind11;

namespace gmasim::py_bind {
namespace {

py::object cell_value(const Cell& c) {
  if (c.is_bool) return py::bool_(c.text == "true");
  if (c.is_text) return py::str(c.text);
  return py::float_(c.number);
}

// A table as {column: numpy array (numbers) or list (text)}.
py::dict table_dict(const Table& t) {
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
  return cols;
}

py::dict report_dict(const Report& r) {
  py::dict out, meta;
  for (const auto& [k, v] : r.meta) meta[py::str(k)] = cell_value(v);
  out["meta"] = meta;
  for (const auto& t : r.tables) out[py::str(t.name)] = table_dict(t);
  return out;
}

template <class F>
auto without_gil(F&& f) {
  py::gil_scoped_release release;
  return f();
}

// sweep(): temperature x current x frequency (Fig. 12-14). The keyword arguments of the
// experiments are the Python rows of their request tables
// (gmasim/experiments/experiment_fields.hpp).
void bind_sweep(py::module_& mod) {
  def_request<SweepRequest>(
      mod, "sweep",
      "Temperature x current x frequency grid (Fig. 12-14). Returns {'meta', 'points': {column: "
      "array}, ...}",
      [](const Model& m, SweepRequest& r, const std::vector<std::string>& freeze) {
        r.freeze = parse_freeze(freeze);
        const SweepResult res = without_gil([&] { return run_sweep(m, r); });
        return report_dict(sweep_report(m, r, res));
      },
      Extra<std::vector<std::string>>{"freeze", {}});
}

// frf(): the frequency response (Fig. 15).
void bind_frf(py::module_& mod) {
  def_request<FrfRequest>(
      mod, "frf",
      "Frequency response current -> displacement (Fig. 15): stepped sine and small-signal, modes "
      "of eq. 15. peak_refinements: extra stepped-sine points refining its peak (0: the grid "
      "only).",
      [](const Model& m, FrfRequest& r) {
        const FrfResult res = without_gil([&] { return run_frf(m, r); });
        return report_dict(frf_report(m, r, res));
      });
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

// controller=: a Python callable (reference_um, measured_um, temperature_C) -> current_A, called
// at every sample of the loop (TrackRequest::controller), with its reset() before each run if
// it has one. With a controller run_track runs its points one after another in the calling
// thread, which keeps the GIL (track() does not release it then), so a call costs only the
// Python call itself: the arguments go by vectorcall, without a tuple. The callable is held by
// a shared pointer whose deleter takes the GIL, so copies of the request never touch its
// reference count without it. An exception it raises ends the run and reaches the caller
// unchanged.
void attach_controller(TrackRequest& r, const py::object& controller) {
  if (!PyCallable_Check(controller.ptr()))
    throw InputError(
        "track: controller must be a callable (reference_um, measured_um, "
        "temperature_C) -> current_A, not " +
        std::string(py::str(py::type::of(controller).attr("__name__"))));
  auto held = std::shared_ptr<py::object>(new py::object(controller), [](py::object* o) {
    py::gil_scoped_acquire gil;
    delete o;
  });
  r.controller = [held](double ref_um, double y_um, double T_C) {
    PyObject* args[3] = {PyFloat_FromDouble(ref_um), PyFloat_FromDouble(y_um),
                         PyFloat_FromDouble(T_C)};
    PyObject* out = PyObject_Vectorcall(held->ptr(), args, 3, nullptr);
    for (PyObject* a : args) Py_XDECREF(a);
    if (out == nullptr) throw py::error_already_set();
    const auto i = py::reinterpret_steal<py::object>(out);
    if (PyFloat_CheckExact(out)) return PyFloat_AS_DOUBLE(out);
    try {
      return i.cast<double>();
    } catch (const py::cast_error&) {
      throw InputError("track: the controller returned " +
                       std::string(py::str(py::type::of(i).attr("__name__"))) +
                       ", not a current in A (a float)");
    }
  };
  if (py::hasattr(controller, "reset")) r.controller_reset = [held] { (*held).attr("reset")(); };
}

// controller="pid" | "pid_temperature" | "pid_inverse": the built-in controllers of `track
// --feedforward` on the nominal plant -- the PID, with the temperature schedule about the bias
// (loop_temperature_feedforward at the evaluation's schedule frequency), or with the dynamic
// inverse-model feed-forward.
void builtin_controller(const Model& m, TrackRequest& r, TrackController c) {
  if (c == TrackController::PidTemperature) {
    CompensateRequest cq;
    cq.frequency_Hz = FeedforwardEvaluationRequest{}.schedule_frequency_Hz;
    r.feedforward = without_gil([&] { return loop_temperature_feedforward(m, cq, r); });
  }
  if (c == TrackController::PidInverse) {
    r.inverse.enabled = true;
    r.inverse.dynamic = true;
  }
}

void bind_track(py::module_& mod) {
  def_request<TrackRequest>(
      mod, "track",
      "Closed-loop tracking with the discrete PID (Fig. 16); gains' units in docs/experiments.md.\n"
      "feedforward='inverse' (or 'inverse_static': the quasi-static inverse alone) adds the "
      "inverse-model feed-forward and evaluates it against plants that differ from the model "
      "(mismatch='all': M_s, k, lambda_s x (1 +- 0.1) and the temperature +-10 degC, 16 plants; "
      "'none': the model itself; 'both'), for each of `controllers` (pid, pid_temperature, "
      "pid_inverse): tables 'runs' (one row per run, rms_error_um), 'ratios' (RMS(pid) / "
      "RMS(controller) over the plants: median, min, max) and 'inverse' (the linear part's "
      "fitted inverse per temperature). docs/experiments.md, 'Inverse-model feed-forward'.\n"
      "controller=f replaces the PID by your own: f(reference_um, measured_um, temperature_C) "
      "-> current_A at every sample (clipped to +-current_limit_A), f.reset() before each run "
      "if it has one; the runs are then sequential. controller='pid_temperature' or "
      "'pid_inverse' runs a built-in controller of the feed-forward evaluation on the model "
      "itself. The result's 'example' holds the first point's run per sample (t_s, "
      "reference_um, y_um, current_A, error_um). docs/experiments.md, 'Your controller in the "
      "loop'",
      [](const Model& m, TrackRequest& r, const std::string& feedforward,
         const std::string& mismatch, const std::vector<std::string>& controllers,
         const py::object& controller) {
        if (!controller.is_none()) {
          if (feedforward != "none")
            throw InputError(
                "track: controller= sets the loop's controller; it cannot be "
                "combined with feedforward='" +
                feedforward + "' (which compares controllers on mismatched plants)");
          if (py::isinstance<py::str>(controller))
            builtin_controller(m, r, parse_track_controller(controller.cast<std::string>()));
          else
            attach_controller(r, controller);
        }
        if (feedforward != "none")
          return track_feedforward(m, r, feedforward, mismatch, controllers);
        // With a callable the points run in this thread, with the GIL (attach_controller).
        const TrackResult res =
            r.controller ? run_track(m, r) : without_gil([&] { return run_track(m, r); });
        py::dict d = report_dict(track_report(m, r, res));
        d["example"] = series_dict(res.example);  // the first point's run, sample by sample
        return d;
      },
      Extra<std::string>{"feedforward", "none"}, Extra<std::string>{"mismatch", "all"},
      Extra<std::vector<std::string>>{
          "controllers", track_controller_names(FeedforwardEvaluationRequest{}.controllers)},
      Extra<py::object>{"controller", py::none()});
}

// compensate(): the drive schedule that restores the stroke, and its tracking.
void bind_compensate(py::module_& mod) {
  def_request<CompensateRequest>(
      mod, "compensate",
      "Temperature compensation: the drive restoring the target stroke at each temperature "
      "(table 'schedule'), and (unless track=False) PID tracking plain vs with temperature "
      "feed-forward (table 'track'; track_* arguments, bias_A, current_limit_A: the CLI's "
      "--track-*, --bias, --current-limit with the same defaults). docs/experiments.md",
      [](const Model& m, CompensateRequest& r, const std::string& adjust, bool track) {
        r.adjust = parse_compensation_adjust(adjust);
        r.tracking.enabled = track;
        if (track) (void)compensate_track_request(r);  // its numbers, before the schedule's runs
        return report_dict(without_gil([&] {
          const CompensateResult res = run_compensate(m, r);
          if (!track) return compensate_report(m, r, res);
          const CompensatedTrack ct = run_compensated_track(m, r);
          return compensate_report(m, r, res, &ct);
        }));
      },
      Extra<std::string>{"adjust", compensation_adjust_name(CompensateRequest{}.adjust)},
      Extra<bool>{"track", CompensateTracking{}.enabled});
}

// The temperature laws: ablate() (Fig. 20), params_vs_temperature() (Fig. 18-19) and
// thermal_expansion() (eq. 21).
void bind_temperature_laws(py::module_& mod) {
  def_request<AblateRequest>(
      mod, "ablate", "Freeze one temperature law at 20 degC at a time (Fig. 20)",
      [](const Model& m, AblateRequest& r) {
        const AblateResult res = without_gil([&] { return run_ablate(m, r); });
        return report_dict(ablate_report(m, r, res));
      });
  def_request<ParamsVsTemperatureRequest>(
      mod, "params_vs_temperature",
      "mu_G, rho_G, M_G, E_G, E_t against temperature (Fig. 19) and stroke retention (Fig. 18)",
      [](const Model& m, ParamsVsTemperatureRequest& r) {
        const ParamsVsTemperatureResult res =
            without_gil([&] { return run_params_vs_temperature(m, r); });
        return report_dict(params_report(m, r, res));
      });
  mod.def(
      "thermal_expansion",
      [](const Model& m) {
        return report_dict(thermal_report(m, thermal_expansion_coefficient(m)));
      },
      py::arg("model"), "Eq. (21): the stack's thermal expansion in um/degC");
}

// _linearize(): the plant as a state space (gmasim.linearize wraps it in a scipy StateSpace).
py::array matrix(const std::vector<double>& v, int rows, int cols) {
  py::array_t<double> a({rows, cols});
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}
py::list complex_list(const std::vector<std::complex<double>>& z) {
  py::list l;
  for (const auto& x : z) l.append(py::cast(x));
  return l;
}
// A state space's A, B, C, D and its states' and outputs' names and units into d.
void put_matrices(py::dict& d, const StateSpace& ss) {
  d["A"] = matrix(ss.A, ss.n_states, ss.n_states);
  d["B"] = matrix(ss.B, ss.n_states, 1);
  d["C"] = matrix(ss.C, ss.n_outputs, ss.n_states);
  d["D"] = matrix(ss.D, ss.n_outputs, 1);
  d["states"] = ss.states;
  d["state_units"] = ss.state_units;
  d["outputs"] = ss.outputs;
  d["output_units"] = ss.output_units;
}
void bind_linearize(py::module_& mod) {
  mod.def(
      "_linearize",
      [](const Model& m, double temperature_C, double bias_A, double amplitude_A,
         const std::vector<double>& frequencies_Hz) {
        const StateSpace ss =
            without_gil([&] { return linearize_plant(m, temperature_C, bias_A); });
        py::dict d;
        if (amplitude_A !=
            0.0) {  // the describing function beside it (gmasim linearize --amplitude)
          const std::vector<DescribingPoint> df =
              without_gil([&] { return describing_function(m, ss, amplitude_A, frequencies_Hz); });
          py::dict t = table_dict(describing_function_table(df));  // the report's columns
          t["amplitude_A"] = amplitude_A;
          d["describing_function"] = t;
        }
        put_matrices(d, ss);
        d["temperature_C"] = ss.temperature_C;
        d["bias_A"] = ss.bias_A;
        py::list blocks;  // the plant split at the sensor mount (StateSpace::blocks)
        for (const StateSpace& b : ss.blocks) {
          py::dict bd;
          put_matrices(bd, b);
          bd["input"] = b.input;
          bd["input_unit"] = b.input_unit;
          blocks.append(bd);
        }
        d["blocks"] = blocks;
        d["interconnection"] = ss.interconnection;
        d["poles"] = complex_list(ss.poles());
        d["zeros_y"] = complex_list(ss.zeros(0));
        std::vector<double> dc;
        for (int k = 0; k < ss.n_outputs; ++k) dc.push_back(ss.dc_gain(k));
        d["dc_gain"] = dc;
        return d;
      },
      py::arg("model"), py::arg("temperature_C") = 20.0, py::arg("bias_A") = 1.0,
      py::arg("amplitude_A") = 0.0,
      py::arg("frequencies_Hz") = std::vector<double>{10.0, 100.0, 1000.0},
      "The plant as a state space: {'A', 'B', 'C', 'D', 'states', 'state_units', 'outputs', "
      "'output_units', 'poles', 'zeros_y', 'dc_gain', ...}; gmasim.linearize returns it as a "
      "scipy.signal.StateSpace");
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
  bind_linearize(mod);
  bind_frf(mod);
  bind_track(mod);
  bind_compensate(mod);
  bind_temperature_laws(mod);
  bind_claims(mod);
}

}  // namespace gmasim::py_bind
