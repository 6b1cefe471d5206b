// gmasim design (gmasim/identify/design.hpp): the quantities of a candidate design, its
// evaluation, the request's checks and the report. The search is nsga2.cpp's.
#include "gmasim/identify/design.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/model/validate.hpp"
#include "identify/checkpoint_text.hpp"

namespace gmasim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// name, unit, how many temperatures it takes (0, 1 or 2), what it is
struct QuantityRow {
  const char* name;
  int temperatures;
  const char* meaning;
};
constexpr QuantityRow kQuantities[] = {
    {"stroke_um", 1, "the drive's stroke at T degC [um] (last period)"},
    {"hysteresis_um", 1, "the drive's hysteresis width at T degC [um]"},
    {"B_pp_T", 1, "the drive's flux density peak-to-peak at T degC [T]"},
    {"retention_pct", 2, "100 stroke(T2) / stroke(T1) [%]"},
    {"coil_copper_loss_W", 1, "the drive's copper loss I_rms^2 R(T) with the coil at T degC [W]"},
    {"temperature_rise_K", 1,
     "that loss over thermal_network.housing_to_ambient_W_per_K: the housing's steady rise [K]"},
    {"bandwidth_Hz", 0,
     "small-signal -3 dB bandwidth at the reference temperature and bias [Hz] (5000: none in "
     "the band)"},
    {"first_resonance_Hz", 0, "small-signal first resonance at the reference temperature [Hz]"},
    {"rods_mass_kg", 0, "the rods' mass, derived from their geometry [kg]"},
    {"rods_volume_m3", 0, "the rods' volume, pi (d_o^2 - d_i^2) l / 4 summed [m^3]"},
    {"coil_resistance_ohm", 0, "the coil's resistance at T_ref [ohm]"},
    {"current_peak_A", 0, "the drive's largest |current| [A]"},
};

const QuantityRow* row_of(const std::string& name) {
  for (const auto& r : kQuantities)
    if (name == r.name) return &r;
  return nullptr;
}

bool is_drive_key(const std::string& key) {
  return std::any_of(std::begin(kDesignDriveKeys), std::end(kDesignDriveKeys),
                     [&](const char* k) { return key == k; });
}

double parse_number(const std::string& s, const std::string& what, const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw InputError(fmt::format("{} '{}': '{}' is not a finite number", what, clip_for_message(text),
                               clip_for_message(s)));
}

// The drive of a candidate: the request's, with its drive variables set.
struct Drive {
  double current_min_A, current_pp_A;
};

Drive drive_of(const DesignRequest& r, const std::vector<double>& x) {
  Drive d{r.current_min_A, r.current_pp_A};
  for (std::size_t k = 0; k < r.variables.size(); ++k) {
    if (r.variables[k].key == "drive.current_pp_A") d.current_pp_A = x[k];
    if (r.variables[k].key == "drive.current_min_A") d.current_min_A = x[k];
  }
  return d;
}

// The temperatures a candidate's runs need, sorted.
std::vector<double> run_temperatures(const std::vector<DesignQuantity>& qs) {
  std::set<double> Ts;
  for (const auto& q : qs) {
    const std::string& n = q.name;
    if (n == "stroke_um" || n == "hysteresis_um" || n == "B_pp_T") Ts.insert(q.T1_C);
    if (n == "retention_pct") Ts.insert({q.T1_C, q.T2_C});
  }
  return {Ts.begin(), Ts.end()};
}

bool needs_markers(const std::vector<DesignQuantity>& qs) {
  return std::any_of(qs.begin(), qs.end(), [](const DesignQuantity& q) {
    return q.name == "bandwidth_Hz" || q.name == "first_resonance_Hz";
  });
}

// The quantities of the objectives, then those of the constraints not already among them.
std::vector<DesignQuantity> quantities_of(const DesignRequest& r) {
  std::vector<DesignQuantity> qs;
  auto add = [&](const DesignQuantity& q) {
    for (const auto& p : qs)
      if (p.label() == q.label()) return;
    qs.push_back(q);
  };
  for (const auto& o : r.objectives) add(o.quantity);
  for (const auto& c : r.constraints) add(c.quantity);
  return qs;
}

std::size_t index_of(const std::vector<DesignQuantity>& qs, const DesignQuantity& q) {
  for (std::size_t i = 0; i < qs.size(); ++i)
    if (qs[i].label() == q.label()) return i;
  throw std::logic_error("design: a quantity not in the list");
}

// The spec of a candidate: the base with its model variables set (InputError if refused).
ModelSpec candidate_spec(const ModelSpec& base, const DesignRequest& r,
                         const std::vector<double>& x) {
  ModelSpec spec = base;
  for (std::size_t k = 0; k < r.variables.size(); ++k)
    if (!is_drive_key(r.variables[k].key)) spec.set(r.variables[k].key, x[k]);
  return spec;
}

void check_variables(const ModelSpec& base, const DesignRequest& r) {
  if (r.variables.empty())
    throw InputError("design: no design variable (give --variable KEY=LOWER:UPPER)");
  std::set<std::string> seen;
  for (const auto& v : r.variables) {
    if (!seen.insert(v.key).second)
      throw InputError(fmt::format("--variable {}: the key is given twice", v.key));
    if (!(std::isfinite(v.lower) && std::isfinite(v.upper) && v.lower < v.upper))
      throw InputError(
          fmt::format("--variable {}={:g}:{:g}: the bounds must be finite with "
                      "lower < upper",
                      v.key, v.lower, v.upper));
    if (is_drive_key(v.key)) continue;
    // Both bounds must be values the key's own rule accepts (a length > 0, ...).
    for (double b : {v.lower, v.upper}) {
      ModelSpec spec = base;
      try {
        spec.set(v.key, b);
      } catch (const InputError& e) {
        throw InputError(fmt::format("--variable {}={:g}:{:g}: bound {:g}: {}", v.key, v.lower,
                                     v.upper, b, e.what()));
      }
    }
  }
}

void check_request(const ModelSpec& base, const DesignRequest& r) {
  check_variables(base, r);
  if (r.objectives.size() < 2)
    throw InputError(fmt::format(
        "design: {} objective(s); give two or more (--minimize Q / --maximize Q), Q one of {}",
        r.objectives.size(), design_quantity_list()));
  for (const auto& c : r.constraints)
    if (!std::isfinite(c.bound))
      throw InputError(
          fmt::format("--constraint {}: the bound must be finite", c.quantity.label()));
  require_finite(r.current_min_A, "current minimum (--current-min)", "A");
  if (!(r.current_pp_A >= 0.0) || !std::isfinite(r.current_pp_A))
    throw InputError(
        fmt::format("current peak-to-peak (--current-pp) = {} A: must be >= 0", r.current_pp_A));
  if (!(r.frequency_Hz > 0.0) || !std::isfinite(r.frequency_Hz))
    throw InputError(fmt::format("frequency (--frequency) = {} Hz: must be > 0", r.frequency_Hz));
  if (!(r.periods >= 1.0) || !std::isfinite(r.periods))
    throw InputError(fmt::format("periods (--periods) = {}: must be >= 1", r.periods));
  if (!(r.dt_s >= 0.0) || !std::isfinite(r.dt_s))
    throw InputError(fmt::format("dt = {} s (--dt): must be >= 0 (0: the automatic rule)", r.dt_s));
  require_finite(r.reference_temperature_C, "reference temperature (--reference-temperature)",
                 "degC");
  require_finite(r.bias_A, "bias current (--bias)", "A");
  if (r.generations > 100000)
    throw InputError(
        fmt::format("generations (--generations) = {}: must be <= 100000", r.generations));
  if (r.population > 100000)
    throw InputError(
        fmt::format("population (--population) = {}: must be <= 100000", r.population));
  if (r.resume && r.checkpoint_path.empty())
    throw InputError("--resume: give the checkpoint to resume with --checkpoint FILE");
}

// Everything that decides the search's result, for the checkpoint's fingerprint.
std::string fingerprint(const ModelSpec& base, const DesignRequest& r) {
  std::string s = base.text;
  for (const auto& [name, p] : base.params) s += fmt::format("\n{}={:.17g}", name, p.value);
  for (const auto& v : r.variables)
    s += fmt::format("\nvar {} {:.17g} {:.17g}", v.key, v.lower, v.upper);
  for (const auto& o : r.objectives)
    s += fmt::format("\nobj {} {}", o.quantity.label(), o.maximise);
  for (const auto& c : r.constraints)
    s += fmt::format("\ncon {} {} {:.17g}", c.quantity.label(), c.at_most, c.bound);
  s += fmt::format("\ndrive {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}",
                   r.current_min_A, r.current_pp_A, r.frequency_Hz, r.periods, r.dt_s,
                   r.reference_temperature_C, r.bias_A);
  return s;
}

}  // namespace

std::string DesignQuantity::label() const {
  if (std::isnan(T1_C)) return name;
  if (std::isnan(T2_C)) return fmt::format("{}@{:g}", name, T1_C);
  return fmt::format("{}@{:g}:{:g}", name, T1_C, T2_C);
}

std::string design_quantity_list() {
  std::string s;
  for (const auto& r : kQuantities) {
    const char* form = r.temperatures == 0 ? "" : r.temperatures == 1 ? "@T" : "@T1:T2";
    s += fmt::format("{}{}{} ({})", s.empty() ? "" : "; ", r.name, form, r.meaning);
  }
  return s;
}

DesignQuantity parse_design_quantity(const std::string& text, const std::string& what) {
  const auto at = text.find('@');
  DesignQuantity q;
  q.name = text.substr(0, at);
  const QuantityRow* row = row_of(q.name);
  if (!row)
    throw InputError(fmt::format("{} '{}': unknown quantity '{}'; one of: {}", what,
                                 clip_for_message(text), clip_for_message(q.name),
                                 design_quantity_list()));
  const std::string temps = at == std::string::npos ? "" : text.substr(at + 1);
  const auto colon = temps.find(':');
  const int given = temps.empty() ? 0 : colon == std::string::npos ? 1 : 2;
  if (given != row->temperatures)
    throw InputError(fmt::format("{} '{}': {} takes {} (e.g. {})", what, clip_for_message(text),
                                 q.name,
                                 row->temperatures == 0   ? "no temperature"
                                 : row->temperatures == 1 ? "one temperature in degC, NAME@T"
                                                          : "two temperatures in degC, NAME@T1:T2",
                                 row->temperatures == 0   ? q.name
                                 : row->temperatures == 1 ? q.name + "@20"
                                                          : q.name + "@20:70"));
  if (given >= 1) q.T1_C = parse_number(temps.substr(0, colon), what, text);
  if (given == 2) q.T2_C = parse_number(temps.substr(colon + 1), what, text);
  return q;
}

DesignConstraint parse_design_constraint(const std::string& text) {
  DesignConstraint c;
  auto op = text.find("<=");
  c.at_most = op != std::string::npos;
  if (!c.at_most) op = text.find(">=");
  if (op == std::string::npos || op == 0 || op + 2 >= text.size())
    throw InputError(fmt::format(
        "--constraint '{}': expected QUANTITY<=BOUND or QUANTITY>=BOUND (e.g. rods_mass_kg<=0.1, "
        "temperature_rise_K@20<=10)",
        clip_for_message(text)));
  c.quantity = parse_design_quantity(text.substr(0, op), "--constraint");
  c.bound = parse_number(text.substr(op + 2), "--constraint", text);
  return c;
}

DesignCandidate evaluate_design(const ModelSpec& base, const DesignRequest& r,
                                const std::vector<DesignQuantity>& quantities,
                                const std::vector<double>& x) {
  DesignCandidate c;
  c.x = x;
  c.values.assign(quantities.size(), kNaN);
  const Drive drive = drive_of(r, x);
  try {
    const Model m = compile(candidate_spec(base, r, x));
    std::map<double, Metrics> at;  // the drive's metrics by temperature
    for (double T : run_temperatures(quantities)) {
      SimulationSettings s;
      s.temperature_C = T;
      s.waveform = biased_sine(drive.current_pp_A, r.frequency_Hz, drive.current_min_A);
      s.periods = r.periods;
      s.dt_s = r.dt_s;
      const Result res = simulate(m, s);
      if (res.diverged || !res.has_metrics) {
        c.failed = true;
        return c;
      }
      at[T] = res.metrics;
    }
    LinearFrfMarkers lm;
    if (needs_markers(quantities)) lm = linear_frf_markers(m, r.reference_temperature_C, r.bias_A);
    for (std::size_t i = 0; i < quantities.size(); ++i) {
      const DesignQuantity& q = quantities[i];
      const std::string& n = q.name;
      double v = kNaN;
      if (n == "stroke_um") v = at[q.T1_C].stroke_um;
      if (n == "hysteresis_um") v = at[q.T1_C].hysteresis_um;
      if (n == "B_pp_T") v = at[q.T1_C].B_pp_T;
      if (n == "retention_pct") v = 100.0 * at[q.T2_C].stroke_um / at[q.T1_C].stroke_um;
      if (n == "coil_copper_loss_W" || n == "temperature_rise_K") {
        v = coil_copper_loss_W(m, drive.current_min_A, drive.current_pp_A, q.T1_C);
        if (n == "temperature_rise_K") v /= m.thermal_network.G_housing_ambient_W_per_K;
      }
      if (n == "bandwidth_Hz")
        v = lm.bandwidth_3dB_Hz > 0.0 ? lm.bandwidth_3dB_Hz : FrfRequest{}.f_max_Hz;
      if (n == "first_resonance_Hz") v = lm.first_resonance_Hz;
      if (n == "rods_mass_kg") {
        v = 0.0;
        for (const auto& rod : m.rods) v += rod.mass_kg;
      }
      if (n == "rods_volume_m3") {
        v = 0.0;
        for (const auto& rod : m.rods)
          v += 0.25 * M_PI *
               (rod.outer_diameter_m * rod.outer_diameter_m -
                rod.inner_diameter_m * rod.inner_diameter_m) *
               rod.length_m;
      }
      if (n == "coil_resistance_ohm") v = m.thermal_network.coil_resistance_ohm;
      if (n == "current_peak_A")
        v = std::max(std::fabs(drive.current_min_A),
                     std::fabs(drive.current_min_A + drive.current_pp_A));
      c.values[i] = v;
    }
  } catch (const InputError&) {  // a candidate its keys' rules refuse, or above T_c
    c.failed = true;
    std::fill(c.values.begin(), c.values.end(), kNaN);
    return c;
  } catch (const DivergenceError&) {
    c.failed = true;
    std::fill(c.values.begin(), c.values.end(), kNaN);
    return c;
  }
  for (const auto& k : r.constraints) {
    const double v = c.values[index_of(quantities, k.quantity)];
    const double excess = k.at_most ? v - k.bound : k.bound - v;
    const double scale = k.bound != 0.0 ? std::fabs(k.bound) : 1.0;
    if (!std::isfinite(v))
      c.violation += 1.0;
    else if (excess > 0.0)
      c.violation += excess / scale;
  }
  return c;
}

DesignResult run_design(const ModelSpec& base, const DesignRequest& r) {
  check_request(base, r);
  const auto wall0 = std::chrono::steady_clock::now();
  DesignResult res;
  res.quantities = quantities_of(r);
  const std::size_t nobj = r.objectives.size(), nq = res.quantities.size();
  std::vector<double> lower, upper;
  for (const auto& v : r.variables) {
    lower.push_back(v.lower);
    upper.push_back(v.upper);
  }
  // The evaluator's row: the objectives to minimise, the violation, the failure flag, then
  // every quantity in its own sense.
  auto evaluate = [&](const std::vector<double>& x) {
    const DesignCandidate c = evaluate_design(base, r, res.quantities, x);
    std::vector<double> row(nobj + 2 + nq);
    for (std::size_t k = 0; k < nobj; ++k) {
      const double v = c.values[index_of(res.quantities, r.objectives[k].quantity)];
      row[k] = r.objectives[k].maximise ? -v : v;
    }
    row[nobj] = c.failed ? 1e6 : c.violation;
    row[nobj + 1] = c.failed ? 1.0 : 0.0;
    std::copy(c.values.begin(), c.values.end(),
              row.begin() + static_cast<std::ptrdiff_t>(nobj + 2));
    return row;
  };
  Nsga2Settings s;
  s.population = r.population;
  s.generations = r.generations;
  s.seed = r.seed;
  s.threads = resolve_thread_count(r.threads, static_cast<std::size_t>(r.population));
  s.checkpoint_path = r.checkpoint_path;
  s.fingerprint = fingerprint(base, r);
  s.resume = r.resume;
  s.comm = r.comm;
  s.progress = r.progress;
  const Nsga2Outcome o = nsga2_search(lower, upper, nobj, nobj + 2 + nq, evaluate, s);
  for (std::size_t i = 0; i < o.x.size(); ++i) {
    DesignCandidate c;
    c.x = o.x[i];
    c.violation = o.values[i][nobj];
    c.failed = o.values[i][nobj + 1] != 0.0;
    c.values.assign(o.values[i].begin() + static_cast<std::ptrdiff_t>(nobj + 2), o.values[i].end());
    res.population.push_back(std::move(c));
  }
  res.front = feasible_front(o.values, nobj);
  res.generations = o.generations;
  res.resumed_from = o.resumed_from;
  res.evaluations = o.evaluations;
  res.ranks = r.comm ? r.comm->size() : 1;
  res.threads = s.threads;
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

Report design_report(const DesignRequest& r, const DesignResult& res) {
  Report rep;
  rep.experiment = "design";
  std::vector<std::string> cols;
  for (const auto& v : r.variables) cols.push_back(v.key);
  for (const auto& q : res.quantities) cols.push_back(q.label());
  cols.insert(cols.end(), {"violation", "failed", "on_front"});
  Table front{"front", cols, {}}, pop{"population", cols, {}};
  for (std::size_t i = 0; i < res.population.size(); ++i) {
    const DesignCandidate& c = res.population[i];
    const bool on = std::find(res.front.begin(), res.front.end(), i) != res.front.end();
    std::vector<Cell> row(c.x.begin(), c.x.end());
    row.insert(row.end(), c.values.begin(), c.values.end());
    row.emplace_back(c.violation);
    row.emplace_back(c.failed);
    row.emplace_back(on);
    pop.rows.push_back(row);
  }
  for (std::size_t i : res.front) front.rows.push_back(pop.rows[i]);
  std::string objectives, constraints;
  for (const auto& o : r.objectives)
    objectives += fmt::format("{}{} {}", objectives.empty() ? "" : ", ",
                              o.maximise ? "maximize" : "minimize", o.quantity.label());
  for (const auto& c : r.constraints)
    constraints += fmt::format("{}{}{}{:g}", constraints.empty() ? "" : ", ", c.quantity.label(),
                               c.at_most ? "<=" : ">=", c.bound);
  rep.meta = {{"objectives", Cell(objectives)},
              {"constraints", Cell(constraints.empty() ? std::string("none") : constraints)},
              {"current_min_A", r.current_min_A},
              {"current_pp_A", r.current_pp_A},
              {"frequency_Hz", r.frequency_Hz},
              {"periods", r.periods},
              {"reference_temperature_C", r.reference_temperature_C},
              {"bias_A", r.bias_A},
              {"algorithm", Cell(std::string("NSGA-II (pagmo2)"))},
              {"population", r.population},
              {"generations", res.generations},
              {"resumed_from_generation", res.resumed_from},
              {"seed", static_cast<double>(r.seed)},
              {"evaluations", static_cast<double>(res.evaluations)},
              {"front_size", static_cast<double>(res.front.size())},
              {"ranks", res.ranks},
              {"threads", res.threads},
              {"wall_time_s", res.wall_time_s}};
  rep.tables = {std::move(front), std::move(pop)};
  return rep;
}

}  // namespace gmasim
