// libFuzzer: the measurement CSV loader of gmasim identify (condition comments + columns).
#include "fuzz_common.hpp"
#include "gmasim/identify/identify.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = gmasim_fuzz::write_input(data, size, ".csv");
  return gmasim_fuzz::accept_or_refuse([&] { (void)gmasim::load_measurement_csv(path); });
}
