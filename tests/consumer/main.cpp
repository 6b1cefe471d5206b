// The C++ library from an install prefix: the built-in model stepped 100 times (a current ramp
// to 5 A at 10 us steps), then an installed model file (GMASIM_MODELS_DIR of the package).
#include <cstdio>
#include <exception>
#include <string>

#include "gmasim/io.hpp"
#include "gmasim/model.hpp"
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
    return s.y_m > 0.0 && printed.rod_count() == 3 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer_cpp: %s\n", e.what());
    return 1;
  }
}
