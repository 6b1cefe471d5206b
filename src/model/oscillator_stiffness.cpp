// Eq. (16)-(18): the static stiffness of a rod's oscillator (gmasim/model/model.hpp,
// oscillator_stiffness). In the model layer: the mechanics analysis above it (modes,
// linearisation) and the identify objective use it (docs/layers.md).
#include "gmasim/model/model.hpp"
#include "gmasim/model/rod_laws.hpp"

namespace gmasim {

double oscillator_stiffness(const Conditions& c, const State& s, int rod) {
  const auto i = static_cast<std::size_t>(rod);
  return s.rods[i].k_rod_N_per_m + load_stiffness(c.rods[i], s);  // eq. (16)
}

}  // namespace gmasim
