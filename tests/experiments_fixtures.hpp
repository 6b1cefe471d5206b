// Shared pieces of the experiment tests (test_experiments.cpp, test_frf.cpp, test_track.cpp,
// test_experiments_cli.cpp, test_frf_signal.cpp, test_describing_function.cpp,
// test_preisach_anhysteretic.cpp): the two readings of the built-in model (builtin_models.hpp),
// a two-point FRF request and an InputError probe.
#pragma once

#include <string>

#include "builtin_models.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim_experiments_test {

using gmasim_test::mdma;
using gmasim_test::mdma_printed;

using gmasim::physics::kTwoPi;  // one constant: no ambiguity beside gmasim::physics in a unity file

// The cheapest stepped-sine FRF that probes a point: one temperature, the two frequencies f_min
// and f_max, no peak refinement.
inline gmasim::FrfRequest two_point_frf(double T_C, double f_min_Hz, double f_max_Hz) {
  gmasim::FrfRequest r;
  r.temperatures_C = {T_C};
  r.f_min_Hz = f_min_Hz;
  r.f_max_Hz = f_max_Hz;
  r.points = 2;
  r.peak_refinements = 0;
  return r;
}

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
