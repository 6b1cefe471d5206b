// Bindings of the experiments (filled in with the experiments library).
#include "bindings.hpp"

namespace gmasim::py_bind {
void bind_experiments(pybind11::module_& /*mod*/) {}
}  // namespace gmasim::py_bind
