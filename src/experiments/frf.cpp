// gmasim frf (Fig. 15): frequency response current -> displacement about a DC bias, by a
// stepped sine (time-domain runs of step()) and by a small-signal linearisation of the
// same model, and the modes of eq. (15). docs/experiments.md, "Frequency response".
#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>

#include "experiments/frf_internal.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/claims.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"
#include "gmasim/rod_laws.hpp"
#include "gmasim/run_loop.hpp"
#include "gmasim/validate.hpp"

namespace gmasim {
namespace {

using namespace physics;
using cd = std::complex<double>;

constexpr double kTwoPi = 2.0 * kPi;

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

double unwrap_deg(double prev, double now) {
  while (now - prev > 180.0) now -= 360.0;
  while (now - prev < -180.0) now += 360.0;
  return now;
}

std::vector<double> log_grid(double f0, double f1, int n) {
  std::vector<double> f(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    f[static_cast<std::size_t>(k)] = f0 * std::pow(f1 / f0, static_cast<double>(k) / (n - 1));
  return f;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Linearisation
// ---------------------------------------------------------------------------------------
namespace {

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

std::complex<double> SmallSignalModel::response(double f_Hz) const {
  const auto N = static_cast<Eigen::Index>(n);
  const cd sj(0.0, kTwoPi * f_Hz);
  Eigen::MatrixXcd A = Eigen::MatrixXcd::Identity(N, N);
  Eigen::VectorXcd b(N);
  Eigen::VectorXcd dM(N);
  if (consistent) {  // port equations of the rods (see the struct), solved for dH
    for (Eigen::Index i = 0; i < N; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      b(i) = port_b_At_per_A[ui];
      for (Eigen::Index j = 0; j < N; ++j) {
        const auto uj = static_cast<std::size_t>(j);
        A(i, j) = port_S_per_H[ui * static_cast<std::size_t>(n) + uj] * area_m2[uj] * kMu0 *
                  (1.0 + chi[uj]);
      }
      A(i, i) += length_m[ui] * (1.0 + kappa_s_m_per_H[ui] * sj * kMu0 * (1.0 + chi[ui]));
    }
    const Eigen::VectorXcd dH = A.partialPivLu().solve(b);
    for (Eigen::Index i = 0; i < N; ++i) dM(i) = chi[static_cast<std::size_t>(i)] * dH(i);
  } else {
    for (Eigen::Index i = 0; i < N; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      const cd lag_chi = chi[ui] / (1.0 + tau_s[ui] * sj);  // dM_i / dHc_i
      b(i) = lag_chi * g_A_per_m_per_A[ui];
      for (Eigen::Index j = 0; j < N; ++j)
        A(i, j) -= lag_chi * G[ui * static_cast<std::size_t>(n) + static_cast<std::size_t>(j)];
    }
    dM = A.partialPivLu().solve(b);
  }
  cd Y = 0.0, Q = 0.0;
  for (Eigen::Index i = 0; i < N; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    cd dF = 0.0;
    for (Eigen::Index j = 0; j < N; ++j)
      dF += D_N_per_A_per_m[ui * static_cast<std::size_t>(n) + static_cast<std::size_t>(j)] * dM(j);
    const cd X = dF / (mass_kg[ui] * sj * sj + damping_N_s_per_m[ui] * sj + stiffness_N_per_m[ui]);
    Y += X;
    if (sensor_mount) Q += recoil_per_x[ui] * X;
  }
  // The probe's deflection u = Q s^2 / (s^2 + (c/m) s + k/m) (model.hpp, SensorMountModel).
  if (sensor_mount)
    Y -= Q * sj * sj * sm_mass_kg /
         (sm_mass_kg * sj * sj + sm_damping_N_s_per_m * sj + sm_stiffness_N_per_m);
  return Y;
}

// ---------------------------------------------------------------------------------------
// Modes of eq. (15)
// ---------------------------------------------------------------------------------------
std::vector<Mode> mechanical_modes(const Model& m, const Conditions& c, const State& s) {
  (void)m;
  const auto N = static_cast<Eigen::Index>(s.rods.size());
  // Eq. (15) with the diagonal M, C, K of eq. (16), (24), (25); assembled as full
  // matrices so a model with coupling terms would be handled the same way.
  Eigen::MatrixXd Mm = Eigen::MatrixXd::Zero(N, N), Cm = Mm, Km = Mm;
  for (Eigen::Index i = 0; i < N; ++i) {
    const auto& rc = c.rods[static_cast<std::size_t>(i)];
    Mm(i, i) = rc.mass_osc_kg;
    Cm(i, i) = rc.damping_osc_N_s_per_m;
    Km(i, i) = oscillator_stiffness(c, s, static_cast<int>(i));
  }
  // Undamped modes: K v = w^2 M v; classical modal damping zeta = v'Cv / (2 w v'Mv).
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Km, Mm);
  std::vector<Mode> modes;
  for (Eigen::Index k = 0; k < N; ++k) {
    const double w = std::sqrt(std::max(es.eigenvalues()(k), 0.0));
    const Eigen::VectorXd v = es.eigenvectors().col(k);
    Mode md;
    md.frequency_Hz = w / kTwoPi;
    md.damping_ratio = w > 0 ? v.dot(Cm * v) / (2.0 * w * v.dot(Mm * v)) : 0.0;
    md.damped_frequency_Hz =
        md.damping_ratio < 1.0
            ? md.frequency_Hz * std::sqrt(1.0 - md.damping_ratio * md.damping_ratio)
            : 0.0;
    modes.push_back(md);
  }
  std::sort(modes.begin(), modes.end(),
            [](const Mode& a, const Mode& b) { return a.frequency_Hz < b.frequency_Hz; });
  return modes;
}

// ---------------------------------------------------------------------------------------
// Measurement helpers
// ---------------------------------------------------------------------------------------
std::complex<double> first_harmonic_ratio(const std::vector<double>& t_s,
                                          const std::vector<double>& y,
                                          const std::vector<double>& i, double f_Hz) {
  cd Y = 0.0, I = 0.0;
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    const cd e = std::polar(1.0, -kTwoPi * f_Hz * t_s[k]);
    Y += y[k] * e;
    I += i[k] * e;
  }
  return Y / I;
}

double find_resonance_Hz(const std::vector<double>& f, const std::vector<double>& mag) {
  if (mag.size() < 3) return 0.0;
  double best = 0.0, f_best = 0.0;
  for (std::size_t k = 1; k + 1 < mag.size(); ++k) {
    if (mag[k] > mag[k - 1] && mag[k] >= mag[k + 1] && mag[k] > best) {
      best = mag[k];
      // Parabolic refinement in log f.
      const double a = mag[k - 1], b = mag[k], cc = mag[k + 1];
      const double den = a - 2 * b + cc;
      const double off = den != 0.0 ? 0.5 * (a - cc) / den : 0.0;
      const double lf = std::log(f[k]) + off * 0.5 * (std::log(f[k + 1]) - std::log(f[k - 1]));
      f_best = std::exp(lf);
    }
  }
  return f_best;
}

double find_bandwidth_3dB_Hz(const std::vector<double>& f, const std::vector<double>& mag) {
  if (mag.size() < 2) return 0.0;
  const double level = mag.front() / std::sqrt(2.0);
  for (std::size_t k = 1; k < mag.size(); ++k) {
    if (mag[k] < level) {
      const double u = (mag[k - 1] - level) / (mag[k - 1] - mag[k]);
      return std::exp(std::log(f[k - 1]) + u * (std::log(f[k]) - std::log(f[k - 1])));
    }
  }
  return 0.0;
}

// ---------------------------------------------------------------------------------------
// The experiment
// ---------------------------------------------------------------------------------------
namespace {

void check_request(const FrfRequest& r) {
  if (r.temperatures_C.empty())
    throw InputError("frf: no temperature given (--temperatures): give at least one");
  if (!(r.f_min_Hz > 0.0) || !std::isfinite(r.f_min_Hz))
    throw InputError(fmt::format("lowest frequency (--f-min) = {} Hz: must be > 0", r.f_min_Hz));
  if (!(r.f_max_Hz > r.f_min_Hz) || !std::isfinite(r.f_max_Hz))
    throw InputError(fmt::format(
        "frequency range (--f-min .. --f-max) {} .. {} Hz: the maximum must exceed the minimum",
        r.f_min_Hz, r.f_max_Hz));
  if (r.points < 2)
    throw InputError(fmt::format("points (--points) = {}: need at least 2", r.points));
  if (!(r.amplitude_A > 0.0) || !std::isfinite(r.amplitude_A))
    throw InputError(fmt::format("amplitude (--amplitude) = {} A: must be > 0", r.amplitude_A));
  if (!std::isfinite(r.bias_A)) throw InputError("bias current (--bias): not a finite number");
  if (r.min_steps_per_period < 20)
    throw InputError(fmt::format("steps per period {}: need at least 20", r.min_steps_per_period));
  if (r.settle_periods < 1 || r.measure_periods < 1)
    throw InputError(
        fmt::format("settle periods (--settle-periods) {} / measure periods (--measure-periods) "
                    "{}: must be >= 1",
                    r.settle_periods, r.measure_periods));
  if (!r.stepped_sine && !r.small_signal)
    throw InputError("frf: neither the stepped sine nor the small-signal method is selected");
  for (double T : r.temperatures_C) require_finite(T, "temperature (--temperatures)", "degC");
  if (static_cast<double>(r.temperatures_C.size()) > kMaxListValues)
    throw InputError(fmt::format("frf: {} temperatures: too many (limit {:g})",
                                 r.temperatures_C.size(), kMaxListValues));
  require_in(r.f_max_Hz, 0.0, kMaxFrequency_Hz, "maximum frequency (--f-max)", "Hz");
  (void)checked_count(r.points, kMaxFrfPoints, "frequency points (--points)");
  require_in(r.amplitude_A, 0.0, kMaxCurrent_A, "amplitude (--amplitude)", "A");
  require_in(r.bias_A, -kMaxCurrent_A, kMaxCurrent_A, "bias current (--bias)", "A");
  require_int_in(r.settle_periods, 1, 1000000, "settle periods");
  require_int_in(r.measure_periods, 1, 1000000, "measure periods");
  // Golden section shrinks its bracket by 0.618 per evaluation: 100 reach 1e-21 of it, far below
  // what a double resolves, so more is a typing error that would run for hours.
  require_int_in(r.peak_refinements, 0, 100, "peak refinements (--peak-refinements)");
  if (r.stepped_sine) {
    // The longest stepped-sine run (at f_min) before settling for the model's time
    // constants; the settling is checked again per frequency once those are known.
    const double per = std::max(static_cast<double>(r.min_steps_per_period),
                                std::ceil(1.0 / (r.f_min_Hz * kMaxDt_s) - 1e-9));
    (void)StepGrid::uniform(0.0, 1.0 / (r.f_min_Hz * per),
                            per * (r.settle_periods + r.measure_periods),
                            fmt::format("stepped-sine steps at {:g} Hz", r.f_min_Hz));
  }
}

// The transient of switching the sine on decays with the slowest of the eddy lags and the
// mechanical modes: 10 of those time constants (the transient is then below 5e-5 of its start).
double settling_time_s(const SmallSignalModel& lin) {
  double t_settle = 0.0;
  for (std::size_t i = 0; i < lin.tau_s.size(); ++i) {
    const double zw = lin.damping_N_s_per_m[i] / (2.0 * lin.mass_kg[i]);
    t_settle = std::max({t_settle, 10.0 * lin.tau_s[i], 10.0 / zw});
  }
  if (lin.sensor_mount && lin.sm_damping_N_s_per_m > 0)
    t_settle = std::max(t_settle, 10.0 * 2.0 * lin.sm_mass_kg / lin.sm_damping_N_s_per_m);
  return t_settle;
}

}  // namespace

// One stepped-sine point: the sine switched on at the bias state, >= min_steps_per_period
// steps per period with dt <= 10 us (whole steps per period); settled for settling_time_s and
// at least settle_periods periods (low frequencies need few periods, high frequencies many),
// then the first harmonic of y over measure_periods whole periods.
cd detail::stepped_sine_point(const Model& m, const Conditions& c, const State& bias,
                              const SmallSignalModel& lin, const FrfRequest& r, double fr) {
  const long per =
      steps_to_resolve(1.0 / (fr * kMaxDt_s), r.min_steps_per_period, "steps per period");
  const double dt = 1.0 / (fr * static_cast<double>(per));
  const long settle =
      steps_to_resolve(settling_time_s(lin) * fr, r.settle_periods, "settle periods");
  const long measure = r.measure_periods;
  const StepGrid grid =
      StepGrid::uniform(0.0, dt, static_cast<double>(settle + measure) * static_cast<double>(per),
                        fmt::format("stepped-sine steps at {:g} Hz", fr));
  const double w = kTwoPi * fr;
  std::vector<double> ts, ys, is;
  ts.reserve(static_cast<std::size_t>(measure * per));
  ys.reserve(ts.capacity());
  is.reserve(ts.capacity());
  const long first = settle * per;  // samples first+1 .. total: whole periods
  State s = bias;
  run_loop(
      m, c, s, grid, [&](double t) { return r.bias_A + r.amplitude_A * std::sin(w * t); },
      [&](const State& st, const StepPoint& p) {
        if (p.k <= first) return;
        ts.push_back(p.t_s);
        ys.push_back(st.y_m - lin.y0_m);
        is.push_back(st.current_A - r.bias_A);
      });
  return first_harmonic_ratio(ts, ys, is, fr);
}

namespace {

// The bias point's curve: the bias output, the eddy lags, the modes, the static gain.
FrfCurve bias_curve(const Model& m, const Conditions& c, const State& bias,
                    const SmallSignalModel& lin, double T, const std::vector<double>& f) {
  FrfCurve cv;
  cv.temperature_C = T;
  cv.f_Hz = f;
  cv.y_bias_um = bias.y_m * 1e6;
  for (const auto& rd : bias.rods) cv.eddy_tau_ms.push_back(rd.tau_s * 1e3);
  for (const Mode& md : mechanical_modes(m, c, bias)) {
    cv.mode_frequencies_Hz.push_back(md.frequency_Hz);
    cv.mode_damping_ratios.push_back(md.damping_ratio);
  }
  cv.static_gain_um_per_A = std::abs(lin.response(0.0)) * 1e6;
  return cv;
}

// Magnitudes and unwrapped phases of both methods, their mismatch, resonance and bandwidth.
void fill_curve(FrfCurve& cv, const SmallSignalModel& lin, const cd* stepped,
                const std::vector<double>& f, const FrfRequest& r) {
  cv.f_Hz = f;
  double prev_l = 0.0, prev_s = 0.0;
  for (std::size_t fi = 0; fi < f.size(); ++fi) {
    if (r.small_signal) {
      const cd Y = lin.response(f[fi]);
      cv.linear_mag_um_per_A.push_back(std::abs(Y) * 1e6);
      const double ph = std::arg(Y) * 180.0 / kPi;
      prev_l = fi == 0 ? ph : unwrap_deg(prev_l, ph);
      cv.linear_phase_deg.push_back(prev_l);
    }
    if (r.stepped_sine) {
      const cd Y = stepped[fi];
      cv.stepped_mag_um_per_A.push_back(std::abs(Y) * 1e6);
      const double ph = std::arg(Y) * 180.0 / kPi;
      prev_s = fi == 0 ? ph : unwrap_deg(prev_s, ph);
      cv.stepped_phase_deg.push_back(prev_s);
    }
    if (r.small_signal && r.stepped_sine) {
      const cd d = stepped[fi] - lin.response(f[fi]);
      cv.max_mismatch_pct =
          std::max(cv.max_mismatch_pct, std::abs(d) / std::abs(lin.response(f[fi])) * 100.0);
    }
  }
  if (r.stepped_sine) {
    cv.stepped_first_resonance_Hz = detail::data_peak(f, cv.stepped_mag_um_per_A).f_Hz;
    cv.stepped_bandwidth_3dB_Hz = find_bandwidth_3dB_Hz(f, cv.stepped_mag_um_per_A);
  }
  if (!r.small_signal) return;  // markers from the stepped sine (detail::choose_markers)
  // Resonance and bandwidth of the linear model on a dense grid (cheap to evaluate).
  const LinearFrfMarkers lm = linear_frf_markers(lin, r.f_min_Hz, r.f_max_Hz);
  cv.first_resonance_Hz = lm.first_resonance_Hz;
  if (cv.first_resonance_Hz > 0)
    cv.first_resonance_mag_um_per_A = std::abs(lin.response(cv.first_resonance_Hz)) * 1e6;
  cv.bandwidth_3dB_Hz = lm.bandwidth_3dB_Hz;
  // The same search beyond the band, up to twice the highest mode.
  double f_top = r.f_max_Hz;
  for (double fm : cv.mode_frequencies_Hz) f_top = std::max(f_top, 2.0 * fm);
  const std::vector<double> fe = log_grid(r.f_min_Hz, f_top, 8000);
  std::vector<double> me(fe.size());
  for (std::size_t k = 0; k < fe.size(); ++k) me[k] = std::abs(lin.response(fe[k]));
  cv.linear_peak_extended_Hz = find_resonance_Hz(fe, me);
  cv.linear_peak_search_max_Hz = f_top;
}

}  // namespace

LinearFrfMarkers linear_frf_markers(const SmallSignalModel& lin, double f_min_Hz, double f_max_Hz) {
  const std::vector<double> fd = log_grid(f_min_Hz, f_max_Hz, 4000);
  std::vector<double> md(fd.size());
  for (std::size_t k = 0; k < fd.size(); ++k) md[k] = std::abs(lin.response(fd[k]));
  return {find_resonance_Hz(fd, md), find_bandwidth_3dB_Hz(fd, md)};
}

LinearFrfMarkers linear_frf_markers(const Model& m, double T_C, double bias_A) {
  const FrfRequest r;
  const Conditions c = make_conditions(m, T_C);
  const State bias = settle_at_bias(m, c, bias_A, r.bias_state);
  return linear_frf_markers(linearise(m, c, bias), r.f_min_Hz, r.f_max_Hz);
}

FrfResult run_frf(const Model& m, const FrfRequest& r, const ProgressFn& progress) {
  check_request(r);
  std::vector<Conditions> conds;
  for (double T : r.temperatures_C) conds.push_back(make_conditions(m, T));

  const auto wall0 = std::chrono::steady_clock::now();
  const std::vector<double> f = log_grid(r.f_min_Hz, r.f_max_Hz, r.points);
  const std::size_t nT = r.temperatures_C.size(), nf = f.size();

  // Bias points, linearisations and modes (cheap; one per temperature).
  std::vector<State> bias;
  std::vector<SmallSignalModel> lin;
  FrfResult res;
  res.paper_first_resonance_Hz = builtin_paper_value("first_resonance");
  res.paper_bandwidth_Hz = builtin_paper_value("bandwidth");
  for (std::size_t ti = 0; ti < nT; ++ti) {
    bias.push_back(settle_at_bias(m, conds[ti], r.bias_A, r.bias_state));
    lin.push_back(linearise(m, conds[ti], bias.back()));
    res.curves.push_back(
        bias_curve(m, conds[ti], bias.back(), lin.back(), r.temperatures_C[ti], f));
  }

  // Stepped sine: one work item per (temperature, frequency).
  std::vector<cd> stepped(nT * nf);
  if (r.stepped_sine) {
    const std::size_t n = nT * nf;
    detail::parallel_for(
        n, resolve_thread_count(r.threads, n),
        [&](std::size_t idx) {
          const std::size_t ti = idx / nf, fi = idx % nf;
          stepped[idx] = detail::stepped_sine_point(m, conds[ti], bias[ti], lin[ti], r, f[fi]);
        },
        progress);
  } else if (progress) {
    progress(nT, nT);
  }
  // The stepped sine's peak refined per temperature (golden section in ln f, frf_peak.cpp).
  std::vector<detail::SteppedCurve> sc(nT);
  for (std::size_t ti = 0; ti < nT; ++ti) {
    sc[ti].f_Hz = f;
    sc[ti].Y.assign(stepped.begin() + static_cast<std::ptrdiff_t>(ti * nf),
                    stepped.begin() + static_cast<std::ptrdiff_t>((ti + 1) * nf));
  }
  if (r.stepped_sine && r.peak_refinements > 0)
    detail::parallel_for(nT, resolve_thread_count(r.threads, nT),
                         [&](std::size_t ti) {
                           detail::refine_stepped_peak(m, conds[ti], bias[ti], lin[ti], r, sc[ti]);
                         },
                         {});
  for (std::size_t ti = 0; ti < nT; ++ti) {
    fill_curve(res.curves[ti], lin[ti], sc[ti].Y.data(), sc[ti].f_Hz, r);
    detail::choose_markers(res.curves[ti], lin[ti], conds[ti], r);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  for (auto& cv : res.curves) cv.wall_time_s = wall;
  return res;
}

}  // namespace gmasim
