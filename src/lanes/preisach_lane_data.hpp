// The Preisach law's share of the lanes' data (docs/lanes.md, "Preisach lanes"): its constants at
// temperature as arrays over the lanes (one SIMD load reads a constant of W simulations), and
// each lane's extrema stack (physics::PreisachHistory) as it is, one per rod and lane: the
// stacks differ in depth from lane to lane, so the kernel searches them lane by lane and
// evaluates the Everett function over the lanes. Empty for a Jiles-Atherton batch. Internal to
// src/lanes.
#pragma once

#include <cstddef>
#include <vector>

#include "gmasim/physics/preisach.hpp"
#include "lanes/lane_array.hpp"

namespace gmasim::lanes {

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
