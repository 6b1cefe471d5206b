// The mechanics module: the small-signal linearisation of the actuator about a settled bias
// point (gmasim/mechanics/mechanics.hpp, SmallSignalModel; docs/experiments.md, "Frequency
// response"): the circuit's gains, the eddy lag (eq. 7), the magnetisation law's reversible
// slope, the forces (eq. 11-14) and the oscillators of eq. (15), and the response Y(s)/I.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/model/rod_laws.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"

namespace gmasim {
namespace {

using namespace physics;
using cd = std::complex<double>;

// The eq. (3) permeability of rod i at magnetisation M (rod_laws.hpp, as step() evaluates it).
double mu_at(const Model& m, std::size_t i, const RodConditions& rc, double M) {
  return rod_permeability(rc, m.material.chi_m, M, 0.0, m.rods[i].name);
}

// Static fields H_c,i (eq. 7 first line) of every rod for coil current I and rod
// magnetisations M (through mu(M), eq. 2-3, and the nodal solve of eq. 23).
std::vector<double> static_fields(const Model& m, const Conditions& c, CircuitWorkspace& ws,
                                  double I, const std::vector<double>& M) {
  const std::size_t n = M.size();
  std::vector<double> R(n), mu(n), Hc(n);
  for (std::size_t i = 0; i < n; ++i) {
    mu[i] = mu_at(m, i, c.rods[i], M[i]);
    R[i] = rod_reluctance(c.rods[i].length_m, mu[i], c.rods[i].area_m2);
  }
  if (!solve_circuit(m.circuit, R, I, c.pm_scale, ws, false))
    throw DivergenceError(0.0, "", "nodal matrix of the circuit", 0.0, "not positive definite");
  for (std::size_t i = 0; i < n; ++i) {
    const double phi = ws.phi[static_cast<std::size_t>(m.circuit.rod_branch[i])];
    Hc[i] = static_field(phi, c.rods[i].k_f, mu[i], c.rods[i].area_m2);
  }
  return Hc;
}

// Rod force (eq. 11-14) and rod stiffness (eq. 17) at magnetisation M: update_rod_mechanics
// of rod_laws.hpp, as step() does.
struct ForceStiffness {
  double F, k_rod;
};
ForceStiffness force_at(const Model& m, const RodConditions& rc, double M) {
  RodState r;
  r.M_A_per_m = M;
  update_rod_mechanics(m.material, rc, r);
  return {r.F_N, r.k_rod_N_per_m};
}

// dM/dH with the irreversible state held: the magnetisation law's (the seam,
// gmasim/magnetisation/laws.hpp).
double reversible_susceptibility(const Model& m, const RodConditions& rc, const RodState& r) {
  return with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    return decltype(law)::reversible_susceptibility(rc, r);
  });
}

// Consistent magnetic state: the circuit seen from the rod branches. With rod reluctances R_p
// and extra rod MMFs e, the rod fluxes solve (R_p + S) phi = b I + e (netlist.cpp), whatever
// R_p; probe it. Then per rod the port constants, chi and tau.
void linearise_ports(const Model& m, const Conditions& c, const State& s, CircuitWorkspace& ws,
                     SmallSignalModel& L) {
  const std::size_t n = s.rods.size();
  L.consistent = true;
  const auto N = static_cast<Eigen::Index>(n);
  std::vector<double> Rp(n);
  for (std::size_t i = 0; i < n; ++i)
    Rp[i] = c.rods[i].length_m / (kMu0 * s.rods[i].mu_r * c.rods[i].area_m2);
  auto rod_flux = [&](double I) {
    if (!solve_circuit(m.circuit, Rp, I, 0.0, ws, false))
      throw DivergenceError(0.0, "", "nodal matrix of the circuit", 0.0, "not positive definite");
    Eigen::VectorXd phi(N);
    for (std::size_t i = 0; i < n; ++i)
      phi(static_cast<Eigen::Index>(i)) = ws.phi[static_cast<std::size_t>(m.circuit.rod_branch[i])];
    return phi;
  };
  Eigen::MatrixXd P(N, N);
  for (std::size_t j = 0; j < n; ++j) {
    std::fill(ws.rod_extra_mmf.begin(), ws.rod_extra_mmf.end(), 0.0);
    ws.rod_extra_mmf[j] = 1.0;
    P.col(static_cast<Eigen::Index>(j)) = rod_flux(0.0);
  }
  std::fill(ws.rod_extra_mmf.begin(), ws.rod_extra_mmf.end(), 0.0);
  const Eigen::MatrixXd RS = P.inverse();  // R_p + S
  const Eigen::VectorXd b = RS * rod_flux(1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    const auto& r = s.rods[i];
    for (std::size_t j = 0; j < n; ++j)
      L.port_S_per_H.push_back(RS(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) -
                               (i == j ? Rp[i] - rc.series_reluctance_per_H : 0.0));
    L.port_b_At_per_A.push_back(b(static_cast<Eigen::Index>(i)));
    L.length_m.push_back(rc.length_m);
    L.kappa_s_m_per_H.push_back(rc.eddy_geometry_s_m_per_H);
    L.area_m2.push_back(rc.area_m2);
    const double chi = reversible_susceptibility(m, rc, r);
    L.chi.push_back(chi);
    L.tau_s.push_back(kMu0 * (1.0 + chi) * rc.eddy_geometry_s_m_per_H);
  }
}

// Printed magnetic state: the circuit's dHc/dI at fixed M (linear in I, so any step is
// exact) and dHc/dM_j at fixed I; the eddy lag (eq. 7) and JA with M_irr pinned (eq. 9):
// M = (1-c) M_irr + c M_an(H + alpha M).
void linearise_circuit(const Model& m, const Conditions& c, const State& s, CircuitWorkspace& ws,
                       const std::vector<double>& M0, SmallSignalModel& L) {
  const std::size_t n = s.rods.size();
  const double I0 = s.current_A;
  const double dI = 1e-2;
  const auto Hp = static_fields(m, c, ws, I0 + dI, M0);
  const auto Hm = static_fields(m, c, ws, I0 - dI, M0);
  for (std::size_t i = 0; i < n; ++i) L.g_A_per_m_per_A.push_back((Hp[i] - Hm[i]) / (2 * dI));
  for (std::size_t j = 0; j < n; ++j) {
    const double dM = 1e-5 * c.rods[j].MsT_mu;
    auto Mp = M0, Mm = M0;
    Mp[j] += dM;
    Mm[j] -= dM;
    const auto Hpj = static_fields(m, c, ws, I0, Mp);
    const auto Hmj = static_fields(m, c, ws, I0, Mm);
    for (std::size_t i = 0; i < n; ++i) L.G[i * n + j] = (Hpj[i] - Hmj[i]) / (2 * dM);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    const auto& r = s.rods[i];
    L.tau_s.push_back(mu_at(m, i, rc, r.M_A_per_m) * rc.eddy_geometry_s_m_per_H);
    L.chi.push_back(reversible_susceptibility(m, rc, r));
  }
}

// Force and stiffness: F_net,i = F_i(M_i) - K_i(M) x0_i (eq. 14-18 about the bias).
void linearise_forces(const Model& m, const Conditions& c, const State& s,
                      const std::vector<double>& M0, SmallSignalModel& L) {
  const std::size_t n = s.rods.size();
  L.D_N_per_A_per_m.assign(n * n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    const double dM = 1e-5 * c.rods[j].MsT_mag;
    State sp = s, sm = s;
    const auto fp = force_at(m, c.rods[j], M0[j] + dM);
    const auto fm = force_at(m, c.rods[j], M0[j] - dM);
    sp.rods[j].k_rod_N_per_m = fp.k_rod;
    sm.rods[j].k_rod_N_per_m = fm.k_rod;
    for (std::size_t i = 0; i < n; ++i) {
      const double dK = (oscillator_stiffness(c, sp, static_cast<int>(i)) -
                         oscillator_stiffness(c, sm, static_cast<int>(i))) /
                        (2 * dM);
      double d = -dK * s.rods[i].x_m;
      if (i == j) d += (fp.F - fm.F) / (2 * dM);
      L.D_N_per_A_per_m[i * n + j] = d;
    }
  }
}

}  // namespace

SmallSignalModel linearise(const Model& m, const Conditions& c, const State& s) {
  const std::size_t n = s.rods.size();
  SmallSignalModel L;
  L.temperature_C = c.temperature_C;
  L.bias_A = s.current_A;
  L.n = static_cast<int>(n);
  L.y0_m = s.y_m;
  std::vector<double> M0(n);
  for (std::size_t i = 0; i < n; ++i) {
    M0[i] = s.rods[i].M_A_per_m;
    L.M0_A_per_m.push_back(M0[i]);
    L.H0_A_per_m.push_back(s.rods[i].H_A_per_m);
    L.x0_m.push_back(s.rods[i].x_m);
  }
  CircuitWorkspace ws;
  ws.resize(m.circuit);
  if (m.sensor_mount.enabled) {
    L.sensor_mount = true;
    L.sm_mass_kg = m.sensor_mount.mass_kg;
    L.sm_stiffness_N_per_m = m.sensor_mount.stiffness_N_per_m;
    L.sm_damping_N_s_per_m = m.sensor_mount.damping_N_s_per_m;
    L.sm_on_output = m.options.sensor_mount_base == SensorMountBase::Output;
    for (std::size_t i = 0; i < n; ++i)
      L.recoil_per_x.push_back(c.rods[i].momentum_mass_kg / m.sensor_mount.actuator_mass_kg);
  }
  L.G.assign(n * n, 0.0);
  if (m.options.magnetic_state == MagneticState::Consistent) {
    linearise_ports(m, c, s, ws, L);
  } else {
    linearise_circuit(m, c, s, ws, M0, L);
  }
  linearise_forces(m, c, s, M0, L);
  for (std::size_t i = 0; i < n; ++i) {
    L.mass_kg.push_back(c.rods[i].mass_osc_kg);
    L.damping_N_s_per_m.push_back(c.rods[i].damping_osc_N_s_per_m);
    L.stiffness_N_per_m.push_back(oscillator_stiffness(c, s, static_cast<int>(i)));
  }
  return L;
}

namespace {

constexpr int kSmallRods = 8;
using SmallMatrix =
    Eigen::Matrix<cd, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kSmallRods, kSmallRods>;
using SmallVector = Eigen::Matrix<cd, Eigen::Dynamic, 1, Eigen::ColMajor, kSmallRods, 1>;

// dM of the response at s = sj: the rods' port equations solved for dH (consistent), or the
// circuit's lagged gains solved for dM, into the n-vector x. The n x n system goes into a
// (column-major) and x, then Eigen's PartialPivLU: on max-size (stack) matrices up to
// kSmallRods rods, on heap matrices beyond.
void response_dM(const SmallSignalModel& L, cd sj, cd* a, cd* x) {
  const auto n = static_cast<std::size_t>(L.n);
  auto A = [&](std::size_t i, std::size_t j) -> cd& { return a[j * n + i]; };
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i) A(i, j) = i == j ? cd(1.0) : cd(0.0);
  if (L.consistent) {  // port equations of the rods (see the struct), solved for dH
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = L.port_b_At_per_A[i];
      for (std::size_t j = 0; j < n; ++j)
        A(i, j) = L.port_S_per_H[i * n + j] * L.area_m2[j] * kMu0 * (1.0 + L.chi[j]);
      A(i, i) += L.length_m[i] * (1.0 + L.kappa_s_m_per_H[i] * sj * kMu0 * (1.0 + L.chi[i]));
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const cd lag_chi = L.chi[i] / (1.0 + L.tau_s[i] * sj);  // dM_i / dHc_i
      x[i] = lag_chi * L.g_A_per_m_per_A[i];
      for (std::size_t j = 0; j < n; ++j) A(i, j) -= lag_chi * L.G[i * n + j];
    }
  }
  const auto N = static_cast<Eigen::Index>(n);
  if (L.n <= kSmallRods) {  // Eigen on stack storage: no heap in the markers' 4000 solves
    const SmallVector r = Eigen::PartialPivLU<SmallMatrix>(Eigen::Map<SmallMatrix>(a, N, N))
                              .solve(Eigen::Map<SmallVector>(x, N));
    for (std::size_t i = 0; i < n; ++i) x[i] = r(static_cast<Eigen::Index>(i));
  } else {
    const Eigen::VectorXcd r = Eigen::Map<Eigen::MatrixXcd>(a, N, N).partialPivLu().solve(
        Eigen::Map<Eigen::VectorXcd>(x, N));
    for (std::size_t i = 0; i < n; ++i) x[i] = r(static_cast<Eigen::Index>(i));
  }
  if (L.consistent)
    for (std::size_t i = 0; i < n; ++i) x[i] = L.chi[i] * x[i];  // dM = chi dH
}

}  // namespace

std::complex<double> SmallSignalModel::response(double f_Hz) const {
  const auto un = static_cast<std::size_t>(n);
  const cd sj(0.0, kTwoPi * f_Hz);
  constexpr std::size_t kMax = kSmallRods;
  cd a_small[kMax * kMax], x_small[kMax];
  std::vector<cd> a_big, x_big;  // only for more than kSmallRods rods
  if (un > kMax) {
    a_big.resize(un * un);
    x_big.resize(un);
  }
  cd* const dM = un > kMax ? x_big.data() : x_small;
  response_dM(*this, sj, un > kMax ? a_big.data() : a_small, dM);
  cd Y = 0.0, Q = 0.0;
  for (std::size_t i = 0; i < un; ++i) {
    cd dF = 0.0;
    for (std::size_t j = 0; j < un; ++j) dF += D_N_per_A_per_m[i * un + j] * dM[j];
    const cd X = dF / (mass_kg[i] * sj * sj + damping_N_s_per_m[i] * sj + stiffness_N_per_m[i]);
    Y += X;
    if (sensor_mount) Q += recoil_per_x[i] * X;
  }
  // On the output: the probe follows Y through its bracket, z = Y (c s + k)/(m s^2 + c s + k).
  if (sensor_mount && sm_on_output)
    return Y * (sm_damping_N_s_per_m * sj + sm_stiffness_N_per_m) /
           (sm_mass_kg * sj * sj + sm_damping_N_s_per_m * sj + sm_stiffness_N_per_m);
  // The probe's deflection u = Q s^2 / (s^2 + (c/m) s + k/m) (model.hpp, SensorMountModel).
  if (sensor_mount)
    Y -= Q * sj * sj * sm_mass_kg /
         (sm_mass_kg * sj * sj + sm_damping_N_s_per_m * sj + sm_stiffness_N_per_m);
  return Y;
}

}  // namespace gmasim
