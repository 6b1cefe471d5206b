// The condition of a measurement file (docs/data.md): condition keys in the CSV's header
// comments and/or its TOML sidecar, checked against each other and against the record.
#include "identify/measurement_condition.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "common/text_io.hpp"
#include "common/toml_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/model/validity.hpp"

namespace gmasim {
namespace identify_detail {
namespace {

namespace fs = std::filesystem;

using io_detail::trim;

bool is_identifier(std::string_view s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

enum class KeyType { Number, Text };
struct ConditionKey {
  std::string_view name;
  KeyType type;
};
constexpr ConditionKey kConditionKeys[] = {
    {"temperature_C", KeyType::Number},
    {"frequency_Hz", KeyType::Number},
    {"current_pp_A", KeyType::Number},
    {"current_min_A", KeyType::Number},
    {"compare_from_s", KeyType::Number},
    {"current_source", KeyType::Text},
    {"label", KeyType::Text},
    {"compare_from_sample", KeyType::Number},
    {"rod", KeyType::Text},
    {"precycles", KeyType::Number},
    {"offset", KeyType::Text},
    {"flux_offset", KeyType::Text},
    {"prestress_MPa", KeyType::Number},
    {"initial_state", KeyType::Text},
};

constexpr std::pair<InitialState, std::string_view> kInitialStateNames[] = {
    {InitialState::Demagnetised, "demagnetised"},
    {InitialState::NegativeRemanence, "negative_remanence"},
    {InitialState::PositiveRemanence, "positive_remanence"},
};

constexpr std::pair<OffsetMode, std::string_view> kOffsetNames[] = {
    {OffsetMode::Absolute, "absolute"},
    {OffsetMode::FirstSample, "first_sample"},
    {OffsetMode::Fitted, "fitted"},
};

std::string known_keys() {
  std::string s;
  for (const auto& k : kConditionKeys) {
    if (!s.empty()) s += ", ";
    s += k.name;
  }
  return s;
}

const ConditionKey* find_key(std::string_view name) {
  for (const auto& k : kConditionKeys)
    if (k.name == name) return &k;
  return nullptr;
}

// The keys of one record; fail(key, message) throws at the key's file:line, or at the
// header line of the CSV file for a key not given.
class ConditionKeys {
 public:
  ConditionKeys(const KeyMap& keys, const std::string& path, long header_line)
      : keys_(keys), path_(path), header_line_(header_line) {}

  bool has(const std::string& key) const { return keys_.count(key) > 0; }
  const KeyValue& at(const std::string& key) const { return keys_.at(key); }
  double number(const std::string& key) const { return keys_.at(key).number; }
  const std::string& text(const std::string& key) const { return keys_.at(key).text; }
  const std::string& path() const { return path_; }
  long header_line() const { return header_line_; }

  [[noreturn]] void fail(const std::string& key, const std::string& msg) const {
    const auto it = keys_.find(key);
    if (it == keys_.end()) throw InputError(located(path_, header_line_, msg));
    throw InputError(located(it->second.file, it->second.line, msg));
  }

 private:
  const KeyMap& keys_;
  const std::string& path_;
  long header_line_;
};

OffsetMode parse_offset(const KeyValue& kv, std::string_view key) {
  for (const auto& [mode, name] : kOffsetNames)
    if (kv.text == name) return mode;
  throw InputError(
      located(kv.file, kv.line,
              fmt::format("{} = '{}': must be absolute, first_sample or fitted", key, kv.text)));
}

// The keys of issue 9 item 7: rod, precycles, offset, flux_offset.
void read_record_keys(const ConditionKeys& keys, const Measurement& m, MeasurementCondition& c) {
  const bool rod_columns =
      m.drive_kind == DriveInput::Field || m.response_kind == ResponseOutput::Strain;
  if (keys.has("rod")) {
    c.rod = keys.text("rod");
    if (!rod_columns)
      keys.fail("rod", fmt::format(
                           "rod = '{}': names the rod of a field_A_per_m or strain_ppm column, and "
                           "this record has neither",
                           c.rod));
    if (!is_identifier(c.rod))
      keys.fail(
          "rod",
          fmt::format("rod = '{}': must be a rod name of the model (letters, digits, _)", c.rod));
  }
  if (m.drive_kind == DriveInput::Field && c.current_source == "sine")
    keys.fail("current_source",
              "current_source = sine drives the model with a current; this record's drive is "
              "field_A_per_m");
  if (keys.has("offset")) c.offset = parse_offset(keys.at("offset"), "offset");
  if (keys.has("flux_offset")) {
    c.flux_offset = parse_offset(keys.at("flux_offset"), "flux_offset");
    if (m.flux_T.empty()) keys.fail("flux_offset", "flux_offset: the record has no flux_T column");
  }
  if (keys.has("initial_state")) {
    const auto& kv = keys.at("initial_state");
    const auto* it = std::find_if(std::begin(kInitialStateNames), std::end(kInitialStateNames),
                                  [&](const auto& e) { return e.second == kv.text; });
    if (it == std::end(kInitialStateNames))
      keys.fail("initial_state",
                fmt::format("initial_state = '{}': must be demagnetised, negative_remanence or "
                            "positive_remanence",
                            kv.text));
    c.initial_state = it->first;
  }
  if (keys.has("precycles")) {
    const double n = keys.number("precycles");
    if (!(n >= 0.0 && n <= static_cast<double>(kMaxPrecycles) && n == std::floor(n)))
      keys.fail("precycles", fmt::format("precycles = {:g}: must be a whole number in [0, {}]", n,
                                         kMaxPrecycles));
    c.precycles = static_cast<long>(n);
  }
  if (c.precycles > 0) {
    // A pass repeats the record's drive: it must end where it starts, or each pass would
    // end with a jump the real actuator never saw.
    double first = m.drive.front(), last = m.drive.back();
    if (c.current_source == "sine") {
      const Waveform w = biased_sine(c.current_pp_A, c.frequency_Hz, c.current_min_A);
      first = w.current_at(m.t_s.front());
      last = w.current_at(m.t_s.back());
    }
    const double range = c.current_source == "sine" ? c.current_pp_A : peak_to_peak(m.drive);
    if (!(std::fabs(last - first) <= 0.02 * range))
      keys.fail(
          "precycles",
          fmt::format("precycles = {}: pre-cycling repeats the record's drive, which must end "
                      "where it starts (within 2 % of its range {:g}): first {:g}, last {:g}",
                      c.precycles, range, first, last));
  }
  if (c.quasi_static) {
    if (!(peak_to_peak(m.drive) > 0.0))
      throw InputError(located(m.path, 0,
                               fmt::format("the {} column does not vary: a quasi-static record "
                                           "needs a drive that moves",
                                           m.drive_column())));
  }
}

// temperature_C: required, above absolute zero.
double read_temperature(const ConditionKeys& keys) {
  if (!keys.has("temperature_C")) {
    keys.fail("temperature_C",
              fmt::format("condition missing: temperature_C (write '# temperature_C = 20' above "
                          "the header, or temperature_C = 20.0 in the sidecar {})",
                          sidecar_path(keys.path())));
  }
  const double t = keys.number("temperature_C");
  if (!(t > -273.15 && t < 1e4))
    keys.fail("temperature_C", fmt::format("temperature_C = {:g}: must be > -273.15 degC", t));
  return t;
}

// A quasi-static record has no time: the keys of a timed or periodic one are errors.
void check_untimed_keys(const ConditionKeys& keys) {
  for (const char* k : {"frequency_Hz", "current_pp_A", "current_source", "compare_from_s"})
    if (keys.has(k))
      keys.fail(k, fmt::format("{}: a quasi-static record (no t_s column) has no time, frequency "
                               "or sine; give t_s, or drop {} (compare_from_sample selects the "
                               "first compared sample)",
                               k, k));
}

// A periodic condition: frequency_Hz and current_pp_A, both or neither.
void read_periodic_keys(const ConditionKeys& keys, const Measurement& m, MeasurementCondition& c) {
  const double t0_rec = m.t_s.front(), t1_rec = m.t_s.back();
  const bool has_f = keys.has("frequency_Hz");
  const bool has_pp = keys.has("current_pp_A");
  if (has_f) {
    c.frequency_Hz = keys.number("frequency_Hz");
    if (!(c.frequency_Hz > 0.0 && c.frequency_Hz <= kMaxFrequency_Hz))
      keys.fail("frequency_Hz", fmt::format("frequency_Hz = {:g}: must be in (0, {:g}] Hz",
                                            c.frequency_Hz, kMaxFrequency_Hz));
    // The record must span a whole number of steps the simulator can take: at least the
    // 8-step floor per period, at most kMaxSteps over the record.
    if (!((t1_rec - t0_rec) * c.frequency_Hz * 8.0 <= kMaxSteps))
      keys.fail("frequency_Hz",
                fmt::format("frequency_Hz = {:g}: {:.4g} periods over the record's {:g} s: too "
                            "many to simulate (limit {:g} steps)",
                            c.frequency_Hz, (t1_rec - t0_rec) * c.frequency_Hz, t1_rec - t0_rec,
                            kMaxSteps));
    if (!has_pp) {
      keys.fail("frequency_Hz",
                "condition missing: current_pp_A (a periodic condition, with frequency_Hz, also "
                "names its current peak-to-peak)");
    }
  }
  if (has_pp) {
    if (!has_f) {
      keys.fail("current_pp_A",
                "condition missing: frequency_Hz (current_pp_A describes a periodic excitation)");
    }
    c.current_pp_A = keys.number("current_pp_A");
    if (!(c.current_pp_A > 0.0 && c.current_pp_A <= 2.0 * kMaxCurrent_A))
      keys.fail("current_pp_A", fmt::format("current_pp_A = {:g}: must be in (0, {:g}] A",
                                            c.current_pp_A, 2.0 * kMaxCurrent_A));
  }
}

// current_min_A and current_source (measured, or the sine of the periodic condition).
void read_current_keys(const ConditionKeys& keys, MeasurementCondition& c) {
  if (keys.has("current_min_A")) {
    c.current_min_A = keys.number("current_min_A");
    if (!(std::fabs(c.current_min_A) <= kMaxCurrent_A))
      keys.fail("current_min_A", fmt::format("current_min_A = {:g}: must be in [-{:g}, {:g}] A",
                                             c.current_min_A, kMaxCurrent_A, kMaxCurrent_A));
  }
  if (keys.has("current_source")) {
    c.current_source = keys.text("current_source");
    if (c.current_source != "measured" && c.current_source != "sine")
      keys.fail("current_source",
                fmt::format("current_source = '{}': must be measured or sine", c.current_source));
    if (c.current_source == "sine" && !keys.has("frequency_Hz"))
      keys.fail("current_source", "current_source = sine needs frequency_Hz and current_pp_A");
  }
}

// A quasi-static record: the index of the first compared sample (compare_from_sample, at
// least 3 samples compared; default 0).
double first_compared_sample(const ConditionKeys& keys, const Measurement& m) {
  if (!keys.has("compare_from_sample")) return 0.0;
  const double k0 = keys.number("compare_from_sample");
  if (!(k0 >= 0.0 && k0 == std::floor(k0) && k0 + 3.0 <= static_cast<double>(m.t_s.size())))
    keys.fail("compare_from_sample",
              fmt::format("compare_from_sample = {:g}: must be a whole sample index in [0, {}] "
                          "(at least 3 samples compared)",
                          k0, m.t_s.size() - 3));
  return k0;
}

// A timed record: the time of the first compared sample (compare_from_s; default one period
// after the start of a periodic record that is not pre-cycled, else the start), with at
// least 3 samples compared.
double first_compared_time(const ConditionKeys& keys, const Measurement& m,
                           const MeasurementCondition& c) {
  if (keys.has("compare_from_sample"))
    keys.fail("compare_from_sample",
              "compare_from_sample is for quasi-static records (no t_s column); a timed record "
              "uses compare_from_s");
  const bool has_f = keys.has("frequency_Hz");
  const double t0 = m.t_s.front(), t1 = m.t_s.back();
  double from = 0.0;
  if (keys.has("compare_from_s")) {
    from = keys.number("compare_from_s");
  } else {
    // A pre-cycled record is already on its loop: everything is compared.
    from = has_f && c.precycles == 0 && c.initial_state == InitialState::Demagnetised
               ? t0 + 1.0 / c.frequency_Hz
               : t0;
  }
  // At least 3 compared samples.
  const auto first = std::lower_bound(m.t_s.begin(), m.t_s.end(), from - 1e-12 * (t1 - t0));
  if (m.t_s.end() - first < 3) {
    if (keys.has("compare_from_s")) {
      keys.fail("compare_from_s", fmt::format("compare_from_s = {:g} s leaves fewer than 3 "
                                              "samples to compare (the record ends at {:g} s)",
                                              from, t1));
    }
    throw InputError(located(keys.path(), keys.header_line(),
                             fmt::format("the record ({:g} .. {:g} s) is shorter than one period "
                                         "({:g} s) plus 3 samples: nothing is left to compare "
                                         "after the first period (set compare_from_s)",
                                         t0, t1, has_f ? 1.0 / c.frequency_Hz : 0.0)));
  }
  return from;
}

}  // namespace

std::optional<std::string> parse_number(std::string_view cell, double& v) {
  switch (io_detail::parse_finite(cell, v)) {
    case io_detail::CellError::None:
      return std::nullopt;
    case io_detail::CellError::Empty:
      return std::string("empty cell");
    case io_detail::CellError::NonNumeric:
      return fmt::format("non-numeric value '{}'", cell);
    case io_detail::CellError::OutOfRange:
      return fmt::format("out-of-range value '{}'", cell);
    case io_detail::CellError::NaN:
      return fmt::format("NaN ('{}')", cell);
    case io_detail::CellError::Inf:
      return fmt::format("Inf ('{}')", cell);
  }
  return std::nullopt;
}

void read_comment_key(std::string_view comment, const std::string& path, long line, KeyMap& keys) {
  const auto sep = comment.find_first_of("=:");
  if (sep == std::string_view::npos) return;
  const std::string_view key = trim(comment.substr(0, sep));
  if (!is_identifier(key)) return;  // free text such as "# note: ..." with spaces
  std::string_view value = trim(comment.substr(sep + 1));
  const ConditionKey* k = find_key(key);
  if (!k) {
    // An identifier followed by '=' is a condition key: a typo must not pass silently.
    if (comment[sep] == '=' || key.find('_') != std::string_view::npos) {
      throw InputError(
          located(path, line,
                  fmt::format("unknown condition key '{}'; known keys: {}", key, known_keys())));
    }
    return;
  }
  if (keys.count(std::string(key))) {
    throw InputError(located(path, line, fmt::format("condition key '{}' is given twice", key)));
  }
  if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') &&
      value.back() == value.front())
    value = value.substr(1, value.size() - 2);
  KeyValue kv{std::string(value), 0.0, path, line};
  if (k->type == KeyType::Number) {
    if (auto bad = parse_number(value, kv.number))
      throw InputError(located(path, line, fmt::format("condition key {}: {}", key, *bad)));
  }
  keys[std::string(key)] = kv;
}

std::string sidecar_path(const std::string& csv) {
  fs::path p(csv);
  p.replace_extension(".toml");
  return p.string();
}

void read_sidecar(const std::string& path, KeyMap& keys) {
  const toml::table root =
      io_detail::parse_toml(io_detail::read_text_file(path, "condition sidecar"), path);
  for (const auto& [key, node] : root) {
    const std::string name(key.str());
    const long line = static_cast<long>(node.source().begin.line);
    const ConditionKey* k = find_key(name);
    if (!k) {
      throw InputError(
          located(path, line,
                  fmt::format("unknown condition key '{}'; known keys: {}", name, known_keys())));
    }
    KeyValue kv{"", 0.0, path, line};
    if (k->type == KeyType::Number) {
      if (auto v = node.value<double>()) {
        kv.number = *v;
        kv.text = fmt::format("{:g}", *v);
      } else {
        throw InputError(located(path, line, fmt::format("{}: expected a number", name)));
      }
      if (!std::isfinite(kv.number))
        throw InputError(located(path, line, fmt::format("{}: must be finite", name)));
    } else {
      if (auto v = node.value<std::string>()) {
        kv.text = *v;
      } else {
        throw InputError(located(path, line, fmt::format("{}: expected a string", name)));
      }
    }
    const auto it = keys.find(name);
    if (it != keys.end()) {
      const bool same =
          k->type == KeyType::Number ? it->second.number == kv.number : it->second.text == kv.text;
      if (!same) {
        throw InputError(
            located(path, line,
                    fmt::format("{} = {} contradicts {} = {} at {}:{}", name, kv.text, name,
                                it->second.text, it->second.file, it->second.line)));
      }
      continue;
    }
    keys[name] = kv;
  }
}

MeasurementCondition make_condition(const KeyMap& keys, const Measurement& m,
                                    const std::string& path, long header_line) {
  const ConditionKeys k(keys, path, header_line);
  MeasurementCondition c;
  c.temperature_C = read_temperature(k);
  c.temperature_file = k.at("temperature_C").file;
  c.temperature_line = k.at("temperature_C").line;
  if (m.condition.quasi_static) check_untimed_keys(k);
  read_periodic_keys(k, m, c);
  read_current_keys(k, c);
  if (k.has("prestress_MPa")) {  // the stress in the first rod of stack.rods (docs/data.md)
    c.prestress_MPa = k.number("prestress_MPa");
    if (!(c.prestress_MPa >= 0.0 && c.prestress_MPa <= kMaxPrestress_Pa * 1e-6))
      k.fail("prestress_MPa", fmt::format("prestress_MPa = {:g}: must be in [0, {:g}] MPa",
                                          c.prestress_MPa, kMaxPrestress_Pa * 1e-6));
  }
  c.label = k.has("label") ? k.text("label") : fs::path(path).stem().string();
  c.quasi_static = m.condition.quasi_static;
  read_record_keys(k, m, c);
  c.compare_from_s = c.quasi_static ? first_compared_sample(k, m) : first_compared_time(k, m, c);
  return c;
}

}  // namespace identify_detail

std::string initial_state_name(InitialState s) {
  for (const auto& [m, name] : identify_detail::kInitialStateNames)
    if (m == s) return std::string(name);
  return "demagnetised";
}

std::string offset_mode_name(OffsetMode mode) {
  for (const auto& [m, name] : identify_detail::kOffsetNames)
    if (m == mode) return std::string(name);
  return "absolute";
}

}  // namespace gmasim
