// Forwarding header: gmasim/identify.hpp moved to gmasim/identify/identify.hpp (issue 21;
// docs/layers.md, "The public headers"). Kept so that existing users still compile; include the new
// path.
#pragma once

#include "gmasim/identify/identify.hpp"
