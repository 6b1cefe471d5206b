// simulate()'s recorded series (src/simulate/run.cpp), shared with the lanes' simulate_lanes
// (src/lanes/simulate_lanes.cpp) so that both record the same columns the same way.
#pragma once

#include <cstddef>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

// The columns of Result::series (t_s, current_A, y_um, ..., then per rod), each reserving
// `reserve` rows.
void make_columns(const Model& m, TimeSeries& ts, std::size_t reserve);
// One row of the series from the state at the end of a step.
void record(const Conditions& c, const State& s, TimeSeries& ts);

// compute_metrics (src/simulate/metrics.cpp) from the columns it reads, held apart from a
// series (simulate_lanes' metrics_only runs keep only these, over the metrics window).
Metrics compute_metrics(const std::vector<double>& t_s, const std::vector<double>& current_A,
                        const std::vector<double>& y_um, const std::vector<double>& B_T,
                        double t0_s, double t1_s);

// simulate() for a caller that keeps only the metrics (sweeps, compensate's searches: the
// scalar counterpart of simulate_lanes' metrics_only): a periodic run without energy ledger or
// self-heating records only compute_metrics' columns over the last period, and returns no
// series; its metrics, steps and errors are simulate()'s, bit for bit. Other runs: simulate().
Result simulate_metrics_only(const Model& m, const SimulationSettings& s);

}  // namespace gmasim
