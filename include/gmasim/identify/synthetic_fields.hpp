// The request table of `gmasim identify synthesize` (SyntheticRequest,
// gmasim/identify/identify.hpp; the machinery: gmasim/experiments/request_table.hpp): its CLI
// options are generated from it, with the defaults of the struct's initialisers. The choices
// (--drive, --response, --offset,
// --initial-state) and --no-flux (the inverse of with_flux) are the command's own options
// (apps/gmasim/cmd_identify.cpp). synthesize_measurements checks every row's rule after its own
// checks, whose messages stay; the rules here are no stricter than those.
#pragma once

#include <tuple>

#include "gmasim/experiments/request_table.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim::fields {

template <>
struct RequestFields<SyntheticRequest> {
  using R = SyntheticRequest;
  static constexpr std::string_view experiment = "identify synthesize";
  static constexpr auto rows = std::tuple{
      field<R>("temperatures_C", "degC", finite(), "--temperatures", "Temperatures [degC]", Cli,
               GMASIM_REF(R, temperatures_C)),
      field<R>("currents_pp_A", "A", in(0.0, 2.0 * kMaxCurrent_A), "--currents",
               "Current peak-to-peak values [A]", Cli, GMASIM_REF(R, currents_pp_A)),
      field<R>("frequencies_Hz", "Hz", in(0.0, kMaxFrequency_Hz), "--frequencies",
               "Frequencies [Hz]", Cli, GMASIM_REF(R, frequencies_Hz)),
      field<R>("current_min_A", "A", in(-kMaxCurrent_A, kMaxCurrent_A), "--current-min",
               "Current minimum [A] (Fig. 11)", Cli, GMASIM_REF(R, current_min_A)),
      field<R>("periods", "-", in(1.0, kMaxPeriods), "--periods",
               "Record length [periods]; the first is not compared", Cli, GMASIM_REF(R, periods)),
      field<R>("samples_per_period", "-", in(8.0, kMaxRecordedRows), "--samples-per-period",
               "Samples per period", Cli, GMASIM_REF(R, samples_per_period)),
      field<R>("noise_pct", "%", in(0.0, 100.0), "--noise",
               "Displacement noise: Gaussian sigma in % of each condition's p-p", Cli,
               GMASIM_REF(R, noise_pct)),
      field<R>("flux_noise_pct", "%", in(0.0, 100.0), "--flux-noise",
               "Flux noise: sigma in % of p-p", Cli, GMASIM_REF(R, flux_noise_pct)),
      field<R>("seed", "-", any(), "--seed", "Noise seed", Cli, GMASIM_REF(R, seed)),
      field<R>("dt_s", "s", in(0.0, kMaxStepDt_s), "--dt",
               "Simulation time step [s]; 0: period / steps", Cli, GMASIM_REF(R, objective.dt_s)),
      field<R>("steps_per_period", "-", in(8.0, 1e6), "--steps-per-period",
               "Time steps per period (use the same value for identify)", Cli,
               GMASIM_REF(R, objective.steps_per_period)),
      field<R>("quasi_static", "-", any(), "--quasi-static",
               "Quasi-static records: the sine's samples as equilibria, no t_s column (one "
               "record per temperature x current; --frequencies is ignored)",
               Cli, GMASIM_REF(R, quasi_static)),
      field<R>("rod", "-", any(), "--rod", "Rod of the field / strain columns (default: the first)",
               Cli, GMASIM_REF(R, rod)),
      field<R>("response_offset", "um or ppm", in(-1e6, 1e6), "--response-offset",
               "Constant added to the response with --offset fitted [um or ppm]", Cli,
               GMASIM_REF(R, response_offset)),
      field<R>("precycles", "-", in(0.0, static_cast<double>(kMaxPrecycles)), "--precycles",
               "Pre-cycles written into each record (then every period is compared)", Cli,
               GMASIM_REF(R, precycles)),
  };
};

}  // namespace gmasim::fields
