// simulate()'s recorded series (src/simulate/run.cpp), shared with the lanes' simulate_lanes
// (src/lanes/simulate_lanes.cpp) so that both record the same columns the same way.
#pragma once

#include <algorithm>
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

// A metrics-only run's record (simulate_metrics_only, simulate_lanes' metrics_only): the columns
// compute_metrics reads (t_s, current_A, y_um, B_T: what record() writes there), from the step
// before the last period's window on, at the record's rows; no other column.
struct MetricsWindow {
  static constexpr std::size_t kColumns = 4;
  long first = 0;  // the first step recorded (<= 0: the rest state's row too)
  std::vector<std::vector<double>> columns;  // empty until start()

  bool enabled() const { return !columns.empty(); }
  // A run of `steps` steps whose last period is `period_steps` of them, every record_every-th
  // step recorded.
  void start(long steps, long period_steps, long record_every) {
    first = steps - period_steps - 1;
    const auto rows = static_cast<std::size_t>((steps - std::max(first, 0L)) / record_every + 3);
    columns.assign(kColumns, {});
    for (auto& col : columns) col.reserve(rows);
  }
  void push(const State& st) {
    const double row[kColumns] = {st.t_s, st.current_A, st.y_m * 1e6, st.B_T};
    for (std::size_t q = 0; q < kColumns; ++q) columns[q].push_back(row[q]);
  }
  Metrics metrics(double t0_s, double t1_s) const {
    return compute_metrics(columns[0], columns[1], columns[2], columns[3], t0_s, t1_s);
  }
};

// simulate() for a caller that keeps only the metrics (sweeps, compensate's searches: the
// scalar counterpart of simulate_lanes' metrics_only): a periodic run without energy ledger or
// self-heating records only compute_metrics' columns over the last period, and returns no
// series; its metrics, steps and errors are simulate()'s, bit for bit. Other runs: simulate().
Result simulate_metrics_only(const Model& m, const SimulationSettings& s);

}  // namespace gmasim
