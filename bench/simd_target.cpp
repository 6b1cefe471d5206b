// GMASIM_BENCH_SIMD: run gmasim_bench's batched benchmarks on a narrower SIMD target than the
// CPU's best, to see how the lanes scale with the vector width in one binary (docs/performance.md,
// "Width scaling"):
//   GMASIM_BENCH_SIMD=avx2 build/ci/bin/gmasim_bench --benchmark_filter='batched'
// Values: avx3, avx2, sse4, emu128, scalar (Highway's targets; the counter simd_lanes and the
// label name the one used). Unset: the CPU's best. A value that is not one of these, or a target
// this CPU or build does not have, ends the run before any benchmark (exit status 2).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <string>
#include <string_view>

#include "gmasim/errors.hpp"
#include "hwy/targets.h"

namespace {

struct BenchSimdTarget {
  BenchSimdTarget() {
    const char* env = std::getenv("GMASIM_BENCH_SIMD");
    if (env == nullptr || *env == '\0') return;
    const std::string_view want(env);
    struct Named {
      std::string_view name;
      int64_t target;
    };
    constexpr Named kTargets[] = {{"avx3", HWY_AVX3},
                                  {"avx2", HWY_AVX2},
                                  {"sse4", HWY_SSE4},
                                  {"emu128", HWY_EMU128},
                                  {"scalar", HWY_SCALAR}};
    for (const Named& t : kTargets) {
      if (t.name != want) continue;
      hwy::SetSupportedTargetsForTest(t.target);
      const auto got = hwy::SupportedAndGeneratedTargets();
      if (got.empty() || got.front() != t.target) {
        std::fprintf(stderr,
                     "gmasim_bench: GMASIM_BENCH_SIMD=%s: this CPU or build has no such target\n",
                     env);
        std::exit(2);
      }
      return;
    }
    std::string_view names[std::size(kTargets)];  // the table's names, for the message
    for (std::size_t i = 0; i < std::size(kTargets); ++i) names[i] = kTargets[i].name;
    std::fprintf(stderr, "gmasim_bench: GMASIM_BENCH_SIMD=%s: must be %s\n", env,
                 gmasim::choice_list(names).c_str());
    std::exit(2);
  }
};
const BenchSimdTarget bench_simd_target;

}  // namespace
