// The mechanics module: the static stiffness of a rod's oscillator (eq. 16-18), defined in
// src/mechanics/stiffness.cpp. gmasim/model/model.hpp declares it too (its old place), so code
// that includes only model.hpp keeps compiling.
#pragma once

#include "gmasim/model/model.hpp"

namespace gmasim {

// Static stiffness of rod i's oscillator (eq. 16-18) at the state's magnetisation: its axial
// stiffness (eq. 17) plus the load chain's (eq. 18).
double oscillator_stiffness(const Conditions& c, const State& s, int rod);

}  // namespace gmasim
