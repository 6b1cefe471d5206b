// Forwarding header: gmasim/simulate.hpp moved to gmasim/simulate/simulate.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/simulate/simulate.hpp"
