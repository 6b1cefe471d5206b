// gmasim linearize (gmasim/experiments/experiments.hpp, linearize_plant, linearize_report): the
// plant at a temperature and bias as a state space, and its report.
#include <fmt/format.h>

#include <cmath>
#include <complex>

#include "experiments/frf_internal.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {
namespace {

// A matrix of the state space as a table: one row per row of the matrix, named by its state or
// output and its unit; one column per state (or the input).
Table matrix_table(const std::string& name, const std::vector<double>& v,
                   const std::vector<std::string>& row_names,
                   const std::vector<std::string>& row_units,
                   const std::vector<std::string>& col_names) {
  Table t{name, {"row", "unit"}, {}};
  t.columns.insert(t.columns.end(), col_names.begin(), col_names.end());
  const std::size_t cols = col_names.size();
  for (std::size_t i = 0; i < row_names.size(); ++i) {
    std::vector<Cell> row{row_names[i], row_units[i]};
    for (std::size_t j = 0; j < cols; ++j) row.emplace_back(v[i * cols + j]);
    t.rows.push_back(std::move(row));
  }
  return t;
}

// Eigenvalues as rows: real and imaginary parts [1/s], |s| / 2 pi [Hz] and -Re / |s|.
Table roots_table(const std::string& name, const std::vector<std::complex<double>>& roots) {
  Table t{name, {"real_per_s", "imag_per_s", "frequency_Hz", "damping_ratio"}, {}};
  for (const auto& z : roots) {
    const double mag = std::abs(z);
    t.rows.push_back({z.real(), z.imag(), mag / (2.0 * M_PI), mag > 0 ? -z.real() / mag : 1.0});
  }
  return t;
}

}  // namespace

StateSpace linearize_plant(const Model& m, const Conditions& c, double bias_A) {
  require_in(bias_A, -kMaxCurrent_A, kMaxCurrent_A, "bias current (--bias, bias_A)", "A");
  return state_space(m, linearise(m, c, settle_at_bias(m, c, bias_A, BiasState::Anhysteretic)));
}

StateSpace linearize_plant(const Model& m, double temperature_C, double bias_A) {
  return linearize_plant(m, make_conditions(m, temperature_C), bias_A);
}

std::vector<DescribingPoint> describing_function(const Model& m, const StateSpace& ss,
                                                 double amplitude_A,
                                                 const std::vector<double>& f_Hz, int threads) {
  require_positive_at_most(amplitude_A, kMaxCurrent_A,
                           "describing-function amplitude (--amplitude)", "A");
  if (f_Hz.empty())
    throw InputError("describing function: no frequency given (--frequencies): give at least one");
  for (double f : f_Hz)
    require_positive_at_most(f, kMaxFrequency_Hz, "describing-function frequency (--frequencies)",
                             "Hz");
  const Conditions c = make_conditions(m, ss.temperature_C);
  const State bias = settle_at_bias(m, c, ss.bias_A, BiasState::Anhysteretic);
  const SmallSignalModel lin = linearise(m, c, bias);
  FrfRequest r;
  r.temperatures_C = {ss.temperature_C};
  r.bias_A = ss.bias_A;
  r.amplitude_A = amplitude_A;
  std::vector<DescribingPoint> out(f_Hz.size());
  detail::parallel_for(f_Hz.size(), resolve_thread_count(threads, f_Hz.size()),
                       [&](std::size_t k) {
                         const std::complex<double> Y =
                             detail::stepped_sine_point(m, c, bias, lin, r, f_Hz[k]);
                         const std::complex<double> L = ss.response(f_Hz[k]);
                         out[k] = {f_Hz[k], 1e6 * std::abs(Y), std::arg(Y) * 180.0 / M_PI,
                                   1e6 * std::abs(L), std::arg(L) * 180.0 / M_PI};
                       },
                       {});
  return out;
}

Table describing_function_table(const std::vector<DescribingPoint>& df) {
  Table t{"describing_function",
          {"frequency_Hz", "gain_um_per_A", "phase_deg", "small_signal_gain_um_per_A",
           "small_signal_phase_deg", "gain_ratio"},
          {}};
  for (const DescribingPoint& p : df)
    t.rows.push_back({p.f_Hz, p.gain_um_per_A, p.phase_deg, p.small_signal_gain_um_per_A,
                      p.small_signal_phase_deg, p.gain_um_per_A / p.small_signal_gain_um_per_A});
  return t;
}

Report linearize_report(const Model& m, const StateSpace& ss,
                        const std::vector<DescribingPoint>* df, double amplitude_A) {
  Report r;
  r.experiment = "linearize";
  r.meta.emplace_back("model", m.spec.source);
  r.meta.emplace_back("temperature_C", ss.temperature_C);
  r.meta.emplace_back("bias_A", ss.bias_A);
  r.meta.emplace_back("states", ss.n_states);
  r.meta.emplace_back("input", ss.input + " [" + ss.input_unit + "]");
  r.meta.emplace_back("magnetic_states", ss.magnetic_state);
  r.meta.emplace_back("dc_gain_y_um_per_A", 1e6 * ss.dc_gain(0));
  if (ss.n_outputs > 1) r.meta.emplace_back("dc_gain_B_mT_per_A", 1e3 * ss.dc_gain(1));
  Table states{"states", {"index", "state", "unit"}, {}};
  for (std::size_t i = 0; i < ss.states.size(); ++i)
    states.rows.push_back({static_cast<int>(i), ss.states[i], ss.state_units[i]});
  const std::vector<std::string> input{ss.input};
  r.tables = {states,
              matrix_table("A", ss.A, ss.states, ss.state_units, ss.states),
              matrix_table("B", ss.B, ss.states, ss.state_units, input),
              matrix_table("C", ss.C, ss.outputs, ss.output_units, ss.states),
              matrix_table("D", ss.D, ss.outputs, ss.output_units, input),
              roots_table("poles", ss.poles()),
              roots_table("zeros", ss.zeros(0))};
  // The plant split at the sensor mount (StateSpace::blocks): each block's A, B, C, D.
  r.meta.emplace_back("interconnection", ss.interconnection);
  for (const StateSpace& b : ss.blocks) {
    const std::string name = b.input == "q" ? "mount" : "stack";
    const std::vector<std::string> in{b.input};
    r.tables.push_back(matrix_table(name + "_A", b.A, b.states, b.state_units, b.states));
    r.tables.push_back(matrix_table(name + "_B", b.B, b.states, b.state_units, in));
    r.tables.push_back(matrix_table(name + "_C", b.C, b.outputs, b.output_units, b.states));
    r.tables.push_back(matrix_table(name + "_D", b.D, b.outputs, b.output_units, in));
  }
  if (df != nullptr) {
    r.meta.emplace_back("describing_function_amplitude_A", amplitude_A);
    r.tables.push_back(describing_function_table(*df));
  }
  return r;
}

}  // namespace gmasim
