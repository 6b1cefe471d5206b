// Thermal expansion coefficient of the stack, eq. (21): the alpha*l products of the model.
#include "gmasim/experiments/claims.hpp"
#include "gmasim/experiments/experiments.hpp"

namespace gmasim {

ThermalExpansionResult thermal_expansion_coefficient(const Model& m) {
  ThermalExpansionResult r;
  r.rod_um_per_C = m.xT_rod_m_per_K * 1e6;
  r.magnetizer_um_per_C = m.xT_magnetizer_m_per_K * 1e6;
  r.output_rod_um_per_C = m.xT_output_rod_m_per_K * 1e6;
  r.sleeve_um_per_C = m.xT_sleeve_m_per_K * 1e6;
  // Eq. (21): the sleeve expands against the stack (Fig. 7).
  r.um_per_C = r.rod_um_per_C + r.magnetizer_um_per_C + r.output_rod_um_per_C - r.sleeve_um_per_C;
  r.paper_model_um_per_C = builtin_paper_value("thermal_model");
  r.paper_measured_um_per_C = builtin_paper_value("thermal_measured");
  return r;
}

}  // namespace gmasim
