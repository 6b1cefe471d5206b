// libFuzzer: the measurement manifest (TOML listing CSV files and weights).
#include "fuzz_common.hpp"
#include "gmasim/identify/identify.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = gmasim_fuzz::write_input(data, size, ".toml");
  return gmasim_fuzz::accept_or_refuse([&] { (void)gmasim::load_manifest(path); });
}
