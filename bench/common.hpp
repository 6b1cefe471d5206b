// Shared pieces of the benchmarks.
#pragma once

#include "gmasim/io.hpp"
#include "gmasim/model.hpp"

namespace gmasim::bench {

// The built-in MDMA model, loaded once.
inline const Model& mdma() {
  static const Model m = load_model("");
  return m;
}

}  // namespace gmasim::bench
