// A plain explicit RK4 of the model's ODE (the reference the exact step is measured
// against). Same laws, same circuit; only the time integration differs.
#include <array>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/rod_laws.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"

namespace gmasim {
namespace {

using namespace physics;
constexpr std::size_t kMax = 8;
// The integrated state: per rod H, the magnetisation law's ODE variable q (Law::ode_*: M_irr
// for Jiles-Atherton), x, v; and M (the law's algebraic output, kept as the warm start).
struct Y {
  std::array<double, kMax> H{}, q{}, x{}, v{}, M{};
};

// Derivatives at (y, I). M of each rod is re-solved from (H, q) (warm-started).
template <class Law>
void rhs(const Model& m, const Conditions& c, State& s, Y& y, double I, Y& dy) {
  const std::size_t n = s.rods.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    y.M[i] = Law::ode_magnetisation(rc, s.rods[i], y.H[i], y.q[i], y.M[i]);
    s.rod_reluctance[i] = set_rod_permeability(m, i, rc, s.rods[i], y.M[i], s.t_s);
  }
  if (!solve_circuit(m.circuit, s.rod_reluctance, I, c.pm_scale, s.circuit))
    throw DivergenceError(s.t_s, "", "nodal matrix of the circuit", 0.0, "not positive definite");
  std::array<RodState, kMax> stage{};  // force and stiffness of this stage, per rod
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    const double Hc = rod_static_field(m, i, rc, s.rods[i], s.circuit);
    const double tau = s.rods[i].mu_r * kMu0 * rc.eddy_geometry_s_m_per_H;
    dy.H[i] = (Hc - y.H[i]) / tau;
    dy.q[i] = Law::ode_rate(rc, y.H[i], y.M[i], y.q[i], dy.H[i]);
    stage[i].M_A_per_m = y.M[i];
    update_rod_mechanics(m.material, rc, stage[i]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& rc = c.rods[i];
    const double K = stage[i].k_rod_N_per_m + load_stiffness(rc, [&](int j) {
                       return stage[static_cast<std::size_t>(j)].k_rod_N_per_m;
                     });
    dy.x[i] = y.v[i];
    dy.v[i] = (stage[i].F_N - rc.damping_osc_N_s_per_m * y.v[i] - K * y.x[i]) / rc.mass_osc_kg;
  }
}

template <class Law>
void rk4_step_law(const Model& m, const Conditions& c, State& s, double I0, double Imid, double I1,
                  double h) {
  if (m.options.magnetic_state != MagneticState::Printed || m.sensor_mount.enabled)
    throw InputError(
        "rk4_reference_step: the RK4 reference integrates the printed magnetic state without a "
        "sensor mount only (options.magnetic_state = \"printed\", no [mechanics.sensor_mount])");
  const std::size_t n = s.rods.size();
  Y y0, k1, k2, k3, k4, yt;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = s.rods[i];
    y0.H[i] = r.H_A_per_m;
    y0.q[i] = Law::ode_variable(r);
    y0.x[i] = r.x_m;
    y0.v[i] = r.v_m_per_s;
    y0.M[i] = r.M_A_per_m;
  }
  auto axpy = [&](const Y& a, double f, const Y& d) {
    yt = a;
    for (std::size_t i = 0; i < n; ++i) {
      yt.H[i] += f * d.H[i];
      yt.q[i] += f * d.q[i];
      yt.x[i] += f * d.x[i];
      yt.v[i] += f * d.v[i];
    }
  };
  rhs<Law>(m, c, s, y0, I0, k1);
  axpy(y0, 0.5 * h, k1);
  rhs<Law>(m, c, s, yt, Imid, k2);
  axpy(y0, 0.5 * h, k2);
  rhs<Law>(m, c, s, yt, Imid, k3);
  axpy(y0, h, k3);
  rhs<Law>(m, c, s, yt, I1, k4);
  for (std::size_t i = 0; i < n; ++i) {
    auto& r = s.rods[i];
    r.H_A_per_m += h / 6 * (k1.H[i] + 2 * k2.H[i] + 2 * k3.H[i] + k4.H[i]);
    const double q1 = y0.q[i] + h / 6 * (k1.q[i] + 2 * k2.q[i] + 2 * k3.q[i] + k4.q[i]);
    r.x_m += h / 6 * (k1.x[i] + 2 * k2.x[i] + 2 * k3.x[i] + k4.x[i]);
    r.v_m_per_s += h / 6 * (k1.v[i] + 2 * k2.v[i] + 2 * k3.v[i] + k4.v[i]);
    r.M_prev_A_per_m = r.M_A_per_m;
    Law::ode_commit(c.rods[i], r, q1, yt.M[i]);
    update_rod_mechanics(m.material, c.rods[i], r);
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

}  // namespace

void rk4_reference_step(const Model& m, const Conditions& c, State& s, double I0, double Imid,
                        double I1, double h) {
  with_magnetisation_law(m.options.magnetisation_law,
                         [&](auto law) { rk4_step_law<decltype(law)>(m, c, s, I0, Imid, I1, h); });
}

}  // namespace gmasim
