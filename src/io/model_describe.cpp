// `gmasim model show`: the rows of a model (numbers, options, structure) with their values,
// units, provenance and meaning; and the trailing-comment reader behind the provenance.
#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/derived.hpp"
#include "io/model_loader.hpp"
#include "io/schema.hpp"

namespace gmasim {

namespace schema {

std::string trailing_comment(std::string_view line) {
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    const char c = line[i];
    if (c == '#') {
      std::string_view rest = line.substr(i + 1);
      const auto b = rest.find_first_not_of(" \t");
      if (b == std::string_view::npos) return "";
      const auto e = rest.find_last_not_of(" \t\r");
      return std::string(rest.substr(b, e - b + 1));
    }
    if (c == '"' || c == '\'') {
      const std::string triple(3, c);
      if (line.substr(i, 3) == triple) {
        const auto close = line.find(triple, i + 3);
        if (close == std::string_view::npos) return "";  // multi-line string continues
        i = close + 3;
        continue;
      }
      ++i;
      while (i < n && line[i] != c) {
        if (c == '"' && line[i] == '\\') ++i;  // escape in a basic string
        ++i;
      }
      ++i;  // closing quote
      continue;
    }
    ++i;
  }
  return "";
}

}  // namespace schema

namespace {

using io_detail::join;

// The model text behind spec.source, for the comments of options and structure rows; empty
// if it cannot be read (e.g. a spec parsed from a string).
std::string source_text(const std::string& source) {
  if (source == io_detail::builtin_source_name()) return kBuiltinModelToml;
  try {
    return io_detail::read_text_file(source, "model file");
  } catch (const InputError&) {
    return {};  // describe_model shows empty provenance for these rows
  }
}

}  // namespace

namespace {

// The rows of describe_model, with the comments of the source text at their lines.
class Describer {
 public:
  explicit Describer(const ModelSpec& spec)
      : spec_(spec),
        text_(source_text(spec.source)),
        lines_(io_detail::split_lines(text_, io_detail::StripCR::Yes)) {}

  std::vector<ParamRow> rows() {
    std::map<std::string, DerivedQuantity> derived;
    for (auto& d : derived_quantities(spec_)) derived.emplace(d.name, std::move(d));
    for (const auto& [name, pv] : spec_.params) {
      const ParamDef* def = spec_.def_of(name);
      std::string provenance = pv.provenance;
      // A value given where the geometry derives one: the derived value beside it.
      if (const auto d = derived.find(name); d != derived.end() && d->second.overridden)
        provenance +=
            fmt::format("{}[override; derived {:.4g} {}: {}]", provenance.empty() ? "" : " ",
                        d->second.derived, spec_.unit_of(name), d->second.formula);
      rows_.push_back({name, fmt::format("{:g}", pv.value), spec_.unit_of(name), provenance,
                       pv.line, def ? std::string(def->doc) : std::string()});
    }
    for (const auto& [name, value] : spec_.meta)
      add(name, value, "text", line_of(name), "the model's " + name.substr(5));
    for (const auto& o : option_table()) {
      const std::string name = "options." + std::string(o.key);
      add(name, std::string(option_word(o, spec_.options)), "option", line_of(name),
          std::string(o.doc));
    }
    add_structure();
    std::stable_sort(rows_.begin(), rows_.end(),
                     [](const ParamRow& a, const ParamRow& b) { return a.line < b.line; });
    return std::move(rows_);
  }

 private:
  const ModelSpec& spec_;
  std::string text_;
  std::vector<std::string_view> lines_;
  std::vector<ParamRow> rows_;

  std::string comment_at(long line) const {
    if (line < 1 || line > static_cast<long>(lines_.size())) return "";
    return schema::trailing_comment(lines_[static_cast<std::size_t>(line - 1)]);
  }
  long line_of(const std::string& key) const {
    const auto it = spec_.option_lines.find(key);
    return it == spec_.option_lines.end() ? 0 : it->second;
  }
  void add(const std::string& name, std::string value, std::string unit, long line,
           std::string doc) {
    rows_.push_back(
        {name, std::move(value), std::move(unit), comment_at(line), line, std::move(doc)});
  }

  // A branch's comment: on its [[circuit.branches]] line, else on its `name =` line.
  std::string branch_comment(long header) const {
    std::string c = comment_at(header);
    if (!c.empty() || header < 1) return c;
    for (auto i = static_cast<std::size_t>(header); i < lines_.size(); ++i) {
      std::string_view l = lines_[i];
      const auto b = l.find_first_not_of(" \t");
      if (b == std::string_view::npos) continue;
      l.remove_prefix(b);
      if (l.starts_with('[')) break;
      if (l.starts_with("name")) {
        const auto e = l.find_first_not_of(" \t", 4);
        if (e != std::string_view::npos && l[e] == '=') return comment_at(static_cast<long>(i) + 1);
      }
    }
    return "";
  }

  void add_structure() {
    add("stack.rods", join(spec_.rods, ", "), "rods", line_of("stack.rods"),
        "the rods, in stack order");
    if (!spec_.reference_node.empty())
      add("circuit.reference_node", spec_.reference_node, "node", line_of("circuit.reference_node"),
          "the reference node of the nodal solve, eq. (23)");
    if (!spec_.nodes.empty())
      add("circuit.nodes", join(spec_.nodes, ", "), "nodes", spec_.nodes_line,
          "the other nodes: one KCL row each, eq. (23)");
    for (const auto& b : spec_.branches) {
      std::string value = fmt::format("{} -> {}: ", b.from, b.to);
      value += b.rod.empty() ? join(b.series, " + ") : "rod " + b.rod;
      rows_.push_back({"circuit.branches." + b.name, value, "branch", branch_comment(b.line),
                       b.line, "a branch of the magnetic circuit, eq. (23)"});
    }
    add("sensor.flux_branches", join(spec_.flux_sensor_branches, ", "), "branches",
        line_of("sensor.flux_branches"), "the branches the induction coil encloses");
    for (const auto& rod : spec_.rods) {
      const auto it = spec_.chains.find(rod);
      if (it == spec_.chains.end()) continue;
      add("mechanics.chains." + rod, join(it->second, ", "), "chain",
          line_of("mechanics.chains." + rod), "the rod's load chain, eq. (18), (27), (28)");
    }
  }
};

}  // namespace

std::vector<ParamRow> describe_model(const ModelSpec& spec) { return Describer(spec).rows(); }

}  // namespace gmasim
