// The fit specification: which model parameters to identify (bounds, scale) and which scalar
// targets to match. TOML file or inline "name:lower:upper[:log],...". docs/identify.md.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <string_view>

#include "common/text_io.hpp"
#include "common/toml_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/claims.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"

namespace gmasim {
namespace {

struct KindName {
  TargetKind kind;
  std::string_view name;
  bool needs_reference;  // a change/retention target: also runs at reference_temperature_C
  bool sine;             // computed from a biased-sine run (else: resonance at the bias)
};
constexpr KindName kKinds[] = {
    {TargetKind::StrokeUm, "stroke_um", false, true},
    {TargetKind::HysteresisUm, "hysteresis_um", false, true},
    {TargetKind::BppT, "B_pp_T", false, true},
    {TargetKind::StrokeChangePct, "stroke_change_pct", true, true},
    {TargetKind::HysteresisChangePct, "hysteresis_change_pct", true, true},
    {TargetKind::BppChangePct, "B_pp_change_pct", true, true},
    {TargetKind::RetentionPct, "retention_pct", true, true},
    {TargetKind::ResonanceHz, "resonance_Hz", false, false},
    {TargetKind::FrfPeakHz, "frf_peak_Hz", false, false},
    {TargetKind::BandwidthHz, "bandwidth_Hz", false, false},
    {TargetKind::ModulusGPa, "modulus_GPa", false, false},
};

std::string kind_list() {
  std::string s;
  for (const auto& k : kKinds) {
    if (!s.empty()) s += ", ";
    s += k.name;
  }
  return s;
}

long line_of(const toml::node& n) {
  const auto l = static_cast<long>(n.source().begin.line);
  return l > 0 ? l : 1;
}

void check_bounds(const FitParameter& p, const std::string& src) {
  auto fail = [&](const std::string& msg) {
    throw InputError(located(src, p.line, fmt::format("parameter {}: {}", p.name, msg)));
  };
  if (!std::isfinite(p.lower) || !std::isfinite(p.upper)) fail("bounds must be finite");
  if (!(p.lower < p.upper))
    fail(fmt::format("lower bound {:g} must be < upper bound {:g}", p.lower, p.upper));
  if (p.scale == ParamScale::Log && !(p.lower * p.upper > 0.0)) {
    fail(
        fmt::format("log scale needs bounds of one sign, both non-zero (got {:g} .. {:g}); use "
                    "scale = \"linear\"",
                    p.lower, p.upper));
  }
  if (p.has_start && !std::isfinite(p.start)) fail("start must be finite");
}

double number(const toml::table& t, std::string_view key, const std::string& src, bool& found) {
  const toml::node* n = t.get(key);
  found = n != nullptr;
  if (!n) return 0.0;
  const auto v = n->value<double>();
  if (!v) throw InputError(located(src, line_of(*n), fmt::format("{}: expected a number", key)));
  if (!std::isfinite(*v))
    throw InputError(located(src, line_of(*n), fmt::format("{}: must be finite", key)));
  return *v;
}

void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed,
                const std::string& where, const std::string& src) {
  for (const auto& [k, v] : t) {
    bool ok = false;
    for (auto a : allowed) ok = ok || a == k.str();
    if (!ok) {
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      throw InputError(located(
          src, line_of(v),
          fmt::format("unknown key '{}' in {}; expected one of: {}", k.str(), where, list)));
    }
  }
}

FitParameter read_parameter(const toml::table& t, const std::string& src) {
  check_keys(t, {"name", "lower", "upper", "scale", "start"}, "[[parameter]]", src);
  FitParameter p;
  p.line = line_of(t);
  const auto name = t["name"].value<std::string>();
  if (!name || name->empty())
    throw InputError(located(src, p.line, "[[parameter]]: missing name = \"dotted.model.name\""));
  p.name = *name;
  bool has_lo = false, has_hi = false;
  p.lower = number(t, "lower", src, has_lo);
  p.upper = number(t, "upper", src, has_hi);
  if (!has_lo || !has_hi) {
    throw InputError(
        located(src, p.line,
                fmt::format("parameter {}: missing {} bound", p.name, has_lo ? "upper" : "lower")));
  }
  p.start = number(t, "start", src, p.has_start);
  if (const toml::node* s = t.get("scale")) {
    const auto v = s->value<std::string>();
    if (v && *v == "log") {
      p.scale = ParamScale::Log;
    } else if (v && *v == "linear") {
      p.scale = ParamScale::Linear;
    } else {
      throw InputError(
          located(src, line_of(*s),
                  fmt::format("parameter {}: scale must be \"linear\" or \"log\"", p.name)));
    }
  }
  check_bounds(p, src);
  return p;
}

const KindName* find_kind(std::string_view name) {
  for (const auto& k : kKinds)
    if (k.name == name) return &k;
  return nullptr;
}

// A target `claim = "<id>"`: the claim's fit target (kind, value, condition) from the claims
// data (data/claims.toml, or the spec's `claims = "file"`).
ClaimFitTarget resolve_claim(const toml::table& t, const std::string& src,
                             const ClaimsData& claims) {
  const toml::node* n = t.get("claim");
  const auto id = n->value<std::string>();
  if (!id || id->empty())
    throw InputError(located(src, line_of(*n), "[[target]]: claim must be a claim id (string)"));
  const ClaimSpec* c = claims.find(*id);
  if (!c)
    throw InputError(located(src, line_of(*n),
                             fmt::format("[[target]]: no claim '{}' in {}", *id, claims.source)));
  const auto ft = claim_fit_target(*c);
  if (!ft)
    throw InputError(
        located(src, line_of(*n),
                fmt::format("[[target]]: claim '{}' (kind {}, {}:{}) has no fit target "
                            "counterpart; claims of kind {} can be targets",
                            *id, c->kind, claims.source, c->line, [] {
                              std::string s;
                              for (const auto& k : claim_kinds())
                                if (!k.fit_target.empty()) s += (s.empty() ? "" : ", ") + k.name;
                              return s;
                            }())));
  if (const toml::node* k = t.get("kind")) {
    const auto kind = k->value<std::string>();
    if (!kind || *kind != ft->kind)
      throw InputError(located(
          src, line_of(*k),
          fmt::format("[[target]]: kind '{}' contradicts claim '{}', a {} target; leave kind out",
                      kind ? *kind : "?", *id, ft->kind)));
  }
  return *ft;
}

// The target's kind: the claim's, or `kind = "..."`.
const KindName& target_kind(const toml::table& t, const std::string& src, long line,
                            const ClaimFitTarget* from) {
  const auto kind = from ? std::optional<std::string>(from->kind) : t["kind"].value<std::string>();
  const KindName* kn = kind ? find_kind(*kind) : nullptr;
  if (!kn) {
    throw InputError(located(src, line,
                             fmt::format("[[target]]: kind must be one of {}{}", kind_list(),
                                         kind ? fmt::format(" (got '{}')", *kind) : "")));
  }
  return *kn;
}

// The numbers of one [[target]] table: written in it, or given by the claim it names
// (`from`; such a number must not be written again).
class TargetFields {
 public:
  TargetFields(const toml::table& t, const std::string& src, long line, const KindName& kind,
               const ClaimFitTarget* from, const std::string& claim_id)
      : t_(t), src_(src), line_(line), kind_(kind), from_(from), claim_id_(claim_id) {}

  double required(std::string_view key) const {
    bool found = false;
    const double v = given(key, found);
    if (!found) {
      throw InputError(located(
          src_, line_,
          fmt::format("[[target]] {}: missing {}{}", kind_.name, key,
                      from_ ? fmt::format(" (claim '{}' does not give it)", claim_id_) : "")));
    }
    return v;
  }
  double optional(std::string_view key, double def) const {
    bool found = false;
    const double v = given(key, found);
    return found ? v : def;
  }
  // Throws "src:line: [[target]] <kind>: <msg>".
  [[noreturn]] void fail(const std::string& msg) const {
    throw InputError(located(src_, line_, fmt::format("[[target]] {}: {}", kind_.name, msg)));
  }

 private:
  // What the claim gives: its value and condition (NaN: the claim does not give it).
  double from_claim(std::string_view key) const {
    if (!from_) return std::numeric_limits<double>::quiet_NaN();
    const ClaimCondition& c = from_->condition;
    if (key == "value") return from_->value;
    if (key == "temperature_C") return c.temperature_C;
    if (key == "reference_temperature_C") return c.reference_temperature_C;
    if (key == "current_pp_A") return c.current_pp_A;
    if (key == "frequency_Hz") return c.frequency_Hz;
    return std::numeric_limits<double>::quiet_NaN();
  }
  double given(std::string_view key, bool& found) const {
    const double c = from_claim(key);
    const double v = number(t_, key, src_, found);
    if (!std::isnan(c)) {
      if (found) {
        throw InputError(located(src_, line_of(*t_.get(key)),
                                 fmt::format("[[target]] {}: {} comes from claim '{}' ({:g}); "
                                             "leave it out",
                                             kind_.name, key, claim_id_, c)));
      }
      found = true;
      return c;
    }
    return v;
  }

  const toml::table& t_;
  const std::string& src_;
  long line_;
  const KindName& kind_;
  const ClaimFitTarget* from_;
  const std::string& claim_id_;
};

// A target computed from a biased-sine run: its current and frequency, in range.
void read_sine_condition(const TargetFields& in, FitTarget& g) {
  g.current_pp_A = in.required("current_pp_A");
  g.frequency_Hz = in.required("frequency_Hz");
  g.current_min_A = in.optional("current_min_A", -3.0);
  if (!(g.current_pp_A > 0.0) || !(g.frequency_Hz > 0.0))
    in.fail("current_pp_A and frequency_Hz must be > 0");
  auto range = [&](const char* key, double v, double lo, double hi, const char* unit) {
    if (!(std::isfinite(v) && v >= lo && v <= hi))
      in.fail(fmt::format("{} = {:g} {}: must be in [{:g}, {:g}]", key, v, unit, lo, hi));
  };
  range("current_pp_A", g.current_pp_A, 0.0, 2.0 * kMaxCurrent_A, "A");
  range("frequency_Hz", g.frequency_Hz, 0.0, kMaxFrequency_Hz, "Hz");
  range("current_min_A", g.current_min_A, -kMaxCurrent_A, kMaxCurrent_A, "A");
}

// The relative weight and the scale of the error (default |value|).
void read_weight_and_scale(const TargetFields& in, FitTarget& g) {
  g.weight = in.optional("weight", 1.0);
  if (!(g.weight > 0.0)) in.fail("weight must be > 0");
  // Relative weights: an extreme one scales every other residual to nothing (issue 8).
  if (!(g.weight >= 1e-6 && g.weight <= 1e6))
    in.fail(fmt::format("weight = {:g}: must be in [1e-6, 1e6]", g.weight));
  g.scale = in.optional("scale", 0.0);
  if (g.scale < 0.0) in.fail("scale must be > 0");
  if (g.scale == 0.0) g.scale = std::fabs(g.value);
  if (!(g.scale > 0.0)) {
    in.fail(
        "value 0 needs an explicit scale (the error is 100 (sim - value) / "
        "scale %)");
  }
}

FitTarget read_target(const toml::table& t, const std::string& src, const ClaimsData* claims) {
  check_keys(t,
             {"kind", "claim", "label", "temperature_C", "reference_temperature_C", "current_pp_A",
              "current_min_A", "frequency_Hz", "bias_A", "value", "weight", "scale"},
             "[[target]]", src);
  FitTarget g;
  g.line = line_of(t);
  std::optional<ClaimFitTarget> from;
  std::string claim_id;
  if (t.get("claim")) {
    from = resolve_claim(t, src, claims ? *claims : builtin_claims());
    claim_id = *t["claim"].value<std::string>();
  }
  const KindName& kn = target_kind(t, src, g.line, from ? &*from : nullptr);
  g.kind = kn.kind;
  const TargetFields in(t, src, g.line, kn, from ? &*from : nullptr, claim_id);
  g.value = in.required("value");
  g.temperature_C = in.required("temperature_C");
  if (kn.sine) {
    read_sine_condition(in, g);
  } else {
    g.bias_A = in.optional("bias_A", 1.0);
    if (!(std::fabs(g.bias_A) <= kMaxCurrent_A))
      in.fail(fmt::format("bias_A = {:g} A: must be in [-{:g}, {:g}]", g.bias_A, kMaxCurrent_A,
                          kMaxCurrent_A));
  }
  if (kn.needs_reference) g.reference_temperature_C = in.optional("reference_temperature_C", 20.0);
  read_weight_and_scale(in, g);
  const auto label = t["label"].value<std::string>();
  g.label = label ? *label
                  : (kn.sine ? fmt::format("{} {:g}C {:g}A {:g}Hz", kn.name, g.temperature_C,
                                           g.current_pp_A, g.frequency_Hz)
                             : fmt::format("{} {:g}C {:g}A", kn.name, g.temperature_C, g.bias_A));
  if (from && !label) g.label = fmt::format("{} ({})", claim_id, g.label);
  g.claim = claim_id;
  return g;
}

// [[by_construction]]: a claim a chosen constant sets, with the reason.
std::pair<std::string, std::string> read_by_construction(const toml::table& t,
                                                         const std::string& src,
                                                         const ClaimsData& claims) {
  check_keys(t, {"claim", "reason"}, "[[by_construction]]", src);
  const long line = line_of(t);
  const auto id = t["claim"].value<std::string>();
  const auto reason = t["reason"].value<std::string>();
  if (!id || id->empty())
    throw InputError(located(src, line, "[[by_construction]]: claim = \"<id>\" is required"));
  if (!reason || reason->empty())
    throw InputError(
        located(src, line,
                fmt::format("[[by_construction]] claim '{}': reason = \"...\" is required "
                            "(which constant sets it, and how)",
                            *id)));
  if (!claims.find(*id))
    throw InputError(located(
        src, line,
        fmt::format("[[by_construction]]: unknown claim '{}' (not in {})", *id, claims.source)));
  return {*id, *reason};
}

bool parse_double(std::string_view s, double& v) {
  if (s.starts_with('+')) s.remove_prefix(1);
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && p == s.data() + s.size() && std::isfinite(v);
}

FitSpec parse_inline(const std::string& text) {
  FitSpec spec;
  spec.source = "--fit";
  std::string_view rest = text;
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    std::vector<std::string_view> f;
    while (true) {
      const auto c = item.find(':');
      f.push_back(item.substr(0, c));
      if (c == std::string_view::npos) break;
      item = item.substr(c + 1);
    }
    auto bad = [&](const std::string& why) {
      throw InputError(
          fmt::format("--fit '{}': {}; expected name:lower:upper[:log] items "
                      "separated by commas, or a TOML fit file",
                      text, why));
    };
    if (f.size() < 3 || f.size() > 4) bad(fmt::format("item '{}' has {} fields", f[0], f.size()));
    FitParameter p;
    p.name = std::string(f[0]);
    if (p.name.empty()) bad("empty parameter name");
    if (!parse_double(f[1], p.lower) || !parse_double(f[2], p.upper))
      bad(fmt::format("bounds of '{}' are not numbers", p.name));
    if (f.size() == 4) {
      if (f[3] == "log")
        p.scale = ParamScale::Log;
      else if (f[3] != "linear")
        bad(fmt::format("scale '{}' of '{}' must be log or linear", f[3], p.name));
    }
    check_bounds(p, spec.source);
    spec.parameters.push_back(p);
  }
  return spec;
}

}  // namespace

std::string target_kind_name(TargetKind k) {
  for (const auto& kn : kKinds)
    if (kn.kind == k) return std::string(kn.name);
  return "?";
}

FitSpec parse_fit_spec(const std::string& toml_text, const std::string& source_name,
                       const ClaimsData* claims) {
  const toml::table root = io_detail::parse_toml(toml_text, source_name);
  FitSpec spec;
  spec.source = source_name;
  check_keys(root, {"claims", "parameter", "target", "by_construction"}, "the fit spec",
             source_name);
  // `claims = "file"` (relative to the spec): the claims `[[target]] claim = "<id>"` refers
  // to, instead of the built-in data/claims.toml.
  std::optional<ClaimsData> own_claims;
  if (const toml::node* n = root.get("claims")) {
    const auto path = n->value<std::string>();
    if (!path || path->empty())
      throw InputError(located(source_name, line_of(*n), "claims: expected a file name"));
    std::filesystem::path p(*path);
    if (p.is_relative()) p = std::filesystem::path(source_name).parent_path() / p;
    own_claims = load_claims(p.string());
    claims = &*own_claims;
  }
  auto tables = [&](std::string_view key) {
    std::vector<const toml::table*> out;
    if (const toml::node* n = root.get(key)) {
      const toml::array* a = n->as_array();
      if (!a) {
        throw InputError(
            located(source_name, line_of(*n), fmt::format("{}: expected [[{}]] tables", key, key)));
      }
      for (const auto& e : *a) {
        if (!e.as_table())
          throw InputError(
              located(source_name, line_of(e), fmt::format("[[{}]]: expected a table", key)));
        out.push_back(e.as_table());
      }
    }
    return out;
  };
  for (const auto* t : tables("parameter"))
    spec.parameters.push_back(read_parameter(*t, source_name));
  for (const auto* t : tables("target"))
    spec.targets.push_back(read_target(*t, source_name, claims));
  for (const auto* t : tables("by_construction"))
    spec.by_construction.push_back(
        read_by_construction(*t, source_name, claims ? *claims : builtin_claims()));
  if (spec.parameters.empty())
    throw InputError(located(source_name, 1, "no [[parameter]] to fit: name at least one"));
  return spec;
}

std::vector<std::string> fitted_claims(const FitSpec& spec) {
  std::vector<std::string> ids;
  auto add = [&](const std::string& id) {
    if (!id.empty() && std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
  };
  for (const auto& t : spec.targets) add(t.claim);
  for (const auto& [id, reason] : spec.by_construction) add(id);
  return ids;
}

FitSpec load_fit_spec(const std::string& file_or_inline) {
  std::error_code ec;
  const bool looks_like_file =
      file_or_inline.ends_with(".toml") || std::filesystem::is_regular_file(file_or_inline, ec);
  if (!looks_like_file) return parse_inline(file_or_inline);
  return parse_fit_spec(read_input_file(file_or_inline, "fit spec"), file_or_inline);
}

}  // namespace gmasim
