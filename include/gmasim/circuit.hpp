// Forwarding header: gmasim/circuit.hpp moved to gmasim/model/circuit.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/model/circuit.hpp"
