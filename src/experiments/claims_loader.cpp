// Claims files (data/claims.toml, docs/claims.md): TOML -> ClaimsData, validated key by key;
// every problem is an InputError "file:line: message". The extractor kinds and what they
// need come from src/experiments/claims.cpp (claim_kinds()).
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string_view>

#include "common/text_io.hpp"
#include "common/toml_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/claims.hpp"

namespace gmasim {

extern const std::size_t kBuiltinClaimsTomlSize;

namespace {

long line_of(const toml::node& n) {
  const auto l = static_cast<long>(n.source().begin.line);
  return l > 0 ? l : 1;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "(none)" : s;
}

struct Reader {
  const std::string& src;

  [[noreturn]] void fail(long line, const std::string& msg) const {
    throw InputError(located(src, line, msg));
  }

  void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed,
                  const std::string& where) const {
    for (const auto& [k, v] : t) {
      if (std::find(allowed.begin(), allowed.end(), k.str()) != allowed.end()) continue;
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(line_of(v),
           fmt::format("unknown key '{}' in {}; expected one of: {}", k.str(), where, list));
    }
  }

  // A required (or, with `found`, optional) string.
  std::string text(const toml::table& t, std::string_view key, const std::string& where,
                   bool required = true, bool allow_empty = false) const {
    const toml::node* n = t.get(key);
    if (!n) {
      if (required) fail(line_of(t), fmt::format("{}: missing {} = \"...\"", where, key));
      return "";
    }
    const auto v = n->value<std::string>();
    if (!v) fail(line_of(*n), fmt::format("{}: {} must be a string", where, key));
    if (!allow_empty && v->empty()) fail(line_of(*n), fmt::format("{}: {} is empty", where, key));
    return *v;
  }

  double number(const toml::node& n, std::string_view key, const std::string& where,
                bool allow_nan = false) const {
    if (!n.is_number()) fail(line_of(n), fmt::format("{}: {} must be a number", where, key));
    const double v = *n.value<double>();
    if (std::isinf(v) || (std::isnan(v) && !allow_nan))
      fail(line_of(n), fmt::format("{}: {} must be finite{}", where, key,
                                   allow_nan ? " (or nan: not a number)" : ""));
    return v;
  }

  const toml::table& table(const toml::table& t, std::string_view key,
                           const std::string& where) const {
    const toml::node* n = t.get(key);
    if (!n) fail(line_of(t), fmt::format("{}: missing {} = {{ ... }}", where, key));
    const toml::table* tt = n->as_table();
    if (!tt) fail(line_of(*n), fmt::format("{}: {} must be a table {{ ... }}", where, key));
    return *tt;
  }
};

struct ToleranceName {
  ToleranceKind kind;
  std::string_view name;
};
constexpr ToleranceName kTolerances[] = {
    {ToleranceKind::Absolute, "absolute"},
    {ToleranceKind::Relative, "relative"},
    {ToleranceKind::LessThan, "less_than"},
    {ToleranceKind::GreaterThan, "greater_than"},
    {ToleranceKind::Order, "order"},
    {ToleranceKind::Top, "top"},
    {ToleranceKind::NotApplicable, "not_applicable"},
};

ClaimTolerance read_tolerance(const Reader& rd, const toml::table& t, const ClaimSpec& c,
                              const ClaimKindInfo& kind) {
  const std::string where = fmt::format("claim {}: tolerance", c.id);
  rd.check_keys(t, {"kind", "value", "bound", "names", "text"}, where);
  ClaimTolerance tol;
  const std::string name = rd.text(t, "kind", where);
  const ToleranceName* tn = nullptr;
  for (const auto& k : kTolerances)
    if (k.name == name) tn = &k;
  if (!tn) {
    std::string list;
    for (const auto& k : kTolerances) list += (list.empty() ? "" : ", ") + std::string(k.name);
    rd.fail(line_of(*t.get("kind")),
            fmt::format("{}: kind '{}' is not one of {}", where, name, list));
  }
  tol.kind = tn->kind;
  tol.text = rd.text(t, "text", where, false);
  // The parameter each rule takes; any other is an error.
  const bool want_value =
      tol.kind == ToleranceKind::Absolute || tol.kind == ToleranceKind::Relative;
  const bool want_bound =
      tol.kind == ToleranceKind::LessThan || tol.kind == ToleranceKind::GreaterThan;
  const bool want_names = tol.kind == ToleranceKind::Order || tol.kind == ToleranceKind::Top;
  auto param = [&](std::string_view key, bool wanted) -> const toml::node* {
    const toml::node* n = t.get(key);
    if (wanted && !n)
      rd.fail(line_of(t), fmt::format("{}: a '{}' rule needs {}", where, name, key));
    if (!wanted && n)
      rd.fail(line_of(*n), fmt::format("{}: a '{}' rule takes no {}", where, name, key));
    return n;
  };
  if (const toml::node* n = param("value", want_value)) {
    tol.value = rd.number(*n, "value", where);
    if (tol.kind == ToleranceKind::Absolute ? tol.value < 0.0 : !(tol.value > 0.0))
      rd.fail(line_of(*n),
              fmt::format("{}: value must be {} (got {:g})", where,
                          tol.kind == ToleranceKind::Absolute ? ">= 0" : "> 0", tol.value));
  }
  if (const toml::node* n = param("bound", want_bound)) tol.bound = rd.number(*n, "bound", where);
  if (const toml::node* n = param("names", want_names)) {
    const toml::array* a = n->as_array();
    if (!a) rd.fail(line_of(*n), fmt::format("{}: names must be an array of strings", where));
    for (const auto& e : *a) {
      const auto s = e.value<std::string>();
      if (!s) rd.fail(line_of(*n), fmt::format("{}: names must be an array of strings", where));
      if (std::find(kind.values.begin(), kind.values.end(), *s) == kind.values.end())
        rd.fail(line_of(*n), fmt::format("{}: '{}' is not a value of kind {} ({})", where, *s,
                                         kind.name, join(kind.values)));
      if (std::find(tol.names.begin(), tol.names.end(), *s) != tol.names.end())
        rd.fail(line_of(*n), fmt::format("{}: '{}' is named twice", where, *s));
      tol.names.push_back(*s);
    }
    if (tol.kind == ToleranceKind::Order && tol.names.size() < 2)
      rd.fail(line_of(*n), fmt::format("{}: an order needs at least two names", where));
    if (tol.kind == ToleranceKind::Top &&
        (tol.names.empty() || tol.names.size() >= kind.values.size()))
      rd.fail(line_of(*n),
              fmt::format("{}: top needs 1 to {} names", where, kind.values.size() - 1));
  }
  // The rule must fit the kind: rankings compare named values, the others one number.
  const long kline = line_of(*t.get("kind"));
  if (want_names && kind.values.empty())
    rd.fail(kline, fmt::format("{}: kind {} gives one number, not named values to rank; use "
                               "absolute, relative, less_than or greater_than",
                               where, kind.name));
  if ((want_value || want_bound) && !kind.values.empty())
    rd.fail(kline, fmt::format("{}: kind {} gives named values ({}); use order or top", where,
                               kind.name, join(kind.values)));
  const bool measurements = kind.name == "paper_measurements";
  if (measurements != (tol.kind == ToleranceKind::NotApplicable))
    rd.fail(kline, measurements
                       ? fmt::format("{}: kind paper_measurements is never scored; use "
                                     "kind = \"not_applicable\"",
                                     where)
                       : fmt::format("{}: not_applicable is for kind paper_measurements", where));
  if (want_value && !std::isfinite(c.paper))
    rd.fail(kline, fmt::format("{}: an '{}' rule needs a finite paper value", where, name));
  return tol;
}

ClaimCondition read_condition(const Reader& rd, const toml::table* t, long claim_line,
                              const ClaimSpec& c, const ClaimKindInfo& kind) {
  const std::string where = fmt::format("claim {}: condition", c.id);
  ClaimCondition cond;
  struct Key {
    std::string_view name;
    double ClaimCondition::*field;
  };
  static constexpr Key kKeys[] = {
      {"temperature_C", &ClaimCondition::temperature_C},
      {"reference_temperature_C", &ClaimCondition::reference_temperature_C},
      {"current_pp_A", &ClaimCondition::current_pp_A},
      {"frequency_Hz", &ClaimCondition::frequency_Hz},
      {"amplitude_um", &ClaimCondition::amplitude_um},
  };
  auto listed = [](const std::vector<std::string>& v, std::string_view k) {
    return std::find(v.begin(), v.end(), k) != v.end();
  };
  if (t) {
    for (const auto& [k, v] : *t) {
      const Key* key = nullptr;
      for (const auto& kk : kKeys)
        if (kk.name == k.str()) key = &kk;
      if (!key) {
        std::string list;
        for (const auto& kk : kKeys) list += (list.empty() ? "" : ", ") + std::string(kk.name);
        rd.fail(line_of(v),
                fmt::format("{}: unknown key '{}'; expected one of: {}", where, k.str(), list));
      }
      if (!listed(kind.required, k.str()) && !listed(kind.optional, k.str()))
        rd.fail(line_of(v), fmt::format("{}: {} does not apply to kind {} (it uses: {})", where,
                                        k.str(), kind.name, join(kind.required)));
      const double x = rd.number(v, k.str(), where);
      // a condition the study cannot hold (0 Hz, a negative current, below absolute zero) was
      // scored "no sweep point at ..." instead of refused
      const std::string_view name = k.str();
      const bool temperature = name == "temperature_C" || name == "reference_temperature_C";
      if (temperature ? !(x > -273.15) : !(x > 0.0))
        rd.fail(line_of(v), fmt::format("{}: {} = {:g}: must be {}", where, name, x,
                                        temperature ? "> -273.15 degC" : "> 0"));
      cond.*(key->field) = x;
    }
  }
  for (const auto& k : kind.required) {
    if (!t || !t->get(k))
      rd.fail(t ? line_of(*t) : claim_line, fmt::format("{}: kind {} needs {} (it uses: {})", where,
                                                        kind.name, k, join(kind.required)));
  }
  return cond;
}

ClaimSpec read_claim(const Reader& rd, const toml::table& t,
                     const std::map<std::string, ClaimKindInfo>& kinds) {
  ClaimSpec c;
  c.line = line_of(t);
  rd.check_keys(
      t, {"id", "claim", "source", "kind", "paper", "unit", "tolerance", "condition", "note"},
      "[[claim]]");
  c.id = rd.text(t, "id", "[[claim]]");
  for (char ch : c.id)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.'))
      rd.fail(line_of(*t.get("id")),
              fmt::format("[[claim]]: id '{}' may hold only letters, digits, '_', '-', '.'", c.id));
  const std::string where = "claim " + c.id;
  c.claim = rd.text(t, "claim", where);
  c.source = rd.text(t, "source", where);
  c.kind = rd.text(t, "kind", where);
  const auto it = kinds.find(c.kind);
  if (it == kinds.end()) {
    std::string list;
    for (const auto& [k, v] : kinds) list += (list.empty() ? "" : ", ") + k;
    rd.fail(line_of(*t.get("kind")),
            fmt::format("{}: unknown kind '{}'; expected one of: {}", where, c.kind, list));
  }
  const toml::node* paper = t.get("paper");
  if (!paper)
    rd.fail(c.line, fmt::format("{}: missing paper = <number> (nan for a claim that is not a "
                                "number)",
                                where));
  c.paper = rd.number(*paper, "paper", where, true);
  c.unit = rd.text(t, "unit", where, true, true);
  c.note = rd.text(t, "note", where, false);
  const toml::table* cond = nullptr;
  if (const toml::node* n = t.get("condition")) {
    cond = n->as_table();
    if (!cond) rd.fail(line_of(*n), fmt::format("{}: condition must be a table {{ ... }}", where));
  }
  c.condition = read_condition(rd, cond, c.line, c, it->second);
  c.tolerance = read_tolerance(rd, rd.table(t, "tolerance", where), c, it->second);
  return c;
}

}  // namespace

ClaimsData parse_claims(const std::string& toml_text, const std::string& source_name) {
  const toml::table root = io_detail::parse_toml(toml_text, source_name);
  const Reader rd{source_name};
  rd.check_keys(root, {"claim"}, "the claims file");
  std::map<std::string, ClaimKindInfo> kinds;
  for (auto& k : claim_kinds()) kinds.emplace(k.name, std::move(k));
  ClaimsData data;
  data.source = source_name;
  const toml::node* n = root.get("claim");
  if (!n) rd.fail(1, "no [[claim]] tables");
  const toml::array* a = n->as_array();
  if (!a) rd.fail(line_of(*n), "claim: expected [[claim]] tables");
  for (const auto& e : *a) {
    const toml::table* t = e.as_table();
    if (!t) rd.fail(line_of(e), "[[claim]]: expected a table");
    ClaimSpec c = read_claim(rd, *t, kinds);
    if (const ClaimSpec* prev = data.find(c.id))
      rd.fail(c.line, fmt::format("claim {}: duplicate id (first at line {})", c.id, prev->line));
    data.claims.push_back(std::move(c));
  }
  if (data.claims.empty()) rd.fail(line_of(*n), "no [[claim]] tables");
  return data;
}

ClaimsData load_claims(const std::string& path) {
  return parse_claims(io_detail::read_text_file(path, "claims file"), path);
}

const ClaimsData& builtin_claims() {
  static const ClaimsData data =
      parse_claims(std::string(kBuiltinClaimsToml, kBuiltinClaimsTomlSize), kBuiltinClaimsName);
  return data;
}

double builtin_paper_value(const std::string& id) {
  const ClaimSpec* c = builtin_claims().find(id);
  if (c == nullptr)
    throw std::logic_error(fmt::format("{} has no claim '{}'", kBuiltinClaimsName, id));
  return c->paper;
}

}  // namespace gmasim
