// The magnetisation laws a model can select (options.magnetisation_law; docs/layers.md, "Adding
// a magnetisation law"). Each has its folder: include/gmasim/magnetisation/<law>.hpp (the law's
// seam functions) and src/model/magnetisation/<law>.cpp (its parameter rows and temperature
// laws), and one registration in gmasim/magnetisation/laws.hpp.
#pragma once

namespace gmasim {

enum class MagnetisationLaw { JilesAtherton, Preisach };

}  // namespace gmasim
