// Forwarding header: gmasim/rod_laws.hpp moved to gmasim/model/rod_laws.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/model/rod_laws.hpp"
