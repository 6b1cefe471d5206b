// libFuzzer: the identify checkpoint reader (src/identify/checkpoint.cpp).
#include "fuzz_common.hpp"
#include "identify/internal.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = gmasim_fuzz::write_input(data, size, ".ckpt");
  return gmasim_fuzz::accept_or_refuse(
      [&] { (void)gmasim::identify_detail::read_checkpoint(path); });
}
