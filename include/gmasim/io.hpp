// Forwarding header: gmasim/io.hpp moved to gmasim/io/io.hpp (issue 21; docs/layers.md,
// "The public headers"). Kept so that existing users still compile; include the new path.
#pragma once

#include "gmasim/io/io.hpp"
