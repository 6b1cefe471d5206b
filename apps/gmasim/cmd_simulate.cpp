// gmasim simulate: one time-domain run of the model.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/simulate_fields.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

// The energy ledgers (docs/model.md, "Energy ledgers") as mean powers over the metrics window,
// and the coil's terminal quantities.
void print_energy(const Result& r, bool periodic) {
  const auto& e = r.energy;
  const double T = e.duration_s;
  const auto& c = r.coil;
  fmt::print("  energy, mean power {} [W]:\n", periodic ? "over the last period" : "over the run");
  fmt::print(
      "    magnetic:   coil {:.4g} + magnet {:.3g} = stored {:.3g} + hysteresis {:.4g} + eddy "
      "{:.4g}  (residual {:.2g} of the input)\n",
      e.coil_J / T, e.magnet_J / T, (e.d_circuit_J + e.d_series_J + e.d_material_J) / T,
      e.hysteresis_J / T, e.eddy_J / T, e.magnetic_residual_rel);
  fmt::print(
      "    mechanical: force {:.4g} + stiffness {:.4g} = stored {:.3g} + damping {:.4g}  "
      "(residual {:.2g})\n",
      e.force_work_J / T, e.stiffness_work_J / T, (e.d_kinetic_J + e.d_elastic_J) / T,
      e.damping_J / T, e.mechanical_residual_rel);
  fmt::print(
      "    coupling:   the mechanical input, not drawn from the coil (one-way coupling), is "
      "{:.2f} % of the magnetic input\n",
      100.0 * e.coupling_fraction);
  fmt::print(
      "    coil:       {:.4g} A rms, {:.4g} V rms ({:.4g} V peak) with R = {:.3g} ohm; power "
      "{:.4g} W mean (copper {:.4g} W), {:.4g} W peak, {:.4g} VA apparent\n",
      c.current_rms_A, c.voltage_rms_V, c.voltage_peak_V, c.resistance_ohm, c.power_mean_W,
      c.copper_W, c.power_peak_W, c.apparent_VA);
}

// The options of the table (gmasim/experiments/simulate_fields.hpp) and the command's own.
struct SimulateArgs : SimulateOptions {
  RequestOptions<SimulateOptions> options;
  ModelArgs model;
  std::string waveform_csv, out = "out/simulate";
  // one or several (comma list, start:step:stop) [degC]; temperature_C: the one of this run
  std::string temperatures = fmt::format("{:g}", SimulateOptions{}.temperature_C);
  bool record_every_given = false, current_min_given = false;
  bool plot = false, progress = false;
  double ambient_C = std::nan("");
  std::vector<std::string> quantities, freeze;
};

Waveform make_waveform(const SimulateArgs& a) {
  if (!a.waveform_csv.empty()) return load_waveform_csv(a.waveform_csv);
  Waveform w;
  if (a.kind == "sine") {
    w = biased_sine(a.current_pp_A, a.frequency_Hz, a.current_min_A);
  } else if (a.kind == "dc") {
    w.kind = WaveformKind::DC;
    w.level_A = a.level_A;
  } else if (a.kind == "step") {
    w.kind = WaveformKind::Step;
    w.level_A = a.level_A;
    w.step_to_A = a.step_to_A;
    w.step_time_s = a.step_time_s;
  } else if (a.kind == "chirp") {
    w.kind = WaveformKind::Chirp;
    w.f0_Hz = a.f0_Hz;
    w.f1_Hz = a.f1_Hz;
    w.amplitude_A = a.amplitude_A;
    w.offset_A = a.offset_A;
    w.duration_s = a.duration_s;
    if (!(a.duration_s > 0)) throw InputError("--duration: a chirp needs a duration > 0 s");
    if (!(a.f0_Hz > 0 && a.f1_Hz > 0))
      throw InputError("--f0/--f1: chirp frequencies must be > 0 Hz");
  }
  return w;
}

// The flags that shape the current waveform, and the waveforms that use each (issue 19, item
// 10): a flag the chosen waveform ignores is a usage error, never silently dropped. "csv" is
// --waveform FILE.
struct WaveformFlag {
  const char* flag;
  std::vector<std::string> kinds;
};
const std::vector<WaveformFlag>& waveform_flags() {
  static const std::vector<WaveformFlag> flags = {
      {"--current-pp", {"sine"}},  {"--current-min", {"sine"}},
      {"--frequency", {"sine"}},   {"--periods", {"sine"}},
      {"--level", {"dc", "step"}}, {"--step-to", {"step"}},
      {"--step-time", {"step"}},   {"--f0", {"chirp"}},
      {"--f1", {"chirp"}},         {"--amplitude", {"chirp"}},
      {"--offset", {"chirp"}},     {"--duration", {"dc", "step", "chirp", "csv"}},
  };
  return flags;
}

void check_waveform_flags(const CLI::App& sub, const SimulateArgs& a) {
  const bool csv = !a.waveform_csv.empty();
  if (csv && sub.count("--waveform-kind") > 0)
    throw UsageError(fmt::format(
        "--waveform-kind {} with --waveform {}: the CSV is the whole current waveform; give one "
        "of them",
        a.kind, clip_for_message(a.waveform_csv)));
  const std::string kind = csv ? "csv" : a.kind;
  const std::string used_by =
      csv ? "--waveform " + clip_for_message(a.waveform_csv) : "--waveform-kind " + a.kind;
  // the self-heating run's own flags, without --self-heating: ignored, so refused
  for (const char* flag : {"--ambient", "--thermal-step"})
    if (sub.count(flag) > 0 && !a.self_heating)
      throw UsageError(fmt::format(
          "{}: only a self-heating run uses it; add --self-heating, or remove {}", flag, flag));
  for (const auto& f : waveform_flags()) {
    if (sub.count(f.flag) == 0) continue;
    if (std::find(f.kinds.begin(), f.kinds.end(), kind) != f.kinds.end()) continue;
    std::vector<std::string> users;
    for (const auto& k : f.kinds)
      users.push_back(k == "csv" ? "--waveform FILE" : "--waveform-kind " + k);
    throw UsageError(
        fmt::format("{}: this run's waveform is {}, which does not use it (only {} do); remove {}",
                    f.flag, used_by, fmt::join(users, ", "), f.flag));
  }
}

SimulationSettings settings_of(const SimulateArgs& a) {
  SimulationSettings s;
  s.temperature_C = a.temperature_C;
  s.energy_ledger = true;
  s.waveform = make_waveform(a);
  s.periods = a.periods;
  s.duration_s = a.duration_s;
  s.metrics_window_s = a.metrics_window_s;
  s.dt_s = a.dt_s;
  s.record_every = a.record_every;
  s.progress = stderr_progress("simulate", a.progress);
  s.self_heating.enabled = a.self_heating;
  s.self_heating.thermal_step_s = a.thermal_step_s;
  s.self_heating.ambient_C = a.ambient_C;
  s.freeze = parse_freeze(a.freeze);
  return s;
}

// Fails before the run, not after it: no output may replace an input (the model file, the
// waveform CSV; issue 19, item 1), and the directory must be writable.
void prepare_simulate_out(const SimulateArgs& a) {
  std::vector<FileArg> inputs = model_inputs(a.model);
  if (!a.waveform_csv.empty()) inputs.push_back({a.waveform_csv, "--waveform"});
  if (a.out.empty()) ensure_output_dir(a.out);  // refuses the empty name
  require_outputs_distinct(inputs, files_in(a.out,
                                            {"timeseries.csv", "metrics.json", "self_heating.csv",
                                             "simulate.png", "simulate.svg"},
                                            "--out"));
  ensure_output_dir(a.out);
}

// A run longer than this many recorded rows writes every k-th row to timeseries.csv unless
// --record-every is given (a row of the MDMA is ~400 bytes: 60 s of self-heating at 10 Hz,
// 1.2 million steps, would be ~480 MB; thinned, ~4 MB); the metrics are computed from every
// recorded step all the same.
constexpr std::size_t kCsvRows = 10000;

// Every k-th row of ts, its last row, and every k_window-th row from full_from_s on (the last
// three metrics windows, which simulate.png draws: about kWindowRows a window; thinned like the
// rest, a self-heating run's last period had ~16 points, issue 41).
constexpr double kWindowRows = 2000.0;
TimeSeries thinned(const TimeSeries& ts, std::size_t k, double full_from_s, std::size_t k_window) {
  TimeSeries out;
  out.names = ts.names;
  out.columns.resize(ts.columns.size());
  const std::size_t n = ts.rows();
  const std::vector<double>& t = ts.column("t_s");
  for (std::size_t i = 0; i < n; ++i) {
    if (i % k != 0 && i != n - 1 && !(t[i] >= full_from_s && i % k_window == 0)) continue;
    for (std::size_t c = 0; c < ts.columns.size(); ++c) out.columns[c].push_back(ts.columns[c][i]);
  }
  return out;
}

// A biased sine that crosses 0 A in a model without a bias magnet: the strain follows |M| and
// doubles the frequency (a butterfly), which a 0-6 A drive given as --current-pp 6 alone
// (default --current-min -3 A, the paper's Fig. 11) would produce unseen.
void warn_zero_crossing(const Model& m, const SimulateArgs& a, const Waveform& w) {
  if (w.kind != WaveformKind::BiasedSine || !(w.min_A < 0.0 && w.min_A + w.pp_A > 0.0)) return;
  for (const auto& b : m.circuit.branches)
    if (b.pm_mmf_At != 0.0) return;
  print_warning(fmt::format(
      "the drive {:g} .. {:g} A crosses 0 A and {} has no bias magnet: the strain follows |M| "
      "and doubles the frequency (a butterfly loop){}; for a unipolar drive give --current-min 0",
      w.min_A, w.min_A + w.pp_A, m.spec.source,
      a.current_min_given ? "" : " (--current-min defaults to -3 A, the paper's Fig. 11 bias)"));
}

void print_metrics(const Result& r, const SimulationSettings& s, const Model& model) {
  // The window said: the last period, the run's last S seconds (given, or a table's declared
  // period), or the whole run (what a waveform that is none of these measures).
  const double t0 = r.metrics.window_start_s, t1 = r.metrics.window_end_s;
  const std::string window =
      s.waveform.periodic() ? std::string("over the last period")
      : t0 > 0.0
          ? fmt::format("over the last {:g} s, t {:g}..{:g} s: {}", t1 - t0, t0, t1,
                        s.metrics_window_s > 0.0 ? "--metrics-window" : "the waveform's period_s")
          : std::string("over the whole run; --metrics-window S for the last S seconds");
  for (const MetricRow& row : kMetricRows) {  // the table of Metrics (gmasim/simulate.hpp)
    if (row.label.empty()) continue;
    const std::string value =
        fmt::format("  {:<12}{:9.{}f} ", row.label, r.metrics.*row.member, row.precision);
    if (row.note.empty())
      fmt::print("{}{}\n", value, row.unit);
    else
      fmt::print("{}{:<5}{}\n", value, row.unit, fmt::format(fmt::runtime(row.note), window));
  }
  fmt::print(
      "  drift       {:9.3f} um   (thermal offset x_T vs T_ref {:g} degC at the end, {} y; "
      "{:+.3f} um over the run)\n",
      r.thermal_expansion_um, model.T_ref_C,
      model.options.thermal_expansion_in_output ? "included in" : "not in",
      r.thermal_expansion_um - r.thermal_expansion_start_um);
  if (r.metrics.stroke_um > 0.0 && std::fabs(r.thermal_expansion_um) > r.metrics.stroke_um)
    print_warning(fmt::format(
        "the thermal offset drift {:.3f} um exceeds the stroke {:.3f} um ({:.1f} x) at {:g} "
        "degC: a sensor on the housing reads it; compensate it or hold the temperature",
        r.thermal_expansion_um, r.metrics.stroke_um,
        std::fabs(r.thermal_expansion_um) / r.metrics.stroke_um, s.temperature_C));
}

void print_heating(const Result& r, const SimulateArgs& a) {
  const auto& h = r.heating;
  const std::size_t n = h.rows() - 1;
  // The first thermal step holds the virgin magnetisation curve: the drift is read from the
  // second one on when there is one.
  const std::size_t b = n >= 2 ? 2 : 1;
  const double balance = r.energy_in_J - r.energy_stored_J - r.energy_out_J;
  fmt::print(
      "  self-heating over {:.1f} s (thermal step {:.3g} s, ambient {:.1f} degC):\n"
      "    coil {:.2f} degC, rods {:.2f} degC, housing {:.2f} degC at the end\n"
      "    losses at the end: copper {:.3f} W, eddy {:.4f} W, hysteresis {:.4f} W, damping "
      "{:.4f} W\n"
      "    stroke {:.3f} um over thermal step {}, {:.3f} um over the last ({:+.2f} %)\n"
      "    thermal expansion {:.3f} -> {:.3f} um ({:+.3f} um drift of the output offset)\n"
      "    energy: in {:.2f} J = stored {:.2f} J + to ambient {:.2f} J (residual {:.2e} J)\n",
      h.columns[0][n], h.columns[0][1], std::isnan(a.ambient_C) ? a.temperature_C : a.ambient_C,
      h.column("coil_C")[n], h.column("rods_C")[n], h.column("housing_C")[n],
      h.column("P_copper_W")[n], h.column("P_eddy_W")[n], h.column("P_hysteresis_W")[n],
      h.column("P_damping_W")[n], h.column("stroke_um")[b], b, h.column("stroke_um")[n],
      (h.column("stroke_um")[n] / h.column("stroke_um")[b] - 1.0) * 100.0,
      r.thermal_expansion_start_um, r.thermal_expansion_um,
      r.thermal_expansion_um - r.thermal_expansion_start_um, r.energy_in_J, r.energy_stored_J,
      r.energy_out_J, balance);
}

void print_result(const Result& r, const SimulationSettings& s, const Model& model,
                  const SimulateArgs& a) {
  fmt::print("  temperature {:.1f} degC, dt {:.4g} us, {} steps, wall time {:.3f} s\n",
             s.temperature_C, r.dt_s * 1e6, r.steps, r.wall_time_s);
  if (r.has_metrics) print_metrics(r, s, model);
  if (r.step.valid)
    fmt::print(
        "  step        y {:.3f} -> {:.3f} um, rise (10-90 %) {:.4g} ms, overshoot {:.2f} %, "
        "settling (2 %) {:.4g} ms\n",
        r.step.y_initial_um, r.step.y_final_um, r.step.rise_time_s * 1e3, r.step.overshoot_pct,
        r.step.settling_time_s * 1e3);
  for (const auto& q : r.quantities)
    fmt::print("  {:<22} rms {:.6g}  peak {:.6g}  p-p {:.6g}  mean {:.6g}\n", q.name, q.rms, q.peak,
               q.pp, q.mean);
  if (r.has_energy) print_energy(r, s.waveform.periodic());
  if (!r.has_metrics)
    fmt::print("  thermal expansion {:.3f} um ({} the output y)\n", r.thermal_expansion_um,
               model.options.thermal_expansion_in_output ? "included in" : "not in");
  if (r.heating.rows() > 1) print_heating(r, a);
}

// One temperature: the run, its output set in a.out, the console summary.
int run_one(const Model& model, const SimulateArgs& a) {
  const SimulationSettings s = settings_of(a);
  prepare_simulate_out(a);
  Result r = simulate(model, s);
  if (!r.diverged && !a.quantities.empty()) add_quantity_stats(r, a.quantities);
  const std::filesystem::path dir(a.out);
  const std::size_t rows = r.series.rows();
  const std::size_t k =
      a.record_every_given || rows <= kCsvRows ? 1 : (rows + kCsvRows - 1) / kCsvRows;
  // One set: both temporaries are complete before either is renamed, and metrics.json
  // (renamed last) names the hash of its timeseries.csv.
  // The last three metrics windows, where the window is not the whole run.
  const double window_s = r.metrics.window_end_s - r.metrics.window_start_s;
  const bool windowed = r.has_metrics && window_s > 0.0 && r.metrics.window_start_s > 0.0;
  const double full_from_s =
      windowed ? r.metrics.window_end_s - 3.0 * window_s : std::numeric_limits<double>::infinity();
  const auto k_window = static_cast<std::size_t>(
      windowed && r.dt_s > 0.0
          ? std::max(1.0, std::ceil(std::round(window_s / r.dt_s) / kWindowRows))  // steps, whole
          : 1.0);
  const TimeSeries thin = k > 1 ? thinned(r.series, k, full_from_s, k_window) : TimeSeries{};
  const std::string csv = timeseries_csv(k > 1 ? thin : r.series);
  std::vector<std::pair<std::string, std::string>> files = {
      {(dir / "timeseries.csv").string(), csv}};
  if (s.self_heating.enabled)
    files.emplace_back((dir / "self_heating.csv").string(), timeseries_csv(r.heating));
  files.emplace_back((dir / "metrics.json").string(), metrics_json(r, s, model, csv));
  write_files_atomic(files);
  print_result(r, s, model, a);
  fmt::print("  wrote {}/timeseries.csv{} and {}/metrics.json\n", a.out,
             s.self_heating.enabled ? fmt::format(", {}/self_heating.csv", a.out) : "", a.out);
  if (k > 1)
    fmt::print(
        "  timeseries.csv holds one row in {} of the {} recorded ({} rows{}): a run over {} rows "
        "is thinned by default (--record-every N sets the recording, 1 keeps every step); the "
        "metrics use every step\n",
        k, rows, thin.rows(),
        windowed ? fmt::format("; one in {} over the last three metrics windows", k_window) : "",
        kCsvRows);
  if (a.plot && r.steps > 0) fmt::print("  wrote {}\n", render_plot("simulate", a.out));
  if (r.diverged) {
    print_error(r.error +
                fmt::format(" (the {} steps before it are in {}/timeseries.csv)", r.steps, a.out));
    return 3;
  }
  return 0;
}

// The loops of several temperatures on one figure (python/gmasim/simulate_overlay.py).
std::string render_overlay(const std::string& out, const std::vector<std::string>& dirs) {
  PythonCommand c;
  c.python_path = python_package_path();
  c.module = "gmasim.simulate_overlay";
  c.args = {out};
  c.args.insert(c.args.end(), dirs.begin(), dirs.end());
  const int rc = run_python(c);
  if (rc != 0)
    throw InputError(
        fmt::format("--plot: the overlay figure failed ({}); the data files are "
                    "written",
                    c.text()));
  return (std::filesystem::path(out) / "simulate_temperatures.png").string();
}

// --temperature 20,150: one output set per temperature in <out>/T<temperature>C, and with
// --plot their loops overlaid in <out>/simulate_temperatures.png.
// The words of --temperature as usage errors, as CLI11 reports a number flag's ("80C": not a
// number; "nan": not finite); then the list (comma-separated, or start:step:stop).
std::vector<double> parse_temperatures(const std::string& text) {
  std::string word;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    if (i < text.size() && text[i] != ',' && text[i] != ':') {
      word += text[i];
      continue;
    }
    char* end = nullptr;
    const double v = std::strtod(word.c_str(), &end);
    if (word.empty() || end != word.c_str() + word.size())
      throw UsageError(fmt::format("--temperature '{}': not a number (in degC, without the unit)",
                                   clip_for_message(word)));
    if (!std::isfinite(v))
      throw UsageError(
          fmt::format("--temperature {}: must be a finite number", clip_for_message(word)));
    word.clear();
  }
  return parse_list(text, "--temperature", "degC");
}

int run_simulate(const SimulateArgs& a) {
  const std::vector<double> temps = parse_temperatures(a.temperatures);
  if (temps.empty()) throw InputError("--temperature: give at least one temperature [degC]");
  const Model model = load_model_args(a.model);
  warn_temperatures(model, temps, "--temperature");
  if (a.self_heating && !std::isnan(a.ambient_C))
    warn_temperatures(model, {a.ambient_C}, "--ambient");
  warn_zero_crossing(model, a, make_waveform(a));
  fmt::print("gmasim simulate  model: {}\n", model_label(a.model));
  if (temps.size() == 1) {
    SimulateArgs one = a;
    one.temperature_C = temps.front();
    return run_one(model, one);
  }
  // Every temperature is checked, and its directory named, before the first run: a bad one
  // last in the list left the others' outputs and an empty directory; two that print alike
  // (20 and 20.0000001: T20C) wrote one directory twice.
  std::vector<std::string> names;
  for (const double T : temps) {
    (void)make_conditions(model, T, {});
    std::string name = fmt::format("T{:g}C", T);
    for (std::size_t q = 0; q < names.size(); ++q)
      if (names[q] == name)
        throw InputError(fmt::format(
            "--temperature: {:.17g} and {:.17g} degC both write {}/{}: give distinct temperatures "
            "(they are named to 6 significant digits)",
            temps[q], T, a.out, name));
    names.push_back(std::move(name));
  }
  int rc = 0;
  std::vector<std::string> dirs;
  for (std::size_t q = 0; q < temps.size(); ++q) {
    const double T = temps[q];
    SimulateArgs one = a;
    one.temperature_C = T;
    one.out = (std::filesystem::path(a.out) / names[q]).string();
    one.plot = false;
    rc = std::max(rc, run_one(model, one));
    dirs.push_back(one.out);
  }
  if (a.plot && rc == 0) fmt::print("  wrote {}\n", render_overlay(a.out, dirs));
  return rc;
}

}  // namespace

Runner add_simulate(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  auto* sub = app.add_subcommand(
      "simulate", "Run the model in the time domain; writes timeseries.csv and metrics.json");
  add_model_options(sub, a->model);
  sub->add_option("--temperature", a->temperatures,
                  "Operating temperature [degC]; several (20,150 or 20:65:150) run one after "
                  "the other, each into <out>/T<temperature>C, loops overlaid with --plot")
      ->capture_default_str();
  // --current-pp ... --thermal-step: the table's options, in its order.
  a->options.add(sub, *a);
  a->options.option("--waveform-kind")->check(CLI::IsMember({"sine", "dc", "step", "chirp"}));
  sub->add_option("--waveform", a->waveform_csv,
                  "Arbitrary current waveform, CSV with header t_s,current_A [s, A]");
  sub->add_option(
      "--quantity", a->quantities,
      "Also report RMS, peak, p-p and mean of these columns (e.g. rod1_F_N) [column units]");
  sub->add_option("--freeze", a->freeze,
                  fmt::format("Hold these temperature laws at T_ref (20 degC), as `ablate` does; "
                              "comma-separated: {}",
                              freeze_name_list()))
      ->delimiter(',');
  sub->add_flag("--progress", a->progress,
                "Progress with ETA on stderr even when it is not a terminal (a terminal gets it "
                "for runs over 2 s), a line every 2 s at most");
  sub->add_option("--ambient", a->ambient_C,
                  "Self-heating: ambient temperature [degC]; default: --temperature");
  sub->add_flag("--plot", a->plot, "Also draw <out>/simulate.png and .svg (matplotlib)");
  sub->add_option("--out", a->out, "Output directory")->capture_default_str();
  return [a, sub]() -> int {
    if (!sub->parsed()) return -1;
    check_waveform_flags(*sub, *a);
    a->record_every_given = sub->count("--record-every") > 0;
    a->current_min_given = sub->count("--current-min") > 0;
    return run_simulate(*a);
  };
}

}  // namespace gmasim::cli
