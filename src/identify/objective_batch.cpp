// Objective::Impl::targets_batch (objective_impl.hpp): the scalar targets' runs of several
// candidates at once, their sine runs sharing SIMD lanes as their records do.
#include <deque>
#include <vector>

#include "identify/objective_impl.hpp"

namespace gmasim {

namespace {

using identify_detail::BiasRamp;
using identify_detail::SinePoint;
using identify_detail::StartCache;

}  // namespace

bool Objective::Impl::targets_batch(const std::vector<const Model*>& models,
                                    std::vector<TargetOutputs>& out,
                                    std::vector<char>& failed) const {
  const std::size_t P = models.size();
  if (!settings.lanes || sine_runs.size() < 2 || P < 2) return false;  // target_runs's path
  for (const Model* m : models)
    if (!lanes_supported(*m)) return false;
  std::deque<StartCache> starts;  // stable addresses
  std::vector<StartCache*> caches;
  std::vector<std::deque<BiasRamp>> ramps(P);
  std::vector<std::vector<const Conditions*>> rc(P);
  std::vector<std::vector<double>> I0(P);
  std::vector<std::vector<std::size_t>> which(P);
  std::vector<SinePoint> points(P);
  try {  // make_ramps_in_lanes, for every candidate at once
    for (std::size_t c = 0; c < P; ++c) {
      caches.push_back(&starts.emplace_back(*models[c]));
      identify_detail::bias_ramps(*models[c], res_runs, ramps[c], rc[c], I0[c], which[c]);
    }
    std::vector<std::vector<State>> st = StartCache::make_in_lanes(caches, target_starts(), rc, I0);
    for (std::size_t c = 0; c < P; ++c)
      for (std::size_t j = 0; j < which[c].size(); ++j)
        ramps[c][which[c][j]].ramped = std::move(st[c][j]);
  } catch (const InputError&) {
    return false;
  } catch (const DivergenceError&) {
    return false;
  }
  failed.assign(P, 0);
  for (std::size_t c = 0; c < P; ++c) {
    points[c].m = models[c];
    points[c].starts = caches[c];
    try {  // the frf targets' DC settling beside the sines, if it fits (target_runs)
      points[c].held = identify_detail::settlings_beside_sines(*models[c], sine_runs, settings,
                                                               res_runs, ramps[c]);
    } catch (const std::exception&) {
      points[c].failed = true;
    }
  }
  try {
    identify_detail::run_sines_lanes(points, sine_runs, settings, false);
  } catch (const InputError&) {  // a start state made here failed (make_state): each alone
    return false;
  } catch (const DivergenceError&) {
    return false;
  }
  out.resize(P);
  for (std::size_t c = 0; c < P; ++c) {
    if (points[c].failed) {
      failed[c] = 1;
      continue;
    }
    out[c].sm = std::move(points[c].metrics);
    out[c].res.resize(res_runs.size());
    try {
      for (std::size_t k = 0; k < res_runs.size(); ++k)
        out[c].res[k] =
            identify_detail::lowest_resonance_Hz(*models[c], res_runs[k], *caches[c], &ramps[c][k]);
    } catch (const std::exception&) {
      failed[c] = 1;
    }
  }
  return true;
}

}  // namespace gmasim
