// Allocation counter shared by the tests that prove a call allocates nothing (tests/
// alloc_counter.cpp interposes glibc's malloc family for the whole test binary; under
// AddressSanitizer, which owns malloc, the sanitizer's allocation hooks count instead).
// Set g_allocations = 0 and g_counting = true, run the code, set g_counting = false.
#pragma once

#include <atomic>

namespace gmasim_test {
extern std::atomic<bool> g_counting;
extern std::atomic<long> g_allocations;
}  // namespace gmasim_test
