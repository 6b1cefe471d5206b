// libFuzzer: the fit spec ([[parameter]], [[target]], claims by id) and the claims data.
#include "fuzz_common.hpp"
#include "gmasim/experiments/claims.hpp"
#include "gmasim/identify/identify.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text = gmasim_fuzz::as_text(data, size);
  gmasim_fuzz::accept_or_refuse([&] { (void)gmasim::parse_fit_spec(text, "fuzz.toml"); });
  return gmasim_fuzz::accept_or_refuse([&] { (void)gmasim::parse_claims(text, "fuzz.toml"); });
}
