// find_param_def: the row of a stored number, through an index of the parameter table built
// once. It runs for every number of every compile() (check_value), and identify compiles a
// model per parameter point.
#include <algorithm>
#include <string_view>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/model/parameters.hpp"

namespace gmasim {
namespace {

// A group's table path split at its instance placeholder ("<rod>", "<name>"), and its rows in
// the order of parameter_table().
struct GroupLookup {
  std::string_view path, prefix, suffix;
  bool instanced = false;  // the path has a placeholder
  bool rod = false;        // the placeholder is "<rod>": the instance must be in stack.rods
  std::vector<const ParamDef*> rows;
};

const std::vector<GroupLookup>& group_lookup() {
  static const std::vector<GroupLookup> groups = [] {
    std::vector<GroupLookup> out;
    for (const GroupDef& g : parameter_groups()) {
      GroupLookup l;
      l.path = g.path;
      if (const auto open = g.path.find('<'); open != std::string_view::npos) {
        const auto close = g.path.find('>', open);
        l.instanced = true;
        l.prefix = g.path.substr(0, open);
        l.suffix = g.path.substr(close + 1);
        l.rod = g.path.substr(open, close - open + 1) == "<rod>";
      }
      for (const ParamDef& p : parameter_table())
        if (p.group == g.group) l.rows.push_back(&p);
      out.push_back(std::move(l));
    }
    return out;
  }();
  return groups;
}

// Whether table path `table` ("rod2.ja") is an instance of the group's path ("<rod>.ja").
bool table_matches(const ModelSpec& spec, const GroupLookup& g, std::string_view table) {
  if (!g.instanced) return g.path == table;
  if (table.size() <= g.prefix.size() + g.suffix.size() || !table.starts_with(g.prefix) ||
      !table.ends_with(g.suffix))
    return false;
  const std::string_view name =
      table.substr(g.prefix.size(), table.size() - g.prefix.size() - g.suffix.size());
  if (name.find('.') != std::string_view::npos) return false;
  return !g.rod || std::find(spec.rods.begin(), spec.rods.end(), name) != spec.rods.end();
}

}  // namespace

const ParamDef* find_param_def(const ModelSpec& spec, std::string_view dotted) {
  const auto dot = dotted.rfind('.');
  if (dot == std::string_view::npos) return nullptr;
  const std::string_view table = dotted.substr(0, dot), key = dotted.substr(dot + 1);
  for (const GroupLookup& g : group_lookup()) {
    if (!table_matches(spec, g, table)) continue;
    for (const ParamDef* p : g.rows)
      if (p->key == key || (p->key == "*" && !key.empty())) return p;
    return nullptr;
  }
  return nullptr;
}

}  // namespace gmasim
