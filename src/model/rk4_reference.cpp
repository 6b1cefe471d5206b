// A plain explicit RK4 of the model's ODE (the reference the exact step is measured
// against). Same laws, same circuit; only the time integration differs.
#include <array>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/model.hpp"
#include "gmasim/physics/jiles_atherton.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"

namespace gmasim {
namespace {

using namespace physics;
constexpr std::size_t kMax = 8;
struct Y {
  std::array<double, kMax> H{}, Mirr{}, x{}, v{}, M{};
};

// Derivatives at (y, I). M of each rod is re-solved from (H, M_irr) (warm-started).
void rhs(const Model& m, const Conditions& c, State& s, Y& y, double I, Y& dy) {
  const std::size_t n = s.rods.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    y.M[i] = ja_total_magnetisation(y.H[i], y.Mirr[i], y.M[i], rc.MsT_ja, rc.ja);
    const double inv_chi =
        inverse_susceptibility(y.M[i] / rc.MsT_mu, m.material.chi_m, rc.S_mu_J_per_m3, rc.MsT_mu);
    const double mu = permeability(inv_chi);
    s.rods[i].mu_r = mu / kMu0;
    s.rod_reluctance[i] = rod_reluctance(rc.length_m, mu, rc.area_m2);
  }
  if (!solve_circuit(m.circuit, s.rod_reluctance, I, c.pm_scale, s.circuit))
    throw DivergenceError(s.t_s, "", "nodal matrix of the circuit", 0.0, "not positive definite");
  std::array<double, kMax> krod{}, F{};
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    const double mu = s.rods[i].mu_r * kMu0;
    const double phi = s.circuit.phi[static_cast<std::size_t>(m.circuit.rod_branch[i])];
    const double Hc = static_field(phi, rc.k_f, mu, rc.area_m2);
    const double tau = mu * rc.eddy_geometry_s_m_per_H;
    dy.H[i] = (Hc - y.H[i]) / tau;
    const double delta = dy.H[i] >= 0.0 ? 1.0 : -1.0;
    dy.Mirr[i] =
        ja_irreversible_slope(y.H[i], y.M[i], y.Mirr[i], delta, rc.MsT_ja, rc.ja) * dy.H[i];
    const double E = delta_e_modulus(y.M[i] / rc.MsT_E, rc.dE);
    const double lam = magnetostriction(y.M[i] / rc.MsT_ja, m.material.lambda_s, rc.sigma_p_Pa, E);
    F[i] = rod_force(lam, E, rc.area_m2);
    krod[i] = axial_stiffness(E, rc.area_m2, rc.length_m);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    double inv_k = rc.fixed_compliance_m_per_N;
    for (int j = 0; j < rc.chain_rod_count; ++j)
      inv_k += 1.0 / krod[static_cast<std::size_t>(rc.chain_rods[static_cast<std::size_t>(j)])];
    const double K = krod[i] + 1.0 / inv_k;
    dy.x[i] = y.v[i];
    dy.v[i] = (F[i] - rc.damping_osc_N_s_per_m * y.v[i] - K * y.x[i]) / rc.mass_osc_kg;
  }
}

}  // namespace

void rk4_reference_step(const Model& m, const Conditions& c, State& s, double I0, double Imid,
                        double I1, double h) {
  const std::size_t n = s.rods.size();
  Y y0, k1, k2, k3, k4, yt;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = s.rods[i];
    y0.H[i] = r.H_A_per_m;
    y0.Mirr[i] = r.Mirr_A_per_m;
    y0.x[i] = r.x_m;
    y0.v[i] = r.v_m_per_s;
    y0.M[i] = r.M_A_per_m;
  }
  auto axpy = [&](const Y& a, double f, const Y& d) {
    yt = a;
    for (std::size_t i = 0; i < n; ++i) {
      yt.H[i] += f * d.H[i];
      yt.Mirr[i] += f * d.Mirr[i];
      yt.x[i] += f * d.x[i];
      yt.v[i] += f * d.v[i];
    }
  };
  rhs(m, c, s, y0, I0, k1);
  axpy(y0, 0.5 * h, k1);
  rhs(m, c, s, yt, Imid, k2);
  axpy(y0, 0.5 * h, k2);
  rhs(m, c, s, yt, Imid, k3);
  axpy(y0, h, k3);
  rhs(m, c, s, yt, I1, k4);
  for (std::size_t i = 0; i < n; ++i) {
    auto& r = s.rods[i];
    r.H_A_per_m += h / 6 * (k1.H[i] + 2 * k2.H[i] + 2 * k3.H[i] + k4.H[i]);
    r.Mirr_A_per_m += h / 6 * (k1.Mirr[i] + 2 * k2.Mirr[i] + 2 * k3.Mirr[i] + k4.Mirr[i]);
    r.x_m += h / 6 * (k1.x[i] + 2 * k2.x[i] + 2 * k3.x[i] + k4.x[i]);
    r.v_m_per_s += h / 6 * (k1.v[i] + 2 * k2.v[i] + 2 * k3.v[i] + k4.v[i]);
    r.M_prev_A_per_m = r.M_A_per_m;
    r.M_A_per_m = ja_total_magnetisation(r.H_A_per_m, r.Mirr_A_per_m, yt.M[i], c.rods[i].MsT_ja,
                                         c.rods[i].ja);
    r.E_Pa = delta_e_modulus(r.M_A_per_m / c.rods[i].MsT_E, c.rods[i].dE);
    r.lambda = magnetostriction(r.M_A_per_m / c.rods[i].MsT_ja, m.material.lambda_s,
                                c.rods[i].sigma_p_Pa, r.E_Pa);
    r.F_N = rod_force(r.lambda, r.E_Pa, c.rods[i].area_m2);
    r.k_rod_N_per_m = axial_stiffness(r.E_Pa, c.rods[i].area_m2, c.rods[i].length_m);
    if (!std::isfinite(r.x_m) || std::fabs(r.x_m) > 1.0)
      throw DivergenceError(s.t_s + h, m.rods[i].name, "x [m] (RK4)", r.x_m,
                            "explicit RK4 unstable");
  }
  s.t_s += h;
  s.current_A = I1;
  double y = 0.0;
  for (const auto& r : s.rods) y += r.x_m;
  s.y_m = y;
}

}  // namespace gmasim
