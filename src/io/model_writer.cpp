// Changing and saving models: "name=value" assignments (the --set flag of every command,
// Python Model.with_params) and the model file of a changed spec (Model.save, `gmasim model
// save`). The file is the spec's own source text with each changed value replaced on its
// line, so comments, layout and the provenance of unchanged values survive.
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <map>
#include <stdexcept>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/derived.hpp"
#include "gmasim/model/validate.hpp"
#include "io/schema.hpp"

namespace gmasim {

namespace schema {

std::optional<ValueSpan> value_span(std::string_view line, std::string_view leaf) {
  std::size_t pos = 0;
  while ((pos = line.find(leaf, pos)) != std::string_view::npos) {
    const bool left_ok =
        pos == 0 || std::string_view(" \t{,").find(line[pos - 1]) != std::string_view::npos;
    std::size_t q = pos + leaf.size();
    while (q < line.size() && (line[q] == ' ' || line[q] == '\t')) ++q;
    if (left_ok && q < line.size() && line[q] == '=') {
      ++q;
      while (q < line.size() && (line[q] == ' ' || line[q] == '\t')) ++q;
      std::size_t end = q;
      if (q < line.size() && line[q] == '"') {  // a basic string: up to its closing quote
        end = line.find('"', q + 1);
        end = end == std::string_view::npos ? line.size() : end + 1;
      } else {
        while (end < line.size() &&
               std::string_view(" \t,}#").find(line[end]) == std::string_view::npos)
          ++end;
      }
      return ValueSpan{q, end};
    }
    pos += leaf.size();
  }
  return std::nullopt;
}

std::string toml_float(double v) {
  std::string s = fmt::format("{}", v);  // shortest text that reads back as v
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

}  // namespace schema

namespace {

// Replaces the value of `leaf` on line `line_no` (1-based) by `value_text`; on a plain line
// the trailing comment becomes `comment`.
void replace_value(std::vector<std::string>& lines, long line_no, std::string_view leaf,
                   const std::string& value_text, const std::string& comment,
                   const std::string& source) {
  if (line_no < 1 || line_no > static_cast<long>(lines.size()))
    throw InputError(fmt::format("{}: no source line for '{}'", source, leaf));
  std::string& line = lines[static_cast<std::size_t>(line_no - 1)];
  const auto span = schema::value_span(line, leaf);
  if (!span)
    throw InputError(fmt::format("{}:{}: '{} =' not found on its line", source, line_no, leaf));
  if (line.find('{') == std::string::npos) {
    line = line.substr(0, span->begin) + value_text + "  # " + comment;
  } else {
    line = line.substr(0, span->begin) + value_text + line.substr(span->end);
  }
}

// A key of a pair (preload.force_N | preload.prestress_MPa) set in place of the other, which
// the source text holds: the other's line becomes this key's.
void replace_alternative(std::vector<std::string>& lines, const ModelSpec& original,
                         const std::string& name, double value, const std::string& why) {
  const ParamDef* def = find_param_def(original, name);
  const std::string table = name.substr(0, name.rfind('.'));
  const std::string leaf = name.substr(name.rfind('.') + 1);
  const auto other = def && !def->alternative.empty()
                         ? original.params.find(table + "." + std::string(def->alternative))
                         : original.params.end();
  if (other == original.params.end() || other->second.line < 1 ||
      other->second.line > static_cast<long>(lines.size()))
    throw InputError(
        fmt::format("{}: parameter '{}' is not in its source text", original.source, name));
  std::string& line = lines[static_cast<std::size_t>(other->second.line - 1)];
  const auto at = line.find(def->alternative);
  line = fmt::format("{}{} = {}  # set: {}; was {} = {}", line.substr(0, at), leaf,
                     schema::toml_float(value), why, def->alternative,
                     schema::toml_float(other->second.value));
}

// The table leaf of a magnetisation law's group ("ja", "preisach").
std::string law_leaf(MagnetisationLaw law) {
  for (const GroupDef& g : parameter_groups())
    if (g.law && *g.law == law) return std::string(g.path.substr(g.path.rfind('.') + 1));
  return {};
}

// A change of magnetisation law: each rod's table of the old law ([<rod>.ja]) is commented out
// in place (its line numbers stay valid), with a note on its header line.
void comment_out_law_tables(std::vector<std::string>& lines, const ModelSpec& original,
                            const std::string& new_word, const std::string& why) {
  const std::string leaf = law_leaf(original.options.magnetisation_law);
  for (const auto& rod : original.rods) {
    const std::string header = "[" + rod + "." + leaf + "]";
    std::size_t k = 0;
    while (k < lines.size() && !io_detail::trim(lines[k]).starts_with(header)) ++k;
    if (k == lines.size())
      throw InputError(fmt::format(
          "{}: cannot change options.magnetisation_law: the law's table {} is not a table of "
          "its own in the file (write it as a [{}.{}] section)",
          original.source, header, rod, leaf));
    lines[k] = fmt::format("# {}  # unused: options.magnetisation_law = \"{}\" (set: {})",
                           io_detail::trim(lines[k]), new_word, why);
    for (++k; k < lines.size() && !io_detail::trim(lines[k]).starts_with('['); ++k)
      if (!io_detail::trim(lines[k]).empty()) lines[k] = "# " + lines[k];
  }
}
// The changed options: on their lines, or (an omitted option) into `added` for [options].
void write_options(std::vector<std::string>& lines,
                   std::map<std::string, std::vector<std::string>>& added, const ModelSpec& spec,
                   const ModelSpec& original, const std::string& why) {
  auto leaf_of = [](const std::string& dotted) { return dotted.substr(dotted.rfind('.') + 1); };
  for (const auto& def : option_table()) {
    const std::string name = "options." + std::string(def.key);
    const std::string value(option_word(def, spec.options));
    const std::string was(option_word(def, original.options));
    if (value == was) continue;
    if (!original.option_lines.count(name)) {  // an omitted option: added to [options]
      const std::string text = def.boolean ? value : "\"" + value + "\"";
      added["options"].push_back(
          fmt::format("{} = {}  # set: {}; was its default {}", def.key, text, why, was));
      continue;
    }
    const long line_no = spec.line_of(name);
    const std::string& line = lines.at(static_cast<std::size_t>(std::max(1L, line_no) - 1));
    const auto span = schema::value_span(line, leaf_of(name));
    const bool quoted = span && span->begin < line.size() && line[span->begin] == '"';
    replace_value(lines, line_no, leaf_of(name), quoted ? "\"" + value + "\"" : value,
                  fmt::format("set: {}; was {}", why, was), spec.source);
  }
}
}  // namespace

ModelSpec apply_assignments(ModelSpec spec, const std::vector<std::string>& assignments,
                            std::string_view flag) {
  // The options first, together (checked as a whole): a change of magnetisation law brings
  // the new law's numbers into the spec (ModelSpec::set_options), which the numbers may set.
  std::vector<std::pair<std::string, std::string>> options;
  struct Number {
    std::string shown, name, value;
  };
  std::vector<Number> numbers;
  for (const std::string& a : assignments) {
    const std::string shown = clip_for_message(a);
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(
          fmt::format("{} '{}': expected name=value (e.g. material.Ms_A_per_m=7e5 or "
                      "options.magnetic_state=printed)",
                      flag, shown));
    const std::string name(io_detail::trim(std::string_view(a).substr(0, eq)));
    const std::string value(io_detail::trim(std::string_view(a).substr(eq + 1)));
    if (name.starts_with("options.")) {
      if (!find_option_def(name))
        throw InputError(fmt::format("{} '{}': the model has no option '{}'", flag, shown, name));
      if (value.empty() || value.find_first_of(" \t\"'#") != std::string::npos)
        throw InputError(
            fmt::format("{} '{}': an option value is one word (no spaces or quotes)", flag, shown));
      options.emplace_back(name, value);
      continue;
    }
    numbers.push_back({shown, name, value});
  }
  if (!options.empty()) spec.set_options(options);
  for (const auto& [shown, name, value] : numbers) {
    double v = 0;
    if (io_detail::parse_finite(value, v) != io_detail::CellError::None) {
      if (name.starts_with("meta."))  // text: a model's name and description
        throw InputError(fmt::format(
            "{} '{}': {} is text, not a parameter; --set changes the model's numbers (and the "
            "words of options.*): edit [meta] in the file (gmasim model save writes one to edit)",
            flag, shown, name));
      try {
        (void)spec.get(name);  // the parameter exists: the value is what is wrong
      } catch (const InputError& e) {
        throw InputError(fmt::format("{} '{}': {}", flag, shown, e.what()));
      }
      throw InputError(
          fmt::format("{} '{}': {} takes a number; the value '{}' is not a finite number", flag,
                      shown, name, value));
    }
    try {
      spec.set(name, v);
    } catch (const InputError& e) {  // name the flag too (issue 19, item 11)
      throw InputError(fmt::format("{} '{}': {}", flag, shown, e.what()));
    }
  }
  apply_derivations(spec);  // a --set of the geometry moves what it derives
  return spec;
}

namespace {

// Defaulted keys and omitted options: below their table's header if the file has one, else
// in a new table at the end (returned). Bottom-up, so earlier line numbers stay valid.
std::string insert_added(std::vector<std::string>& lines, const ModelSpec& original,
                         const std::map<std::string, std::vector<std::string>>& added,
                         const std::string& why) {
  std::vector<std::pair<long, std::string>> inserts;
  std::string appended;
  // The line of a table's header: recorded for the optional tables, else found in the text
  // ([<rod>] of a key the file leaves to its derivation); 0 if the file has none.
  auto header_line = [&](const std::string& table) -> long {
    const auto it = original.option_lines.find("[" + table + "]");
    if (it != original.option_lines.end() && it->second > 0) return it->second;
    const std::string header = "[" + table + "]";
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const std::string_view l = io_detail::trim(lines[i]);
      if (l.starts_with(header) &&
          (l.size() == header.size() || l[header.size()] == ' ' || l[header.size()] == '#'))
        return static_cast<long>(i) + 1;
    }
    return 0;
  };
  for (const auto& [table, keys] : added) {
    const long at = header_line(table);
    std::string block;
    for (const auto& k : keys) block += (block.empty() ? "" : "\n") + k;
    if (at > 0) {
      inserts.emplace_back(at, block);
    } else {
      appended += fmt::format("\n[{}]  # added by: {}\n{}\n", table, why, block);
    }
  }
  std::sort(inserts.begin(), inserts.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [line_no, block] : inserts)
    lines.insert(lines.begin() + std::min<long>(line_no, static_cast<long>(lines.size())), block);
  return appended;
}

}  // namespace

std::string model_toml(const ModelSpec& given, const std::string& why) {
  // The derived quantities at the spec's current geometry (gmasim/model/derived.hpp): they are
  // not written (the file derives them again), an override is.
  ModelSpec spec = given;
  const std::vector<std::string> derived = apply_derivations(spec);
  auto is_derived = [&](const std::string& name) {
    return std::find(derived.begin(), derived.end(), name) != derived.end();
  };
  if (spec.text.empty())
    throw InputError(fmt::format("{}: the model has no source text to save from", spec.source));
  if (auto missing = schema::unset_message(spec))
    throw InputError(fmt::format("{}: {}", spec.source, *missing));
  const ModelSpec original = parse_model_spec(spec.text, spec.source);
  const bool law_changed = spec.options.magnetisation_law != original.options.magnetisation_law;
  const std::string new_law_leaf = law_leaf(spec.options.magnetisation_law);
  const auto views = io_detail::split_lines(spec.text);
  std::vector<std::string> lines(views.begin(), views.end());
  auto leaf_of = [](const std::string& dotted) { return dotted.substr(dotted.rfind('.') + 1); };
  std::map<std::string, std::vector<std::string>> added;  // table -> new "key = value" lines
  for (const auto& [name, pv] : spec.params) {
    if (is_derived(name)) continue;
    const auto it = original.params.find(name);
    const std::string table = name.substr(0, name.rfind('.'));
    if (it == original.params.end() && law_changed &&
        table.ends_with("." + new_law_leaf)) {  // the new law's numbers: its new tables
      added[table].push_back(
          fmt::format("{} = {}  # set: {}", leaf_of(name), schema::toml_float(pv.value), why));
      continue;
    }
    if (it == original.params.end()) {
      replace_alternative(lines, original, name, pv.value, why);
      continue;
    }
    const ParamValue& was = it->second;
    if (std::bit_cast<std::uint64_t>(was.value) == std::bit_cast<std::uint64_t>(pv.value)) continue;
    // The old comment described the old value ("about 6 MPa"): it is not kept.
    const std::string comment = fmt::format("set: {}; was {}", why, schema::toml_float(was.value));
    if (was.line == 0) {  // a defaulted key the file does not hold: added below
      added[name.substr(0, name.rfind('.'))].push_back(
          fmt::format("{} = {}  # {}", leaf_of(name), schema::toml_float(pv.value), comment));
      continue;
    }
    replace_value(lines, was.line, leaf_of(name), schema::toml_float(pv.value), comment,
                  spec.source);
  }
  write_options(lines, added, spec, original, why);
  if (law_changed)
    comment_out_law_tables(
        lines, original,
        std::string(option_word(*find_option_def("options.magnetisation_law"), spec.options)), why);
  const std::string appended = insert_added(lines, original, added, why);
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  text += appended;
  // The file must load, carry exactly the spec's values, and compile.
  const ModelSpec check = parse_model_spec(text, spec.source);
  for (const auto& [name, pv] : spec.params) {
    if (std::bit_cast<std::uint64_t>(check.params.at(name).value) !=
        std::bit_cast<std::uint64_t>(pv.value))
      throw std::runtime_error(fmt::format("model_toml: {} reads back as {} instead of {}", name,
                                           check.params.at(name).value, pv.value));
  }
  if (check.options != spec.options)
    throw std::runtime_error("model_toml: the options do not read back");
  (void)compile(check);
  return text;
}

void save_model(const ModelSpec& spec, const std::string& path, const std::string& why) {
  write_file_atomic(path, model_toml(spec, why));
}

}  // namespace gmasim
