// Measurement files (docs/data.md): one CSV per test condition, the condition in header
// comments and/or a TOML sidecar, and a TOML manifest listing the files and their weights.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "common/text_io.hpp"
#include "common/toml_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/identify.hpp"
#include "gmasim/io.hpp"
#include "gmasim/validate.hpp"

namespace gmasim {
namespace {

namespace fs = std::filesystem;

using io_detail::read_text_file;
using io_detail::split_cells;
using io_detail::trim;

// The TOML file at `path` (`what` names it in the open/read error).
toml::table read_toml(const std::string& path, std::string_view what) {
  return io_detail::parse_toml(read_text_file(path, what), path);
}

// A finite number, or the reason it is not one.
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

// ---- condition keys ------------------------------------------------------------------
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

struct KeyValue {
  std::string text;  // as written (numbers are re-parsed)
  double number = 0.0;
  std::string file;
  long line = 0;
};
using KeyMap = std::map<std::string, KeyValue>;

bool is_identifier(std::string_view s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

// "# key = value" / "# key: value" in a CSV comment; free-text comments are ignored.
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
  const toml::table root = read_toml(path, "condition sidecar");
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

OffsetMode parse_offset(const KeyValue& kv, std::string_view key) {
  for (const auto& [mode, name] : kOffsetNames)
    if (kv.text == name) return mode;
  throw InputError(located(kv.file, kv.line,
                           fmt::format("{} = '{}': must be absolute, first_sample or fitted", key,
                                       kv.text)));
}

// The keys of issue 9 item 7: rod, precycles, offset, flux_offset; `fail(key, message)`
// throws at the key's file:line.
template <class Fail>
void read_record_keys(const KeyMap& keys, const Measurement& m, MeasurementCondition& c,
                      Fail&& fail) {
  const bool rod_columns =
      m.drive_kind == DriveInput::Field || m.response_kind == ResponseOutput::Strain;
  if (keys.count("rod")) {
    c.rod = keys.at("rod").text;
    if (!rod_columns)
      fail("rod",
           fmt::format("rod = '{}': names the rod of a field_A_per_m or strain_ppm column, and "
                       "this record has neither",
                       c.rod));
    if (!is_identifier(c.rod))
      fail("rod", fmt::format("rod = '{}': must be a rod name of the model (letters, digits, _)",
                              c.rod));
  }
  if (m.drive_kind == DriveInput::Field && c.current_source == "sine")
    fail("current_source",
         "current_source = sine drives the model with a current; this record's drive is "
         "field_A_per_m");
  if (keys.count("offset")) c.offset = parse_offset(keys.at("offset"), "offset");
  if (keys.count("flux_offset")) {
    c.flux_offset = parse_offset(keys.at("flux_offset"), "flux_offset");
    if (m.flux_T.empty()) fail("flux_offset", "flux_offset: the record has no flux_T column");
  }
  if (keys.count("precycles")) {
    const double n = keys.at("precycles").number;
    if (!(n >= 0.0 && n <= static_cast<double>(kMaxPrecycles) && n == std::floor(n)))
      fail("precycles", fmt::format("precycles = {:g}: must be a whole number in [0, {}]", n,
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
      fail("precycles",
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

MeasurementCondition make_condition(const KeyMap& keys, const Measurement& m,
                                    const std::string& path, long header_line) {
  MeasurementCondition c;
  auto where = [&](const std::string& key) -> std::pair<std::string, long> {
    const auto it = keys.find(key);
    return it == keys.end() ? std::pair{path, header_line}
                            : std::pair{it->second.file, it->second.line};
  };
  auto fail = [&](const std::string& key, const std::string& msg) {
    const auto [f, l] = where(key);
    throw InputError(located(f, l, msg));
  };
  const std::string side = sidecar_path(path);
  if (!keys.count("temperature_C")) {
    fail("temperature_C",
         fmt::format("condition missing: temperature_C (write '# temperature_C = 20' above the "
                     "header, or temperature_C = 20.0 in the sidecar {})",
                     side));
  }
  c.temperature_C = keys.at("temperature_C").number;
  if (!(c.temperature_C > -273.15 && c.temperature_C < 1e4))
    fail("temperature_C",
         fmt::format("temperature_C = {:g}: must be > -273.15 degC", c.temperature_C));
  if (m.condition.quasi_static) {
    for (const char* k : {"frequency_Hz", "current_pp_A", "current_source", "compare_from_s"})
      if (keys.count(k))
        fail(k, fmt::format("{}: a quasi-static record (no t_s column) has no time, frequency "
                            "or sine; give t_s, or drop {} (compare_from_sample selects the "
                            "first compared sample)",
                            k, k));
  }
  const double t0_rec = m.t_s.front(), t1_rec = m.t_s.back();
  const bool has_f = keys.count("frequency_Hz") > 0;
  const bool has_pp = keys.count("current_pp_A") > 0;
  if (has_f) {
    c.frequency_Hz = keys.at("frequency_Hz").number;
    if (!(c.frequency_Hz > 0.0 && c.frequency_Hz <= kMaxFrequency_Hz))
      fail("frequency_Hz", fmt::format("frequency_Hz = {:g}: must be in (0, {:g}] Hz",
                                       c.frequency_Hz, kMaxFrequency_Hz));
    // The record must span a whole number of steps the simulator can take: at least the
    // 8-step floor per period, at most kMaxSteps over the record.
    if (!((t1_rec - t0_rec) * c.frequency_Hz * 8.0 <= kMaxSteps))
      fail("frequency_Hz",
           fmt::format("frequency_Hz = {:g}: {:.4g} periods over the record's {:g} s: too many "
                       "to simulate (limit {:g} steps)",
                       c.frequency_Hz, (t1_rec - t0_rec) * c.frequency_Hz, t1_rec - t0_rec,
                       kMaxSteps));
    if (!has_pp) {
      fail("frequency_Hz",
           "condition missing: current_pp_A (a periodic condition, with frequency_Hz, also "
           "names its current peak-to-peak)");
    }
  }
  if (has_pp) {
    if (!has_f) {
      fail("current_pp_A",
           "condition missing: frequency_Hz (current_pp_A describes a periodic excitation)");
    }
    c.current_pp_A = keys.at("current_pp_A").number;
    if (!(c.current_pp_A > 0.0 && c.current_pp_A <= 2.0 * kMaxCurrent_A))
      fail("current_pp_A", fmt::format("current_pp_A = {:g}: must be in (0, {:g}] A",
                                       c.current_pp_A, 2.0 * kMaxCurrent_A));
  }
  if (keys.count("current_min_A")) {
    c.current_min_A = keys.at("current_min_A").number;
    if (!(std::fabs(c.current_min_A) <= kMaxCurrent_A))
      fail("current_min_A", fmt::format("current_min_A = {:g}: must be in [-{:g}, {:g}] A",
                                        c.current_min_A, kMaxCurrent_A, kMaxCurrent_A));
  }
  if (keys.count("current_source")) {
    c.current_source = keys.at("current_source").text;
    if (c.current_source != "measured" && c.current_source != "sine")
      fail("current_source",
           fmt::format("current_source = '{}': must be measured or sine", c.current_source));
    if (c.current_source == "sine" && !has_f)
      fail("current_source", "current_source = sine needs frequency_Hz and current_pp_A");
  }
  c.label = keys.count("label") ? keys.at("label").text : fs::path(path).stem().string();
  c.quasi_static = m.condition.quasi_static;
  read_record_keys(keys, m, c, fail);
  const double t0 = m.t_s.front(), t1 = m.t_s.back();
  if (c.quasi_static) {
    c.compare_from_s = 0.0;
    if (keys.count("compare_from_sample")) {
      const double k0 = keys.at("compare_from_sample").number;
      if (!(k0 >= 0.0 && k0 == std::floor(k0) && k0 + 3.0 <= static_cast<double>(m.t_s.size())))
        fail("compare_from_sample",
             fmt::format("compare_from_sample = {:g}: must be a whole sample index in [0, {}] "
                         "(at least 3 samples compared)",
                         k0, m.t_s.size() - 3));
      c.compare_from_s = k0;
    }
    return c;
  }
  if (keys.count("compare_from_sample"))
    fail("compare_from_sample",
         "compare_from_sample is for quasi-static records (no t_s column); a timed record "
         "uses compare_from_s");
  if (keys.count("compare_from_s")) {
    c.compare_from_s = keys.at("compare_from_s").number;
  } else {
    // A pre-cycled record is already on its loop: everything is compared.
    c.compare_from_s = has_f && c.precycles == 0 ? t0 + 1.0 / c.frequency_Hz : t0;
  }
  // At least 3 compared samples.
  const auto first =
      std::lower_bound(m.t_s.begin(), m.t_s.end(), c.compare_from_s - 1e-12 * (t1 - t0));
  if (m.t_s.end() - first < 3) {
    if (keys.count("compare_from_s")) {
      fail("compare_from_s", fmt::format("compare_from_s = {:g} s leaves fewer than 3 samples to "
                                         "compare (the record ends at {:g} s)",
                                         c.compare_from_s, t1));
    }
    throw InputError(located(path, header_line,
                             fmt::format("the record ({:g} .. {:g} s) is shorter than one period "
                                         "({:g} s) plus 3 samples: nothing is left to compare "
                                         "after the first period (set compare_from_s)",
                                         t0, t1, has_f ? 1.0 / c.frequency_Hz : 0.0)));
  }
  return c;
}

}  // namespace

std::string offset_mode_name(OffsetMode mode) {
  for (const auto& [m, name] : kOffsetNames)
    if (m == mode) return std::string(name);
  return "absolute";
}

std::string_view Measurement::drive_column() const {
  return drive_kind == DriveInput::Field ? "field_A_per_m" : "current_A";
}
std::string_view Measurement::response_column() const {
  return response_kind == ResponseOutput::Strain ? "strain_ppm" : "displacement_um";
}
std::string_view Measurement::response_unit() const {
  return response_kind == ResponseOutput::Strain ? "ppm" : "um";
}

Measurement load_measurement_csv(const std::string& path) {
  const std::string text = read_text_file(path, "measurement file");
  Measurement m;
  m.path = path;
  KeyMap keys;

  // Columns (docs/data.md): [t_s], one drive (current_A | field_A_per_m), one response
  // (displacement_um | strain_ppm), [flux_T].
  enum Col { T, I, H, Y, S, B, kCols };
  static constexpr std::string_view kNames[kCols] = {
      "t_s", "current_A", "field_A_per_m", "displacement_um", "strain_ppm", "flux_T"};
  constexpr std::string_view kExpected =
      "[t_s,]current_A|field_A_per_m,displacement_um|strain_ppm[,flux_T]";
  int col_of[kCols] = {-1, -1, -1, -1, -1, -1};
  std::size_t ncols = 0;
  long header_line = 0;
  double drive_limit = kMaxCurrent_A;

  std::string_view rest = text;
  if (rest.starts_with("\xEF\xBB\xBF")) rest.remove_prefix(3);
  long line_no = 0;
  while (!rest.empty()) {
    const auto nl = rest.find('\n');
    const std::string_view raw = rest.substr(0, nl);
    rest = nl == std::string_view::npos ? std::string_view{} : rest.substr(nl + 1);
    ++line_no;
    const std::string_view line = trim(raw);
    if (line.empty()) continue;
    if (line.front() == '#') {
      read_comment_key(trim(line.substr(1)), path, line_no, keys);
      continue;
    }
    const auto cells = split_cells(line);
    if (header_line == 0) {
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const auto it = std::find(std::begin(kNames), std::end(kNames), cells[c]);
        if (it == std::end(kNames)) {
          throw InputError(located(
              path, line_no,
              fmt::format("unknown column '{}' in the header; expected {}", cells[c], kExpected)));
        }
        const auto k = static_cast<std::size_t>(it - std::begin(kNames));
        if (col_of[k] >= 0)
          throw InputError(
              located(path, line_no, fmt::format("column '{}' appears twice", cells[c])));
        col_of[k] = static_cast<int>(c);
      }
      auto exactly_one = [&](int a, int b, std::string_view what) {
        if (col_of[a] >= 0 && col_of[b] >= 0)
          throw InputError(located(path, line_no,
                                   fmt::format("columns '{}' and '{}' are both given: a record "
                                               "has one {} column",
                                               kNames[a], kNames[b], what)));
        if (col_of[a] < 0 && col_of[b] < 0)
          throw InputError(located(path, line_no,
                                   fmt::format("missing {} column ('{}' or '{}') in the header "
                                               "'{}'; expected {}",
                                               what, kNames[a], kNames[b], line, kExpected)));
      };
      exactly_one(I, H, "drive");
      exactly_one(Y, S, "response");
      m.drive_kind = col_of[H] >= 0 ? DriveInput::Field : DriveInput::Current;
      m.response_kind = col_of[S] >= 0 ? ResponseOutput::Strain : ResponseOutput::Displacement;
      drive_limit = col_of[H] >= 0 ? kMaxField_A_per_m : kMaxCurrent_A;
      ncols = cells.size();
      header_line = line_no;
      continue;
    }
    if (cells.size() != ncols) {
      throw InputError(located(path, line_no,
                               fmt::format("mismatched columns: {} cells, the header has {} ('{}')",
                                           cells.size(), ncols, line)));
    }
    double v[kCols] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < kCols; ++k) {
      if (col_of[k] < 0) continue;
      if (auto bad = parse_number(cells[static_cast<std::size_t>(col_of[k])], v[k]))
        throw InputError(located(path, line_no, fmt::format("{} in column {}", *bad, kNames[k])));
    }
    const int drive_col = col_of[H] >= 0 ? H : I;
    if (!(std::fabs(v[drive_col]) <= drive_limit))
      throw InputError(located(path, line_no,
                               fmt::format("{} = {:g}: must be in [-{:g}, {:g}]", kNames[drive_col],
                                           v[drive_col], drive_limit, drive_limit)));
    if (col_of[T] < 0) {
      v[T] = static_cast<double>(m.t_s.size());  // quasi-static: the sample index
    } else if (!m.t_s.empty()) {
      const double prev = m.t_s.back();
      if (v[T] == prev) {
        throw InputError(
            located(path, line_no, fmt::format("duplicate timestamp t_s = {:g} s", v[T])));
      }
      if (v[T] < prev) {
        throw InputError(
            located(path, line_no,
                    fmt::format("time {:g} s does not increase (previous {:g} s)", v[T], prev)));
      }
    }
    m.t_s.push_back(v[T]);
    m.drive.push_back(v[drive_col]);
    m.response.push_back(v[col_of[S] >= 0 ? S : Y]);
    if (col_of[B] >= 0) m.flux_T.push_back(v[B]);
  }
  if (header_line == 0) {
    throw InputError(located(path, line_no > 0 ? line_no : 1,
                             line_no > 0 ? fmt::format("no header: expected {}", kExpected)
                                         : std::string("empty file")));
  }
  if (m.t_s.size() < 4) {
    throw InputError(
        located(path, line_no, fmt::format("needs at least 4 data rows, found {}", m.t_s.size())));
  }
  m.condition.quasi_static = col_of[T] < 0;
  const std::string side = sidecar_path(path);
  std::error_code ec;
  if (fs::exists(side, ec)) read_sidecar(side, keys);
  m.condition = make_condition(keys, m, path, header_line);
  return m;
}

MeasurementSet load_manifest(const std::string& path) {
  const toml::table root = read_toml(path, "manifest");
  MeasurementSet set;
  set.manifest = path;
  for (const auto& [key, node] : root) {
    if (key.str() != "measurement") {
      throw InputError(located(path, static_cast<long>(node.source().begin.line),
                               fmt::format("unknown key '{}'; a manifest holds [[measurement]] "
                                           "tables with file and weight",
                                           key.str())));
    }
  }
  const toml::array* list = root["measurement"].as_array();
  if (!list || list->empty()) {
    throw InputError(located(path, 1,
                             "no [[measurement]] entries: list at least one file "
                             "([[measurement]] file = \"...\", weight = 1.0)"));
  }
  const fs::path base = fs::path(path).parent_path();
  std::set<std::string> seen;
  for (const auto& node : *list) {
    const long line = static_cast<long>(node.source().begin.line);
    const toml::table* t = node.as_table();
    if (!t) throw InputError(located(path, line, "[[measurement]]: expected a table"));
    for (const auto& [k, v] : *t) {
      if (k.str() != "file" && k.str() != "weight") {
        throw InputError(located(path, static_cast<long>(v.source().begin.line),
                                 fmt::format("unknown key '{}' in [[measurement]]; expected file, "
                                             "weight",
                                             k.str())));
      }
    }
    const auto file = (*t)["file"].value<std::string>();
    if (!file || file->empty())
      throw InputError(located(path, line, "[[measurement]]: missing file = \"name.csv\""));
    double weight = 1.0;
    if (const toml::node* w = t->get("weight")) {
      const auto wv = w->value<double>();
      const long wl = static_cast<long>(w->source().begin.line);
      if (!wv) throw InputError(located(path, wl, "weight: expected a number"));
      if (!(*wv > 0.0) || !std::isfinite(*wv))
        throw InputError(located(path, wl, fmt::format("weight = {:g}: must be > 0", *wv)));
      // Weights are relative: a range of 1e-6..1e6 covers any use, and an extreme one
      // would scale every other residual to nothing ("RMS 0 %", issue 8).
      if (!(*wv >= 1e-6 && *wv <= 1e6))
        throw InputError(
            located(path, wl, fmt::format("weight = {:g}: must be in [1e-6, 1e6]", *wv)));
      weight = *wv;
    }
    const fs::path fp = fs::path(*file).is_absolute() ? fs::path(*file) : base / *file;
    const std::string full = fp.lexically_normal().string();
    if (!seen.insert(full).second)
      throw InputError(located(path, line, fmt::format("file '{}' is listed twice", *file)));
    std::error_code ec;
    if (!fs::exists(fp, ec)) {
      throw InputError(located(
          path, line, fmt::format("measurement file '{}' does not exist ({})", *file, full)));
    }
    Measurement m = load_measurement_csv(full);
    m.weight = weight;
    set.items.push_back(std::move(m));
  }
  return set;
}

std::string measurement_csv(const Measurement& m) {
  const auto& c = m.condition;
  std::string s = "# gmasim measurement file (docs/data.md)\n";
  s += fmt::format("# label = {}\n", c.label);
  s += fmt::format("# temperature_C = {:.17g}\n", c.temperature_C);
  if (m.periodic()) {
    s += fmt::format("# frequency_Hz = {:.17g}\n", c.frequency_Hz);
    s += fmt::format("# current_pp_A = {:.17g}\n", c.current_pp_A);
    s += fmt::format("# current_min_A = {:.17g}\n", c.current_min_A);
  }
  if (c.quasi_static) {
    if (c.compare_from_s > 0.0) s += fmt::format("# compare_from_sample = {:.17g}\n", c.compare_from_s);
  } else {
    s += fmt::format("# compare_from_s = {:.17g}\n", c.compare_from_s);
  }
  if (c.current_source != "measured") s += fmt::format("# current_source = {}\n", c.current_source);
  if (!c.rod.empty()) s += fmt::format("# rod = {}\n", c.rod);
  if (c.precycles > 0) s += fmt::format("# precycles = {}\n", c.precycles);
  if (c.offset != OffsetMode::Absolute) s += fmt::format("# offset = {}\n", offset_mode_name(c.offset));
  if (c.flux_offset != OffsetMode::Absolute)
    s += fmt::format("# flux_offset = {}\n", offset_mode_name(c.flux_offset));
  const bool flux = !m.flux_T.empty();
  if (!c.quasi_static) s += "t_s,";
  s += fmt::format("{},{}{}\n", m.drive_column(), m.response_column(), flux ? ",flux_T" : "");
  for (std::size_t i = 0; i < m.t_s.size(); ++i) {
    if (!c.quasi_static) s += fmt::format("{:.17g},", m.t_s[i]);
    s += fmt::format("{:.17g},{:.17g}", m.drive[i], m.response[i]);
    if (flux) s += fmt::format(",{:.17g}", m.flux_T[i]);
    s += '\n';
  }
  return s;
}

void write_measurement_set(const MeasurementSet& set, const std::string& dir) {
  ensure_output_dir(dir);
  std::string manifest =
      "# gmasim measurement manifest (docs/data.md): one [[measurement]] per CSV file\n";
  for (const auto& m : set.items) {
    const std::string name = fs::path(m.path).filename().string();
    write_file_atomic((fs::path(dir) / name).string(), measurement_csv(m));
    manifest += fmt::format("\n[[measurement]]\nfile = \"{}\"\nweight = {:.6g}\n", name, m.weight);
  }
  write_file_atomic((fs::path(dir) / "manifest.toml").string(), manifest);
}

}  // namespace gmasim
