// pybind11 bindings: gmasim._gmasim. Thin: models, simulate; arrays out as numpy.
// Experiments are bound in experiments.cpp. No physics here.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>

#include "bindings.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/simulate_fields.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "request_args.hpp"

namespace py = pybind11;
using namespace gmasim;

namespace gmasim::py_bind {

py::array_t<double> to_numpy(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::dict series_dict(const TimeSeries& ts) {
  py::dict d;
  for (std::size_t i = 0; i < ts.names.size(); ++i)
    d[py::str(ts.names[i])] = to_numpy(ts.columns[i]);
  return d;
}

py::dict metrics_dict(const Metrics& m) {
  py::dict d;
  for (const MetricRow& row : kMetricRows) d[py::str(row.name.data())] = m.*row.member;
  return d;
}

// The energy ledgers over the metrics window as mean powers [W] (gmasim/model/energy.hpp).
py::dict energy_dict(const Model& m, const Result& r) {
  const auto& e = r.energy;
  const double T = e.duration_s;
  py::dict d;
  d["window_s"] = T;
  d["coil_input_W"] = e.coil_J / T;
  d["magnet_work_W"] = e.magnet_J / T;
  d["magnetic_stored_change_W"] = (e.d_circuit_J + e.d_series_J + e.d_material_J) / T;
  d["hysteresis_W"] = e.hysteresis_J / T;
  d["eddy_W"] = e.eddy_J / T;
  d["magnetic_residual_rel"] = e.magnetic_residual_rel;
  py::dict rods;
  for (std::size_t i = 0; i < e.rod_hysteresis_J.size() && i < m.rods.size(); ++i) {
    py::dict rd;
    rd["hysteresis_W"] = e.rod_hysteresis_J[i] / T;
    rd["eddy_W"] = e.rod_eddy_J[i] / T;
    rods[py::str(m.rods[i].name)] = rd;
  }
  d["rods"] = rods;
  d["force_work_W"] = e.force_work_J / T;
  d["stiffness_work_W"] = e.stiffness_work_J / T;
  d["mechanical_stored_change_W"] = (e.d_kinetic_J + e.d_elastic_J) / T;
  d["damping_W"] = e.damping_J / T;
  d["mechanical_residual_rel"] = e.mechanical_residual_rel;
  d["coupling_fraction"] = e.coupling_fraction;
  d["coil_resistance_ohm"] = r.coil.resistance_ohm;
  d["coil_current_rms_A"] = r.coil.current_rms_A;
  d["coil_voltage_rms_V"] = r.coil.voltage_rms_V;
  d["coil_voltage_peak_V"] = r.coil.voltage_peak_V;
  d["coil_power_mean_W"] = r.coil.power_mean_W;
  d["coil_power_peak_W"] = r.coil.power_peak_W;
  d["coil_copper_W"] = r.coil.copper_W;
  d["coil_apparent_VA"] = r.coil.apparent_VA;
  return d;
}

}  // namespace gmasim::py_bind

namespace {

using namespace gmasim::py_bind;

// A 1-D array of numbers from a Python sequence or array; TypeError naming the argument and
// the expected type otherwise (issue 19, item 11: not "Unable to cast Python instance").
std::vector<double> numbers_1d(const py::handle& o, const char* what) {
  if (py::isinstance<py::str>(o) || py::isinstance<py::bytes>(o))
    throw py::type_error(fmt::format("{}: expected a 1-D array of numbers, not a string", what));
  py::array_t<double, py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::forcecast>::ensure(o);
  } catch (const py::error_already_set&) {
  }
  if (!a)
    throw py::type_error(
        fmt::format("{}: expected a 1-D array of numbers, not {}", what,
                    py::str(py::type::of(o).attr("__name__")).cast<std::string>()));
  if (a.ndim() != 1)
    throw py::type_error(
        fmt::format("{}: expected a 1-D array of numbers, not a {}-D array", what, a.ndim()));
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

Waveform table_waveform(const py::object& waveform) {
  const char* shape =
      "waveform: expected a pair (t_s, current_A) of equally long 1-D arrays of numbers [s, A]";
  if (!py::isinstance<py::sequence>(waveform) || py::isinstance<py::str>(waveform) ||
      py::len(waveform) != 2)
    throw py::type_error(fmt::format(
        "{}, not {}", shape, py::str(py::type::of(waveform).attr("__name__")).cast<std::string>()));
  const py::sequence pair = waveform.cast<py::sequence>();
  Waveform w;
  w.kind = WaveformKind::Table;
  w.table_t_s = numbers_1d(pair[0], "waveform[0] (t_s)");
  w.table_current_A = numbers_1d(pair[1], "waveform[1] (current_A)");
  w.table_source = "<python>";
  if (w.table_t_s.size() < 2 || w.table_t_s.size() != w.table_current_A.size())
    throw InputError(fmt::format("{}, of at least 2 samples (got {} and {})", shape,
                                 w.table_t_s.size(), w.table_current_A.size()));
  for (std::size_t i = 1; i < w.table_t_s.size(); ++i)
    if (!(w.table_t_s[i] > w.table_t_s[i - 1]))
      throw InputError("waveform: time must increase strictly (sample " + std::to_string(i) + ")");
  return w;
}

double optional_number(const py::object& o, const char* what);

// current_A=array sampled every current_dt_s seconds from t = 0: the Table waveform
// t_k = k dt (linear interpolation between samples, held after the last).
Waveform sampled_waveform(const py::object& current_A, double dt_s) {
  Waveform w;
  w.kind = WaveformKind::Table;
  w.table_current_A = numbers_1d(current_A, "current_A");
  w.table_source = "<python current_A>";
  if (w.table_current_A.size() < 2)
    throw InputError(
        fmt::format("current_A: at least 2 samples are needed (got {})", w.table_current_A.size()));
  if (!(dt_s > 0.0) || !std::isfinite(dt_s))
    throw InputError(
        fmt::format("current_dt_s = {:g} s: must be > 0 (the spacing of the "
                    "current_A samples)",
                    dt_s));
  for (std::size_t k = 0; k < w.table_current_A.size(); ++k)
    w.table_t_s.push_back(static_cast<double>(k) * dt_s);
  return w;
}

// The current of a run: waveform=(t_s, current_A), current_A=array with current_dt_s, or the
// biased sine / dc of `kind`.
Waveform drive_of(const py::object& waveform, const py::object& current_A,
                  const py::object& current_dt_s, const std::string& kind, double current_pp_A,
                  double frequency_Hz, double current_min_A) {
  if (!current_A.is_none()) {
    if (!waveform.is_none())
      throw InputError("give waveform=(t_s, current_A) or current_A= with current_dt_s=, not both");
    if (current_dt_s.is_none())
      throw InputError("current_A= needs current_dt_s= (the sample spacing [s])");
    return sampled_waveform(current_A, optional_number(current_dt_s, "current_dt_s"));
  }
  if (!current_dt_s.is_none()) throw InputError("current_dt_s= goes with current_A=");
  if (!waveform.is_none()) {
    if (py::isinstance<py::array>(waveform) && waveform.cast<py::array>().ndim() == 1)
      throw py::type_error(
          "waveform: expected a pair (t_s, current_A); for a current sampled at a fixed "
          "spacing pass current_A=array, current_dt_s=spacing instead");
    return table_waveform(waveform);
  }
  if (kind == "sine") return biased_sine(current_pp_A, frequency_Hz, current_min_A);
  if (kind == "dc") {
    Waveform w;
    w.kind = WaveformKind::DC;
    w.level_A = current_pp_A;
    return w;
  }
  throw InputError("kind '" + kind +
                   "': use 'sine' or 'dc', or pass waveform=(t_s, current_A) or current_A=");
}

double optional_number(const py::object& o, const char* what) {
  if (py::isinstance<py::bool_>(o) ||
      !(py::isinstance<py::float_>(o) || py::isinstance<py::int_>(o) ||
        py::hasattr(o, "__float__")) ||
      py::isinstance<py::str>(o))
    throw py::type_error(
        fmt::format("{}: expected a number or None, not {}", what,
                    py::str(py::type::of(o).attr("__name__")).cast<std::string>()));
  return py::float_(o).cast<double>();
}

// A UserWarning (issue 19, items 3 and 8: values far outside the material's range, a
// temperature outside the validated range); an error if the warnings filter says so.
void warn(const std::string& message) {
  if (PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 2) != 0) throw py::error_already_set();
}

std::shared_ptr<Model> checked_model(Model m) {
  for (const auto& w : model_warnings(m)) warn(w);
  return std::make_shared<Model>(std::move(m));
}

// simulate() on a run that diverged raises gmasim.DivergenceError, as Stepper.step does (issue
// 19, item 11: one behaviour); the exception's `result` holds the partial run's dict.
[[noreturn]] void raise_divergence(const std::string& message, const py::dict& partial) {
  const py::object type = py::module_::import("gmasim._gmasim").attr("DivergenceError");
  py::object e = type(message);
  e.attr("result") = partial;
  PyErr_SetObject(type.ptr(), e.ptr());
  throw py::error_already_set();
}

// simulate(): the options' keyword arguments and defaults are the Python rows of their table
// (gmasim/experiments/simulate_fields.hpp), then the arguments below.
py::dict simulate_py(const Model& m, const SimulateOptions& o, py::object waveform,
                     const std::vector<std::string>& freeze,
                     const std::vector<std::string>& quantities, py::object ambient_C,
                     py::object current_A, py::object current_dt_s) {
  const double temperature_C = o.temperature_C;
  const bool self_heating = o.self_heating;
  if (auto w = temperature_warning(m, temperature_C)) warn(*w);
  SimulationSettings s;
  s.energy_ledger = true;
  s.self_heating.enabled = self_heating;
  s.self_heating.thermal_step_s = o.thermal_step_s;
  if (!ambient_C.is_none()) s.self_heating.ambient_C = optional_number(ambient_C, "ambient_C");
  s.temperature_C = temperature_C;
  s.periods = o.periods;
  s.dt_s = o.dt_s;
  s.record_every = o.record_every;
  s.duration_s = o.duration_s;
  s.metrics_window_s = o.metrics_window_s;
  s.freeze = parse_freeze(freeze);
  s.waveform = drive_of(waveform, current_A, current_dt_s, o.kind, o.current_pp_A, o.frequency_Hz,
                        o.current_min_A);
  Result r;
  {
    py::gil_scoped_release release;
    r = simulate(m, s);
  }
  // The statistics of the requested columns, by default of the drive, the output and B.
  if (!r.diverged)
    add_quantity_stats(
        r, quantities.empty() ? std::vector<std::string>{"current_A", "y_um", "B_T"} : quantities);
  py::dict d;
  d["series"] = series_dict(r.series);
  if (r.has_metrics) d["metrics"] = metrics_dict(r.metrics);
  d["dt_s"] = r.dt_s;
  d["steps"] = r.steps;
  d["wall_time_s"] = r.wall_time_s;
  d["diverged"] = r.diverged;
  d["error"] = r.error;
  d["thermal_expansion_um"] = r.thermal_expansion_um;
  d["thermal_expansion_start_um"] = r.thermal_expansion_start_um;
  if (r.has_energy) d["energy"] = energy_dict(m, r);
  if (self_heating) {
    d["heating"] = series_dict(r.heating);
    d["energy_in_J"] = r.energy_in_J;
    d["energy_stored_J"] = r.energy_stored_J;
    d["energy_out_J"] = r.energy_out_J;
  }
  py::dict q;
  for (const auto& qs : r.quantities) {
    py::dict e;
    e["rms"] = qs.rms;
    e["peak"] = qs.peak;
    e["pp"] = qs.pp;
    e["mean"] = qs.mean;
    q[py::str(qs.name)] = e;
  }
  d["quantities"] = q;
  if (r.diverged) raise_divergence(r.error, d);
  return d;
}

// gmasim.Model: load, parameters, ranges, changed copies, save.
void bind_model(py::module_& mod) {
  py::class_<Model, std::shared_ptr<Model>>(mod, "Model", "A compiled, immutable model")
      .def(py::init([](const std::string& path) { return checked_model(load_model(path)); }),
           py::arg("path") = std::string(), "Load a model file (TOML); empty path = built-in MDMA")
      .def_property_readonly("source", [](const Model& m) { return m.spec.source; })
      .def_property_readonly("rods",
                             [](const Model& m) {
                               std::vector<std::string> r;
                               for (const auto& rod : m.rods) r.push_back(rod.name);
                               return r;
                             })
      .def(
          "params",
          [](const Model& m) {
            py::dict d;
            for (const auto& [name, p] : m.spec.params)
              d[py::str(name)] = py::make_tuple(p.value, m.spec.unit_of(name), p.provenance);
            return d;
          },
          "Every numeric parameter: name -> (value, unit, provenance)")
      .def(
          "get", [](const Model& m, const std::string& name) { return m.spec.get(name); },
          py::arg("name"))
      .def(
          "temperature_ranges",
          [](const Model& m) {
            py::dict d;
            const auto c = computable_range(m);
            d["computable_C"] = c ? py::object(py::make_tuple(c->min_C, c->max_C)) : py::none();
            const auto v = validated_range(m);
            d["validated_C"] = py::make_tuple(v.min_C, v.max_C);
            return d;
          },
          "{'computable_C': (min, max) where the laws can be evaluated (outside: InputError; "
          "the max may be T_c itself, excluded), 'validated_C': (min, max) where the model was "
          "validated (outside: a UserWarning)}")
      .def(
          "warnings", [](const Model& m) { return model_warnings(m); },
          "Values far outside Terfenol-D's known range (also issued as UserWarning on load)")
      .def(
          "with_params",
          [](const Model& m, const py::dict& values) {
            ModelSpec spec = m.spec;
            std::vector<std::string> words;  // options: set together, checked as a whole
            for (const auto& [k, v] : values) {
              const std::string name = py::str(k);
              if (py::isinstance<py::str>(v)) {
                words.push_back(name + "=" + v.cast<std::string>());
              } else if (py::isinstance<py::bool_>(v) ||
                         !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v) ||
                           py::hasattr(v, "__float__"))) {
                throw py::type_error(fmt::format(
                    "with_params: '{}' = {}: expected a number (in the parameter's unit) or, for "
                    "an option, a word (str)",
                    name, py::repr(v).cast<std::string>()));
              } else {
                spec.set(name, v.cast<double>());
              }
            }
            if (!words.empty()) spec = apply_assignments(std::move(spec), words, "with_params");
            return checked_model(compile(spec));
          },
          py::arg("values"),
          "A new model with some parameters changed: {dotted name: number in the file's units} "
          "or {'options.<name>': 'word'}; the same rules as the CLI's --set")
      .def(
          "toml", [](const Model& m, const std::string& why) { return model_toml(m.spec, why); },
          py::arg("why") = "Python Model.toml",
          "The model file text: the source file with each changed value replaced on its line "
          "and a 'set: <why>; was <old>' comment")
      .def(
          "save",
          [](const Model& m, const std::string& path, const std::string& why) {
            save_model(m.spec, path, why);
          },
          py::arg("path"), py::arg("why") = "Python Model.save",
          "Write the model file (see toml()) atomically; Model(path) loads it back unchanged");
}

}  // namespace

PYBIND11_MODULE(_gmasim, mod) {
  mod.doc() =
      "gmasim: temperature-dependent giant magnetostrictive actuator simulator (MCTD model)";
  py::register_exception<InputError>(mod, "InputError", PyExc_ValueError);
  py::register_exception<DivergenceError>(mod, "DivergenceError", PyExc_ArithmeticError);

  bind_model(mod);

  def_request<SimulateOptions>(
      mod, "simulate",
      "Time-domain run.\n\n"
      "The coil current is one of:\n"
      "  * kind='sine' (default): the biased sine of Fig. 11, current_min_A + current_pp_A/2 "
      "(1 - cos 2 pi f t), run for `periods` periods;\n"
      "  * kind='dc': a constant current_pp_A for duration_s;\n"
      "  * current_A=ndarray, current_dt_s=spacing: samples at t = 0, dt, 2 dt, ... [A, s] "
      "(linear between samples, held after the last; the run lasts to the last sample "
      "unless duration_s is given);\n"
      "  * waveform=(t_s, current_A): a pair of equally long 1-D arrays, t_s strictly "
      "increasing from 0 [s, A].\n\n"
      "Returns a dict (printed as a short summary): 'series' {column: ndarray}, 'metrics' "
      "(stroke_um, hysteresis_um, B_pp_T, y_mean_um over the last period or the whole run), "
      "'quantities' {column: {rms, peak, pp, mean}} (default: current_A, y_um, B_T; or the "
      "columns named in quantities=), 'thermal_expansion_um' (eq. 21 at the end of the run; "
      "'thermal_expansion_start_um' at its start), 'energy', dt_s, steps; with "
      "self_heating=True also 'heating' (one row per thermal step: node temperatures, losses, "
      "stroke) and the energy balance (energy_in_J = energy_stored_J + energy_out_J)",
      &simulate_py, Extra<py::object>{"waveform", py::none()},
      Extra<std::vector<std::string>>{"freeze", {}},
      Extra<std::vector<std::string>>{"quantities", {}}, Extra<py::object>{"ambient_C", py::none()},
      Extra<py::object>{"current_A", py::none()}, Extra<py::object>{"current_dt_s", py::none()});
  // The table of Metrics (gmasim/simulate/simulate.hpp kMetricRows): the keys of simulate()'s
  // "metrics" dict in order; gmasim's SimulationResult prints those with a label.
  mod.def(
      "metric_rows",
      [] {
        py::list rows;
        for (const MetricRow& row : kMetricRows) {
          py::dict d;
          d["name"] = std::string(row.name);
          d["unit"] = std::string(row.unit);
          d["label"] = std::string(row.label);
          d["precision"] = row.precision;
          rows.append(d);
        }
        return rows;
      },
      "The table of simulate()'s metrics: [{name, unit, label, precision}] in the dict's order; "
      "label: the CLI summary's ('' : not printed there)");
  // The names freeze=[...] takes (simulate, Stepper, sweep), from the C++ table.
  py::list laws;
  for (const auto& sw : gmasim::kFreezeSwitches) laws.append(sw.name);
  mod.attr("FREEZE_LAWS") = py::tuple(laws);
  gmasim::py_bind::bind_experiments(mod);
  gmasim::py_bind::bind_stepper(mod);
  gmasim::py_bind::bind_parameters(mod);
  gmasim::py_bind::bind_sensitivity(mod);
  gmasim::py_bind::bind_paper_claims(mod);
}
