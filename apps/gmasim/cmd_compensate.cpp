// gmasim compensate: the drive that restores a target stroke at each temperature, the gain
// schedule, and tracking with the schedule as temperature feed-forward beside the plain PID.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <memory>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

struct CompensateArgs : ExperimentArgs<CompensateRequest> {
  std::string adjust = "amplitude";
  bool no_track = false;  // CompensateTracking::enabled off
};

// A steady temperature rise of the housing above this, from the schedule's largest copper loss
// over the thermal network's housing-to-ambient conductance, is warned about: it is the 10 K
// step of compensate's usual grid (judgement).
constexpr double kSteadyRiseWarn_K = 10.0;

void print_target(const CompensateArgs& a, const CompensateResult& res) {
  const auto& r = a.req;
  const std::string reference =
      fmt::format("{} A p-p from {} A at {} degC", r.reference_current_pp_A, r.current_min_A,
                  r.reference_temperature_C);
  fmt::print(
      "  target stroke {:.3f} um ({}); drive: biased sine at {} Hz, adjusting {}; |i| <= {} A\n",
      res.target_stroke_um,
      r.target_stroke_um > 0.0 ? std::string("given")
      : res.target_lowered     ? "the largest stroke every temperature reaches"
                               : reference,
      r.frequency_Hz,
      r.adjust == CompensationAdjust::Amplitude ? "the p-p (minimum held)"
      : r.adjust == CompensationAdjust::Swing   ? "the p-p about the mean"
                                                : "min and p-p together",
      r.max_current_A);
  if (res.target_lowered)
    fmt::print(
        "  the reference drive ({}) gives {:.3f} um, beyond the reach of |i| <= {} A at some "
        "temperatures (column 'reach um'); --target-stroke {:.3f} keeps it (those temperatures "
        "are then reported not reachable)\n",
        reference, res.reference.stroke_um, r.max_current_A, res.reference.stroke_um);
}

void print_schedule(const Model& m, const CompensateArgs& a, const CompensateResult& res) {
  print_target(a, res);
  fmt::print("  {:>6} {:>9} {:>9} {:>9} {:>8} {:>10} {:>11} {:>9} {:>8} {:>8} {:>5}\n", "T degC",
             "i_pp A", "i_min A", "i_max A", "i_pp/ref", "stroke um", "uncomp. um", "reach um",
             "hyst um", "P_Cu W", "sims");
  for (const auto& p : res.points) {
    if (p.diverged) {
      fmt::print("  {:6.1f}  diverged: {}\n", p.temperature_C, p.error);
      continue;
    }
    const double P = coil_copper_loss_W(m, p.current_min_A, p.current_pp_A, p.temperature_C);
    fmt::print(
        "  {:6.1f} {:9.4f} {:9.4f} {:9.4f} {:8.4f} {:10.3f} {:11.3f} {:9.3f} {:8.3f} {:8.1f} "
        "{:5d}{}\n",
        p.temperature_C, p.current_pp_A, p.current_min_A, p.current_max_A, p.gain, p.stroke_um,
        p.uncompensated_stroke_um, p.reach_stroke_um, p.hysteresis_um, P, p.evaluations,
        p.reachable ? "" : "  not reachable: the largest drive falls short");
  }
  fmt::print(
      "  i_pp/ref: the schedule's current p-p over the reference's. reach: the stroke of the "
      "largest drive |i| <= {:g} A allows. P_Cu: the coil's copper loss I_rms^2 R(T) with the "
      "coil at T ({:g} ohm at {:g} degC, thermal_network)\n",
      a.req.max_current_A, m.thermal_network.coil_resistance_ohm, m.T_ref_C);
  // The coil-heating line: the schedule holds the actuator at T, the loss heats it.
  const double G = m.thermal_network.G_housing_ambient_W_per_K;
  const ScheduleHeating heat = schedule_heating(m, res);
  const double P_max = heat.max_copper_loss_W, rise_K = heat.steady_rise_K;
  fmt::print(
      "  coil heating: the largest loss, {:.1f} W at {:g} degC, over the housing-to-ambient "
      "conductance {:g} W/K is a steady rise of {:.1f} K; `gmasim simulate --self-heating` gives "
      "its transient\n",
      P_max, heat.at_temperature_C, G, rise_K);
  if (rise_K > kSteadyRiseWarn_K)
    print_warning(fmt::format(
        "the schedule drives the coil at up to {:.0f} W of copper loss: in steady state that holds "
        "the housing {:.0f} K above ambient (thermal_network.housing_to_ambient_W_per_K = {:g}), "
        "so the actuator will not stay at the scheduled temperature without cooling; "
        "`gmasim simulate --self-heating` shows it",
        P_max, rise_K, G));
}

void print_track(const CompensatedTrack& t) {
  fmt::print(
      "\n  tracking (PID of `gmasim track`), plain vs with the schedule as temperature "
      "feed-forward\n  (i = bias + g(T) (u_PID + (r - y_bias)/K_ref); g(T): the swing schedule "
      "about the bias, K_ref = {:.4f} um/A at the reference temperature):\n",
      t.static_gain_um_per_A);
  const double T0 = t.plain.points.empty() ? 0.0 : t.plain.points.front().temperature_C;
  bool several = false;
  for (const auto& p : t.plain.points) several = several || p.temperature_C != T0;
  fmt::print("  growth: the change of e_rms from the same amplitude and frequency at {:g} degC{}\n",
             T0,
             several ? " (the first tracking temperature)"
                     : ": one tracking temperature, so no growth to show");
  fmt::print("  {:>6} {:>6} {:>6} {:>12} {:>12} {:>10} {:>10} {:>6}\n", "T degC", "A um", "f Hz",
             "e_rms PID", "e_rms FF", "growth PID", "growth FF", "g");
  for (std::size_t i = 0; i < t.plain.points.size(); ++i) {
    const auto& a = t.plain.points[i];
    const auto& b = t.compensated.points[i];
    fmt::print("  {:6.1f} {:6.2f} {:6.1f} {:9.4f} um {:9.4f} um {:+9.1f}% {:+9.1f}% {:6.3f}{}\n",
               a.temperature_C, a.amplitude_um, a.frequency_Hz, a.error_rms_um, b.error_rms_um,
               a.error_change_pct, b.error_change_pct, b.feedforward_gain,
               a.saturated || b.saturated ? " saturated" : "");
  }
}

int run_compensate_cmd(CompensateArgs& a) {
  const Model model = load_model_args(a.model);
  a.options.apply();
  warn_temperatures(model, a.req.temperatures_C, "--temperatures");
  warn_temperatures(model, {a.req.reference_temperature_C}, "--reference-temperature");
  a.req.adjust = parse_compensation_adjust(a.adjust);
  a.req.tracking.enabled = !a.no_track;
  // The tracking's numbers under compensate's own flag names, before the schedule's runs.
  if (a.req.tracking.enabled) (void)compensate_track_request(a.req);
  prepare_output_dir(a.out, {"compensate"}, model_inputs(a.model));
  const CompensateResult res =
      run_compensate(model, a.req, stderr_progress("compensate", a.progress));
  std::unique_ptr<CompensatedTrack> tr;
  if (a.req.tracking.enabled)
    tr = std::make_unique<CompensatedTrack>(
        run_compensated_track(model, a.req, stderr_progress("compensate track", a.progress)));
  auto files = write_report(a.out, "compensate", compensate_report(model, a.req, res, tr.get()));
  fmt::print("gmasim compensate  model: {}\n", model_label(a.model));
  print_schedule(model, a, res);
  if (tr) print_track(*tr);
  if (a.plot) files.push_back(render_plot("compensate", a.out));
  fmt::print("  {} temperatures in {:.2f} s on {} threads\n  wrote {}\n", res.points.size(),
             res.wall_time_s, res.threads, fmt::join(files, ", "));
  for (const auto& p : res.points)
    if (p.diverged) {
      print_error(fmt::format("diverged at {:g} degC: {}", p.temperature_C, p.error));
      return 3;
    }
  return 0;
}

}  // namespace

Runner add_compensate(CLI::App& app) {
  auto own = [](CLI::App* sub, CompensateArgs& a) {
    sub->add_option("--adjust", a.adjust,
                    "amplitude: change the p-p with the minimum held; swing: the p-p about the "
                    "mean; scale: scale the whole waveform (an amplifier gain)")
        ->check(CLI::IsMember({"amplitude", "swing", "scale"}))
        ->capture_default_str();
    sub->add_flag("--no-track", a.no_track, "Skip the tracking comparison");
    // the tracking's flags with --no-track were ignored: a usage error instead
    CLI::Option* no_track = sub->get_option("--no-track");
    for (const char* flag : {"--track-temperatures", "--track-amplitudes", "--track-frequencies",
                             "--bias", "--current-limit"})
      no_track->excludes(sub->get_option(flag));
  };
  return add_experiment<CompensateArgs>(
      app,
      {"compensate",
       "Temperature compensation: the drive current that restores a target stroke at each "
       "temperature (gain schedule), and PID tracking with that schedule as feed-forward beside "
       "the plain PID. Writes compensate.csv (schedule), compensate_track.csv, compensate.json",
       "out/compensate", "Also draw compensate.png (matplotlib)"},
      own, run_compensate_cmd);
}

}  // namespace gmasim::cli
