// Forwarding header: gmasim/validity.hpp moved to gmasim/model/validity.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/model/validity.hpp"
