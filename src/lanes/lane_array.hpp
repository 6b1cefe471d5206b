// The lanes' arrays (lane_data.hpp, preisach_lane_data.hpp): std::vector<double> on a 64-byte
// boundary. With LaneData::npad a multiple of 8 doubles, each vector of a full chunk of these
// arrays is one aligned cache line; from std::vector's 16-byte alignment most AVX-512 loads and
// stores of the rods' state spanned two (bench/experiments/run.sh unaligned: the batched sweep
// and 16-point objective 7 and 10 % slower without it). Internal to src/lanes.
#pragma once

#include <cstddef>
#include <limits>
#include <new>
#include <vector>

namespace gmasim::lanes {

template <class T>
struct CacheLineAllocator {
  static_assert(alignof(T) <= 64, "CacheLineAllocator: a type aligned beyond a cache line");
  using value_type = T;
  static constexpr std::align_val_t kAlign{64};
  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    if (n > std::numeric_limits<std::size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(::operator new(n * sizeof(T), kAlign));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, kAlign); }
  template <class U>  // stateless: any two compare equal, whatever their value types
  friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator<U>&) noexcept {
    return true;
  }
};

using LaneArray = std::vector<double, CacheLineAllocator<double>>;

}  // namespace gmasim::lanes
