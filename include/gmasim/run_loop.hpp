// Forwarding header: gmasim/run_loop.hpp moved to gmasim/simulate/run_loop.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/simulate/run_loop.hpp"
