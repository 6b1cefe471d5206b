// Forwarding header: gmasim/claims.hpp moved to gmasim/experiments/claims.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/experiments/claims.hpp"
