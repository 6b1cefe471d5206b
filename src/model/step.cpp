// The coupled step: circuit (eq. 2-3, 23) -> eddy lag (eq. 7) -> JA (eq. 9) -> Delta-E,
// strain and force (eq. 11-14) -> mechanics (eq. 15-18), as the named stages of
// gmasim/model/step_stages.hpp. See docs/model.md, "The step".
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <string_view>

#include "gmasim/errors.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/rod_laws.hpp"
#include "gmasim/model/step_stages.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"

namespace gmasim {
namespace {

using namespace physics;

// The guard's failure, out of line: no string is made on the step's path (a literal name such
// as "sensor mount" made a std::string every step where check() was not inlined).
[[noreturn, gnu::cold, gnu::noinline]] void diverged(double value, double t, std::string_view rod,
                                                     const char* quantity, double limit) {
  throw DivergenceError(t, std::string(rod), quantity, value,
                        std::isfinite(value) ? fmt::format("|value| exceeds {:g}", limit)
                                             : std::string("not finite"));
}

inline void check(double value, double t, std::string_view rod, const char* quantity,
                  double limit) {
  if (std::fabs(value) <= limit) [[likely]]
    return;  // false for NaN
  diverged(value, t, rod, quantity, limit);
}

// Eq. (20): the stack's displacement, the sum of the rods' x.
double stack_displacement_m(const State& s) {
  double y = 0.0;
  for (const auto& r : s.rods) y += r.x_m;
  return y;
}

void finish_outputs(const Model& m, const Conditions& c, State& s) {
  double y = stack_displacement_m(s);
  s.y_stack_m = y;             // eq. (20)
  if (m.sensor_mount.enabled)  // the probe: its deflection u = q - z, or itself on the output
    y = m.options.sensor_mount_base == SensorMountBase::Output ? s.z_m : y + (s.z_m - s.q_m);
  if (m.options.thermal_expansion_in_output) y += c.thermal_expansion_m;
  s.y_m = y;
  double phi = 0.0, area = 0.0;
  for (int b : m.flux_sensor_branches) {
    const int rod = m.circuit.branches[static_cast<std::size_t>(b)].rod;
    phi += s.circuit.phi[static_cast<std::size_t>(b)];
    area += c.rods[static_cast<std::size_t>(rod)].area_m2;
  }
  s.B_T = phi / area;
  for (std::size_t i = 0; i < s.rods.size(); ++i)
    s.rods[i].B_T = s.rods[i].phi_Wb * c.rods[i].inv_area_per_m2;
}

// The housing's recoil q = p / M (model.hpp, SensorMountModel): p = sum (m/2 + m_lr) x.
double recoil_m(const Model& m, const Conditions& c, const State& s) {
  double p = 0.0;
  for (std::size_t i = 0; i < s.rods.size(); ++i) p += c.rods[i].momentum_mass_kg * s.rods[i].x_m;
  return p / m.sensor_mount.actuator_mass_kg;
}

// The base of the sensor mount's bracket (options.sensor_mount_base): the housing's recoil, or
// the output y_stack = sum x (eq. 20).
double mount_base_m(const Model& m, const Conditions& c, const State& s) {
  return m.options.sensor_mount_base == SensorMountBase::Recoil ? recoil_m(m, c, s)
                                                                : stack_displacement_m(s);
}

// The sensor mount (model.hpp, SensorMountModel): with w = u - q, m w'' + c w' + k w =
// -(c q' + k q), so z = -w = q - u solves m z'' + c (z' - q') + k (z - q) = 0 with q linear over
// the step: linear forcing, and oscillator_step is exact.
void advance_sensor_mount(const SensorMountModel& o, double q0_m, double q1_m, double h_s,
                          State& s) {
  base_excited_step(o.mass_kg, 1.0 / o.mass_kg, o.damping_N_s_per_m, o.stiffness_N_per_m, q0_m,
                    q1_m, h_s, s.z_m, s.z_v_m_per_s, s.mount_decay);
  s.q_m = q1_m;
}

// The consistent state's end of step for one rod: the law's last Newton trial at H1 (its flux
// density B1), the eddy field of eq. (7) (trapezoid; at rest H_c = H), the histories of the
// first guess and the slope mu_r = 1 + dM/dH.
// g = 2 kappa / h (eddy_static_field_trapezoid).
template <class Law>
void commit_rod(const RodConditions& rc, RodState& r, const typename Law::JointTrial& trial,
                double H1, double B0, double B1, bool quasi_static, double g) {
  r.M_prev2_A_per_m = r.M_prev_A_per_m;
  r.M_prev_A_per_m = r.M_A_per_m;
  Law::commit_trial(rc, r, trial);
  r.Hc_A_per_m =
      quasi_static ? H1 : eddy_static_field_trapezoid(r.H_A_per_m, H1, r.Hc_A_per_m, B0, B1, g);
  r.H_prev2_A_per_m = r.H_prev_A_per_m;
  r.H_prev_A_per_m = r.H_A_per_m;
  r.H_A_per_m = H1;
  r.mu_r = 1.0 + trial.dM_dH;
  r.tau_s = kMu0 * r.mu_r * rc.eddy_geometry_s_m_per_H;
  r.phi_Wb = B1 * rc.area_m2;
}

// After a full (undamped) correction the iterate solves the circuit linearised at the last
// iterate exactly: the rods' branches and the network are linear in (H, M, phi), and M* is on
// the law's tangent. The next correction is then the circuit's response to the laws' own steps
// M_next - M* alone (law_steps: the sum of their sizes): at fixed flux a rod's field moves by
// -(M_next - M*) / mu_r, and the passive network's response adds at most as much, so
// |dH| <= 2 law_steps. Where every law holds and that bound is within a quarter of every rod's
// field tolerance, the iterate has converged without the confirming solve (one solve a step).
inline bool next_correction_within_tolerance(std::size_t n, double law_steps,
                                             const std::array<double, 8>& H) {
  for (std::size_t i = 0; i < n; ++i)
    if (!(2.0 * law_steps <= 0.25 * (1e-7 + 1e-11 * std::fabs(H[i])))) return false;
  return true;
}

// A rod's branch U = R_eff phi + U_off linearised at the Newton iterate (H*, M_next) of
// consistent_magnetic_update, with B* = mu0 (H* + M_next), inv_mud = 1/(mu0 mu_r) and the eddy
// field's g = 2 kappa / h, B0 and e0 = H_c - H at the step's start: R_eff and the MMF -U_off.
inline void linearise_rod_branch(const RodConditions& rc, double H, double Bs, double inv_mud,
                                 double g, double B0, double e0, double& R_eff, double& mmf) {
  R_eff = rc.length_over_area_per_m * (inv_mud + g) + rc.series_reluctance_per_H;
  mmf = -rc.length_m * (H - Bs * inv_mud - g * B0 - e0);
}

// Consistent magnetic state (docs/model.md, "Magnetic state"). At the end of the step every
// rod i satisfies, with its own JA state (eq. 9) and the circuit (eq. 23):
//   phi_i = A_i B_i,  B_i = mu0 (H_i + M_i(H_i)),  U_i = l_i H_c,i + R_s,i phi_i  (eq. 7, first
//   line, with k_f's series reluctance R_s: physics::series_reluctance)
//   H_c,i = H_i + kappa_i dB_i/dt  (eq. 7's eddy field, trapezoidal over the step)
// Newton's method on the rods' fields and magnetisations jointly: at the iterate (H*, M*) each
// rod's law is evaluated once (Law::joint_trial: no inner solve), its magnetisation corrected
// by the law's own Newton step to M_next and linearised (slope dM/dH) into a branch
// U = R_eff phi + U_off, the circuit is solved with R_eff and the MMF -U_off, H* moves to the
// field that flux implies and M* to M_next + dM/dH dH (the law's tangent). Quadratic; damped
// after 8 iterations (the JA slope jumps where M_irr starts or stops moving). Converged when
// every field correction is below 1e-7 A/m + 1e-11 |H| and every law holds at its iterate
// (JA: |M* - F(M*)| <= 1e-12 M_s^T); the last evaluation, which the solve used, is committed as
// it is (Law::commit_trial). First guess: H and M extrapolated quadratically from the last
// three steps (H = 3 H_n - 3 H_n-1 + H_n-2), so that one correction usually converges (two
// solves and two law evaluations a step).
// quasi_static drops the eddy term (the at-rest ramp of make_state) and starts at H_n.
// N: the number of rods fixed at compile time (3, the built-in actuator: its loops unrolled), or 0
// for any (consistent_magnetic_update chooses); the same operations in the same order either way.
template <class Law, std::size_t N>
void consistent_magnetic_update_n(const Model& m, const Conditions& c, State& s, double current_A,
                                  double pm_scale, double h_s, bool quasi_static, double t1) {
  const std::size_t n = N > 0 ? N : s.rods.size();
  std::array<double, 8> H, Mg, inv_mud, B0, e0, g, Bs;  // set before read (no fill)
  std::array<typename Law::MoveStart, 8> start;
  std::array<typename Law::JointTrial, 8> trial;
  const double two_over_h = 2.0 / h_s;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = s.rods[i];
    const auto& rc = c.rods[i];
    start[i] = Law::begin_move(rc, r);
    B0[i] = flux_density(r.H_A_per_m, r.M_A_per_m);
    if (quasi_static) {
      H[i] = r.H_A_per_m;
      Mg[i] = r.M_A_per_m;
      e0[i] = g[i] = 0.0;  // no eddy term at rest
    } else {
      e0[i] = r.Hc_A_per_m - r.H_A_per_m;
      g[i] = rc.eddy_geometry_s_m_per_H * two_over_h;
      H[i] = 3.0 * (r.H_A_per_m - r.H_prev_A_per_m) + r.H_prev2_A_per_m;
      Mg[i] = 3.0 * (r.M_A_per_m - r.M_prev_A_per_m) + r.M_prev2_A_per_m;
    }
  }
  constexpr int kMaxIterations = 60;
  for (int it = 0;; ++it) {
    bool laws_hold = true;
    double law_steps = 0.0;  // sum over the rods of |M_next - M*|, the laws' own Newton steps
    for (std::size_t i = 0; i < n; ++i) {
      Law::joint_trial(c.rods[i], s.rods[i], start[i], H[i], Mg[i], trial[i]);
      laws_hold = laws_hold && trial[i].converged;
      law_steps += std::fabs(trial[i].M_next - Mg[i]);
    }
    if (it >= 1 && it <= 8 && laws_hold && next_correction_within_tolerance(n, law_steps, H))
      break;  // the iterate has converged without the confirming solve (nor its linearisation)
    for (std::size_t i = 0; i < n; ++i) {  // each rod's branch, linearised at the iterate
      Bs[i] = flux_density(H[i], trial[i].M_next);
      inv_mud[i] = trial[i].inv_mu_r * (1.0 / kMu0);
      linearise_rod_branch(c.rods[i], H[i], Bs[i], inv_mud[i], g[i], B0[i], e0[i],
                           s.rod_reluctance[i], s.circuit.rod_extra_mmf[i]);
    }
    ++s.newton_solves;
    if (!solve_circuit(m.circuit, s.rod_reluctance, current_A, pm_scale, s.circuit,
                       s.energy.enabled))
      throw DivergenceError(t1, "", "nodal matrix of the circuit", 0.0, "not positive definite");
    double worst = 0.0;
    int worst_rod = 0;
    bool converged = true;
    std::array<double, 8> dH;  // written for rods 0..n-1 below
    for (std::size_t i = 0; i < n; ++i) {
      const double phi = s.circuit.phi[static_cast<std::size_t>(m.circuit.rod_branch[i])];
      dH[i] = (phi * c.rods[i].inv_area_per_m2 - Bs[i]) * inv_mud[i];
      // The rod's Newton step: its field's and its law's (A/m both); NaN propagates.
      const double dM = std::fabs(trial[i].M_next - Mg[i]);
      const double step = dM <= std::fabs(dH[i]) ? std::fabs(dH[i]) : dM;
      if (!(step <= worst)) {
        worst = step;
        worst_rod = static_cast<int>(i);
      }
      if (!(std::fabs(dH[i]) <= 1e-7 + 1e-11 * std::fabs(H[i])) || !trial[i].converged)
        converged = false;
    }
    if (converged) break;  // the last iterate: its correction is below the tolerance
    if (it == kMaxIterations || !std::isfinite(worst)) {
      if (worst <= 1e-3) break;  // 1 mA/m: far below anything the outputs resolve
      throw DivergenceError(t1, m.rods[static_cast<std::size_t>(worst_rod)].name,
                            "field H [A/m] of the consistent magnetic state", worst,
                            "Newton's method did not converge");
    }
    const double damping = it < 8 ? 1.0 : 0.5;
    for (std::size_t i = 0; i < n; ++i) {
      H[i] += damping * dH[i];
      Mg[i] = trial[i].M_next + trial[i].dM_dH * damping * dH[i];  // on the law's tangent
    }
  }
  for (std::size_t i = 0; i < n; ++i) {  // commit the end-of-step state: the last iterate
    commit_rod<Law>(c.rods[i], s.rods[i], trial[i], H[i], B0[i], flux_density(H[i], trial[i].M),
                    quasi_static, g[i]);
    s.circuit.phi[static_cast<std::size_t>(m.circuit.rod_branch[i])] = s.rods[i].phi_Wb;
  }
}
template <class Law>
void consistent_magnetic_update(const Model& m, const Conditions& c, State& s, double current_A,
                                double pm_scale, double h_s, bool quasi_static, double t1) {
  if (s.rods.size() == 3)
    consistent_magnetic_update_n<Law, 3>(m, c, s, current_A, pm_scale, h_s, quasi_static, t1);
  else
    consistent_magnetic_update_n<Law, 0>(m, c, s, current_A, pm_scale, h_s, quasi_static, t1);
}

// The magnetic state at rest (no eddy lag: eq. 7 with dB/dt = 0) moved along its
// hysteresis loop to the MMF of current_A and the magnets at pm_scale: one increment of
// make_state's ramp and of quasi_static_step.
template <class Law>
void quasi_static_magnetic_update(const Model& m, const Conditions& c, State& s, double current_A,
                                  double pm_scale, double t) {
  const std::size_t n = s.rods.size();
  if (m.options.magnetic_state == MagneticState::Consistent) {
    consistent_magnetic_update<Law>(m, c, s, current_A, pm_scale, 1.0, true, t);
    return;
  }
  for (std::size_t i = 0; i < n; ++i)
    s.rod_reluctance[i] = set_rod_permeability(m, i, c.rods[i], s.rods[i], s.rods[i].M_A_per_m, t);
  if (!solve_circuit(m.circuit, s.rod_reluctance, current_A, pm_scale, s.circuit))
    throw DivergenceError(t, "", "nodal matrix of the circuit", 0.0, "not positive definite");
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    auto& r = s.rods[i];
    const double Hc = rod_static_field(m, i, rc, r, s.circuit);
    Law::commit(rc, r, Hc, r.M_A_per_m, nullptr);
    r.H_A_per_m = Hc;
    r.Hc_A_per_m = Hc;
  }
}

}  // namespace

// The actuator at rest at its magnetic state: the hold values for the next step, each rod's
// modulus, strain and force (eq. 11-14), and the static equilibrium x = F / K of eq. (15)
// with x'' = x' = 0; the output stage rests on the stack.
void settle_at_rest(const Model& m, const Conditions& c, State& s) {
  const bool consistent = m.options.magnetic_state == MagneticState::Consistent;
  const std::size_t n = s.rods.size();
  for (std::size_t i = 0; i < n; ++i) {
    auto& r = s.rods[i];
    hold_history(r);
    if (!consistent) r.tau_s = r.mu_r * kMu0 * c.rods[i].eddy_geometry_s_m_per_H;
    update_rod_mechanics(m.material, c.rods[i], r);
  }
  for (std::size_t i = 0; i < n; ++i) {  // static equilibrium x = F / K (eq. 15 at rest)
    auto& r = s.rods[i];
    r.k_load_N_per_m = load_stiffness(c.rods[i], s);
    r.K_osc_N_per_m = r.k_rod_N_per_m + r.k_load_N_per_m;
    r.x_m = r.F_N / r.K_osc_N_per_m;
    r.v_m_per_s = 0.0;
  }
  if (m.sensor_mount.enabled) {  // the probe at rest on its bracket: u = 0
    s.q_m = s.z_m = mount_base_m(m, c, s);
    s.z_v_m_per_s = 0.0;
  }
  finish_outputs(m, c, s);
}

namespace {

template <class Law>
State demagnetised_state_law(const Model& m, const Conditions& c, double current_A) {
  State s;
  const std::size_t n = m.rods.size();
  s.rods.assign(n, RodState{});
  s.rod_reluctance.assign(n, 0.0);
  s.circuit.resize(m.circuit);
  s.energy.phi_prev_Wb.assign(m.circuit.branches.size(), 0.0);
  s.current_A = current_A;
  for (std::size_t i = 0; i < n; ++i) Law::init_state(c.rods[i], s.rods[i]);
  return s;
}

template <class Law>
State make_state_law(const Model& m, const Conditions& c, double current_A, int ramp_steps) {
  State s = demagnetised_state_law<Law>(m, c, current_A);
  // Quasi-static ramp of the total MMF from zero (demagnetised rods, no field) to its
  // value at t = 0, along the initial magnetisation curve; no eddy lag (at rest).
  for (int k = 1; k <= ramp_steps; ++k) {
    const double f = static_cast<double>(k) / ramp_steps;
    s.energy.enabled = k == ramp_steps;  // the last increment solves every branch (the ledger's
                                         // start values, gmasim/energy.hpp)
    quasi_static_magnetic_update<Law>(m, c, s, f * current_A, f * c.pm_scale, 0.0);
  }
  s.energy.enabled = false;
  settle_at_rest(m, c, s);
  return s;
}

}  // namespace

template <class Law>
void quasi_static_step_law(const Model& m, const Conditions& c, State& s, double current_A) {
  quasi_static_magnetic_update<Law>(m, c, s, current_A, c.pm_scale, s.t_s);
  settle_at_rest(m, c, s);
  s.current_A = current_A;
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    check(s.rods[i].H_A_per_m, s.t_s, m.rods[i].name, "H [A/m]", 1e9);
    check(s.rods[i].M_A_per_m, s.t_s, m.rods[i].name, "M [A/m]", 1.5 * c.rods[i].MsT_mag);
    check(s.rods[i].x_m, s.t_s, m.rods[i].name, "x [m]", 1.0);
  }
}

State demagnetised_state(const Model& m, const Conditions& c, double current_A) {
  return with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    return demagnetised_state_law<decltype(law)>(m, c, current_A);
  });
}

State make_state(const Model& m, const Conditions& c, double current_A) {
  return make_state(m, c, current_A, kRestRampSteps);
}

State make_state(const Model& m, const Conditions& c, double current_A, int ramp_increments) {
  if (ramp_increments < 1)
    throw InputError(fmt::format("make_state: ramp_increments {}: must be >= 1", ramp_increments));
  return with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    return make_state_law<decltype(law)>(m, c, current_A, ramp_increments);
  });
}

void quasi_static_step(const Model& m, const Conditions& c, State& s, double current_A) {
  with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    quasi_static_step_law<decltype(law)>(m, c, s, current_A);
  });
}

namespace {

// The printed magnetic state (model.hpp, MagneticState::Printed): explicit, in sequence.
template <class Law>
void printed_magnetic_update(const Model& m, const Conditions& c, State& s, const StepInput& in,
                             double t1) {
  const double h = in.dt_s;
  const std::size_t n = s.rods.size();
  // Rod reluctances (eq. 2-3) at the magnetisation extrapolated to the end of the step
  // (M* = 2 M_n - M_{n-1}, second order), then the nodal solve (eq. 23).
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    auto& r = s.rods[i];
    double Mx = 2.0 * r.M_A_per_m - r.M_prev_A_per_m;
    const double lim = 0.999 * rc.MsT_mu;
    Mx = Mx > lim ? lim : (Mx < -lim ? -lim : Mx);
    s.rod_reluctance[i] = set_rod_permeability(m, i, rc, r, Mx, t1);
  }
  if (!solve_circuit(m.circuit, s.rod_reluctance, in.current_A, c.pm_scale, s.circuit,
                     s.energy.enabled))
    throw DivergenceError(t1, "", "nodal matrix of the circuit", 0.0, "not positive definite");
  // Per rod: static field (eq. 7), eddy lag (eq. 7), the law (eq. 9).
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    auto& r = s.rods[i];
    const double Hc1 = rod_static_field(m, i, rc, r, s.circuit);
    r.tau_s = r.mu_r * kMu0 * rc.eddy_geometry_s_m_per_H;
    const double H1 = first_order_lag_step(r.H_A_per_m, r.Hc_A_per_m, Hc1, h, r.tau_s);
    const double M_guess = 2.0 * r.M_A_per_m - r.M_prev_A_per_m;  // linear extrapolation
    r.M_prev_A_per_m = r.M_A_per_m;
    Law::commit(rc, r, H1, M_guess, nullptr);
    r.H_A_per_m = H1;
    r.Hc_A_per_m = Hc1;
  }
}

}  // namespace

// Stage 0: the step's end time and start current; the ledgers' start values (every branch's
// flux and each rod's state before the step, gmasim/energy.hpp) when they are enabled.
void stage_begin(State& s, const StepInput& in, StepScratch& w) {
  w.t1_s = s.t_s + in.dt_s;
  w.current0_A = s.current_A;
  if (!s.energy.enabled) return;
  std::copy(s.circuit.phi.begin(), s.circuit.phi.end(), s.energy.phi_prev_Wb.begin());
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    const auto& r = s.rods[i];
    w.start[i] = {r.H_A_per_m,
                  r.Hc_A_per_m,
                  r.M_A_per_m,
                  r.Mirr_A_per_m,
                  flux_density(r.H_A_per_m, r.M_A_per_m),
                  r.x_m,
                  r.v_m_per_s,
                  r.F_N,
                  r.K_osc_N_per_m};
  }
}

// Stage 1: the magnetic state at the end of the step. Circuit (eq. 2-3, 23), eddy field
// (eq. 7) and the magnetisation law (eq. 9): solved together by Newton's method in the
// consistent state (consistent_magnetic_update), in sequence in the printed reading
// (printed_magnetic_update). Guards: |H| <= 1e9 A/m, |M| <= 1.5 M_s^T.
template <class Law>
void stage_magnetic(const Model& m, const Conditions& c, State& s, const StepInput& in,
                    const StepScratch& w) {
  if (m.options.magnetic_state == MagneticState::Consistent)
    consistent_magnetic_update<Law>(m, c, s, in.current_A, c.pm_scale, in.dt_s, false, w.t1_s);
  else
    printed_magnetic_update<Law>(m, c, s, in, w.t1_s);
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    check(s.rods[i].H_A_per_m, w.t1_s, m.rods[i].name, "H [A/m]", 1e9);
    check(s.rods[i].M_A_per_m, w.t1_s, m.rods[i].name, "M [A/m]", 1.5 * c.rods[i].MsT_mag);
  }
}

// Stage 2: each rod's Delta-E modulus (eq. 13), magnetostriction (eq. 11-12), force (eq. 14)
// and axial stiffness (eq. 17) at its new magnetisation; keeps the start's force and
// stiffness (eq. 16) and the end's compliance 1/k_rod for stage 3.
void stage_strain(const Model& m, const Conditions& c, State& s, StepScratch& w) {
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    w.F0_N[i] = s.rods[i].F_N;
    w.K0_N_per_m[i] = s.rods[i].k_rod_N_per_m + s.rods[i].k_load_N_per_m;
    w.inv_k_rod[i] = update_rod_mechanics(m.material, c.rods[i], s.rods[i]);
  }
}

// Stage 3: mechanics (eq. 15-18). Each rod's oscillator, exact over the step with the force
// linear from F_n to F_{n+1} and the stiffness of eq. (16) at mid-step: the mean of its
// values at the ends, where the end value's load stiffness (eq. 18) needs every rod's new
// modulus (stage 2): the Delta-E effect varies K over the step, its mean keeps the update second
// order in h (docs/model.md, "Time step"). Then the sensor mount (model.hpp, SensorMountModel).
// Guard: |x| <= 1 m.
void stage_mechanics(const Model& m, const Conditions& c, State& s, const StepInput& in,
                     const StepScratch& w) {
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    const auto& rc = c.rods[i];
    auto& r = s.rods[i];
    r.k_load_N_per_m = load_stiffness_from_compliances(rc, w.inv_k_rod.data());
    const double K = mid_step_stiffness(w.K0_N_per_m[i], r.k_rod_N_per_m, r.k_load_N_per_m);
    r.K_osc_N_per_m = K;
    oscillator_step(rc.mass_osc_kg, rc.inv_mass_osc_per_kg, rc.damping_osc_N_s_per_m, K, w.F0_N[i],
                    r.F_N, in.dt_s, r.x_m, r.v_m_per_s, r.osc_decay);
    check(r.x_m, w.t1_s, m.rods[i].name, "x [m]", 1.0);
  }
  if (m.sensor_mount.enabled) {
    advance_sensor_mount(m.sensor_mount, s.q_m, mount_base_m(m, c, s), in.dt_s, s);
    check(s.z_m, w.t1_s, "sensor mount", "z [m]", 1.0);
  }
}

// Stage 4: the outputs (finish_outputs: eq. 20-21 and the flux densities).
void stage_outputs(const Model& m, const Conditions& c, State& s) { finish_outputs(m, c, s); }

// Stage 5: the step's energy ledgers (gmasim/energy.hpp), when enabled.
void stage_ledger(const Model& m, const Conditions& c, State& s, const StepInput& in,
                  const StepScratch& w) {
  if (s.energy.enabled)
    book_step_energy(m, c, s, w.start.data(), w.current0_A, in.current_A, in.dt_s);
}

void step(const Model& m, const Conditions& c, State& s, const StepInput& in) {
  with_magnetisation_law(m.options.magnetisation_law,
                         [&](auto law) { step_law<decltype(law)>(m, c, s, in); });
}

// The step: the stages in order (gmasim/model/step_stages.hpp).
template <class Law>
void step_law(const Model& m, const Conditions& c, State& s, const StepInput& in) {
  StepScratch w;
  stage_begin(s, in, w);
  stage_magnetic<Law>(m, c, s, in, w);
  stage_strain(m, c, s, w);
  stage_mechanics(m, c, s, in, w);
  s.t_s = w.t1_s;
  s.current_A = in.current_A;
  stage_outputs(m, c, s);
  stage_ledger(m, c, s, in, w);
}

template void stage_magnetic<JilesAthertonLaw>(const Model&, const Conditions&, State&,
                                               const StepInput&, const StepScratch&);
template void stage_magnetic<PreisachLaw>(const Model&, const Conditions&, State&, const StepInput&,
                                          const StepScratch&);
template void step_law<JilesAthertonLaw>(const Model&, const Conditions&, State&, const StepInput&);
template void step_law<PreisachLaw>(const Model&, const Conditions&, State&, const StepInput&);
template void quasi_static_step_law<JilesAthertonLaw>(const Model&, const Conditions&, State&,
                                                      double);
template void quasi_static_step_law<PreisachLaw>(const Model&, const Conditions&, State&, double);

}  // namespace gmasim
