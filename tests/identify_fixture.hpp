// The identification tests' model and settings (tests/test_identify.cpp,
// tests/test_identify_inputs.cpp): the paper-as-printed reading calibrated by `gmasim
// identify` (tests/data/identify_fixture.toml, a frozen copy of
// calibration/models/printed__room_referenced__compression_negative.toml), on which the
// identifiability expectations of the tests were measured (docs/identify.md), and the CI
// settings of the objective and the synthetic data.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"

namespace gmasim_test {

inline std::string printed_text() {
  std::ifstream in(std::string(GMASIM_SOURCE_DIR) + "/tests/data/identify_fixture.toml");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline gmasim::ModelSpec printed_spec() {
  return gmasim::parse_model_spec(printed_text(), "tests/data/identify_fixture.toml");
}

// The printed reading, compiled once.
inline const gmasim::Model& printed_fixture() {
  static const gmasim::Model m = gmasim::compile(printed_spec());
  return m;
}

// The CI settings: a coarse but exact-model objective (the data use the same rules).
inline gmasim::ObjectiveSettings ci_objective() {
  gmasim::ObjectiveSettings s;
  s.steps_per_period = 200;
  return s;
}

inline gmasim::SyntheticRequest ci_request(double noise_pct, unsigned seed) {
  gmasim::SyntheticRequest r;  // 20/45/70 degC x 6/8 A x 10/100 Hz
  r.samples_per_period = 100;
  r.periods = 2;
  r.noise_pct = noise_pct;
  r.flux_noise_pct = noise_pct;
  r.seed = seed;
  r.objective = ci_objective();
  return r;
}

}  // namespace gmasim_test
