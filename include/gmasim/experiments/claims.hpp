// The paper's claims as data (data/claims.toml, compiled into the library; docs/claims.md):
// what the paper says, its number, our tolerance, the condition it holds at, and the kind of
// extractor that computes our value from a `gmasim reproduce` study (reproduce.hpp,
// score_claims). Read by `gmasim reproduce` and by the fit specs of `gmasim identify`
// (`[[target]] claim = "<id>"`).
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace gmasim {

// The operating point a claim holds at. NaN: not part of the claim's condition.
struct ClaimCondition {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  double temperature_C = kUnset;            // where our value is taken
  double reference_temperature_C = kUnset;  // a change "from reference to temperature"
  double current_pp_A = kUnset;             // coil current, peak to peak (biased sine)
  double frequency_Hz = kUnset;             // excitation frequency
  double amplitude_um = kUnset;             // closed-loop reference amplitude (Fig. 16)
};

// The rule that decides pass or fail.
enum class ToleranceKind {
  Absolute,       // |ours - paper| <= value (in the claim's unit)
  Relative,       // |ours - paper| <= value |paper| (value a fraction)
  LessThan,       // ours < bound
  GreaterThan,    // ours > bound
  Order,          // the extractor's named values strictly decrease in the order of names
  Top,            // the named values are the largest of the extractor's values
  NotApplicable,  // needs measurements we do not have: never scored
};

struct ClaimTolerance {
  ToleranceKind kind = ToleranceKind::Absolute;
  double value = 0.0;              // Absolute, Relative
  double bound = 0.0;              // LessThan, GreaterThan
  std::vector<std::string> names;  // Order, Top
  std::string text;                // the rule in words ("" = generated from the rule)
  std::string describe(const std::string& unit) const;  // text, or the generated words
};

struct ClaimSpec {
  std::string id;      // short stable key, e.g. "stroke_drop_8A"
  std::string claim;   // what the paper says, in words
  std::string source;  // "section 4.4.4, Fig. 13"
  std::string kind;    // the extractor that computes ours (docs/claims.md lists them)
  double paper = 0.0;  // the paper's value; NaN for a claim that is not a number (a ranking)
  std::string unit;    // "%", "um", "Hz", ...
  ClaimTolerance tolerance;
  ClaimCondition condition;
  std::string note;  // fixed words appended to the extractor's note
  long line = 0;     // of the [[claim]] table in `ClaimsData::source`
};

struct ClaimsData {
  std::string source;  // file name ("data/claims.toml" for the built-in data)
  std::vector<ClaimSpec> claims;
  const ClaimSpec* find(const std::string& id) const;  // nullptr if absent
};

// Parses and validates a claims file: TOML syntax, unknown or missing keys, wrong types,
// duplicate ids, an unknown extractor kind, a condition the kind needs and does not have (or
// has and does not use), a tolerance rule and its parameters. Every problem is an
// InputError "file:line: message".
ClaimsData parse_claims(const std::string& toml_text, const std::string& source_name);
ClaimsData load_claims(const std::string& path);
// data/claims.toml, compiled into the library (parsed once).
const ClaimsData& builtin_claims();
// The paper's value of the built-in claim `id`: how the code that shows a paper's number
// beside ours (FrfResult, ThermalExpansionResult, the reports) reads it, so the number is
// written once, in data/claims.toml. Throws std::logic_error if the built-in data has no
// claim `id` (a build error, not a user's).
double builtin_paper_value(const std::string& id);
extern const char* const kBuiltinClaimsToml;
extern const char* const kBuiltinClaimsName;

// The fit target (gmasim identify, fit spec `[[target]] claim = "<id>"`) a claim stands for:
// the target kind (fit_spec names: "stroke_change_pct", ...), its value in that kind's
// convention (a "drop" of 11.3 % is a change of -11.3 %) and the condition. nullopt when
// the claim's kind has no scalar target counterpart (rankings, closed loop, ...).
struct ClaimFitTarget {
  std::string kind;
  double value = 0.0;
  ClaimCondition condition;
};
std::optional<ClaimFitTarget> claim_fit_target(const ClaimSpec& c);

// The extractor kinds (docs/claims.md): name, the condition keys it needs, the named values
// a ranking rule may refer to (empty: the kind gives one number), the fit target kind ("" if
// none), and what it computes.
struct ClaimKindInfo {
  std::string name;
  std::vector<std::string> required, optional, values;
  std::string fit_target;
  std::string description;
};
std::vector<ClaimKindInfo> claim_kinds();

}  // namespace gmasim
