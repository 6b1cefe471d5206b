// Internal: the model-file reader (TOML -> ModelSpec). The numbers and options are read by
// the parameter table (gmasim/model/parameters.hpp); the structure (rods, circuit, sensor, load
// chains) by the section readers of model_structure.cpp. Every problem of a file is
// collected with its line and reported together. Not part of the public API.
#pragma once

#include <toml++/toml.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gmasim/model/model.hpp"

namespace gmasim::io_detail {

// "models/mdma.toml (built-in)": the source name of the built-in model.
std::string builtin_source_name();
std::string join(const std::vector<std::string>& items, std::string_view sep);
std::string_view type_name(const toml::node& n);
long node_line(const toml::node& n);
bool valid_name(const std::string& name);

struct NamedLine {
  std::string name;
  long line;
};

class ModelLoader {
 public:
  ModelLoader(std::string_view text, const std::string& source);
  ModelSpec run();

 private:
  std::string_view text_;
  std::vector<std::string_view> lines_;
  ModelSpec spec_;
  std::vector<std::pair<long, std::string>> problems_;
  bool rods_ok_ = false;

  void problem(long line, std::string msg) { problems_.emplace_back(line, std::move(msg)); }
  std::string comment_at(long line) const;
  std::string comment_of(const toml::node& n) const;

  // ---- generic readers (model_loader.cpp) ----
  const toml::table* table_at(const toml::table& parent, std::string_view key,
                              const std::string& dotted, long missing_line);
  void check_keys(const toml::table& t, const std::string& where,
                  const std::vector<std::string>& allowed);
  const toml::node* required(const toml::table& t, std::string_view key,
                             const std::string& table_name, long table_line);
  void store_number(const toml::node& node, const std::string& dotted);
  void store_default(const std::string& dotted, const ParamDef& row);
  std::optional<std::string> string_of(const toml::node& node, const std::string& dotted);
  std::optional<std::string> read_string(const toml::table& t, std::string_view key,
                                         const std::string& table_name);
  std::optional<std::vector<NamedLine>> string_array(const toml::node& node,
                                                     const std::string& dotted);
  std::vector<std::pair<std::string, const toml::table*>> named_tables(const toml::table& t,
                                                                       const std::string& dotted);

  // ---- the parameter table (model_loader.cpp) ----
  // The numbers of group `g` in table `t` named `table_name`; `extra` are further keys the
  // table may hold (sub-tables, structure), read elsewhere.
  void read_alternative(const toml::table& t, const ParamDef& row, const std::string& table_name);
  void read_reluctance_geometry(const toml::table& circuit, long line);
  void read_group(const toml::table& t, Group g, const std::string& table_name,
                  const std::vector<std::string>& extra = {});
  // The table of group `g` (its path in parameter_groups(), for `instance`; `parent` holds
  // its last component), under the group's table rule: a missing Required table is reported
  // at `missing_line`; an absent Defaulted table takes every row's default; an absent
  // Optional table is left out.
  void read_group_table(const toml::table& parent, Group g, long missing_line,
                        std::string_view instance = {});
  void read_options(const toml::table& root);
  void read_meta(const toml::table& root);

  // ---- sections (model_structure.cpp) ----
  void read_root(const toml::table& root);
  void check_top_level(const toml::table& root);
  void read_stack(const toml::table& root);
  void read_rods(const toml::table& root);
  void read_circuit(const toml::table& root);
  std::optional<std::vector<std::string>> read_reluctances(const toml::table& circuit, long line);
  void read_branches(const toml::table& circuit, long circuit_line,
                     const std::optional<std::vector<std::string>>& reluctances);
  void read_branch(const toml::table& b, std::size_t index, std::vector<std::string>& names,
                   const std::optional<std::vector<std::string>>& reluctances);
  bool read_branch_source(const toml::table& b, const std::string& label, SpecBranch& sb,
                          const std::optional<std::vector<std::string>>& reluctances);
  void read_nodes(const toml::table& circuit, long circuit_line);
  void read_sensor(const toml::table& root);
  void read_calibration(const toml::table& root);
  void read_mechanics(const toml::table& root);
  bool read_members(const toml::table& mech, long mech_line, std::string_view key, Group g,
                    std::vector<std::string>& names);
  void read_chains(const toml::table& mech, long mech_line, bool members_ok);
};

}  // namespace gmasim::io_detail
