// gmasim frf: frequency response current -> displacement (Fig. 15) by stepped sine and by
// small-signal linearisation, with the mechanical modes of eq. (15).
#include <fmt/format.h>

#include <cmath>
#include <complex>
#include <memory>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kMismatchWarnPct = 5.0;  // stepped sine vs linearisation: warn above

struct FrfArgs : ExperimentArgs<FrfRequest> {
  std::string method = "both", bias_state = "anhysteretic";
};

// The resonance's shift and the change of its amplitude across the temperatures (Fig. 15:
// the paper's peak moves < 0.17 % and its amplitude hardly changes).
void print_resonance_change(const FrfResult& res) {
  const auto& c0 = res.curves.front();
  const auto& c1 = res.curves.back();
  if (res.curves.size() < 2 || !(c0.first_resonance_Hz > 0) || !(c1.first_resonance_Hz > 0)) return;
  fmt::print(
      "\n  {:g} -> {:g} degC: first resonance {:+.3f} % in frequency, {:+.1f} % in amplitude "
      "(|Y/I| {:.4g} -> {:.4g} um/A)\n",
      c0.temperature_C, c1.temperature_C,
      100.0 * (c1.first_resonance_Hz / c0.first_resonance_Hz - 1.0),
      100.0 * (c1.first_resonance_mag_um_per_A / c0.first_resonance_mag_um_per_A - 1.0),
      c0.first_resonance_mag_um_per_A, c1.first_resonance_mag_um_per_A);
}

// One temperature's response table: stepped sine and linearisation side by side.
void print_response_table(const FrfCurve& c) {
  fmt::print("  {:>10} {:>12} {:>10} {:>12} {:>10} {:>9}\n", "f", "|Y/I| step", "phase step",
             "|Y/I| lin", "phase lin", "mismatch");
  fmt::print("  {:>10} {:>12} {:>10} {:>12} {:>10} {:>9}\n", "(Hz)", "(um/A)", "(deg)", "(um/A)",
             "(deg)", "(%)");
  for (std::size_t k = 0; k < c.f_Hz.size(); ++k) {
    const bool s = k < c.stepped_mag_um_per_A.size(), l = k < c.linear_mag_um_per_A.size();
    std::string mis = "-";
    if (s && l) {
      const auto Ys = std::polar(c.stepped_mag_um_per_A[k], c.stepped_phase_deg[k] * kDeg);
      const auto Yl = std::polar(c.linear_mag_um_per_A[k], c.linear_phase_deg[k] * kDeg);
      mis = fmt::format("{:.3f}", std::abs(Ys - Yl) / std::abs(Yl) * 100.0);
    }
    fmt::print("  {:10.2f} {:>12} {:>10} {:>12} {:>10} {:>9}\n", c.f_Hz[k],
               s ? fmt::format("{:.5f}", c.stepped_mag_um_per_A[k]) : "-",
               s ? fmt::format("{:.2f}", c.stepped_phase_deg[k]) : "-",
               l ? fmt::format("{:.5f}", c.linear_mag_um_per_A[k]) : "-",
               l ? fmt::format("{:.2f}", c.linear_phase_deg[k]) : "-", mis);
  }
}

// Small or large signal (docs/experiments.md): which data the markers come from, and a warning
// on stderr when the stepped sine disagrees with the linearisation.
void print_signal_regime(const FrfRequest& req, const FrfCurve& c) {
  if (!req.stepped_sine) return;
  fmt::print(
      "  stimulus +-{:g} A: {} signal (small up to +-{:.3g} mA here: every rod's field "
      "excursion within 10 % of its reversible range c k/(1-c)); markers from the {}\n",
      req.amplitude_A, c.large_signal ? "large" : "small", c.small_signal_limit_A * 1e3,
      c.markers_from);
  if (!req.small_signal || !(c.max_mismatch_pct > kMismatchWarnPct)) return;
  fmt::print(stderr,
             "gmasim frf: warning: at {:g} degC the stepped sine differs from the small-signal "
             "linearisation by up to {:.1f} % of |Y/I|{}; the linearised curve does not describe "
             "this stimulus (markers and the -3 dB line are from the stepped sine{})\n",
             c.temperature_C, c.max_mismatch_pct,
             c.large_signal ? fmt::format(": the stimulus +-{:g} A is large (small-signal limit "
                                          "+-{:.3g} mA)",
                                          req.amplitude_A, c.small_signal_limit_A * 1e3)
                            : " although the stimulus is small (a creeping minor loop?)",
             c.large_signal ? "" : " only for a large stimulus");
}

int run_frf_cmd(FrfArgs& a) {
  const Model model = load_model_args(a.model);
  a.options.apply();
  warn_temperatures(model, a.req.temperatures_C, "--temperatures");
  a.req.stepped_sine = a.method != "linear";
  a.req.small_signal = a.method != "stepped";
  a.req.bias_state =
      a.bias_state == "initial-curve" ? BiasState::InitialCurve : BiasState::Anhysteretic;
  prepare_output_dir(a.out, {"frf"}, model_inputs(a.model));
  const FrfResult res = run_frf(model, a.req, stderr_progress("frf", a.progress));
  auto files = write_report(a.out, "frf", frf_report(model, a.req, res));

  fmt::print("gmasim frf  model: {}\n", model_label(a.model));
  fmt::print(
      "  current -> displacement about {} A DC ({} bias state); stepped sine {} A amplitude{}; "
      "small-signal linearisation{}\n",
      a.req.bias_A, a.bias_state, a.req.amplitude_A, a.req.stepped_sine ? "" : " (off)",
      a.req.small_signal ? "" : " (off)");
  for (const auto& c : res.curves) {
    fmt::print("\n  T = {:.1f} degC   y at bias {:.3f} um   static gain {:.4f} um/A\n",
               c.temperature_C, c.y_bias_um, c.static_gain_um_per_A);
    print_response_table(c);
    print_signal_regime(a.req, c);
    auto hz = [](double f) { return f > 0 ? fmt::format("{:.1f} Hz", f) : std::string("none"); };
    fmt::print(
        "  first resonance (largest |Y/I| peak of the {} in {}-{} Hz): {}, |Y/I| {:.4g} um/A   "
        "(paper, Fig. 15: {} Hz)\n",
        c.markers_from, a.req.f_min_Hz, a.req.f_max_Hz, hz(c.first_resonance_Hz),
        c.first_resonance_mag_um_per_A, res.paper_first_resonance_Hz);
    if (a.req.small_signal)
      fmt::print("  |Y/I| peak of the linear model searched up to {:.0f} Hz: {}\n",
                 c.linear_peak_search_max_Hz, hz(c.linear_peak_extended_Hz));
    fmt::print("  -3 dB bandwidth (re |Y/I| {:.4g} um/A at {:g} Hz): {}   (paper: > {} Hz)\n",
               c.reference_gain_um_per_A, a.req.f_min_Hz, hz(c.bandwidth_3dB_Hz),
               res.paper_bandwidth_Hz);
    if (a.req.stepped_sine && a.req.small_signal)
      fmt::print("  stepped sine vs linearisation: max |difference| {:.3f} % of |Y/I|\n",
                 c.max_mismatch_pct);
    fmt::print("  eq. (15) modes at the bias point:");
    for (std::size_t k = 0; k < c.mode_frequencies_Hz.size(); ++k)
      fmt::print("  {:.0f} Hz (zeta {:.3f})", c.mode_frequencies_Hz[k], c.mode_damping_ratios[k]);
    fmt::print("\n  eddy time constants:");
    for (std::size_t k = 0; k < c.eddy_tau_ms.size(); ++k)
      fmt::print(" {:.3f} ms", c.eddy_tau_ms[k]);
    fmt::print("\n");
  }
  print_resonance_change(res);
  if (model.sensor_mount.enabled) {
    const auto& sm = model.sensor_mount;
    fmt::print(
        "\n  The first resonance is the sensor mount's ({:.3g} kg probe and bracket, {:.4g} N/m, "
        "{:.3g} N s/m: {:.0f} Hz), shaken by the {:.3g} kg housing's recoil against the moving "
        "stack; eq. (15)'s rod oscillators ring at the modes above (docs/model.md, \"The sensor "
        "mount\").\n",
        sm.mass_kg, sm.stiffness_N_per_m, sm.damping_N_s_per_m,
        std::sqrt(sm.stiffness_N_per_m / sm.mass_kg) / (2.0 * 3.141592653589793),
        sm.actuator_mass_kg);
  } else {
    fmt::print(
        "\n  This model has no sensor mount: the paper's {:g} Hz first resonance is not a mode "
        "of eq. (15) with Table 6's masses and stiffnesses; its diagonal oscillators ring at the "
        "frequencies above and the eddy-current lag sets the roll-off (docs/experiments.md).\n",
        res.paper_first_resonance_Hz);
  }
  if (a.plot) files.push_back(render_plot("frf", a.out));
  fmt::print("  wrote {}\n", fmt::join(files, ", "));
  return 0;
}

}  // namespace

Runner add_frf(CLI::App& app) {
  auto own = [](CLI::App* sub, FrfArgs& a) {
    sub->add_option("--method", a.method, "stepped, linear or both")
        ->check(CLI::IsMember({"stepped", "linear", "both"}))
        ->capture_default_str();
    sub->add_option("--bias-state", a.bias_state,
                    "Magnetic state at the bias: anhysteretic (after AC shake-down) or "
                    "initial-curve (virgin curve; the JA minor loop then creeps)")
        ->check(CLI::IsMember({"anhysteretic", "initial-curve"}))
        ->capture_default_str();
  };
  return add_experiment<FrfArgs>(
      app,
      {"frf",
       "Frequency response current -> displacement (Fig. 15): stepped sine and/or small-signal "
       "linearisation about a DC bias, first resonance, -3 dB bandwidth, eq. (15) modes. Writes "
       "frf.csv, frf_summary.csv, frf_modes.csv, frf_eddy.csv and frf.json",
       "out/frf", "Also draw <out>/frf.png and .svg (matplotlib)"},
      own, run_frf_cmd);
}

}  // namespace gmasim::cli
