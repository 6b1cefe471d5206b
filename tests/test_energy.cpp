// The energy ledgers (gmasim/model/energy.hpp, docs/model.md "Energy ledgers"): both close per
// cycle, each term comes from its own law (perturbing one breaks the balance), a closed-form
// eddy-current loss, the JA energy split and its positive dissipation, the printed reading's
// violation, and the time step's observed order.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>

#include "builtin_models.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/energy.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/jiles_atherton.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;

namespace {

using gmasim_test::mdma;

// The automatic step of a periodic run (docs/model.md, "Time step"): T/2000, at most 10 us.
int steps_per_period(double f_Hz) {
  return std::max(2000, static_cast<int>(std::lround(1.0 / (f_Hz * kMaxDt_s))));
}

// Runs `steps` steps of h under waveform w, booking every step, and returns the ledgers
// between the snapshots after steps `from` and `to`.
EnergyBalance ledger_of(const Model& m, double T_C, const Waveform& w, double h, long from,
                        long to) {
  const Conditions c = make_conditions(m, T_C);
  State s = make_state(m, c, w.current_at(0.0));
  s.energy.enabled = true;
  EnergySnapshot a = energy_snapshot(m, c, s);
  for (long k = 1; k <= to; ++k) {
    step(m, c, s, {w.current_at(static_cast<double>(k) * h), h});
    s.t_s = static_cast<double>(k) * h;
    if (k == from) a = energy_snapshot(m, c, s);
  }
  return energy_balance(a, energy_snapshot(m, c, s));
}

// The same over a biased sine (Fig. 11) of `spp` steps per period.
EnergyBalance ledger(const Model& m, double T_C, double pp_A, double f_Hz, long from, long to,
                     int spp) {
  return ledger_of(m, T_C, biased_sine(pp_A, f_Hz), 1.0 / (f_Hz * spp), from, to);
}

EnergyBalance last_cycle(const Model& m, double T_C, double pp_A, double f_Hz) {
  const int spp = steps_per_period(f_Hz);
  return ledger(m, T_C, pp_A, f_Hz, 2L * spp, 3L * spp, spp);
}

}  // namespace

// Over the model check's grid, in the consistent reading, both ledgers close per cycle to
// <= 1e-6 of their input (observed: <= 4e-9, the mechanical ledger's quadrature at 10 Hz); the
// coupling the one-way model does not draw from the coil stays near 1 % of the input.
TEST(Energy, BothLedgersClosePerCycleInTheConsistentReading) {
  for (double f : {10.0, 400.0})
    for (double T : {20.0, 70.0, 150.0})
      for (double I : {6.0, 12.0}) {
        const EnergyBalance e = last_cycle(mdma(), T, I, f);
        EXPECT_LE(e.magnetic_residual_rel, 1e-6) << f << " Hz " << T << " degC " << I << " A";
        EXPECT_LE(e.mechanical_residual_rel, 1e-6) << f << " Hz " << T << " degC " << I << " A";
        EXPECT_GT(e.hysteresis_J, 0.0);
        EXPECT_GT(e.eddy_J, 0.0);
        EXPECT_GT(e.damping_J, 0.0);
        EXPECT_LT(std::fabs(e.coupling_fraction), 0.03);
        // Over a whole period the stored energies return (to the period's transient).
        const double in = e.coil_J + e.magnet_J;
        EXPECT_LT(std::fabs(e.d_material_J), 1e-3 * in);
      }
}

// The magnetic ledger closes to its quadrature and Newton tolerances whatever the step: the
// material's work over a step is the trapezoid the circuit delivers, and the dissipation is
// integrated along the path on which that trapezoid is exact (physics::ja_step_dissipation).
// Observed: 1e-9 of the input or below at 1000 to 4000 steps per period.
TEST(Energy, MagneticLedgerClosesAtEveryStepSize) {
  for (int spp : {1000, 2000, 4000}) {
    const EnergyBalance e = ledger(mdma(), 20.0, 12.0, 400.0, 2L * spp, 3L * spp, spp);
    EXPECT_LT(e.magnetic_residual_rel, 1e-8) << spp << " steps per period";
  }
}

// No term is the residual of the others: scaling any one term by 1.01 puts the relative
// residual above 1e-3. A term moves the residual by 1e-3 only where it is >= 10 % of the
// ledger's input, so three windows together cover every term: the rising half of a period
// (the stored energies change), a whole period (the losses are the input) and a quarter
// period at 3 kHz, near the rods' modes (their kinetic energy swings).
TEST(Energy, EveryTermIsBookedFromItsOwnLaw) {
  using Term = std::function<double&(EnergyBalance&)>;
  struct Named {
    const char* name;
    bool magnetic;
    Term term;
  };
  const std::vector<Named> terms = {
      {"coil", true, [](EnergyBalance& x) -> double& { return x.coil_J; }},
      {"magnet", true, [](EnergyBalance& x) -> double& { return x.magnet_J; }},
      {"circuit", true, [](EnergyBalance& x) -> double& { return x.d_circuit_J; }},
      {"series", true, [](EnergyBalance& x) -> double& { return x.d_series_J; }},
      {"material", true, [](EnergyBalance& x) -> double& { return x.d_material_J; }},
      {"hysteresis", true, [](EnergyBalance& x) -> double& { return x.hysteresis_J; }},
      {"eddy", true, [](EnergyBalance& x) -> double& { return x.eddy_J; }},
      {"force", false, [](EnergyBalance& x) -> double& { return x.force_work_J; }},
      {"stiffness", false, [](EnergyBalance& x) -> double& { return x.stiffness_work_J; }},
      {"kinetic", false, [](EnergyBalance& x) -> double& { return x.d_kinetic_J; }},
      {"elastic", false, [](EnergyBalance& x) -> double& { return x.d_elastic_J; }},
      {"damping", false, [](EnergyBalance& x) -> double& { return x.damping_J; }}};
  const int spp = steps_per_period(100.0);
  const std::vector<std::pair<const char*, EnergyBalance>> windows = {
      {"rising half period", ledger(mdma(), 20.0, 12.0, 100.0, 2L * spp, 2L * spp + spp / 2, spp)},
      {"whole period", ledger(mdma(), 20.0, 12.0, 100.0, 2L * spp, 3L * spp, spp)},
      // 6 kHz: the rods' kinetic energy is 22 % of the mechanical input over the quarter
      // period on issue 37's model (3 kHz gave 5 %, below the 10 % this test needs to see it)
      {"quarter period at 6 kHz", ledger(mdma(), 20.0, 2.0, 6000.0, 8000, 8500, 2000)}};
  std::map<std::string, int> checked;
  for (const auto& [where, e] : windows) {
    ASSERT_LT(e.magnetic_residual_rel, 1e-6) << where;
    ASSERT_LT(e.mechanical_residual_rel, 1e-6) << where;
    for (const auto& t : terms) {
      EnergyBalance p = e;
      const double in = t.magnetic ? p.coil_J + p.magnet_J : p.force_work_J + p.stiffness_work_J;
      if (std::fabs(t.term(p)) < 0.1 * std::fabs(in)) continue;
      t.term(p) *= 1.01;
      const double res =
          t.magnetic ? (p.coil_J + p.magnet_J) - (p.d_circuit_J + p.d_series_J + p.d_material_J +
                                                  p.hysteresis_J + p.eddy_J)
                     : (p.force_work_J + p.stiffness_work_J) -
                           (p.d_kinetic_J + p.d_elastic_J + p.damping_J);
      EXPECT_GT(std::fabs(res) / std::fabs(in), 1e-3) << t.name << " over the " << where;
      ++checked[t.name];
    }
  }
  for (const auto& t : terms) EXPECT_GT(checked[t.name], 0) << t.name << " never significant";
}

// A closed-form case: a linear rod, no hysteresis, eddy currents only. With JA reduced to its
// anhysteretic slope (c -> 1, k -> 0, alpha = 0, a small field: M = chi H with chi = M_s/(3a))
// the rod branch is linear, B = mu H, mu = mu0 (1 + chi), and the one-loop circuit of a coil
// with N turns, the fixed reluctance R around it and the rod (U = l H_c + R_s phi,
// H_c = H + kappa dB/dt) gives for i = I sin(w t):
//   H = N I / (l (1 + j w kappa mu) + (R + R_s) mu A),   eddy loss per period
//   E = pi/w * l A kappa mu^2 w^2 |H|^2 (= the coil's work per period: nothing else loses).
TEST(Energy, EddyLossOfALinearRodMatchesTheClosedForm) {
  ModelSpec spec = load_model_spec(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod.toml");
  for (const auto& [k, v] : std::vector<std::pair<std::string, double>>{{"rod.ja.c0", 0.999999},
                                                                        {"rod.ja.k0_A_per_m", 1e-3},
                                                                        {"rod.ja.alpha0", 0.0},
                                                                        {"rod.ja.a0_A_per_m", 1e7},
                                                                        {"preload.force_N", 1e-6}})
    spec.set(k, v);
  const Model m = compile(spec);
  ASSERT_EQ(m.rods.size(), 1u);
  const Conditions c = make_conditions(m, m.T_ref_C);
  const auto& rc = c.rods[0];
  // The one-loop circuit's reluctance outside the rod, from the netlist: the rod branch sees
  // the rest of the circuit as a Thevenin reluctance; probe it with two rod reluctances.
  CircuitWorkspace ws;
  ws.resize(m.circuit);
  auto rod_flux = [&](double R_rod) {
    const std::vector<double> R = {R_rod};
    EXPECT_TRUE(solve_circuit(m.circuit, R, 1.0, 0.0, ws));
    return ws.phi[static_cast<std::size_t>(m.circuit.rod_branch[0])];
  };
  const double R1 = 1e7, R2 = 2e7, p1 = rod_flux(R1), p2 = rod_flux(R2);
  const double S = (R2 * p2 - R1 * p1) / (p1 - p2);  // phi = b/(R_rod + S)
  const double b = p1 * (R1 + S);                    // At per A
  const double chi = rc.MsT_mag / (3.0 * rc.ja.a_A_per_m);
  const double mu = physics::kMu0 * (1.0 + chi);
  const double l = rc.length_m, A = rc.area_m2, kappa = rc.eddy_geometry_s_m_per_H;
  const double f = 200.0, w = 2.0 * physics::kPi * f, I = 1e-2;
  const std::complex<double> H =
      b * I /
      (l * std::complex<double>(1.0, w * kappa * mu) + (S + rc.series_reluctance_per_H) * mu * A);
  const double E = physics::kPi / w * l * A * kappa * mu * mu * w * w * std::norm(H);
  // A sine about 0 A (the template has no magnet), small enough for M = chi H.
  const int spp = 4000, periods = 40;
  State s = make_state(m, c, 0.0);
  s.energy.enabled = true;
  const double h = 1.0 / (f * spp);
  EnergySnapshot a;
  for (long k = 1; k <= static_cast<long>(periods) * spp; ++k) {
    const double t = static_cast<double>(k) * h;
    step(m, c, s, {I * std::sin(w * t), h});
    s.t_s = t;
    if (k == static_cast<long>(periods - 1) * spp) a = energy_snapshot(m, c, s);
  }
  const EnergyBalance e = energy_balance(a, energy_snapshot(m, c, s));
  EXPECT_NEAR(e.eddy_J, E, 1e-4 * E);
  EXPECT_NEAR(e.coil_J, E, 1e-4 * E);
  EXPECT_LT(std::fabs(e.hysteresis_J), 1e-5 * E);
}

// Eq. (9)'s energy split (physics::ja_stored_energy_density, ja_step_dissipation): along a
// loop stepped by ja_step, mu0 int H dM (each step's trapezoid) = Phi(end) - Phi(start) + the
// steps' dissipations, each >= 0 (to rounding where M_irr is pinned); over the closed loop
// the dissipation is the loop's area.
TEST(Energy, JilesAthertonSplitClosesAndDissipatesPositively) {
  const Conditions c = make_conditions(mdma(), 20.0);
  const auto& rc = c.rods[0];
  const auto& p = rc.ja;
  const double Ms = rc.MsT_mag;
  auto phi = [&](double H, double M, double Mirr) {
    return physics::ja_stored_energy_density(
        H, M, Mirr, physics::anhysteretic_field(Mirr, Ms, p.a_A_per_m), Ms, p);
  };
  double H = 0.0, Mirr = 0.0, M = 0.0, work = 0.0, diss = 0.0, phi0 = 0.0;
  const int n = 4000;  // H = 4e4 sin(pi k / n): +peak at n/2, a whole loop to 5n/2
  for (int k = 1; k <= 5 * n / 2; ++k) {
    const double H1 = 4e4 * std::sin(physics::kPi * k / n);
    if (k == n / 2 + 1) phi0 = phi(H, M, Mirr);
    const double M0 = M;
    physics::ja_step(H, H1, Ms, p, Mirr, M);
    const double d = physics::ja_step_dissipation(H, M0, H1, M, Ms, p);
    const double w = physics::kMu0 * 0.5 * (H + H1) * (M - M0);
    EXPECT_GE(d, -1e-5 * std::fabs(w) - 1e-12) << k;  // pinned steps: observed -3e-7 |w|
    if (k > n / 2) {
      work += w;
      diss += d;
    }
    H = H1;
  }
  const double dphi = phi(H, M, Mirr) - phi0;
  EXPECT_GT(diss, 0.0);
  EXPECT_NEAR(work, dphi + diss, 1e-8 * diss);
  EXPECT_LT(std::fabs(dphi), 1e-2 * diss);  // the loop closes: its area is the dissipation
}

// The printed reading cannot close: its rod branches carry phi = U mu_G A / l while the
// material's state holds B = mu0 (H + M), so the circuit delivers another energy than the
// material absorbs (docs/model.md, "Energy ledgers").
TEST(Energy, PrintedReadingViolatesTheMagneticLedger) {
  const Model m = load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml");
  const int spp = steps_per_period(10.0);
  const EnergyBalance e = ledger(m, 20.0, 8.0, 10.0, 2L * spp, 3L * spp, spp);
  EXPECT_GT(e.magnetic_residual_rel, 1e-2);
  EXPECT_LT(e.mechanical_residual_rel, 1e-6);  // the mechanics close in either reading
}

// Issue 18 item 6: the observed order of stroke and hysteresis at 8 A, 400 Hz, 70 degC with
// dt = 20 / 10 / 5 / 2.5 us is second order (the trapezoidal eddy field, eq. 9's update with
// M_an linear in the path, the mid-step stiffness, and the cubic refinement of the metrics).
TEST(Numerics, StrokeAndHysteresisConvergeAtSecondOrder) {
  SimulationSettings s;
  s.temperature_C = 70.0;
  s.waveform = biased_sine(8.0, 400.0);
  s.periods = 3;
  std::vector<double> stroke, hyst;
  for (double dt : {20e-6, 10e-6, 5e-6, 2.5e-6}) {
    s.dt_s = dt;
    const Result r = simulate(mdma(), s);
    ASSERT_FALSE(r.diverged) << r.error;
    stroke.push_back(r.metrics.stroke_um);
    hyst.push_back(r.metrics.hysteresis_um);
  }
  for (const auto* v : {&stroke, &hyst})
    for (std::size_t k = 0; k + 2 < v->size(); ++k) {
      const double p = std::log2(((*v)[k] - (*v)[k + 1]) / ((*v)[k + 1] - (*v)[k + 2]));
      EXPECT_GE(p, 1.7) << (v == &stroke ? "stroke" : "hysteresis") << " at " << k;
      EXPECT_LE(p, 2.3) << (v == &stroke ? "stroke" : "hysteresis") << " at " << k;
    }
}

// docs/model.md's time-step table is the output of `gmasim model check --dt-table` on the
// built-in model (between its markers): regenerate it when the model or the step change.
TEST(DocsTimeStepTable, IsCurrent) {
  std::ifstream in(std::string(GMASIM_SOURCE_DIR) + "/docs/model.md");
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string a = "<!-- dt-table: gmasim model check --dt-table -->\n",
                    b = "<!-- end dt-table -->";
  const auto i = doc.find(a), j = doc.find(b);
  ASSERT_NE(i, std::string::npos);
  ASSERT_NE(j, std::string::npos);
  EXPECT_EQ(doc.substr(i + a.size(), j - i - a.size()), time_step_table_markdown(mdma()))
      << "regenerate: gmasim model check --dt-table, between the markers of docs/model.md";
}
