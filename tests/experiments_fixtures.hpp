// Shared pieces of the experiment tests (test_experiments.cpp, test_frf.cpp, test_track.cpp,
// test_experiments_cli.cpp): the two readings of the built-in model and an InputError probe.
#pragma once

#include <string>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim_experiments_test {

inline const gmasim::Model& mdma() {
  static const gmasim::Model m = gmasim::load_model("");
  return m;
}

// The paper-as-printed reading (models/mdma_printed.toml): eq. 2, 3, 7, 10, 11 as printed.
inline const gmasim::Model& mdma_printed() {
  static const gmasim::Model m =
      gmasim::load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml");
  return m;
}

inline constexpr double kTwoPi = 2.0 * gmasim::physics::kPi;

template <class F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const gmasim::InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace gmasim_experiments_test
