// Forwarding header: the short power series shared by the step's laws (polynomial7,
// exp_series7, expm1_series10, cos_half_pi, exp_near, exp_cached) are written once over the
// number type in gmasim/physics/laws-inl.h (issue 38), instantiated for double by laws.hpp.
#pragma once

#include "gmasim/physics/laws.hpp"
