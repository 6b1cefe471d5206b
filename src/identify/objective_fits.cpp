// The fit report's view of the objective: each record's errors and overlay, each target's
// simulated value (Objective::condition_fits, Objective::target_fits).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>

#include "gmasim/identify/identify.hpp"
#include "identify/objective_impl.hpp"

namespace gmasim {
namespace {

using identify_detail::CondData;
using identify_detail::SineMetrics;
using identify_detail::StartCache;

// overlay_<label>.csv with the label's unsafe characters replaced, unique among `out`.
std::string overlay_file(const std::string& label, const std::vector<ConditionFit>& out) {
  std::string safe;
  for (char ch : label) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' || ch == '.';
    safe += ok ? ch : '_';
  }
  std::string name = "overlay_" + safe;
  for (int k = 2;
       std::any_of(out.begin(), out.end(),
                   [&](const ConditionFit& o) { return o.overlay_file == name + ".csv"; });
       ++k)
    name = fmt::format("overlay_{}_{}", safe, k);
  return name + ".csv";
}

// The errors of a simulated record (y, B: offsets applied) and its overlay table.
void fill_fit(ConditionFit& f, const Measurement& meas, const CondData& cd,
              const std::vector<double>& y, const std::vector<double>& B) {
  const bool has_flux = !meas.flux_T.empty();
  double ss = 0.0, ssB = 0.0;
  for (std::size_t i = cd.compare_begin; i < f.samples; ++i) {
    const double d = y[i] - meas.response[i];
    ss += d * d;
    f.max_err = std::max(f.max_err, std::fabs(d));
    if (has_flux) ssB += (B[i] - meas.flux_T[i]) * (B[i] - meas.flux_T[i]);
  }
  f.rms = std::sqrt(ss / static_cast<double>(f.compared));
  f.rms_pct = 100.0 * f.rms / f.pp;
  if (has_flux) {
    const double ppB = peak_to_peak(std::span<const double>(meas.flux_T).subspan(cd.compare_begin));
    if (ppB > 0.0) f.flux_rms_pct = 100.0 * std::sqrt(ssB / static_cast<double>(f.compared)) / ppB;
  }
  f.width_measured.fill(std::nan(""));
  f.width_simulated.fill(std::nan(""));
  if (meas.drive.size() == f.samples && f.compared >= 3) {
    // the loop's widths over the compared samples, at the measured span's levels
    const std::size_t b = cd.compare_begin, m = f.samples - b;
    const std::span<const double> x = std::span<const double>(meas.drive).subspan(b, m),
                                  ym = std::span<const double>(meas.response).subspan(b, m),
                                  ys = std::span<const double>(y).subspan(b, m);
    const auto [lo, hi] = std::minmax_element(ym.begin(), ym.end());
    const bool field = meas.drive_kind == DriveInput::Field;
    f.width_unit = field ? "kA/m" : "A";
    f.width_measured = loop_widths(x, ym, *lo, *hi);
    f.width_simulated = loop_widths(x, ys, *lo, *hi);
    for (auto* w : {&f.width_measured, &f.width_simulated})
      for (double& v : *w) v *= field ? 1e-3 : 1.0;  // A/m -> kA/m
  }
  TimeSeries& ts = f.overlay;
  // Timed current/displacement records keep their historical column names; the others
  // name their own columns (sample index, field, strain).
  const std::string unit = f.response_unit;
  ts.names = {meas.condition.quasi_static ? "sample" : "t_s", std::string(meas.drive_column()),
              "measured_" + unit, "simulated_" + unit, "compared"};
  ts.columns = {meas.t_s, meas.drive, meas.response, y, std::vector<double>(f.samples, 0.0)};
  for (std::size_t i = cd.compare_begin; i < f.samples; ++i) ts.columns[4][i] = 1.0;
  if (has_flux) {
    ts.names.insert(ts.names.end(), {"measured_flux_T", "simulated_flux_T"});
    ts.columns.push_back(meas.flux_T);
    ts.columns.push_back(B);
  }
}

}  // namespace

std::vector<ConditionFit> Objective::condition_fits(const std::vector<double>& u) const {
  const Impl& I = *impl_;
  std::vector<ConditionFit> out;
  std::optional<Model> model;
  std::string model_error;
  try {
    model.emplace(I.model_at(u.data()));
  } catch (const InputError& e) {
    model_error = e.what();
  }
  for (const auto& cd : I.conds) {
    const Measurement& meas = I.data.items[cd.index];
    ConditionFit f;
    f.label = meas.condition.label;
    f.path = meas.path;
    f.overlay_file = overlay_file(f.label, out);
    f.condition = meas.condition;
    f.weight = meas.weight;
    f.samples = meas.t_s.size();
    f.compared = f.samples - cd.compare_begin;
    f.pp = cd.pp_um;
    f.response_unit = std::string(meas.response_unit());
    if (!meas.drive.empty()) {
      const auto [lo, hi] = std::minmax_element(meas.drive.begin(), meas.drive.end());
      const bool field = meas.drive_kind == DriveInput::Field;
      f.drive_label = field ? "H p-p [kA/m]" : "I p-p [A]";
      f.drive_pp = (*hi - *lo) * (field ? 1e-3 : 1.0);
    }
    std::vector<double> y, B;
    const bool has_flux = !meas.flux_T.empty();
    try {
      if (!model) throw InputError(model_error);
      simulate_measurement(*model, meas, I.settings, y, has_flux ? &B : nullptr);
      f.offset =
          identify_detail::apply_offset(meas.condition.offset, meas.response, cd.compare_begin, y);
      if (has_flux)
        f.flux_offset_T = identify_detail::apply_offset(meas.condition.flux_offset, meas.flux_T,
                                                        cd.compare_begin, B);
    } catch (const std::exception& e) {
      f.failed = true;
      f.error = e.what();
      out.push_back(std::move(f));
      continue;
    }
    fill_fit(f, meas, cd, y, B);
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<TargetFit> Objective::target_fits(const std::vector<double>& u) const {
  const Impl& I = *impl_;
  std::vector<TargetFit> out;
  if (I.targets.empty()) return out;
  std::vector<SineMetrics> sm(I.sine_runs.size());
  std::vector<double> res(I.res_runs.size());
  bool failed = false;
  try {
    const Model model = I.model_at(u.data());
    StartCache starts(model);
    I.target_runs(model, starts, sm, res);
  } catch (const std::exception&) {
    failed = true;
  }
  for (const auto& td : I.targets) {
    TargetFit f;
    f.label = td.t.label;
    f.kind = target_kind_name(td.t.kind);
    f.value = td.t.value;
    f.weight = td.t.weight;
    f.failed = failed;
    if (!failed) {
      f.simulated = Impl::target_value(td, sm, res);
      f.error_pct = 100.0 * (f.simulated - f.value) / td.t.scale;
    }
    out.push_back(f);
  }
  return out;
}

}  // namespace gmasim
