// Forwarding header: gmasim/lanes.hpp is gmasim/simulate/lanes.hpp (issue 21; docs/layers.md,
// "The public headers"). Kept so that existing users still compile; include the new path.
#pragma once

#include "gmasim/simulate/lanes.hpp"
