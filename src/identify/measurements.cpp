// Measurement files (docs/data.md): one CSV per test condition, the condition in header
// comments and/or a TOML sidecar (measurement_condition.cpp), and a TOML manifest listing
// the files and their weights.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "common/text_io.hpp"
#include "common/toml_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"
#include "identify/measurement_condition.hpp"

namespace gmasim {
namespace {

namespace fs = std::filesystem;

using identify_detail::KeyMap;
using io_detail::read_text_file;
using io_detail::split_cells;
using io_detail::trim;

// Columns (docs/data.md): [t_s], one drive (current_A | field_A_per_m | field_kA_per_m), one
// response (displacement_um | strain_ppm), [flux_T]. A field in kA/m is read as 1000 A/m.
enum Col { T, I, H, HK, Y, S, B, kCols };
constexpr std::string_view kNames[kCols] = {
    "t_s",        "current_A", "field_A_per_m", "field_kA_per_m", "displacement_um",
    "strain_ppm", "flux_T"};
constexpr std::string_view kExpected =
    "[t_s,]current_A|field_A_per_m|field_kA_per_m,displacement_um|strain_ppm[,flux_T]";

// Where each column is (-1: absent), from the header line.
struct CsvLayout {
  int col_of[kCols] = {-1, -1, -1, -1, -1, -1, -1};
  std::size_t ncols = 0;
  long header_line = 0;  // 0: no header read yet

  bool has(Col c) const { return col_of[c] >= 0; }
  Col drive() const { return has(H) ? H : has(HK) ? HK : I; }
  Col response() const { return has(S) ? S : Y; }
  // The drive column's limit in its own unit, and its factor to SI.
  double drive_limit() const {
    return has(H) ? kMaxField_A_per_m : has(HK) ? kMaxField_A_per_m / 1e3 : kMaxCurrent_A;
  }
  double drive_to_si() const { return has(HK) ? 1e3 : 1.0; }
};

CsvLayout read_header(const std::vector<std::string_view>& cells, std::string_view line,
                      const std::string& path, long line_no) {
  CsvLayout lay;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const auto it = std::find(std::begin(kNames), std::end(kNames), cells[c]);
    if (it == std::end(kNames)) {
      throw InputError(located(
          path, line_no,
          fmt::format("unknown column '{}' in the header; expected {}", cells[c], kExpected)));
    }
    const auto k = static_cast<std::size_t>(it - std::begin(kNames));
    if (lay.col_of[k] >= 0)
      throw InputError(located(path, line_no, fmt::format("column '{}' appears twice", cells[c])));
    lay.col_of[k] = static_cast<int>(c);
  }
  auto exactly_one = [&](Col a, Col b, std::string_view what) {
    if (lay.has(a) && lay.has(b))
      throw InputError(located(path, line_no,
                               fmt::format("columns '{}' and '{}' are both given: a record "
                                           "has one {} column",
                                           kNames[a], kNames[b], what)));
    if (!lay.has(a) && !lay.has(b))
      throw InputError(located(path, line_no,
                               fmt::format("missing {} column ('{}' or '{}') in the header "
                                           "'{}'; expected {}",
                                           what, kNames[a], kNames[b], line, kExpected)));
  };
  if (lay.has(HK) && (lay.has(I) || lay.has(H)))
    throw InputError(located(path, line_no,
                             fmt::format("columns '{}' and '{}' are both given: a record has one "
                                         "drive column",
                                         kNames[HK], kNames[lay.has(I) ? I : H])));
  if (!lay.has(HK)) exactly_one(I, H, "drive");
  exactly_one(Y, S, "response");
  lay.ncols = cells.size();
  lay.header_line = line_no;
  return lay;
}

// One data row, appended to m: every cell a finite number, the drive in range, the time
// increasing (a quasi-static record: t is the sample index).
void read_row(const CsvLayout& lay, const std::vector<std::string_view>& cells,
              std::string_view line, const std::string& path, long line_no, Measurement& m) {
  if (cells.size() != lay.ncols) {
    throw InputError(located(path, line_no,
                             fmt::format("mismatched columns: {} cells, the header has {} ('{}')",
                                         cells.size(), lay.ncols, line)));
  }
  double v[kCols] = {0, 0, 0, 0, 0, 0, 0};
  for (int k = 0; k < kCols; ++k) {
    if (lay.col_of[k] < 0) continue;
    if (auto bad =
            identify_detail::parse_number(cells[static_cast<std::size_t>(lay.col_of[k])], v[k]))
      throw InputError(located(path, line_no, fmt::format("{} in column {}", *bad, kNames[k])));
  }
  const Col drive = lay.drive();
  const double limit = lay.drive_limit();
  if (!(std::fabs(v[drive]) <= limit))
    throw InputError(located(
        path, line_no,
        fmt::format("{} = {:g}: must be in [-{:g}, {:g}]", kNames[drive], v[drive], limit, limit)));
  if (!lay.has(T)) {
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
  m.drive.push_back(v[drive] * lay.drive_to_si());
  m.response.push_back(v[lay.response()]);
  if (lay.has(B)) m.flux_T.push_back(v[B]);
}

// The TOML file at `path` (`what` names it in the open/read error).
toml::table read_toml(const std::string& path, std::string_view what) {
  return io_detail::parse_toml(read_text_file(path, what), path);
}

}  // namespace

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
  CsvLayout lay;
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
      identify_detail::read_comment_key(trim(line.substr(1)), path, line_no, keys);
      continue;
    }
    const auto cells = split_cells(line);
    if (lay.header_line == 0) {
      lay = read_header(cells, line, path, line_no);
      m.drive_kind = lay.has(H) || lay.has(HK) ? DriveInput::Field : DriveInput::Current;
      m.drive_header = std::string(kNames[lay.drive()]);
      m.response_kind = lay.has(S) ? ResponseOutput::Strain : ResponseOutput::Displacement;
    } else {
      read_row(lay, cells, line, path, line_no, m);
    }
  }
  if (lay.header_line == 0) {
    throw InputError(located(path, line_no > 0 ? line_no : 1,
                             line_no > 0 ? fmt::format("no header: expected {}", kExpected)
                                         : std::string("empty file")));
  }
  if (m.t_s.size() < 4) {
    throw InputError(
        located(path, line_no, fmt::format("needs at least 4 data rows, found {}", m.t_s.size())));
  }
  m.condition.quasi_static = !lay.has(T);
  const std::string side = identify_detail::sidecar_path(path);
  std::error_code ec;
  if (fs::exists(side, ec)) identify_detail::read_sidecar(side, keys);
  m.condition = identify_detail::make_condition(keys, m, path, lay.header_line);
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
    if (c.compare_from_s > 0.0)
      s += fmt::format("# compare_from_sample = {:.17g}\n", c.compare_from_s);
  } else {
    s += fmt::format("# compare_from_s = {:.17g}\n", c.compare_from_s);
  }
  if (c.current_source != "measured") s += fmt::format("# current_source = {}\n", c.current_source);
  if (!c.rod.empty()) s += fmt::format("# rod = {}\n", c.rod);
  if (c.precycles > 0) s += fmt::format("# precycles = {}\n", c.precycles);
  if (c.initial_state != InitialState::Demagnetised)
    s += fmt::format("# initial_state = {}\n", initial_state_name(c.initial_state));
  if (c.offset != OffsetMode::Absolute)
    s += fmt::format("# offset = {}\n", offset_mode_name(c.offset));
  if (c.flux_offset != OffsetMode::Absolute)
    s += fmt::format("# flux_offset = {}\n", offset_mode_name(c.flux_offset));
  if (!std::isnan(c.prestress_MPa))
    s += fmt::format("# prestress_MPa = {:.17g}\n", c.prestress_MPa);
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
