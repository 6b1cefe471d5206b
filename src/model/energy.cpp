// The energy ledgers: per-step booking (called by step()), the stored energies of a state,
// and the balance between two snapshots. docs/model.md, "Energy ledgers".
#include "gmasim/model/energy.hpp"

#include <algorithm>
#include <cmath>

#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/mechanics.hpp"

namespace gmasim {
namespace {

using namespace physics;

bool consistent(const Model& m) { return m.options.magnetic_state == MagneticState::Consistent; }

double rod_volume_m3(const RodConditions& rc) { return rc.length_m * rc.area_m2; }

// Gauss-Legendre, 4 points on [0, 1]: exact for polynomials of degree 7.
constexpr double kGlNode[4] = {0.5 - 0.5 * 0.8611363115940526, 0.5 - 0.5 * 0.3399810435848563,
                               0.5 + 0.5 * 0.3399810435848563, 0.5 + 0.5 * 0.8611363115940526};
constexpr double kGlWeight[4] = {0.5 * 0.3478548451374538, 0.5 * 0.6521451548225463,
                                 0.5 * 0.6521451548225463, 0.5 * 0.3478548451374538};

// The magnetic terms of rod i over one step.
template <class Law>
void book_rod_magnetic(const Model& m, const RodConditions& rc, const StepStart& a, RodState& r,
                       double h) {
  const double V = rod_volume_m3(rc);
  const double B1 = flux_density(r.H_A_per_m, r.M_A_per_m);
  const double dB = B1 - a.B;
  RodEnergy& e = r.energy;
  e.material_work_J += V * 0.5 * (a.H + r.H_A_per_m) * dB;
  if (consistent(m))  // eq. (7): H_c - H = kappa dB/dt, so the eddy field's work is kappa dB^2/h
    e.eddy_J += V * rc.eddy_geometry_s_m_per_H * dB * dB / h;
  else  // printed: the lag's eddy field H_c - H against the material's dB
    e.eddy_J += V * 0.5 * ((a.Hc - a.H) + (r.Hc_A_per_m - r.H_A_per_m)) * dB;
  // The magnetisation law's dissipation over the step (Jiles-Atherton: eq. 9's along the path
  // H, M linear, physics::ja_step_dissipation; Preisach: the switched hysterons' loss).
  e.hysteresis_J += V * Law::step_dissipation(rc, a.H, a.M, r);
}

// The mechanical terms of rod i over one step: the oscillator's exact update (F linear, K
// and c constant over the step) is evaluated at the Gauss-Legendre nodes.
void book_rod_mechanical(const RodConditions& rc, const StepStart& a, RodState& r, double h) {
  RodEnergy& e = r.energy;
  const double K = r.K_osc_N_per_m;
  e.stiffness_work_J += 0.5 * (K - a.K) * a.x * a.x;
  const double mass = rc.mass_osc_kg, c = rc.damping_osc_N_s_per_m;
  const double g = (r.F_N - a.F) / h;
  double work = 0.0, damp = 0.0;
  for (int q = 0; q < 4; ++q) {
    const double s = kGlNode[q] * h;
    double x = a.x, v = a.v;
    oscillator_step(mass, c, K, a.F, a.F + g * s, s, x, v);
    work += kGlWeight[q] * (a.F + g * s) * v;
    damp += kGlWeight[q] * c * v * v;
  }
  e.force_work_J += work * h;
  e.damping_J += damp * h;
}

}  // namespace

void book_step_energy(const Model& m, const Conditions& c, State& s, const StepStart* start,
                      double current0_A, double current1_A, double h_s) {
  auto& acc = s.energy;
  double emf = 0.0;
  for (std::size_t b = 0; b < m.circuit.branches.size(); ++b) {
    const auto& br = m.circuit.branches[b];
    const double dphi = s.circuit.phi[b] - acc.phi_prev_Wb[b];
    if (br.coil_turns != 0.0) {
      acc.coil_J += br.coil_turns * 0.5 * (current0_A + current1_A) * dphi;
      emf += br.coil_turns * dphi / h_s;
    }
    if (br.pm_mmf_At != 0.0) acc.magnet_J += br.pm_mmf_At * c.pm_scale * dphi;
  }
  acc.coil_emf_V = emf;
  with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    for (std::size_t i = 0; i < s.rods.size(); ++i)
      book_rod_magnetic<decltype(law)>(m, c.rods[i], start[i], s.rods[i], h_s);
  });
  for (std::size_t i = 0; i < s.rods.size(); ++i)
    book_rod_mechanical(c.rods[i], start[i], s.rods[i], h_s);
}

namespace {

StoredEnergy stored_energy(const Model& m, const Conditions& c, const State& s) {
  StoredEnergy e;
  for (std::size_t b = 0; b < m.circuit.branches.size(); ++b) {
    const auto& br = m.circuit.branches[b];
    const double phi = s.circuit.phi[b];
    if (br.rod < 0) {
      e.circuit_J += 0.5 * br.fixed_reluctance_per_H * phi * phi;
    } else {
      e.series_J +=
          0.5 * c.rods[static_cast<std::size_t>(br.rod)].series_reluctance_per_H * phi * phi;
    }
  }
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    const auto& rc = c.rods[i];
    const auto& r = s.rods[i];
    const double phi = with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
      return decltype(law)::stored_energy_density(rc, r);
    });
    e.material_J += rod_volume_m3(rc) * (0.5 * kMu0 * r.H_A_per_m * r.H_A_per_m + phi);
    e.kinetic_J += 0.5 * rc.mass_osc_kg * r.v_m_per_s * r.v_m_per_s;
    e.elastic_J += 0.5 * r.K_osc_N_per_m * r.x_m * r.x_m;
  }
  return e;
}

}  // namespace

EnergySnapshot energy_snapshot(const Model& m, const Conditions& c, const State& s) {
  EnergySnapshot snap;
  snap.t_s = s.t_s;
  snap.coil_J = s.energy.coil_J;
  snap.magnet_J = s.energy.magnet_J;
  for (const auto& r : s.rods) snap.rods.push_back(r.energy);
  snap.stored = stored_energy(m, c, s);
  return snap;
}

EnergyBalance energy_balance(const EnergySnapshot& a, const EnergySnapshot& b) {
  EnergyBalance e;
  e.duration_s = b.t_s - a.t_s;
  e.coil_J = b.coil_J - a.coil_J;
  e.magnet_J = b.magnet_J - a.magnet_J;
  e.d_circuit_J = b.stored.circuit_J - a.stored.circuit_J;
  e.d_series_J = b.stored.series_J - a.stored.series_J;
  e.d_material_J = b.stored.material_J - a.stored.material_J;
  e.d_kinetic_J = b.stored.kinetic_J - a.stored.kinetic_J;
  e.d_elastic_J = b.stored.elastic_J - a.stored.elastic_J;
  for (std::size_t i = 0; i < a.rods.size() && i < b.rods.size(); ++i) {
    const RodEnergy &ra = a.rods[i], &rb = b.rods[i];
    e.rod_hysteresis_J.push_back(rb.hysteresis_J - ra.hysteresis_J);
    e.rod_eddy_J.push_back(rb.eddy_J - ra.eddy_J);
    e.hysteresis_J += e.rod_hysteresis_J.back();
    e.eddy_J += e.rod_eddy_J.back();
    e.force_work_J += rb.force_work_J - ra.force_work_J;
    e.stiffness_work_J += rb.stiffness_work_J - ra.stiffness_work_J;
    e.damping_J += rb.damping_J - ra.damping_J;
  }
  const double in = e.coil_J + e.magnet_J;
  e.magnetic_residual_J =
      in - (e.d_circuit_J + e.d_series_J + e.d_material_J + e.hysteresis_J + e.eddy_J);
  // The scale a residual is judged against: the larger of the input, the gross flows, and a
  // thousandth of the energy stored at the window's end. The last matters only when nothing
  // flows (a held current): there the input is round-off and |residual| / |input| would be
  // a ratio of two round-off errors.
  const double stored_mag =
      std::fabs(b.stored.circuit_J) + std::fabs(b.stored.series_J) + std::fabs(b.stored.material_J);
  const double mag_scale =
      std::max({std::fabs(in),
                std::fabs(e.d_circuit_J) + std::fabs(e.d_series_J) + std::fabs(e.d_material_J) +
                    std::fabs(e.hysteresis_J) + std::fabs(e.eddy_J),
                1e-3 * stored_mag});
  e.magnetic_residual_rel = std::fabs(e.magnetic_residual_J) / mag_scale;
  const double mech_in = e.force_work_J + e.stiffness_work_J;
  e.mechanical_residual_J = mech_in - (e.d_kinetic_J + e.d_elastic_J + e.damping_J);
  const double stored_mech = std::fabs(b.stored.kinetic_J) + std::fabs(b.stored.elastic_J);
  const double mech_scale =
      std::max({std::fabs(mech_in),
                std::fabs(e.d_kinetic_J) + std::fabs(e.d_elastic_J) + std::fabs(e.damping_J),
                1e-3 * stored_mech});
  e.mechanical_residual_rel = std::fabs(e.mechanical_residual_J) / mech_scale;
  e.coupling_fraction = mech_in / mag_scale;
  return e;
}

}  // namespace gmasim
