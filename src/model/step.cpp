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
#include "gmasim/physics/stages.hpp"

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

// The scalar step's context of the mechanical stages (gmasim/physics/mechanics_stage-inl.h, the
// one text the lanes also run): the rods' state in State::rods, their constants in
// RodConditions, the sensor mount in State, a failure thrown (DivergenceError at t1).
struct ScalarMechanics {
  const Model& m;
  const Conditions& c;
  State& s;
  double t1;
  RodState* rods_ = s.rods.data();  // the vectors' storage, read once
  const RodConditions* rcs_ = c.rods.data();
  int n_ = static_cast<int>(s.rods.size());

  int rods() const { return n_; }
  const RodConditions& rc(int i) const { return rcs_[i]; }
  RodState& rod(int i) const { return rods_[i]; }
  RodStrain strain_state(int i) const {
    const RodState& r = rod(i);
    return {r.F_N, r.k_rod_N_per_m, r.k_load_N_per_m, r.E_Pa, r.lambda, r.prestress_exp};
  }
  void store_strain(int i, const RodStrain& v) const {
    RodState& r = rod(i);
    r.F_N = v.F;
    r.k_rod_N_per_m = v.k_rod;
    r.E_Pa = v.E;
    r.lambda = v.lambda;
    r.prestress_exp = v.prestress;
  }
  RodOscillator oscillator(int i) const {
    const RodState& r = rod(i);
    return {r.F_N, r.k_rod_N_per_m, r.k_load_N_per_m, r.K_osc_N_per_m,
            r.x_m, r.v_m_per_s,     r.osc_decay};
  }
  void store_oscillator(int i, const RodOscillator& v) const {
    RodState& r = rod(i);
    r.k_load_N_per_m = v.k_load;
    r.K_osc_N_per_m = v.K_osc;
    r.x_m = v.x;
    r.v_m_per_s = v.v;
    r.osc_decay = v.osc_decay;
  }
  double x(int i) const { return rod(i).x_m; }
  double M(int i) const { return rod(i).M_A_per_m; }
  RodMechanicsInputs inputs(int i) const {
    const RodConditions& k = rc(i);
    return {k.inv_MsT_E_m_per_A,
            k.dE,
            k.inv_Ms_strain_m_per_A,
            k.sigma_p_Pa,
            k.four_sigma_p_over_lambda_s_Pa,
            k.area_m2,
            k.area_over_length_m,
            k.length_over_area_per_m,
            k.joint_compliance_m_per_N};
  }
  double lambda_s() const { return m.material.lambda_s; }
  double fixed_compliance(int i) const { return rc(i).fixed_compliance_m_per_N; }
  const int* chain(int i) const { return rc(i).chain_rods.data(); }
  int chain_count(int i) const { return rc(i).chain_rod_count; }
  double mass_osc(int i) const { return rc(i).mass_osc_kg; }
  double inv_mass_osc(int i) const { return rc(i).inv_mass_osc_per_kg; }
  double damping_osc(int i) const { return rc(i).damping_osc_N_s_per_m; }
  void check_x(int i, double x) const {
    check(x, t1, m.rods[static_cast<std::size_t>(i)].name, "x [m]", 1.0);
  }
  bool mount() const { return m.sensor_mount.enabled; }
  bool mount_on_output() const { return m.options.sensor_mount_base == SensorMountBase::Output; }
  double momentum_mass(int i) const { return rc(i).momentum_mass_kg; }
  double actuator_mass() const { return m.sensor_mount.actuator_mass_kg; }
  double mount_mass() const { return m.sensor_mount.mass_kg; }
  double mount_inv_mass() const { return 1.0 / m.sensor_mount.mass_kg; }
  double mount_damping() const { return m.sensor_mount.damping_N_s_per_m; }
  double mount_stiffness() const { return m.sensor_mount.stiffness_N_per_m; }
  MountState mount_state() const { return {s.z_m, s.z_v_m_per_s, s.q_m, s.mount_decay}; }
  void store_mount(const MountState& v) const {
    s.z_m = v.z;
    s.z_v_m_per_s = v.zv;
    s.q_m = v.q;
    s.mount_decay = v.decay;
  }
  void check_z(double z) const { check(z, t1, "sensor mount", "z [m]", 1.0); }
};

void finish_outputs(const Model& m, const Conditions& c, State& s) {
  double y = stack_displacement<double>(ScalarMechanics{m, c, s, s.t_s});
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

// The scalar step's context of the consistent state's solve (gmasim/physics/joint_newton-inl.h,
// the one text the lanes also run): the rods' state in State::rods, the circuit solved by the
// netlist (solve_circuit: the rods' branches R_eff and their extra MMF), the law's own trial and
// commit (Law::begin_move, joint_trial, commit_trial), and a failure thrown (DivergenceError).
// NR: the number of rods fixed at compile time (3, the built-in actuator: the loops unrolled), or
// 0 for any.
template <class Law, std::size_t NR>
struct ScalarNewton {
  const Model& m;
  const Conditions& c;
  State& s;
  double current_A, pm_scale, t1;
  std::array<typename Law::MoveStart, 8> start;  // set before read (not zeroed: the step's cost)
  std::array<typename Law::JointTrial, 8> trial;

  ScalarNewton(const Model& m_, const Conditions& c_, State& s_, double current, double pm,
               double t)
      : m(m_), c(c_), s(s_), current_A(current), pm_scale(pm), t1(t) {}
  int rods() const { return NR > 0 ? static_cast<int>(NR) : static_cast<int>(s.rods.size()); }
  const RodConditions& rc(int i) const { return c.rods[static_cast<std::size_t>(i)]; }
  RodState& rod(int i) { return s.rods[static_cast<std::size_t>(i)]; }
  RodMagnetic load(int i) {
    const RodState& r = rod(i);
    return {r.H_A_per_m,      r.Hc_A_per_m,      r.H_prev_A_per_m, r.H_prev2_A_per_m, r.M_A_per_m,
            r.M_prev_A_per_m, r.M_prev2_A_per_m, r.mu_r,           r.tau_s,           r.phi_Wb};
  }
  void store(int i, const RodMagnetic& v) {
    RodState& r = rod(i);
    r.H_A_per_m = v.H;
    r.Hc_A_per_m = v.Hc;
    r.H_prev_A_per_m = v.H_prev;
    r.H_prev2_A_per_m = v.H_prev2;
    r.M_A_per_m = v.M;
    r.M_prev_A_per_m = v.M_prev;
    r.M_prev2_A_per_m = v.M_prev2;
    r.mu_r = v.mu_r;
    r.tau_s = v.tau;
    r.phi_Wb = v.phi;
    s.circuit.phi[static_cast<std::size_t>(m.circuit.rod_branch[static_cast<std::size_t>(i)])] =
        v.phi;
  }
  double kappa(int i) const { return rc(i).eddy_geometry_s_m_per_H; }
  double length(int i) const { return rc(i).length_m; }
  double length_per_area(int i) const { return rc(i).length_over_area_per_m; }
  double series_reluctance(int i) const { return rc(i).series_reluctance_per_H; }
  double area(int i) const { return rc(i).area_m2; }
  double inv_area(int i) const { return rc(i).inv_area_per_m2; }
  void begin(int i) { start[static_cast<std::size_t>(i)] = Law::begin_move(rc(i), rod(i)); }
  void trial_at(int i, double H, double M_iter, bool /*done: never, while solving*/) {
    Law::joint_trial(rc(i), rod(i), start[static_cast<std::size_t>(i)], H, M_iter,
                     trial[static_cast<std::size_t>(i)]);
  }
  const typename Law::JointTrial& t(int i) const { return trial[static_cast<std::size_t>(i)]; }
  double M_of(int i) const { return t(i).M; }
  double dM_dH(int i) const { return t(i).dM_dH; }
  double inv_mu_r(int i) const { return t(i).inv_mu_r; }
  double M_next(int i) const { return t(i).M_next; }
  bool converged(int i) const { return t(i).converged; }
  void branch(int i, double R, double extra) {
    s.rod_reluctance[static_cast<std::size_t>(i)] = R;
    s.circuit.rod_extra_mmf[static_cast<std::size_t>(i)] = extra;
  }
  bool solve(bool) {
    ++s.newton_solves;
    if (!solve_circuit(m.circuit, s.rod_reluctance, current_A, pm_scale, s.circuit,
                       s.energy.enabled))
      throw DivergenceError(t1, "", "nodal matrix of the circuit", 0.0, "not positive definite");
    return false;
  }
  double flux(int i) const {
    return s.circuit
        .phi[static_cast<std::size_t>(m.circuit.rod_branch[static_cast<std::size_t>(i)])];
  }
  [[noreturn]] void newton_failed(bool, double worst, double worst_rod) {
    throw DivergenceError(t1, m.rods[static_cast<std::size_t>(worst_rod)].name,
                          "field H [A/m] of the consistent magnetic state", worst,
                          "Newton's method did not converge");
  }
  bool initially_done() const { return false; }
  void commit_law(int i) { Law::commit_trial(rc(i), rod(i), trial[static_cast<std::size_t>(i)]); }
};

// Consistent magnetic state (docs/model.md, "Magnetic state"): the joint Newton solve of the
// rods' fields and magnetisations with the circuit and its commit, the one text of
// gmasim/physics/joint_newton-inl.h (joint_newton_start, joint_newton, joint_newton_commit).
// quasi_static drops the eddy term (the at-rest ramp of make_state) and starts at H_n.
template <class Law, std::size_t N>
void consistent_magnetic_update_n(const Model& m, const Conditions& c, State& s, double current_A,
                                  double pm_scale, double h_s, bool quasi_static, double t1) {
  ScalarNewton<Law, N> ctx(m, c, s, current_A, pm_scale, t1);
  JointNewtonT<double, 8> f;  // set before read
  joint_newton_start(ctx, f, quasi_static, 2.0 / h_s);
  joint_newton(ctx, f);
  joint_newton_commit(ctx, f, quasi_static);
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
    const ScalarMechanics k{m, c, s, s.t_s};
    s.q_m = s.z_m = mount_base<double>(k, stack_displacement<double>(k));
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
  ScalarMechanics k{m, c, s, w.t1_s};
  strain_stage<double>(k, w.F0_N.data(), w.K0_N_per_m.data(), w.inv_k_rod.data());
}

// Stage 3: mechanics (eq. 15-18). Each rod's oscillator, exact over the step with the force
// linear from F_n to F_{n+1} and the stiffness of eq. (16) at mid-step: the mean of its
// values at the ends, where the end value's load stiffness (eq. 18) needs every rod's new
// modulus (stage 2): the Delta-E effect varies K over the step, its mean keeps the update second
// order in h (docs/model.md, "Time step"). Then the sensor mount (model.hpp, SensorMountModel).
// Guard: |x| <= 1 m.
void stage_mechanics(const Model& m, const Conditions& c, State& s, const StepInput& in,
                     const StepScratch& w) {
  ScalarMechanics k{m, c, s, w.t1_s};
  oscillators_stage<double>(k, w.F0_N.data(), w.K0_N_per_m.data(), w.inv_k_rod.data(), in.dt_s);
  sensor_mount_stage<double>(k, stack_displacement<double>(k), in.dt_s);
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

// The step: the stages in their order, written once (physics::run_stages), each the stage function
// of gmasim/model/step_stages.hpp (ScalarStages).
template <class Law>
void step_law(const Model& m, const Conditions& c, State& s, const StepInput& in) {
  ScalarStages<Law> st(m, c, s, in);
  physics::run_stages(st);
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
