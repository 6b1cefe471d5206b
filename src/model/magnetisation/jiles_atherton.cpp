// The Jiles-Atherton law's tables and temperature laws (the seam: gmasim/magnetisation/
// laws.hpp; the physics: gmasim/physics/jiles_atherton.hpp): the group [<rod>.ja] with its
// rows (Table 4) and eq. (10) at temperature.
#include "gmasim/physics/jiles_atherton.hpp"

#include <fmt/format.h>

#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/magnetisation/jiles_atherton.hpp"
#include "gmasim/model/model.hpp"
#include "model/conditions_detail.hpp"
#include "model/parameter_rows.hpp"

namespace gmasim::model_detail {
namespace {

using namespace physics;

template <auto P>
double& in_ja(Model& m, std::size_t i) {
  return m.rods[i].ja.*P;
}
#define LAND GMASIM_LAND

// Eq. (10) at temperature T_C for one rod, under the model's reading.
JaCoefficients ja_at(const Model& m, const JaReference& j, double T_C) {
  const double Tc_C = m.material.Tc_C;
  const double T_K = T_C + kZeroCelsiusInK, Tc_K = Tc_C + kZeroCelsiusInK;
  const double Tr_K = m.T_ref_C + kZeroCelsiusInK;
  double t = 0.0, tr = 0.0;
  switch (m.options.eq10_scale) {
    case Eq10Scale::Celsius:
      t = T_C / Tc_C;
      tr = m.T_ref_C / Tc_C;
      break;
    default:
      t = T_K / Tc_K;
      tr = Tr_K / Tc_K;
      break;
  }
  auto law = [&](double p0, double f_t, double f_tr) {
    return m.options.eq10_scale == Eq10Scale::RoomReferenced ? p0 * f_t / f_tr : p0 * f_t;
  };
  JaCoefficients p{};
  p.alpha = law(j.alpha0, eq10_alpha_factor(t, j.beta1), eq10_alpha_factor(tr, j.beta1));
  p.k_A_per_m = law(j.k0_A_per_m, eq10_k_factor(t, j.beta2), eq10_k_factor(tr, j.beta2));
  p.c = law(j.c0, eq10_c_factor(t, j.beta1), eq10_c_factor(tr, j.beta1));
  if (m.options.shape_law == ShapeLaw::MeanField)
    p.a_A_per_m = j.a0_A_per_m * mean_field_a_factor(T_K, Tr_K);
  else
    p.a_A_per_m = law(j.a0_A_per_m, eq10_a_factor(t, j.beta3), eq10_a_factor(tr, j.beta3));
  return p;
}

using G = Group;
using R = Rule;

const GroupDef kGroup[] = {
    {G::RodJa, "<rod>.ja", TableRule::Required,
     "The rod's Jiles-Atherton constants at T_ref (Table 4), eq. (9)-(10)",
     MagnetisationLaw::JilesAtherton},
};

const ParamDef kRows[] = {
    {G::RodJa, "a0_A_per_m", "A/m", R::Positive, "anhysteretic shape a at T_ref, eq. (9)-(10)",
     LAND(in_ja, JaReference, a0_A_per_m)},
    {G::RodJa, "alpha0", "-", R::Any, "inter-domain coupling alpha at T_ref, eq. (9)-(10)",
     LAND(in_ja, JaReference, alpha0)},
    {G::RodJa, "c0", "-", R::UnitInterval, "reversibility c at T_ref, eq. (9)-(10)",
     LAND(in_ja, JaReference, c0)},
    {G::RodJa, "k0_A_per_m", "A/m", R::Positive, "pinning k at T_ref, eq. (9)-(10)",
     LAND(in_ja, JaReference, k0_A_per_m)},
    {G::RodJa, "beta1", "-", R::Positive, "exponent beta_1 of alpha^T and c^T, eq. (10)",
     LAND(in_ja, JaReference, beta1)},
    {G::RodJa, "beta2", "-", R::Positive, "exponent beta_2 of k^T, eq. (10)",
     LAND(in_ja, JaReference, beta2)},
    {G::RodJa, "beta3", "-", R::Positive, "exponent beta_3 of the printed a^T, eq. (10)",
     LAND(in_ja, JaReference, beta3)},
};

}  // namespace

const LawTables& jiles_atherton_tables() {
  static const LawTables t{kGroup, kRows};
  return t;
}

}  // namespace gmasim::model_detail

namespace gmasim {

void JilesAthertonLaw::temperature_laws(const Model& m, const RodModel& rod, double T_law_C,
                                        double T_C, RodConditions& rc) {
  using model_detail::ja_at;
  rc.ja = ja_at(m, rod.ja, T_law_C);  // eq. (10)
  if (m.options.magnetic_state == MagneticState::Consistent) rc.ja.alpha += rc.alpha_sigma;
  rc.ja_inv_a_m_per_A = 1.0 / rc.ja.a_A_per_m;
  rc.ja_inv_k_m_per_A = 1.0 / rc.ja.k_A_per_m;
  if (!(rc.ja.a_A_per_m > 0 && rc.ja.k_A_per_m > 0 && rc.ja.c >= 0 && rc.ja.c < 1 &&
        std::isfinite(rc.ja.alpha)))
    throw InputError(fmt::format(
        "{}: eq. (10) at {} degC gives unphysical JA coefficients in rod '{}' (a = {:.4g} A/m, k "
        "= {:.4g} A/m, c = {:.4g}, alpha = {:.4g})",
        m.spec.source, T_C, rod.name, rc.ja.a_A_per_m, rc.ja.k_A_per_m, rc.ja.c, rc.ja.alpha));
}

}  // namespace gmasim
