// The Preisach law's tables and temperature laws (the seam: gmasim/magnetisation/laws.hpp; the
// physics: gmasim/physics/preisach.hpp; docs/model.md, "The Preisach law"): the group
// [<rod>.preisach] with its rows, and the law at temperature:
//   M_s^T       eq. (4), as for every law (RodConditions::MsT_mag);
//   H_c^T       = H_c0 (M_s^T / M_s)^n_c, the coercivity law; the interaction spread scales
//               with it (H_u^T / H_c^T = H_u0 / H_c0), so the whole distribution scales by one
//               factor and the hysterons keep their states when the temperature changes;
//   a^T         = a0 T / T_ref (kelvin; the mean-field law of the reversible part);
//   c, alpha    constant (alpha plus eq. 3's coupling alpha_sigma in the consistent state).
#include "gmasim/physics/preisach.hpp"

#include <fmt/format.h>

#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/magnetisation/preisach.hpp"
#include "gmasim/model/model.hpp"
#include "model/conditions_detail.hpp"
#include "model/parameter_rows.hpp"

namespace gmasim::model_detail {
namespace {

using namespace physics;

template <auto P>
double& in_preisach(Model& m, std::size_t i) {
  return m.rods[i].preisach.*P;
}
#define LAND GMASIM_LAND

using G = Group;
using R = Rule;

const GroupDef kPreisachGroup[] = {
    {G::RodPreisach, "<rod>.preisach", TableRule::Required,
     "The rod's Preisach constants at T_ref (options.magnetisation_law = \"preisach\"; "
     "docs/model.md, \"The Preisach law\")",
     MagnetisationLaw::Preisach},
};

const ParamDef kPreisachRows[] = {
    {G::RodPreisach, "Hc0_A_per_m", "A/m", R::Positive,
     "median coercive field H_c0 of the hysterons at T_ref (log-normal distribution)",
     LAND(in_preisach, PreisachReference, Hc0_A_per_m)},
    {G::RodPreisach, "sigma_c", "-", R::Positive,
     "log-normal width of the coercive fields (standard deviation of ln h_c)",
     LAND(in_preisach, PreisachReference, sigma_c)},
    {G::RodPreisach, "Hu0_A_per_m", "A/m", R::Positive,
     "standard deviation of the hysterons' Gaussian interaction fields at T_ref",
     LAND(in_preisach, PreisachReference, Hu0_A_per_m)},
    {G::RodPreisach, "n_c", "-", R::NonNegative,
     "coercivity law H_c^T = H_c0 (M_s^T / M_s)^n_c (the interaction spread scales alike)",
     LAND(in_preisach, PreisachReference, n_c)},
    {G::RodPreisach, "c0", "-", R::UnitInterval,
     "reversible fraction c: M = M_s^T [(1 - c) M_hysterons + c L(H_e / a)]",
     LAND(in_preisach, PreisachReference, c0)},
    {G::RodPreisach, "a0_A_per_m", "A/m", R::Positive,
     "shape a of the reversible Langevin part at T_ref (a^T = a0 T/T_ref, kelvin)",
     LAND(in_preisach, PreisachReference, a0_A_per_m)},
    {G::RodPreisach, "alpha0", "-", R::Any,
     "mean-field coupling alpha: H_e = H + alpha M (the moving Preisach model)",
     LAND(in_preisach, PreisachReference, alpha0)},
};

}  // namespace

const LawTables& preisach_tables() {
  static const LawTables t{kPreisachGroup, kPreisachRows};
  return t;
}

}  // namespace gmasim::model_detail

namespace gmasim {

void PreisachLaw::temperature_laws(const Model& m, const RodModel& rod, double T_law_C, double T_C,
                                   RodConditions& rc) {
  using namespace physics;
  const PreisachReference& p = rod.preisach;
  PreisachCoefficients& q = rc.preisach;
  q.Hc_A_per_m = p.Hc0_A_per_m * std::pow(rc.MsT_mag / m.material.Ms_A_per_m, p.n_c);
  q.c = p.c0;
  q.a_A_per_m =
      p.a0_A_per_m * mean_field_a_factor(T_law_C + kZeroCelsiusInK, m.T_ref_C + kZeroCelsiusInK);
  q.alpha = p.alpha0;
  if (m.options.magnetic_state == MagneticState::Consistent) q.alpha += rc.alpha_sigma;
  q.dist = preisach_distribution(p.sigma_c, p.Hu0_A_per_m / p.Hc0_A_per_m);
  if (!(q.Hc_A_per_m > 0 && std::isfinite(q.Hc_A_per_m) && q.a_A_per_m > 0 && q.c >= 0 && q.c < 1 &&
        std::isfinite(q.alpha) && std::isfinite(q.dist.edge[kPreisachBins])))
    throw InputError(fmt::format(
        "{}: the Preisach law at {} degC is not defined in rod '{}' (H_c = {:.4g} A/m, a = "
        "{:.4g} A/m, c = {:.4g}, alpha = {:.4g})",
        m.spec.source, T_C, rod.name, q.Hc_A_per_m, q.a_A_per_m, q.c, q.alpha));
}

}  // namespace gmasim
