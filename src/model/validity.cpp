// Physical validity (gmasim/model/validity.hpp; issue 19, items 3 and 8): the run loop's guard, the
// model's hard limits and warnings, and its computable and validated temperature ranges.
#include "gmasim/model/validity.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/model/derived.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "model/conditions_detail.hpp"

namespace gmasim {
namespace {

[[noreturn]] void beyond(double t_s, const std::string& rod, const char* quantity, double value,
                         double bound, const char* rule) {
  throw DivergenceError(
      t_s, rod, quantity, value,
      fmt::format("beyond the physical bound {:.4g}: {}; the model is outside its range (check "
                  "the values `gmasim model check` warns about)",
                  bound, rule));
}

}  // namespace

void check_physical_validity(const Model& m, const Conditions& c, const State& s, double t_s) {
  const double lambda_s = m.material.lambda_s;
  const bool consistent = m.options.magnetic_state == MagneticState::Consistent;
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    const RodState& r = s.rods[i];
    const RodConditions& rc = c.rods[i];
    const double q = rc.MsT_mag / rc.Ms_strain_A_per_m;
    const double strain_bound = kStrainGuardFactor * lambda_s * q * q;
    if (!(std::fabs(r.lambda) <= strain_bound)) [[unlikely]]
      beyond(t_s, m.rods[i].name, "magnetostriction lambda [-]", r.lambda, strain_bound,
             "eq. (11) gives at most 1.5 lambda_s (M/M_s)^2 with |M| <= 1.5 M_s^T");
    if (!(std::fabs(r.x_m) < rc.length_m)) [[unlikely]]
      beyond(t_s, m.rods[i].name, "displacement x [m]", r.x_m, rc.length_m,
             "a rod cannot move by more than its length l^T");
    if (consistent) {
      const double Ms = std::max(m.material.Ms_A_per_m, rc.MsT_mag);
      const double B_bound = physics::kMu0 * (kFluxGuardMsFactor * Ms + std::fabs(r.H_A_per_m));
      if (!(std::fabs(r.B_T) <= B_bound)) [[unlikely]]
        beyond(t_s, m.rods[i].name, "flux density B [T]", r.B_T, B_bound,
               "B = mu0 (H + M) with |M| <= M_s");
    }
  }
}

void check_model_validity(const Model& m) {
  const double pi = physics::kPi;
  for (const auto& rod : m.rods) {
    const double ro = 0.5 * rod.outer_diameter_m, ri = 0.5 * rod.inner_diameter_m;
    const double area = pi * (ro * ro - ri * ri);
    const double sigma = m.preload_N / area;
    if (sigma > kMaxPrestress_Pa)
      throw InputError(located(
          m.spec.source, m.spec.line_of(preload_key(m.spec)),
          fmt::format("preload.force_N = {:g} N gives rod '{}' a prestress of {:.4g} MPa: above "
                      "{:g} MPa, beyond the compressive strength of Terfenol-D (305-880 MPa), "
                      "the rod would be crushed",
                      m.preload_N, rod.name, sigma * 1e-6, kMaxPrestress_Pa * 1e-6)));
  }
}

namespace {

// Known ranges of Terfenol-D (manufacturer data, Engdahl's handbook) and of actuators of its
// kind, generous: a value outside is a typo or another material.
struct KnownRange {
  const char* key;
  double lo, hi;
  const char* what;
};
constexpr KnownRange kKnownRanges[] = {
    {"material.Ms_A_per_m", 3e5, 1.5e6, "Terfenol-D's saturation magnetisation (7.6e5-8e5 A/m)"},
    {"material.lambda_s", 2e-4, 5e-3, "Terfenol-D's saturation magnetostriction (~1e-3)"},
    {"material.Es_Pa", 5e9, 2.5e11, "Terfenol-D's modulus (18-110 GPa)"},
    {"material.sigma_lambda_Pa", 1e5, 1e9, "the stress scale of eq. (6), (13)"},
    {"material.Tc_C", 250.0, 500.0, "Terfenol-D's Curie temperature (380 degC)"},
    {"material.rho0_ohm_m", 1e-7, 1e-5, "Terfenol-D's resistivity (6e-7 ohm m)"},
    {"material.alpha_thermal_per_K", 1e-6, 1e-4, "Terfenol-D's expansion coefficient (12e-6 /K)"},
};
// A prestress above this is far beyond what actuators use (5-20 MPa, at most ~60 MPa).
constexpr double kWarnPrestress_Pa = 100e6;

}  // namespace

std::vector<std::string> model_warnings(const Model& m) {
  std::vector<std::string> out;
  const ModelSpec& spec = m.spec;
  for (const auto& k : kKnownRanges) {
    const auto it = spec.params.find(k.key);
    if (it == spec.params.end()) continue;
    const double v = it->second.value;
    if (v >= k.lo && v <= k.hi) continue;
    const std::string unit = spec.unit_of(k.key);
    const std::string u = unit == "-" ? "" : " " + unit;
    out.push_back(located(
        spec.source, it->second.line,
        fmt::format("{} = {:g}{}: far outside {}, [{:g}, {:g}]{}; the results may mean nothing",
                    k.key, v, u, k.what, k.lo, k.hi, u)));
  }
  // A value the file gives in place of one the geometry derives (gmasim/model/derived.hpp).
  for (const auto& d : derived_quantities(spec)) {
    if (!d.overridden || !(d.derived > 0)) continue;
    const double off = d.value / d.derived - 1.0;
    if (std::fabs(off) <= kDerivedWarnFraction) continue;
    out.push_back(located(
        spec.source, spec.line_of(d.name),
        fmt::format("{} = {:g} {} overrides the {:.4g} {} its geometry gives ({}), {:+.0f} %: "
                    "remove it to use the derived value, or check the geometry",
                    d.name, d.value, spec.unit_of(d.name), d.derived, spec.unit_of(d.name),
                    d.formula, 100.0 * off)));
  }
  double worst = 0.0;  // the largest prestress over the rods, and where
  std::string where;
  for (const auto& rod : m.rods) {
    const double ro = 0.5 * rod.outer_diameter_m, ri = 0.5 * rod.inner_diameter_m;
    const double sigma = m.preload_N / (physics::kPi * (ro * ro - ri * ri));
    if (sigma > worst) {
      worst = sigma;
      where = rod.name;
    }
  }
  if (worst > kWarnPrestress_Pa)
    out.push_back(located(
        spec.source, spec.line_of(preload_key(spec)),
        fmt::format("preload.force_N = {:g} N: a prestress of up to {:.4g} MPa (rod '{}'), far "
                    "above what actuators use (5-20 MPa; at most ~{:g} MPa)",
                    m.preload_N, worst * 1e-6, where, kWarnPrestress_Pa * 1e-6)));
  return out;
}

namespace {

bool computable_at(const Model& m, double T, const Freeze& fz) {
  try {
    (void)model_detail::conditions_at(m, T, fz);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

// From `good` (computable) towards `limit` (excluded when `limit_excluded`): the last computable
// temperature of the connected stretch, to 0.01 degC.
double edge(const Model& m, const Freeze& fz, double good, double limit, bool limit_excluded) {
  const double dir = limit > good ? 1.0 : -1.0;
  double bad = limit;
  bool found_bad = false;
  for (double t = good + dir; dir * (limit - t) > 0.0; t += dir) {
    if (!computable_at(m, t, fz)) {
      bad = t;
      found_bad = true;
      break;
    }
    good = t;
  }
  if (!found_bad) {
    if (!limit_excluded && computable_at(m, limit, fz)) return limit;
    bad = limit;
  }
  while (std::fabs(bad - good) > 0.005) {
    const double mid = 0.5 * (good + bad);
    (computable_at(m, mid, fz) ? good : bad) = mid;
  }
  return good;
}

}  // namespace

std::optional<TemperatureRange> computable_range(const Model& m, const Freeze& fz) {
  const double Tr = m.T_ref_C, Tc = m.material.Tc_C;
  if (!(Tc > Tr) || !computable_at(m, Tr, fz)) return std::nullopt;
  TemperatureRange r;
  r.min_C = edge(m, fz, Tr, -physics::kZeroCelsiusInK, false);
  r.max_C = edge(m, fz, Tr, Tc, true);
  if (Tc - r.max_C <= 0.01 && computable_at(m, std::nextafter(Tc, Tr), fz)) {
    r.max_C = Tc;
    r.below_curie = true;
  }
  // Rounded inwards to 0.01 degC: every temperature of the printed range is computable.
  r.min_C = std::ceil(r.min_C * 100.0 - 1e-9) / 100.0;
  if (!r.below_curie) r.max_C = std::floor(r.max_C * 100.0 + 1e-9) / 100.0;
  return r;
}

std::string range_text(const TemperatureRange& r) {
  if (r.below_curie) return fmt::format("[{:g}, {:g}) degC (below T_c)", r.min_C, r.max_C);
  return fmt::format("[{:g}, {:g}] degC", r.min_C, r.max_C);
}

TemperatureRange validated_range(const Model& m) {
  return {m.validity.validated_min_C, m.validity.validated_max_C, false};
}

std::optional<std::string> temperature_warning(const Model& m, double T) {
  const TemperatureRange v = validated_range(m);
  if (T >= v.min_C && T <= v.max_C) return std::nullopt;
  return fmt::format(
      "temperature {:g} degC: outside the range where {} was validated, {} "
      "(validity.validated_min_C/max_C); the results are an extrapolation",
      T, m.spec.source, range_text(v));
}

}  // namespace gmasim
