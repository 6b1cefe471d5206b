// The two readings of the built-in model, each compiled once per test binary and shared by
// every test file: mdma() is the built-in model (models/mdma.toml, embedded), mdma_printed()
// the paper-as-printed reading (models/mdma_printed.toml: eq. 2, 3, 7, 10, 11 as printed).
// One definition for all the files: the CI compiles several test files as one translation
// unit (CMakeLists.txt, GMASIM_CI_BUILD), where file-local copies would collide.
#pragma once

#include <string>

#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim_test {

inline const gmasim::Model& mdma() {
  static const gmasim::Model m = gmasim::load_model("");
  return m;
}

inline const gmasim::Model& mdma_printed() {
  static const gmasim::Model m =
      gmasim::load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml");
  return m;
}

// The built-in model with one option changed (a reading of docs/model.md), compiled.
inline gmasim::Model mdma_with_option(const char* key, const char* word) {
  gmasim::ModelSpec spec = gmasim::builtin_model_spec();
  spec.set_option(key, word);
  return gmasim::compile(spec);
}

}  // namespace gmasim_test
