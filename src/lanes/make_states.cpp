// make_states (gmasim/simulate/lanes.hpp): make_state() for many simulations at once, its
// quasi-static ramp advancing in a LaneBatch (src/model/step.cpp, make_state_law).
#include <vector>

#include "gmasim/model/step_stages.hpp"
#include "gmasim/simulate/lanes.hpp"

namespace gmasim {

std::vector<State> make_states(std::span<const Model* const> models,
                               std::span<const Conditions* const> conditions,
                               std::span<const double> current_A) {
  const std::size_t n = models.size();
  std::vector<State> st;
  st.reserve(n);
  std::vector<const State*> ptr(n);
  for (std::size_t j = 0; j < n; ++j) {
    st.push_back(demagnetised_state(*models[j], *conditions[j], current_A[j]));
    ptr[j] = &st[j];
  }
  LaneBatch batch(models, conditions, ptr);
  std::vector<double> cur(n), pm(n);
  for (int k = 1; k <= kRestRampSteps; ++k) {  // make_state's ramp: the MMF from zero
    const double f = static_cast<double>(k) / kRestRampSteps;
    for (std::size_t j = 0; j < n; ++j) {
      cur[j] = f * current_A[j];
      pm[j] = f * conditions[j]->pm_scale;
    }
    batch.rest_increment(cur, pm);
  }
  for (std::size_t j = 0; j < n; ++j) {
    const Model& m = *models[j];
    if (batch.diverged(j)) {  // make_state's own run: its error (or its state)
      st[j] = make_state(m, *conditions[j], current_A[j]);
      continue;
    }
    State& s = st[j];
    batch.unpack(j, s);
    for (std::size_t i = 0; i < s.rods.size(); ++i)  // the rods' fluxes, as the solve leaves them
      s.circuit.phi[static_cast<std::size_t>(m.circuit.rod_branch[i])] = s.rods[i].phi_Wb;
    s.current_A = current_A[j];
    settle_at_rest(m, *conditions[j], s);
  }
  return st;
}

}  // namespace gmasim
