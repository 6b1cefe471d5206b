// The parameter table's pieces that live with their laws (src/model/magnetisation/): each
// magnetisation law brings its group ([<rod>.<law>]) and rows; parameter_groups() and
// parameter_table() (parameters.cpp) place them after the rod's.
#pragma once

#include <span>
#include <vector>

#include "gmasim/model/parameters.hpp"

// The land function and its text, from one spelling: GMASIM_LAND(in_rod, RodModel, length_m).
#define GMASIM_LAND(fn, Struct, field) &fn<&Struct::field>, #Struct "::" #field

namespace gmasim::model_detail {

struct LawTables {
  std::span<const GroupDef> group;  // one group
  std::span<const ParamDef> rows;
};
const LawTables& jiles_atherton_tables();  // src/model/magnetisation/jiles_atherton.cpp
const LawTables& preisach_tables();        // src/model/magnetisation/preisach.cpp

// The registration of the laws' tables, in the order of law_id.hpp.
inline std::vector<const LawTables*> law_tables() {
  return {&jiles_atherton_tables(), &preisach_tables()};
}

// `base` with every law's entries (pick(LawTables)) after its last [<rod>] entry.
template <class T, class GroupOf, class Pick>
std::vector<T> with_law_entries(std::span<const T> base, GroupOf group_of, Pick pick) {
  std::size_t after = 0;
  for (std::size_t i = 0; i < base.size(); ++i)
    if (group_of(base[i]) == Group::Rod) after = i + 1;
  std::vector<T> out(base.begin(), base.begin() + static_cast<std::ptrdiff_t>(after));
  for (const LawTables* law : law_tables()) {
    const auto entries = pick(*law);
    out.insert(out.end(), entries.begin(), entries.end());
  }
  out.insert(out.end(), base.begin() + static_cast<std::ptrdiff_t>(after), base.end());
  return out;
}

}  // namespace gmasim::model_detail
