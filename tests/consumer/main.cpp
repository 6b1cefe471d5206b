// The C++ library from an install prefix: the built-in model stepped 100 times (a current ramp
// to 5 A at 10 us steps), then an installed model file (GMASIM_MODELS_DIR of the package).
// It includes the public headers by their old flat paths (gmasim/io.hpp, gmasim/model.hpp: the
// forwarding headers) and by their folders (gmasim/simulate/run_loop.hpp,
// gmasim/experiments/experiments.hpp, gmasim/model/parameters.hpp): both must keep compiling
// together (docs/layers.md, "The public headers").
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io.hpp"
#include "gmasim/model.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/parameters.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/version.h"

int main() {
  try {
    const gmasim::Model m = gmasim::load_model("");
    const gmasim::Conditions c = gmasim::make_conditions(m, 20.0);
    gmasim::State s = gmasim::make_state(m, c, 0.0);
    for (int k = 1; k <= 100; ++k) {
      gmasim::step(m, c, s, {0.05 * k, 1e-5});
      s.t_s = k * 1e-5;
    }
    std::printf("C++ gmasim %s: y_m %.17g\n", GMASIM_VERSION, s.y_m);
    const std::string path = std::string(CONSUMER_MODELS_DIR) + "/mdma_printed.toml";
    const gmasim::Model printed = gmasim::load_model(path);
    std::printf("C++ installed model %s: %d rods\n", path.c_str(), printed.rod_count());
    // The same ramp through run_loop (new path) from a fresh state: the same stroke (to the
    // rounding of the times t = k dt the drive is evaluated at).
    gmasim::State s2 = gmasim::make_state(m, c, 0.0);
    gmasim::run_loop(m, c, s2, gmasim::StepGrid::uniform(0.0, 1e-5, 100, "consumer ramp"),
                     [](double t) { return 0.05 * (t / 1e-5); });
    std::printf("C++ run_loop: y_m %.17g, %zu parameter rows\n", s2.y_m,
                gmasim::parameter_table().size());
    const bool same = std::fabs(s2.y_m - s.y_m) <= 1e-9 * std::fabs(s.y_m);
    return s.y_m > 0.0 && same && printed.rod_count() == 3 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer_cpp: %s\n", e.what());
    return 1;
  }
}
