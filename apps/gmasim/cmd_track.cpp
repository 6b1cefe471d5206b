// gmasim track: closed-loop displacement tracking with the paper's PID (Fig. 16).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/feedforward.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

constexpr double kLowGainMargin_dB = 6.0, kLowPhaseMargin_deg = 30.0;

struct TrackArgs : ExperimentArgs<TrackRequest> {
  // --feedforward inverse: the evaluation against mismatched plants
  // (gmasim/experiments/feedforward.hpp)
  std::string feedforward = "none", mismatch = "all",
              controllers = fmt::format(
                  "{}",
                  fmt::join(track_controller_names(FeedforwardEvaluationRequest{}.controllers),
                            ","));
  std::vector<CLI::Option*> feedforward_only;  // refused without --feedforward inverse*
};

std::vector<TrackController> parse_controllers(const std::string& text) {
  std::vector<TrackController> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    out.push_back(parse_track_controller(text.substr(start, end - start)));
    start = end + 1;
  }
  return out;
}

// --feedforward inverse: every controller on every plant; the ratios RMS(pid) / RMS(c).
int run_feedforward_cmd(TrackArgs& a, const Model& model) {
  FeedforwardEvaluationRequest r;
  r.track = a.req;
  r.track.inverse.dynamic = a.feedforward == "inverse";
  r.mismatches = parse_plant_mismatches(a.mismatch);
  r.controllers = parse_controllers(a.controllers);
  prepare_output_dir(a.out, {"track"}, model_inputs(a.model));
  const FeedforwardEvaluation res =
      run_feedforward_evaluation(model, r, stderr_progress("track", a.progress));
  auto files = write_report(a.out, "track", feedforward_report(model, r, res));
  fmt::print("gmasim track --feedforward {}  model: {}\n", a.feedforward, model_label(a.model));
  fmt::print("  {} runs ({} plants x {} controllers) on {} threads in {:.1f} s\n", res.runs.size(),
             r.mismatches.size(), r.controllers.size(), res.threads, res.wall_time_s);
  for (std::size_t i = 0; i < res.inverses.size(); ++i)
    fmt::print(
        "  linear inverse at {:g} degC: a1 {:.4g} s, a2 {:.4g} s^2, a3 {:.4g} s^3 (fit to "
        "{:g} Hz, residual {:.2g})\n",
        r.track.temperatures_C[i], res.inverses[i].a[0], res.inverses[i].a[1], res.inverses[i].a[2],
        res.inverses[i].band_Hz, res.inverses[i].max_residual);
  fmt::print(
      "  RMS(pid) / RMS(controller) over the plants:\n  {:>6} {:>7} {:>7} {:>16} {:>8} "
      "{:>8} {:>8}\n",
      "T degC", "f Hz", "A um", "controller", "median", "min", "max");
  for (const auto& q : res.ratios)
    fmt::print("  {:6.1f} {:7.1f} {:7.1f} {:>16} {:8.2f} {:8.2f} {:8.2f}\n", q.temperature_C,
               q.frequency_Hz, q.amplitude_um, track_controller_name(q.controller), q.median, q.min,
               q.max);
  int diverged = 0;
  for (const auto& x : res.runs) diverged += x.point.diverged ? 1 : 0;
  if (a.plot) files.push_back(render_plot("track_feedforward", a.out));
  fmt::print("  wrote {}\n", fmt::join(files, ", "));
  if (diverged > 0) {
    print_error(fmt::format("{} of {} runs diverged (status column of track.csv)", diverged,
                            res.runs.size()));
    return 3;
  }
  return 0;
}

// The PID loop's margins at each temperature (pid_loop_margins), flagged below the classic
// 6 dB / 30 deg, or where the linear closed loop is unstable (a limit cycle or divergence at its
// dominant pole's frequency).
void print_margins(const TrackResult& res) {
  if (res.margins.empty()) return;
  fmt::print(
      "  PID loop about the bias (linearised plant, sampled controller; flagged below {} dB "
      "or {} deg):\n  {:>6} {:>9} {:>9} {:>9} {:>9} {:>14}\n",
      kLowGainMargin_dB, kLowPhaseMargin_deg, "T degC", "GM dB", "at Hz", "PM deg", "at Hz",
      "closed loop");
  for (const auto& k : res.margins) {
    std::string flag;
    if (!k.stable)
      flag = fmt::format("  UNSTABLE: a pole at |z| = {:.4f}, {:.0f} Hz", k.spectral_radius,
                         k.dominant_Hz);
    else if (k.gain_margin_dB < kLowGainMargin_dB)
      flag = fmt::format("  low gain margin: a larger loop gain rings at {:.0f} Hz",
                         k.phase_crossover_Hz);
    else if (k.phase_margin_deg < kLowPhaseMargin_deg)
      flag = fmt::format("  low phase margin: rings near {:.0f} Hz", k.gain_crossover_Hz);
    auto pair = [](double margin, double f, int decimals) {
      return std::isfinite(margin) ? fmt::format("{:9.{}f} {:9.0f}", margin, decimals, f)
                                   : fmt::format("{:>9} {:>9}", "none", "-");
    };
    fmt::print("  {:6.1f} {} {} {:>14}{}\n", k.temperature_C,
               pair(k.gain_margin_dB, k.phase_crossover_Hz, 2),
               pair(k.phase_margin_deg, k.gain_crossover_Hz, 1),
               fmt::format("|z| {:.4f}", k.spectral_radius), flag);
  }
}

int run_track_cmd(TrackArgs& a) {
  const Model model = load_model_args(a.model);
  a.options.apply();
  warn_temperatures(model, a.req.temperatures_C, "--temperatures");
  if (a.feedforward != "none") return run_feedforward_cmd(a, model);
  for (const CLI::Option* o : a.feedforward_only)
    if (o->count() > 0)
      throw InputError(o->get_name() +
                       " applies to the feed-forward evaluation: add --feedforward inverse (or "
                       "inverse_static), or drop " +
                       o->get_name());
  prepare_output_dir(a.out, {"track"}, model_inputs(a.model));
  const TrackResult res = run_track(model, a.req, stderr_progress("track", a.progress));
  auto files = write_report(a.out, "track", track_report(model, a.req, res));
  const std::string ex = (std::filesystem::path(a.out) / "track_example.csv").string();
  write_file_atomic(ex, timeseries_csv(res.example));
  files.push_back(ex);

  const auto& g = a.req.gains;
  fmt::print("gmasim track  model: {}\n", model_label(a.model));
  fmt::print(
      "  PID kp {} /um, ki {} /um per sample, kd {} /um per sample (per-sample gains at {} "
      "Hz);\n  controller and sensor at {} Hz, plant step {:.3g} us; current = {} A + {} A x u "
      "(the amplifier), clipped to +-{} A; sensor noise {} um RMS\n",
      g.kp, g.ki, g.kd, g.reference_rate_Hz, a.req.sample_rate_Hz, res.plant_dt_s * 1e6,
      a.req.bias_A, a.req.amplifier_A_per_unit, a.req.current_limit_A, a.req.sensor_noise_um);
  const double amp = a.req.amplifier_A_per_unit;
  fmt::print(
      "  in one unit (the coil current per um of error, through the amplifier): a kp = {:.4g} "
      "A/um, a Ki = {:.4g} A/(um s), a Kd = {:.4g} A s/um\n",
      amp * g.kp, amp * g.ki * g.reference_rate_Hz, amp * g.kd / g.reference_rate_Hz);
  fmt::print("  reference y_bias + A sin(2 pi f t); errors over the last of {} periods\n",
             a.req.periods);
  fmt::print("  {:>6} {:>7} {:>7} {:>11} {:>11} {:>8} {:>9} {:>14}\n", "T degC", "A um", "f Hz",
             "e_rms um", "e_peak um", "e/A %", "change %", "current A");
  int diverged = 0;
  for (const auto& p : res.points) {
    if (p.diverged) {
      ++diverged;
      fmt::print("  {:6.1f} {:7.2f} {:7.2f}  diverged: {}\n", p.temperature_C, p.amplitude_um,
                 p.frequency_Hz, p.error);
      continue;
    }
    fmt::print("  {:6.1f} {:7.2f} {:7.2f} {:11.4f} {:11.4f} {:8.2f} {:+9.1f} {:6.2f}..{:<6.2f}{}\n",
               p.temperature_C, p.amplitude_um, p.frequency_Hz, p.error_rms_um, p.error_peak_um,
               p.error_rms_pct, p.error_change_pct, p.current_min_A, p.current_max_A,
               std::string(p.saturated ? " saturated" : "") +
                   (p.limit_cycle ? fmt::format(" LIMIT CYCLE: the error flips sign at {:.0f} % "
                                                "of the samples (~{:.0f} Hz)",
                                                100.0 * p.error_alternation, p.error_oscillation_Hz)
                                  : std::string()));
  }
  print_margins(res);
  if (a.plot) files.push_back(render_plot("track", a.out));
  fmt::print("  {} points on {} threads in {:.2f} s\n  wrote {}\n", res.points.size(), res.threads,
             res.wall_time_s, fmt::join(files, ", "));
  if (diverged > 0) {
    for (const auto& p : res.points)
      if (p.diverged) {  // the first one's diagnosis (time, rod, quantity) on stderr too
        print_error(fmt::format(
            "{} of {} points diverged; first at {:g} degC, {:g} um, {:g} Hz: {}", diverged,
            res.points.size(), p.temperature_C, p.amplitude_um, p.frequency_Hz, p.error));
        break;
      }
    return 3;
  }
  return 0;
}

}  // namespace

Runner add_track(CLI::App& app) {
  auto own = [](CLI::App* sub, TrackArgs& a) {
    sub->add_option("--feedforward", a.feedforward,
                    "none: the PID alone (track.csv per point); inverse: the inverse-model "
                    "feed-forward evaluated against plants that differ from the model (track.csv "
                    "per run: temperature_C, frequency_Hz, amplitude_um, mismatch, controller, "
                    "rms_error_um; track_ratios.csv); inverse_static: the same with the "
                    "quasi-static inverse alone. docs/experiments.md")
        ->check(CLI::IsMember({"none", "inverse", "inverse_static"}))
        ->capture_default_str();
    a.feedforward_only.push_back(
        sub->add_option("--mismatch", a.mismatch,
                        "With --feedforward: the plants: all (M_s, k, lambda_s x (1 +- 0.1), "
                        "temperature +-10 degC: 16), none (the model itself), both (17)")
            ->capture_default_str());
    a.feedforward_only.push_back(
        sub->add_option("--controllers", a.controllers,
                        "With --feedforward: pid, pid_temperature, pid_inverse (comma-separated)")
            ->capture_default_str());
    a.feedforward_only.push_back(a.options.option("--feedforward-band"));
  };
  return add_experiment<TrackArgs>(
      app,
      {"track",
       "Closed-loop displacement tracking with the paper's discrete PID (Fig. 16): RMS and peak "
       "tracking error against temperature. Writes track.csv, track.json, track_example.csv",
       "out/track", "Also draw <out>/track.png and .svg (matplotlib)"},
      own, run_track_cmd);
}

}  // namespace gmasim::cli
