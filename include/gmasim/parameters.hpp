// Forwarding header: gmasim/parameters.hpp moved to gmasim/model/parameters.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/model/parameters.hpp"
