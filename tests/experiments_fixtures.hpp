// Shared pieces of the experiment tests (test_experiments.cpp, test_frf.cpp, test_track.cpp,
// test_experiments_cli.cpp): the two readings of the built-in model (builtin_models.hpp) and an
// InputError probe.
#pragma once

#include <string>

#include "builtin_models.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim_experiments_test {

using gmasim_test::mdma;
using gmasim_test::mdma_printed;

using gmasim::physics::kTwoPi;  // one constant: no ambiguity beside gmasim::physics in a unity file

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
