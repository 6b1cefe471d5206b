// gmasim sensitivity: d q / d ln p (or d q / d p) of every claim and metric quantity by
// central differences at two step sizes, all evaluations' experiment points on one work
// list. docs/experiments.md, "Sensitivity".
#include "gmasim/experiments/sensitivity.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "common/numbers.hpp"
#include "experiments/claim_plan.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {
namespace {

// The stencil of each parameter, in evaluation order after the base point: -h_large,
// +h_large, -h_small, +h_small.
constexpr int kStencil = 4;

void check_request(const SensitivityRequest& r) {
  auto fraction = [](double v, const char* what, double lo, double hi) {
    if (!std::isfinite(v) || !(v > lo) || !(v < hi))
      throw InputError(fmt::format("{} {}: must be in ({:g}, {:g})", what, v, lo, hi));
  };
  fraction(r.step_large, "step_large (relative step)", 0.0, 0.5);
  fraction(r.step_small, "step_small (relative step)", 0.0, 0.5);
  if (!(r.step_small < r.step_large))
    throw InputError(fmt::format("steps {:g} and {:g}: the small step must be below the large one",
                                 r.step_small, r.step_large));
  fraction(r.agreement, "agreement (relative)", 0.0, 1.0 + 1e-12);
  if (!std::isfinite(r.floor_fraction) || r.floor_fraction < 0.0 || r.floor_fraction >= 1.0)
    throw InputError(fmt::format("floor_fraction {}: must be in [0, 1)", r.floor_fraction));
  fraction(r.near_null_ratio, "near_null_ratio", 0.0, 1.0);
  if (r.threads < 0) throw InputError(fmt::format("threads {}: must be >= 0", r.threads));
  fields::check_request_fields<SensitivitySettings>(r);  // every row's rule, after these
  if (r.parameters.empty()) throw InputError("sensitivity: no parameter given");
  if (static_cast<double>(r.parameters.size()) > kMaxListValues)
    throw InputError(fmt::format("sensitivity: {} parameters: too many (limit {:g})",
                                 r.parameters.size(), kMaxListValues));
}

std::vector<ParameterInfo> resolve_parameters(const ModelSpec& spec,
                                              const std::vector<SensitivityParameter>& ps) {
  std::vector<ParameterInfo> out;
  for (const auto& p : ps) {
    ParameterInfo info;
    info.name = spec.key_of(p.name);  // InputError if unknown or ambiguous
    for (const auto& o : out)
      if (o.name == info.name) throw InputError(fmt::format("parameter {} given twice", info.name));
    const ParamDef* def = spec.def_of(info.name);
    info.unit = spec.unit_of(info.name);
    info.value = spec.get(info.name);
    info.rule = def ? row_rule_text(*def) : std::string("any");
    info.step = def && def->rule == Rule::Positive ? StepKind::Log : StepKind::Absolute;
    if (!std::isfinite(p.scale) || p.scale < 0.0)
      throw InputError(fmt::format("parameter {}: step scale {}: must be a finite number >= 0",
                                   info.name, p.scale));
    if (info.step == StepKind::Log) {
      info.scale = std::fabs(info.value);
    } else {
      info.scale = p.scale > 0.0 ? p.scale : std::fabs(info.value);
      if (!(info.scale > 0.0))
        throw InputError(
            fmt::format("parameter {} = 0 {} (rule {}): an absolute step needs a scale; give one "
                        "(--param {}:SCALE in {})",
                        info.name, info.unit, info.rule, info.name, info.unit));
    }
    out.push_back(std::move(info));
  }
  return out;
}

// The scale of a claim: its tolerance as a width in its unit; for "less than a bound" the
// bound (the claim allows 0 to it: its values are magnitudes); for "more than a bound" 10 %
// of the bound; none for a ranking (NaN).
double claim_scale(const ClaimSpec& s, std::string& source) {
  const ClaimTolerance& t = s.tolerance;
  switch (t.kind) {
    case ToleranceKind::Absolute:
      source = fmt::format("tolerance +-{:g} {}", t.value, s.unit == "%" ? "pp" : s.unit);
      return t.value;
    case ToleranceKind::Relative:
      source = fmt::format("tolerance {:g} % of the paper's {:g}", 100 * t.value, s.paper);
      return t.value * std::fabs(s.paper);
    case ToleranceKind::LessThan:
      source = fmt::format("the bound {:g} {}", t.bound, s.unit);
      return std::fabs(t.bound);
    case ToleranceKind::GreaterThan:
      source = fmt::format("10 % of the bound {:g} {}", t.bound, s.unit);
      return 0.1 * std::fabs(t.bound);
    default:
      source = "none (a ranking): left out of identifiability";
      return kNaN;
  }
}

struct Selection {
  ClaimsData claims;  // applicable, chosen
  std::vector<MetricQuantity> metrics;
  std::vector<FunctionQuantity> functions;
};

bool wanted(const std::vector<std::string>& only, const std::string& name,
            std::vector<bool>& used) {
  if (only.empty()) return true;
  for (std::size_t k = 0; k < only.size(); ++k)
    if (only[k] == name) {
      used[k] = true;
      return true;
    }
  return false;
}

Selection select_quantities(const SensitivityRequest& r) {
  Selection s;
  std::vector<bool> used(r.only.size(), false);
  const ClaimsData& all = r.claims ? *r.claims : builtin_claims();
  s.claims.source = all.source;
  if (r.use_claims)
    for (const auto& c : all.claims) {
      if (!wanted(r.only, c.id, used)) continue;
      if (c.tolerance.kind == ToleranceKind::NotApplicable) {
        if (!r.only.empty())
          throw InputError(
              fmt::format("claim {} is not applicable (it needs the paper's "
                          "measurements): it has no value to differentiate",
                          c.id));
        continue;
      }
      s.claims.claims.push_back(c);
    }
  for (const auto& m : r.metrics)
    if (wanted(r.only, m.name, used)) s.metrics.push_back(m);
  for (const auto& f : r.functions)
    if (wanted(r.only, f.name, used)) s.functions.push_back(f);
  for (std::size_t k = 0; k < r.only.size(); ++k)
    if (!used[k])
      throw InputError(
          fmt::format("unknown quantity '{}': not a claim of {}, nor a metric or "
                      "function quantity",
                      r.only[k], all.source));
  if (s.claims.claims.empty() && s.metrics.empty() && s.functions.empty())
    throw InputError("sensitivity: no quantity selected");
  return s;
}

// The models of the evaluations: the base, then the stencil of each parameter. A refused
// point (a rule of ModelSpec::set, a check of compile) keeps its message instead.
struct Evaluations {
  std::vector<std::optional<Model>> models;
  std::vector<std::string> refused;
  std::vector<double> values;  // the parameter's value at each point (NaN at the base)
};

double stencil_value(const ParameterInfo& p, int k, double hL, double hS) {
  const double h = k < 2 ? hL : hS;
  const double sign = (k % 2 == 0) ? -1.0 : 1.0;
  return p.step == StepKind::Log ? p.value * (1.0 + sign * h) : p.value + sign * h * p.scale;
}

Evaluations build_models(const Model& m, const std::vector<ParameterInfo>& ps, double hL,
                         double hS) {
  Evaluations ev;
  const std::size_t n = 1 + kStencil * ps.size();
  ev.models.resize(n);
  ev.refused.assign(n, "");
  ev.values.assign(n, kNaN);
  ev.models[0] = m;
  for (std::size_t j = 0; j < ps.size(); ++j)
    for (int k = 0; k < kStencil; ++k) {
      const std::size_t e = 1 + kStencil * j + static_cast<std::size_t>(k);
      const double v = stencil_value(ps[j], k, hL, hS);
      ev.values[e] = v;
      try {
        ModelSpec spec = m.spec;
        spec.set(ps[j].name, v);
        ev.models[e] = compile(spec);
      } catch (const InputError& err) {
        ev.refused[e] = fmt::format("{} = {:.9g}: {}", ps[j].name, v, err.what());
      }
    }
  return ev;
}

struct QuantityValues {
  std::vector<std::vector<double>> q;          // [evaluation][quantity]
  std::vector<std::vector<std::string>> note;  // [evaluation][quantity]
};

// Every quantity at every evaluation: claims (in the selection's order), metrics, functions.
QuantityValues collect(const detail::ClaimPlan& plan, const Evaluations& ev,
                       const std::vector<detail::PartResults>& parts) {
  QuantityValues out;
  const std::size_t nq = plan.claims.claims.size() + plan.metrics.size() + plan.functions.size();
  out.q.assign(ev.models.size(), std::vector<double>(nq, kNaN));
  out.note.assign(ev.models.size(), std::vector<std::string>(nq));
  for (std::size_t e = 0; e < ev.models.size(); ++e) {
    if (!ev.models[e]) continue;
    std::string failed;
    for (const auto& err : parts[e].errors)
      if (!err.empty()) failed += (failed.empty() ? "" : "; ") + err;
    const std::vector<Claim> claims = detail::assemble_claims(plan, *ev.models[e], parts[e]);
    std::size_t i = 0;
    for (const auto& c : claims) {
      out.note[e][i] = c.note;
      out.q[e][i++] = c.ours;
    }
    for (double v : parts[e].metric_values) {
      out.note[e][i] = std::isfinite(v) ? "" : failed;
      out.q[e][i++] = v;
    }
    for (double v : parts[e].function_values) out.q[e][i++] = v;
  }
  return out;
}

std::vector<QuantityInfo> quantity_infos(const detail::ClaimPlan& plan, const QuantityValues& v) {
  std::vector<QuantityInfo> out;
  std::size_t i = 0;
  for (const auto& c : plan.claims.claims) {
    QuantityInfo qi{c.id, c.unit, QuantityKind::Claim, v.q[0][i], 0.0, "", v.note[0][i]};
    qi.scale = claim_scale(c, qi.scale_source);
    out.push_back(std::move(qi));
    ++i;
  }
  for (const auto& m : plan.metrics) {
    const double q0 = v.q[0][i];
    out.push_back({m.name, m.unit, QuantityKind::Metric, q0, m.relative_scale * std::fabs(q0),
                   fmt::format("{:g} % of its value", 100 * m.relative_scale), v.note[0][i]});
    ++i;
  }
  for (const auto& f : plan.functions) {
    out.push_back({f.name, f.unit, QuantityKind::Function, v.q[0][i], f.scale, "given", ""});
    ++i;
  }
  return out;
}

// Why a stencil point gave no finite value, or "".
std::string point_problem(const Evaluations& ev, const QuantityValues& v, std::size_t e,
                          std::size_t i) {
  if (!ev.refused[e].empty()) return ev.refused[e];
  if (std::isfinite(v.q[e][i])) return "";
  return fmt::format("not finite at {}{}", e == 0 ? "the model's parameters" : "a stencil point",
                     v.note[e][i].empty() ? "" : ": " + v.note[e][i]);
}

SensitivityEntry entry(const SensitivityRequest& r, const ParameterInfo& p, const QuantityInfo& qi,
                       const Evaluations& ev, const QuantityValues& v, std::size_t i,
                       std::size_t j) {
  SensitivityEntry en;
  const std::size_t e0 = 1 + kStencil * j;
  for (std::size_t e : {std::size_t{0}, e0, e0 + 1, e0 + 2, e0 + 3}) {
    const std::string why = point_problem(ev, v, e, i);
    if (why.empty()) continue;
    en.flag = ev.refused[e].empty() ? EntryFlag::NonFinite : EntryFlag::StepRefused;
    en.message = why;
    en.derivative_large = en.derivative_small = en.scaled_large = en.scaled_small = kNaN;
    en.disagreement = kNaN;
    return en;
  }
  const auto& q = v.q;
  en.scaled_large = (q[e0 + 1][i] - q[e0][i]) / (2.0 * r.step_large);
  en.scaled_small = (q[e0 + 3][i] - q[e0 + 2][i]) / (2.0 * r.step_small);
  const double per = p.step == StepKind::Log ? 1.0 : p.scale;
  en.derivative_large = en.scaled_large / per;
  en.derivative_small = en.scaled_small / per;
  const double a = std::fabs(en.scaled_large), b = std::fabs(en.scaled_small);
  const double diff = std::fabs(en.scaled_large - en.scaled_small), big = std::max(a, b);
  const double floor =
      r.floor_fraction * (std::isfinite(qi.scale) && qi.scale > 0 ? qi.scale : std::fabs(qi.value));
  en.disagreement = big > 0 ? diff / big : 0.0;
  if (diff > r.agreement * big + floor) {
    en.flag = EntryFlag::Disagree;
    en.message = fmt::format("the steps {:g} and {:g} give {:.4g} and {:.4g} {} per unit {}",
                             r.step_large, r.step_small, en.scaled_large, en.scaled_small, qi.unit,
                             p.step == StepKind::Log ? "ln p" : "p/s");
  }
  return en;
}

Identifiability identify_from(const SensitivityRequest& r, const SensitivityResult& res) {
  std::vector<std::string> names, excluded;
  std::vector<double> scales;
  std::vector<std::vector<double>> rows;
  // A parameter with no finite derivative at all (every stencil refused, ...) enters as a
  // column of zeros (no quantity sees it) rather than removing every quantity.
  const std::size_t np = res.parameters.size();
  std::vector<bool> dead(np, true);
  for (const auto& row : res.entries)
    for (std::size_t j = 0; j < np; ++j) dead[j] = dead[j] && !std::isfinite(row[j].scaled_large);
  for (std::size_t j = 0; j < np; ++j)
    if (dead[j])
      excluded.push_back(res.parameters[j].name + ": no finite derivative (a column of zeros)");
  for (std::size_t i = 0; i < res.quantities.size(); ++i) {
    const QuantityInfo& qi = res.quantities[i];
    std::vector<double> row;
    bool finite = true;
    for (std::size_t j = 0; j < np; ++j) {
      row.push_back(dead[j] ? 0.0 : res.entries[i][j].scaled_large);
      finite = finite && std::isfinite(row.back());
    }
    if (!(std::isfinite(qi.scale) && qi.scale > 0.0)) {
      excluded.push_back(qi.name + ": no scale (" + qi.scale_source + ")");
    } else if (!finite) {
      excluded.push_back(qi.name + ": a derivative is not finite");
    } else {
      names.push_back(qi.name);
      scales.push_back(qi.scale);
      rows.push_back(std::move(row));
    }
  }
  Identifiability id = analyse_identifiability(names, scales, rows, np, r.near_null_ratio);
  id.excluded = std::move(excluded);
  return id;
}

}  // namespace

const char* entry_flag_name(EntryFlag f) {
  switch (f) {
    case EntryFlag::Ok:
      return "ok";
    case EntryFlag::Disagree:
      return "disagree";
    case EntryFlag::NonFinite:
      return "nonfinite";
    case EntryFlag::StepRefused:
      return "step_refused";
  }
  return "?";
}

int SensitivityResult::flagged() const {
  int n = 0;
  for (const auto& row : entries)
    for (const auto& en : row) n += en.flag != EntryFlag::Ok;
  return n;
}

SensitivityResult run_sensitivity(const Model& m, const SensitivityRequest& r,
                                  const ProgressFn& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  check_request(r);
  SensitivityResult res;
  res.parameters = resolve_parameters(m.spec, r.parameters);
  Selection sel = select_quantities(r);
  const detail::ClaimPlan plan = detail::with_lanes(
      detail::plan_claims(sel.claims, r.quick, std::move(sel.metrics), std::move(sel.functions)),
      r.lanes);
  const Evaluations ev = build_models(m, res.parameters, r.step_large, r.step_small);
  // One work list: unit-major (the most expensive units first), evaluation-minor.
  std::vector<detail::PartResults> parts(ev.models.size(), detail::empty_results(plan));
  std::vector<std::pair<std::size_t, std::size_t>> tasks;  // (unit, evaluation)
  for (std::size_t u = 0; u < plan.units.size(); ++u)
    for (std::size_t e = 0; e < ev.models.size(); ++e)
      if (ev.models[e]) tasks.emplace_back(u, e);
  res.threads = resolve_thread_count(r.threads, tasks.size());
  detail::parallel_for(
      tasks.size(), res.threads,
      [&](std::size_t t) {
        const auto [u, e] = tasks[t];
        detail::run_unit(plan, u, *ev.models[e], parts[e]);
      },
      progress);
  const QuantityValues v = collect(plan, ev, parts);
  res.quantities = quantity_infos(plan, v);
  res.entries.assign(res.quantities.size(), {});
  for (std::size_t i = 0; i < res.quantities.size(); ++i)
    for (std::size_t j = 0; j < res.parameters.size(); ++j)
      res.entries[i].push_back(entry(r, res.parameters[j], res.quantities[i], ev, v, i, j));
  res.settings = r;
  res.evaluations = static_cast<long>(ev.models.size());
  res.runs = static_cast<long>(tasks.size());
  res.identifiability = identify_from(r, res);
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

std::vector<SensitivityParameter> model_parameters(const ModelSpec& spec) {
  std::vector<std::pair<long, std::string>> keys;
  for (const auto& [key, pv] : spec.params) {
    const ParamDef* def = spec.def_of(key);
    if (!def || pv.value == 0.0) continue;
    if (def->group == Group::Reference || def->group == Group::ThermalNetwork) continue;
    keys.emplace_back(pv.line, key);
  }
  std::sort(keys.begin(), keys.end());  // file order (defaults, line 0, first)
  std::vector<SensitivityParameter> out;
  for (auto& [line, key] : keys) out.push_back({std::move(key), 0.0});
  return out;
}

}  // namespace gmasim
