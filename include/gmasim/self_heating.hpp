// Forwarding header: gmasim/self_heating.hpp moved to gmasim/model/self_heating.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/model/self_heating.hpp"
