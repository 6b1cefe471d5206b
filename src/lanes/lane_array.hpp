// The lanes' arrays (lane_data.hpp, preisach_lane_data.hpp): std::vector<double> on a 64-byte
// boundary. With LaneData::npad a multiple of 8 doubles, every vector of a full chunk is one
// aligned cache line; from std::vector's 16-byte alignment each AVX-512 load or store of the
// rods' state spanned two (the batched sweep: its rods' loads and stores 10.8 -> 6.6 % of the
// samples; bench/experiments/unaligned.patch measures it). Internal to src/lanes.
#pragma once

#include <cstddef>
#include <limits>
#include <new>
#include <vector>

namespace gmasim::lanes {

template <class T>
struct CacheLineAllocator {
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
  friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator&) { return true; }
};

using LaneArray = std::vector<double, CacheLineAllocator<double>>;

}  // namespace gmasim::lanes
