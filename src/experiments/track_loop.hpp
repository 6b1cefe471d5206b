// One closed-loop tracking run (src/experiments/track.cpp), shared by run_track and the
// feed-forward evaluation against mismatched plants (src/experiments/track_feedforward.cpp).
#pragma once

#include <cstdint>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/feedforward.hpp"

namespace gmasim::detail {

struct TrackJob {
  double T, A, f;  // the loop's temperature (the feed-forward's), amplitude, frequency
};

// The plant the loop drives (the model itself, or a mismatched one at its own temperature) and
// the inverse feed-forward, if any (its model at the loop's temperature).
struct TrackPlant {
  const Model& model;
  const Conditions& conditions;
  InverseFeedforward* inverse = nullptr;
};

// Checks a request (InputError naming the value and the rule).
void check_track_request(const TrackRequest& r);
// Plant steps per controller sample for the request's frequencies (run lengths checked).
long track_substeps(const TrackRequest& r);
// One run: the plant at rest under the bias, the reference centred on its output there,
// `periods` periods; the temperature feed-forward's gain at job.T. Divergence is reported in
// the point.
void track_run(const TrackPlant& plant, const TrackRequest& r, const TrackJob& job, long sub,
               std::uint64_t seed, TrackPoint& p, TimeSeries* example);

}  // namespace gmasim::detail
