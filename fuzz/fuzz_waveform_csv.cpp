// libFuzzer: the waveform CSV loader (t_s,current_A) and the simulation settings built on it.
#include "fuzz_common.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/simulate.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = gmasim_fuzz::write_input(data, size, ".csv");
  return gmasim_fuzz::accept_or_refuse([&] {
    gmasim::SimulationSettings s;
    s.waveform = gmasim::load_waveform_csv(path);
    gmasim::validate(s);  // the run length is checked, not run
  });
}
