// The magnetic-state check of `gmasim model check` (simulate.hpp, MagneticStateCheck).
#include <fmt/format.h>

#include <cmath>

#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

MagneticStateCheck check_magnetic_state(const Model& m) {
  MagneticStateCheck out;
  for (double T : {20.0, 70.0, 150.0})
    for (double I : {6.0, 12.0})
      for (double f : {10.0, 400.0}) {
        SimulationSettings s;
        s.temperature_C = T;
        s.waveform = biased_sine(I, f);
        s.periods = 2;
        s.energy_ledger = true;
        const Conditions c = make_conditions(m, T);
        const Result r = simulate(m, s);
        ++out.runs;
        const auto where = [&](const std::string& rod, double t) {
          return fmt::format("{}, {:g} degC, {:g} A, {:g} Hz, t = {:.6f} s", rod, T, I, f, t);
        };
        if (r.has_energy) {  // the worse ledger over the last period (gmasim/model/energy.hpp)
          const double res =
              std::max(r.energy.magnetic_residual_rel, r.energy.mechanical_residual_rel);
          if (res > out.energy_residual_rel || !std::isfinite(res)) {
            out.energy_residual_rel = res;
            out.where_energy = fmt::format(
                "{:g} degC, {:g} A, {:g} Hz ({} ledger)", T, I, f,
                r.energy.magnetic_residual_rel >= r.energy.mechanical_residual_rel ? "magnetic"
                                                                                   : "mechanical");
          }
          out.max_coupling_fraction =
              std::max(out.max_coupling_fraction, std::fabs(r.energy.coupling_fraction));
        }
        const auto& t = r.series.column("t_s");
        const auto& B = r.series.column("B_T");
        for (double b : B) out.max_B_sensor_T = std::max(out.max_B_sensor_T, std::fabs(b));
        for (std::size_t i = 0; i < m.rods.size(); ++i) {
          const std::string& name = m.rods[i].name;
          const auto& Br = r.series.column(name + "_B_T");
          const auto& H = r.series.column(name + "_H_A_per_m");
          const auto& M = r.series.column(name + "_M_A_per_m");
          const double scale = physics::kMu0 * c.rods[i].MsT_mag;
          for (std::size_t k = 0; k < Br.size(); ++k) {
            if (std::fabs(Br[k]) > out.max_B_rod_T) {
              out.max_B_rod_T = std::fabs(Br[k]);
              out.where_B_rod = where(name, t[k]);
            }
            const double d = std::fabs(Br[k] - physics::flux_density(H[k], M[k]));
            if (d > out.max_inconsistency_T) {
              out.max_inconsistency_T = d;
              out.max_inconsistency_rel = d / (scale + physics::kMu0 * std::fabs(H[k]));
              out.where_inconsistency = where(name, t[k]);
            }
          }
        }
        if (r.diverged && out.divergence.empty())
          out.divergence = fmt::format("{:g} degC, {:g} A, {:g} Hz: {}", T, I, f, r.error);
      }
  return out;
}

}  // namespace gmasim
