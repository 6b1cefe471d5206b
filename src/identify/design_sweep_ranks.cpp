// gmasim sweep --grid over MPI ranks (gmasim/identify/design.hpp, run_design_sweep_ranks): each
// rank runs its share of the designs (run_design_sweep's rank and ranks), writes their numbers
// as text at 17 significant digits (an exact round trip), and rank 0 reads every rank's back
// into the designs the others ran.
#include <fmt/format.h>

#include <sstream>

#include "gmasim/errors.hpp"
#include "gmasim/experiments/design_sweep.hpp"
#include "gmasim/identify/design.hpp"
#include "identify/checkpoint_text.hpp"
#include "identify/communicator.hpp"

namespace gmasim {
namespace {

using identify_detail::numbers;

// One point: its grid values, metrics, changes, divergence and copper loss; then its error.
void write_point(std::string& s, const SweepPoint& p, double loss) {
  const Metrics& m = p.metrics;
  s += fmt::format(
      "p {}\n",
      numbers({p.temperature_C, p.current_pp_A, p.frequency_Hz, m.window_start_s, m.window_end_s,
               m.stroke_um, m.hysteresis_um, m.B_pp_T, m.y_mean_um, p.stroke_change_pct,
               p.hysteresis_change_pct, p.B_pp_change_pct, p.diverged ? 1.0 : 0.0, loss}));
  std::string e = p.error;
  for (char& c : e)
    if (c == '\n' || c == '\r') c = ' ';
  s += fmt::format("e {}\n", e);
}

std::string designs_text(const DesignSweepResult& res, int rank, int ranks) {
  std::string s;
  for (std::size_t d = static_cast<std::size_t>(rank); d < res.designs.size();
       d += static_cast<std::size_t>(ranks)) {
    const DesignPoint& p = res.designs[d];
    s += fmt::format(
        "d {}\n",
        numbers({static_cast<double>(d), p.rods_mass_kg, p.coil_resistance_ohm,
                 p.first_resonance_Hz, p.bandwidth_Hz, static_cast<double>(p.sweep.points.size()),
                 static_cast<double>(p.sweep.reference_points.size()),
                 static_cast<double>(p.sweep.simulations), static_cast<double>(p.sweep.threads),
                 p.sweep.wall_time_s}));
    for (std::size_t i = 0; i < p.sweep.points.size(); ++i)
      write_point(s, p.sweep.points[i], p.copper_loss_W[i]);
    for (std::size_t i = 0; i < p.sweep.reference_points.size(); ++i)
      write_point(s, p.sweep.reference_points[i], p.reference_copper_loss_W[i]);
  }
  return s + "end\n";
}

SweepPoint read_point(identify_detail::LineReader& in, double& loss) {
  const auto v = in.nums(in.expect("p"), 14);
  SweepPoint p;
  p.temperature_C = v[0];
  p.current_pp_A = v[1];
  p.frequency_Hz = v[2];
  p.metrics = {v[3], v[4], v[5], v[6], v[7], v[8]};
  p.stroke_change_pct = v[9];
  p.hysteresis_change_pct = v[10];
  p.B_pp_change_pct = v[11];
  p.diverged = v[12] != 0.0;
  loss = v[13];
  p.error = in.expect("e");
  return p;
}

void read_designs(const std::string& text, int rank, DesignSweepResult& res) {
  identify_detail::LineReader in{fmt::format("(rank {}'s designs)", rank), {}, 0};
  std::istringstream ss(text);
  for (std::string l; std::getline(ss, l);) in.lines.push_back(l);
  while (in.lines.at(in.pos) != "end") {
    const auto h = in.nums(in.expect("d"), 10);
    DesignPoint& p = res.designs.at(static_cast<std::size_t>(h[0]));
    p.rods_mass_kg = h[1];
    p.coil_resistance_ohm = h[2];
    p.first_resonance_Hz = h[3];
    p.bandwidth_Hz = h[4];
    p.sweep.simulations = static_cast<long>(h[7]);
    p.sweep.threads = static_cast<int>(h[8]);
    p.sweep.wall_time_s = h[9];
    double loss = 0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(h[5]); ++i) {
      p.sweep.points.push_back(read_point(in, loss));
      p.copper_loss_W.push_back(loss);
    }
    for (std::size_t i = 0; i < static_cast<std::size_t>(h[6]); ++i) {
      p.sweep.reference_points.push_back(read_point(in, loss));
      p.reference_copper_loss_W.push_back(loss);
    }
  }
}

}  // namespace

DesignSweepResult run_design_sweep_ranks(const ModelSpec& base, const std::vector<GridAxis>& axes,
                                         const SweepRequest& r, Communicator& comm,
                                         const ProgressFn& progress) {
  const int rank = comm.rank(), ranks = comm.size();
  DesignSweepResult res = run_design_sweep(base, axes, r, progress, rank, ranks);
  if (ranks == 1) return res;
  const std::vector<std::string> texts =
      identify_detail::collective(comm).gather(designs_text(res, rank, ranks), 0);
  if (rank != 0) return res;
  for (int k = 1; k < ranks; ++k) read_designs(texts[static_cast<std::size_t>(k)], k, res);
  return res;
}

}  // namespace gmasim
