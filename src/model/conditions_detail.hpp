// make_conditions() without its message about the computable range (src/model/validity.cpp
// scans temperatures with it; make_conditions wraps it).
#pragma once

#include "gmasim/model/model.hpp"

namespace gmasim::model_detail {

// Every temperature-dependent constant at temperature_C; throws InputError where a law is not
// defined there (the message names the law and the rod).
Conditions conditions_at(const Model& m, double temperature_C, const Freeze& freeze);

}  // namespace gmasim::model_detail

namespace gmasim::model_detail {

// The magnetisation laws' temperature laws (src/model/magnetisation/<law>.cpp): the law's
// constants of rod `rod` at temperature T_law_C (T_ref when frozen) into rc, given rc's
// M_s^T (MsT_mag) and eq. (3)'s coupling (alpha_sigma); InputError naming the rod and the
// operating temperature T_C where the law is not defined.
void jiles_atherton_conditions(const Model& m, const RodModel& rod, double T_law_C, double T_C,
                               RodConditions& rc);
void preisach_conditions(const Model& m, const RodModel& rod, double T_law_C, double T_C,
                         RodConditions& rc);

}  // namespace gmasim::model_detail
