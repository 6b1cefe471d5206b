// pybind11 bindings: gmasim._gmasim. Thin: models, simulate; arrays out as numpy.
// Experiments are bound in experiments.cpp. No physics here.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>

#include "bindings.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"
#include "gmasim/simulate.hpp"

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
  d["stroke_um"] = m.stroke_um;
  d["hysteresis_um"] = m.hysteresis_um;
  d["B_pp_T"] = m.B_pp_T;
  d["y_mean_um"] = m.y_mean_um;
  d["window_start_s"] = m.window_start_s;
  d["window_end_s"] = m.window_end_s;
  return d;
}

// The energy ledgers over the metrics window as mean powers [W] (gmasim/energy.hpp).
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

py::dict simulate_py(const Model& m, double temperature_C, double current_pp_A, double frequency_Hz,
                     double periods, double current_min_A, double dt_s, int record_every,
                     const std::string& kind, py::object waveform, double duration_s,
                     const std::vector<std::string>& freeze,
                     const std::vector<std::string>& quantities, bool self_heating,
                     double thermal_step_s, py::object ambient_C) {
  SimulationSettings s;
  s.energy_ledger = true;
  s.self_heating.enabled = self_heating;
  s.self_heating.thermal_step_s = thermal_step_s;
  if (!ambient_C.is_none()) s.self_heating.ambient_C = ambient_C.cast<double>();
  s.temperature_C = temperature_C;
  s.periods = periods;
  s.dt_s = dt_s;
  s.record_every = record_every;
  s.duration_s = duration_s;
  s.freeze = parse_freeze(freeze);
  if (!waveform.is_none()) {
    auto tup = waveform.cast<std::pair<std::vector<double>, std::vector<double>>>();
    Waveform w;
    w.kind = WaveformKind::Table;
    w.table_t_s = tup.first;
    w.table_current_A = tup.second;
    w.table_source = "<python>";
    if (w.table_t_s.size() < 2 || w.table_t_s.size() != w.table_current_A.size())
      throw InputError(
          "waveform: need two equally long arrays (t_s, current_A) of at least 2 samples");
    for (std::size_t i = 1; i < w.table_t_s.size(); ++i)
      if (!(w.table_t_s[i] > w.table_t_s[i - 1]))
        throw InputError("waveform: time must increase strictly (sample " + std::to_string(i) +
                         ")");
    s.waveform = w;
  } else if (kind == "sine") {
    s.waveform = biased_sine(current_pp_A, frequency_Hz, current_min_A);
  } else if (kind == "dc") {
    s.waveform.kind = WaveformKind::DC;
    s.waveform.level_A = current_pp_A;
  } else {
    throw InputError("kind '" + kind + "': use 'sine' or 'dc', or pass waveform=(t_s, current_A)");
  }
  Result r;
  {
    py::gil_scoped_release release;
    r = simulate(m, s);
  }
  if (!r.diverged && !quantities.empty()) add_quantity_stats(r, quantities);
  py::dict d;
  d["series"] = series_dict(r.series);
  if (r.has_metrics) d["metrics"] = metrics_dict(r.metrics);
  d["dt_s"] = r.dt_s;
  d["steps"] = r.steps;
  d["wall_time_s"] = r.wall_time_s;
  d["diverged"] = r.diverged;
  d["error"] = r.error;
  d["thermal_expansion_um"] = r.thermal_expansion_um;
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
  return d;
}

}  // namespace

PYBIND11_MODULE(_gmasim, mod) {
  mod.doc() =
      "gmasim: temperature-dependent giant magnetostrictive actuator simulator (MCTD model)";
  py::register_exception<InputError>(mod, "InputError", PyExc_ValueError);
  py::register_exception<DivergenceError>(mod, "DivergenceError", PyExc_ArithmeticError);

  py::class_<Model, std::shared_ptr<Model>>(mod, "Model", "A compiled, immutable model")
      .def(py::init(
               [](const std::string& path) { return std::make_shared<Model>(load_model(path)); }),
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
          "with_params",
          [](const Model& m, const py::dict& values) {
            ModelSpec spec = m.spec;
            std::vector<std::string> words;  // options: set together, checked as a whole
            for (const auto& [k, v] : values) {
              const std::string name = py::str(k);
              if (py::isinstance<py::str>(v)) {
                words.push_back(name + "=" + v.cast<std::string>());
              } else {
                spec.set(name, v.cast<double>());
              }
            }
            if (!words.empty()) spec = apply_assignments(std::move(spec), words, "with_params");
            return std::make_shared<Model>(compile(spec));
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

  mod.def("simulate", &simulate_py, py::arg("model"), py::arg("temperature_C") = 20.0,
          py::arg("current_pp_A") = 8.0, py::arg("frequency_Hz") = 10.0, py::arg("periods") = 3.0,
          py::arg("current_min_A") = -3.0, py::arg("dt_s") = 0.0, py::arg("record_every") = 1,
          py::arg("kind") = "sine", py::arg("waveform") = py::none(), py::arg("duration_s") = 0.0,
          py::arg("freeze") = std::vector<std::string>{},
          py::arg("quantities") = std::vector<std::string>{}, py::arg("self_heating") = false,
          py::arg("thermal_step_s") = 0.0, py::arg("ambient_C") = py::none(),
          "Time-domain run. Returns {'series': {column: ndarray}, 'metrics': {...}, ...}; with "
          "self_heating=True also 'heating' (one row per thermal step: node temperatures, losses, "
          "stroke) and the energy balance (energy_in_J = energy_stored_J + energy_out_J)");
  // The names freeze=[...] takes (simulate, Stepper, sweep), from the C++ table.
  py::list laws;
  for (const auto& sw : gmasim::kFreezeSwitches) laws.append(sw.name);
  mod.attr("FREEZE_LAWS") = py::tuple(laws);
  gmasim::py_bind::bind_experiments(mod);
  gmasim::py_bind::bind_stepper(mod);
  gmasim::py_bind::bind_parameters(mod);
  gmasim::py_bind::bind_sensitivity(mod);
}
