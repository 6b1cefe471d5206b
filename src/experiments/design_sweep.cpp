// gmasim sweep --grid: the sweep crossed with a grid over model keys, each design compiled
// from the base spec with its values set (include/gmasim/experiments/design_sweep.hpp).
#include "gmasim/experiments/design_sweep.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <set>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {
namespace {

// The designs' values: the axes' cartesian product, the first axis slowest.
std::vector<std::vector<double>> combinations(const std::vector<GridAxis>& axes) {
  std::vector<std::vector<double>> out{{}};
  for (const GridAxis& a : axes) {
    std::vector<std::vector<double>> next;
    for (const auto& head : out)
      for (double v : a.values) {
        next.push_back(head);
        next.back().push_back(v);
      }
    out = std::move(next);
  }
  return out;
}

void check_axes(const ModelSpec& base, const std::vector<GridAxis>& axes) {
  std::set<std::string> seen;
  double designs = 1.0;
  for (const GridAxis& a : axes) {
    if (a.values.empty())
      throw InputError(fmt::format("--grid {}: no values (give KEY=v1,v2,...)", a.key));
    if (!seen.insert(a.key).second)
      throw InputError(fmt::format("--grid {}: the key is given twice; give each key once", a.key));
    try {
      (void)base.get(a.key);
    } catch (const InputError& e) {
      throw InputError(fmt::format("--grid {}: {}", a.key, e.what()));
    }
    designs *= static_cast<double>(a.values.size());
  }
  if (designs > kMaxListValues)
    throw InputError(
        fmt::format("--grid: {:g} designs (the product of the keys' value counts; "
                    "limit {:g})",
                    designs, kMaxListValues));
}

// The base spec with the design's values set, compiled (its derived quantities follow); an error
// names the design.
Model design_model(const ModelSpec& base, const std::vector<GridAxis>& axes,
                   const std::vector<double>& values) {
  ModelSpec spec = base;
  std::string design;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    design += fmt::format("{}{}={:g}", k ? " " : "", axes[k].key, values[k]);
    try {
      spec.set(axes[k].key, values[k]);
    } catch (const InputError& e) {
      throw InputError(fmt::format("--grid {}={:g}: {}", axes[k].key, values[k], e.what()));
    }
  }
  try {
    return compile(spec);
  } catch (const InputError& e) {
    throw InputError(fmt::format("--grid design {}: {}", design, e.what()));
  }
}

}  // namespace

DesignSweepResult run_design_sweep(const ModelSpec& base, const std::vector<GridAxis>& axes,
                                   const SweepRequest& r, const ProgressFn& progress, int rank,
                                   int ranks) {
  check_axes(base, axes);
  const auto wall0 = std::chrono::steady_clock::now();
  DesignSweepResult res;
  res.axes = axes;
  res.bias_A = FrfRequest{}.bias_A;
  const auto all = combinations(axes);
  // Every design compiles before any sweep runs, so that a value its key's rule refuses stops
  // the study at once, naming it; each is compiled again when it runs (holding every Model
  // would cost memory in proportion to the grid, a compile is cheap beside its sweep).
  for (const auto& values : all) (void)design_model(base, axes, values);
  for (std::size_t d = 0; d < all.size(); ++d) {
    DesignPoint p;
    p.values = all[d];
    if (ranks > 1 && static_cast<int>(d % static_cast<std::size_t>(ranks)) != rank) {
      res.designs.push_back(std::move(p));  // another rank's
      continue;
    }
    const Model m = design_model(base, axes, all[d]);
    for (const auto& rod : m.rods) p.rods_mass_kg += rod.mass_kg;
    p.coil_resistance_ohm = m.thermal_network.coil_resistance_ohm;
    const LinearFrfMarkers lm = linear_frf_markers(m, r.reference_temperature_C, res.bias_A);
    p.first_resonance_Hz = lm.first_resonance_Hz;
    p.bandwidth_Hz = lm.bandwidth_3dB_Hz;
    p.sweep = run_sweep(m, r, progress);
    for (const SweepPoint& q : p.sweep.points)
      p.copper_loss_W.push_back(
          coil_copper_loss_W(m, r.current_min_A, q.current_pp_A, q.temperature_C));
    for (const SweepPoint& q : p.sweep.reference_points)
      p.reference_copper_loss_W.push_back(
          coil_copper_loss_W(m, r.current_min_A, q.current_pp_A, q.temperature_C));
    res.designs.push_back(std::move(p));
  }
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

Report design_sweep_report(const Model& base, const SweepRequest& req,
                           const DesignSweepResult& res) {
  const std::vector<std::string> derived = {"rods_mass_kg", "coil_resistance_ohm",
                                            "first_resonance_Hz", "bandwidth_Hz"};
  Table designs{"designs", {}, {}};
  for (const GridAxis& a : res.axes) designs.columns.push_back(a.key);
  designs.columns.insert(designs.columns.end(), derived.begin(), derived.end());
  // Each design's sweep report; the first gives the meta and the tables' columns. The points of
  // every design: the axes' values, the derived columns, then the sweep's own, with the coil
  // copper loss before status and error.
  Report r;
  double simulations = 0.0;
  for (std::size_t d = 0; d < res.designs.size(); ++d) {
    const DesignPoint& dp = res.designs[d];
    const Report one = sweep_report(base, req, dp.sweep);
    simulations += static_cast<double>(dp.sweep.simulations);
    if (d == 0) {
      r = one;
      for (Table& t : r.tables) {
        std::vector<std::string> cols = designs.columns;
        cols.insert(cols.end(), t.columns.begin(), t.columns.end());
        cols.insert(cols.end() - 2, "coil_copper_loss_W");
        t.columns = std::move(cols);
        t.rows.clear();
      }
    }
    std::vector<Cell> head(dp.values.begin(), dp.values.end());
    for (double v :
         {dp.rods_mass_kg, dp.coil_resistance_ohm, dp.first_resonance_Hz, dp.bandwidth_Hz})
      head.emplace_back(v);
    designs.rows.push_back(head);
    for (std::size_t t = 0; t < one.tables.size() && t < r.tables.size(); ++t) {
      const auto& loss = t == 0 ? dp.copper_loss_W : dp.reference_copper_loss_W;
      for (std::size_t i = 0; i < one.tables[t].rows.size(); ++i) {
        std::vector<Cell> row = head;
        row.insert(row.end(), one.tables[t].rows[i].begin(), one.tables[t].rows[i].end());
        row.insert(row.end() - 2, Cell(loss[i]));
        r.tables[t].rows.push_back(std::move(row));
      }
    }
  }
  for (auto& [key, value] : r.meta)  // every design's simulations, not the first's
    if (key == "simulations") value = Cell(simulations);
  r.meta.emplace_back("designs", static_cast<double>(res.designs.size()));
  r.meta.emplace_back("small_signal_bias_A", res.bias_A);
  r.meta.emplace_back("design_wall_time_s", res.wall_time_s);
  r.tables.push_back(std::move(designs));
  return r;
}

}  // namespace gmasim
