// gmasim.Stepper: the actuator stepped sample by sample from Python (gmasim::Stepper, the
// session under the C API too). Also the module's __version__ (bind_stepper is the module's
// one hook for this file).
#include "gmasim/simulate/stepper.hpp"

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "gmasim/version.h"

namespace py = pybind11;

namespace gmasim::py_bind {
namespace {

// A Stepper plus a guard: run() releases the GIL, so another Python thread must not touch the
// same stepper meanwhile (every method checks `busy` with the GIL held).
class PyStepper {
 public:
  PyStepper(std::shared_ptr<const Model> m, double temperature_C, double dt_s, double current_A,
            const std::vector<std::string>& freeze)
      : st_(std::move(m), temperature_C, dt_s, current_A, parse_freeze(freeze)) {}

  const Stepper& get() const {
    if (busy_) throw std::runtime_error("Stepper: busy in run() on another thread");
    return st_;
  }
  Stepper& get() {
    if (busy_) throw std::runtime_error("Stepper: busy in run() on another thread");
    return st_;
  }

  // After a divergence Stepper::step refuses with a DivergenceError naming the first one.
  double step(double current_A) { return get().step(current_A) * 1e6; }

  py::array_t<double> run(
      const py::array_t<double, py::array::c_style | py::array::forcecast>& in) {
    Stepper& s = get();
    if (in.ndim() != 1)
      throw InputError(fmt::format(
          "Stepper.run: currents_A must be a 1-D array of coil currents [A], not {}-D", in.ndim()));
    const double* I = in.data();
    const py::ssize_t n = in.shape(0);
    // Every sample is checked before the first step: a bad one leaves the stepper untouched.
    for (py::ssize_t k = 0; k < n; ++k)
      if (!std::isfinite(I[k]) || std::fabs(I[k]) > kMaxCurrent_A)
        throw InputError(fmt::format(
            "Stepper.run: currents_A[{}] = {} A: must be a finite number in [{:g}, {:g}] A", k,
            I[k], -kMaxCurrent_A, kMaxCurrent_A));
    if (s.diverged()) s.step(0.0);  // raises the refusal
    py::array_t<double> out(n);
    double* y = out.mutable_data();
    busy_ = true;
    try {
      py::gil_scoped_release release;
      for (py::ssize_t k = 0; k < n; ++k) y[k] = s.step(I[k]) * 1e6;
    } catch (...) {
      busy_ = false;
      throw;
    }
    busy_ = false;
    return out;
  }

  // The quantities simulate() records, under the same column names, at the present step.
  py::dict outputs() const {
    const Stepper& st = get();
    const State& s = st.state();
    py::dict d;
    d["t_s"] = s.t_s;
    d["current_A"] = s.current_A;
    d["y_um"] = s.y_m * 1e6;
    d["B_T"] = s.B_T;
    d["xT_um"] = st.conditions().thermal_expansion_m * 1e6;
    d["y_stack_um"] = s.y_stack_m * 1e6;
    const Model& m = st.model();
    for (std::size_t i = 0; i < s.rods.size(); ++i) {
      const RodState& r = s.rods[i];
      const std::string& p = m.rods[i].name;
      d[py::str(p + "_H_A_per_m")] = r.H_A_per_m;
      d[py::str(p + "_M_A_per_m")] = r.M_A_per_m;
      d[py::str(p + "_mu_r")] = r.mu_r;
      d[py::str(p + "_E_GPa")] = r.E_Pa * 1e-9;
      d[py::str(p + "_lambda_ppm")] = r.lambda * 1e6;
      d[py::str(p + "_F_N")] = r.F_N;
      d[py::str(p + "_x_um")] = r.x_m * 1e6;
      d[py::str(p + "_tau_eddy_ms")] = r.tau_s * 1e3;
      d[py::str(p + "_B_T")] = r.B_T;
    }
    d["temperature_C"] = st.temperature_C();
    d["dt_s"] = st.dt_s();
    d["steps"] = st.steps();
    return d;
  }

  template <class F>
  std::vector<double> per_rod(F&& f) const {
    std::vector<double> v;
    for (const RodState& r : get().state().rods) v.push_back(f(r));
    return v;
  }

 private:
  Stepper st_;
  bool busy_ = false;
};

// Stepper's constructor and methods.
void def_stepper_methods(py::class_<PyStepper>& cls) {
  cls.def(py::init([](std::shared_ptr<Model> model, double temperature_C, double dt_s,
                      double current_A, const std::vector<std::string>& freeze) {
            return std::make_unique<PyStepper>(std::move(model), temperature_C, dt_s, current_A,
                                               freeze);
          }),
          py::arg("model"), py::arg("temperature_C") = 20.0, py::arg("dt_s") = 1e-5,
          py::arg("current_A") = 0.0, py::arg("freeze") = std::vector<std::string>{},
          "The actuator at temperature_C [degC] at rest under current_A [A], stepped by dt_s "
          "[s] (0 < dt_s <= 1e-3). freeze: temperature laws held at 20 degC, as in simulate().")
      .def("step", &PyStepper::step, py::arg("current_A"),
           "One step of dt_s to coil current current_A [A] (|I| <= 1000 A); returns y [um].")
      .def("run", &PyStepper::run, py::arg("currents_A"),
           "One step per sample of the 1-D array currents_A [A], without the GIL; returns the "
           "ndarray of y [um] after each step. Every sample is checked first.")
      .def(
          "reset", [](PyStepper& s, double current_A) { s.get().reset(current_A); },
          py::arg("current_A") = 0.0,
          "Back to t = 0 at rest under current_A [A] at the present temperature; clears a "
          "divergence.")
      .def(
          "set_temperature",
          [](PyStepper& s, double temperature_C) { s.get().set_temperature(temperature_C); },
          py::arg("temperature_C"),
          "Recompute the temperature-dependent constants at temperature_C [degC]; the state, "
          "t_s and steps carry on.")
      .def("outputs", &PyStepper::outputs,
           "Every quantity simulate() records, under its column names (y_um, B_T, rod1_F_N, "
           "...), plus temperature_C, dt_s and steps.");
}

// Stepper's read-only properties and its repr.
void def_stepper_properties(py::class_<PyStepper>& cls) {
  cls.def_property_readonly(
         "t_s", [](const PyStepper& s) { return s.get().t_s(); }, "Time since creation/reset [s]")
      .def_property_readonly(
          "y_um", [](const PyStepper& s) { return s.get().y_m() * 1e6; },
          "Output displacement [um]")
      .def_property_readonly(
          "y_m", [](const PyStepper& s) { return s.get().y_m(); }, "Output displacement [m]")
      .def_property_readonly(
          "B_T", [](const PyStepper& s) { return s.get().B_T(); },
          "Flux density seen by the induction coil [T]")
      .def_property_readonly(
          "current_A", [](const PyStepper& s) { return s.get().state().current_A; },
          "Coil current at t_s [A]")
      .def_property_readonly(
          "temperature_C", [](const PyStepper& s) { return s.get().temperature_C(); },
          "Operating temperature [degC]")
      .def_property_readonly(
          "dt_s", [](const PyStepper& s) { return s.get().dt_s(); }, "Time step [s]")
      .def_property_readonly(
          "steps", [](const PyStepper& s) { return s.get().steps(); }, "Steps since creation/reset")
      .def_property_readonly(
          "diverged", [](const PyStepper& s) { return s.get().diverged(); },
          "True after a divergence, until reset()")
      .def_property_readonly(
          "rod_forces_N",
          [](const PyStepper& s) { return s.per_rod([](const RodState& r) { return r.F_N; }); },
          "Force of each rod [N]")
      .def_property_readonly(
          "rod_strains",
          [](const PyStepper& s) { return s.per_rod([](const RodState& r) { return r.lambda; }); },
          "Magnetostrictive strain lambda of each rod, eq. (11) [-]")
      .def_property_readonly(
          "rod_magnetisations_A_per_m",
          [](const PyStepper& s) {
            return s.per_rod([](const RodState& r) { return r.M_A_per_m; });
          },
          "Magnetisation M of each rod [A/m]")
      .def("__repr__", [](const PyStepper& s) {
        const Stepper& st = s.get();
        return "gmasim.Stepper(model='" + st.model().spec.source +
               "', temperature_C=" + py::repr(py::float_(st.temperature_C())).cast<std::string>() +
               ", dt_s=" + py::repr(py::float_(st.dt_s())).cast<std::string>() +
               ", t_s=" + py::repr(py::float_(st.t_s())).cast<std::string>() + ")";
      });
}

}  // namespace

void bind_stepper(py::module_& mod) {
  mod.attr("__version__") = GMASIM_VERSION;
  mod.attr("__git_describe__") = GMASIM_GIT_DESCRIBE;

  py::class_<PyStepper> cls(mod, "Stepper", R"doc(
The actuator stepped sample by sample (real-time loops, co-simulation, your own controller).

    s = gmasim.Stepper(gmasim.Model(), temperature_C=20.0, dt_s=1e-5, current_A=0.0)
    y_um = s.step(1.5)        # one step of dt_s; 1.5 A is the coil current at its end
    y = s.run(currents_A)     # one step per sample, the GIL released; ndarray of y_um

Stepping a sample at a time reproduces gmasim.simulate with the same dt_s and currents bit
for bit (t = k dt_s). Errors: gmasim.InputError (a bad number, the Curie point), and
gmasim.DivergenceError, after which step() refuses until reset().)doc");
  def_stepper_methods(cls);
  def_stepper_properties(cls);
}

}  // namespace gmasim::py_bind
