// libFuzzer: the model loader (TOML text -> ModelSpec -> compiled Model).
#include "fuzz_common.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return gmasim_fuzz::accept_or_refuse([&] {
    const gmasim::ModelSpec spec =
        gmasim::parse_model_spec(gmasim_fuzz::as_text(data, size), "fuzz.toml");
    (void)gmasim::compile(spec);
  });
}
