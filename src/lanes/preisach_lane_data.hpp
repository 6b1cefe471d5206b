// The Preisach law's share of the lanes' data (docs/lanes.md, "Preisach lanes"): its constants at
// temperature as arrays over the lanes (one SIMD load reads a constant of W simulations), and
// each lane's extrema stack (physics::PreisachHistory) as it is, one per rod and lane: the
// stacks differ in depth from lane to lane, so the kernel searches them lane by lane and
// evaluates the Everett function over the lanes. Empty for a Jiles-Atherton batch. Internal to
// src/lanes.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

#include "gmasim/physics/preisach.hpp"

namespace gmasim::lanes {

// The lanes' arrays start on a 64-byte boundary: with npad a multiple of 8 doubles, every
// vector of a full chunk is then one aligned cache line (an AVX-512 load or store of an array
// from std::vector's 16-byte alignment spans two lines: the batched sweep measured its rods'
// loads and stores at 10.8 % of its samples).
template <class T>
struct CacheLineAllocator {
  using value_type = T;
  static constexpr std::align_val_t kAlign{64};
  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlign)); }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, kAlign); }
  friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator&) { return true; }
};
using LaneArray = std::vector<double, CacheLineAllocator<double>>;

// Per rod and lane: physics::PreisachCoefficients (and M_s^T's companions 1/H_c, 1/a, packed once).
enum PreisachField : int {
  kPreC,       // reversible fraction c
  kPreAlpha,   // mean-field coupling alpha
  kPreA,       // a^T of the reversible Langevin part
  kPreInvA,    // 1 / a^T
  kPreInvHc,   // 1 / H_c^T (the unit of the reduced fields)
  kPreSigmaU,  // the interaction fields' spread, reduced
  kPreEdge0,   // the coercive fields' bin edges, kPreisachBins + 1 of them
  kPreDensity0 = kPreEdge0 + physics::kPreisachBins + 1,  // the bins' densities
  kPreFieldCount = kPreDensity0 + physics::kPreisachBins
};

struct PreisachLaneData {
  std::size_t npad = 0;
  LaneArray c;                                 // kPreFieldCount x rods x npad
  std::vector<physics::PreisachHistory> hist;  // rods x npad: rod i, lane j at i npad + j
  void resize(int rods, std::size_t lanes_padded) {
    npad = lanes_padded;
    c.assign(static_cast<std::size_t>(kPreFieldCount * rods) * npad, 0.0);
    hist.assign(static_cast<std::size_t>(rods) * npad, physics::PreisachHistory{});
  }
  // rods: the batch's rod count (the fields of rod i follow those of rods 0 .. i-1).
  double* field(int f, int i, int rods) {
    return c.data() + static_cast<std::size_t>(f * rods + i) * npad;
  }
  physics::PreisachHistory* history(int i) {
    return hist.data() + static_cast<std::size_t>(i) * npad;
  }
};

}  // namespace gmasim::lanes
