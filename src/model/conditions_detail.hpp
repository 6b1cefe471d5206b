// make_conditions() without its message about the computable range (src/model/validity.cpp
// scans temperatures with it; make_conditions wraps it).
#pragma once

#include "gmasim/model/model.hpp"

namespace gmasim::model_detail {

// Every temperature-dependent constant at temperature_C; throws InputError where a law is not
// defined there (the message names the law and the rod).
Conditions conditions_at(const Model& m, double temperature_C, const Freeze& freeze);

}  // namespace gmasim::model_detail

namespace gmasim::model_detail {}  // namespace gmasim::model_detail
