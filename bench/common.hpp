// Shared pieces of the benchmarks.
#pragma once

#include <string>

#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim::bench {

// The built-in MDMA model, loaded once.
inline const Model& mdma() {
  static const Model m = load_model("");
  return m;
}

// The paper-as-printed reading (models/mdma_printed.toml): the RK4 reference needs it.
inline const Model& mdma_printed() {
  static const Model m = load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml");
  return m;
}

}  // namespace gmasim::bench
