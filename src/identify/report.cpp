// Outputs of identify(): the calibrated model file (the start model's text with the fitted
// values and provenance comments), the fit report (JSON and markdown) and the convergence
// history (CSV).
#include <fmt/format.h>

#include <cmath>
#include <ctime>
#include <string_view>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "io/json.hpp"
#include "io/schema.hpp"

namespace gmasim {
namespace {

std::string toml_number(double v) {
  std::string s = fmt::format("{:.12g}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string ci_text(const FittedParameter& p) {
  if (std::isnan(p.ci_low)) return "no interval";
  if (!p.determined) return "not determined (the bounds)";
  return fmt::format("[{:.6g}, {:.6g}]{}", p.ci_low, p.ci_high,
                     p.ci_method == "profile" ? " (profile)" : "");
}

std::string wald_text(const FittedParameter& p) {
  if (std::isnan(p.wald_low)) return "-";
  if (!std::isfinite(p.wald_low) || !std::isfinite(p.wald_high)) return "unbounded";
  return fmt::format("[{:.4g}, {:.4g}]", p.wald_low, p.wald_high);
}

// The provenance of a value before any identify run: a comment "identified: ...; was V (P)"
// written by an earlier run gives P (recursively), "identified: ..." alone gives "". One run
// then describes itself and the parameter's original source, never earlier runs.
std::string original_provenance(std::string c) {
  while (c.starts_with("identified:")) {
    const auto was = c.find("; was ");
    if (was == std::string::npos) return "";
    const auto open = c.find(" (", was + 6);
    if (open == std::string::npos || c.back() != ')') return "";
    c = c.substr(open + 2, c.size() - open - 3);
  }
  return c;
}

// How many leading lines of a model file are the header an earlier identify run wrote
// ("# Calibrated by `gmasim identify` ..." through the "#" line after "# Fitted values carry
// ..."), repeated headers included.
std::size_t earlier_run_header_lines(const std::vector<std::string>& lines) {
  std::size_t n = 0;
  while (n < lines.size() && lines[n].starts_with("# Calibrated by `gmasim identify`")) {
    std::size_t k = n;
    while (k < lines.size() && lines[k].starts_with("#") &&
           !lines[k].starts_with("# Fitted values carry an 'identified:'"))
      ++k;
    if (k == lines.size() || !lines[k].starts_with("# Fitted values carry")) break;
    ++k;
    if (k < lines.size() && lines[k] == "#") ++k;
    n = k;
  }
  return n;
}

std::string data_label(const IdentifyResult& r, const FitProvenance& p) {
  if (!p.data.empty()) return fmt::format("{} ({} files)", p.data, r.conditions.size());
  return "scalar targets only";
}

using io_detail::JsonLayout;
using io_detail::JsonWriter;

// fit_report.json: one Inline object per parameter, condition, target and history step.
void write_parameter(JsonWriter& w, const FittedParameter& fp) {
  // [lo, hi] on one line.
  auto pair = [&w](std::string_view key, double lo, double hi) {
    w.key(key).begin_array(JsonLayout::Inline).number(lo).number(hi).end_array();
  };
  w.begin_object(JsonLayout::Inline);
  w.key("name").string(fp.name);
  w.key("unit").string(fp.unit);
  w.key("scale").string(fp.scale == ParamScale::Log ? "log" : "linear");
  w.numbers({{"lower", fp.lower},
             {"upper", fp.upper},
             {"start", fp.start},
             {"value", fp.value},
             {"std_error", fp.std_error}});
  pair("ci95", fp.ci_low, fp.ci_high);
  pair("ci95_linearised", fp.wald_low, fp.wald_high);
  w.key("ci_method").string(fp.ci_method);
  w.key("determined").boolean(fp.determined);
  w.key("at_bound").boolean(fp.at_bound);
  w.end_object();
}

void write_condition(JsonWriter& w, const ConditionFit& c) {
  w.begin_object(JsonLayout::Inline);
  w.key("label").string(c.label);
  w.key("file").string(c.path);
  w.numbers({{"temperature_C", c.condition.temperature_C},
             {"frequency_Hz", c.condition.frequency_Hz},
             {"current_pp_A", c.condition.current_pp_A},
             {"weight", c.weight}});
  w.key("samples").integer(static_cast<long long>(c.samples));
  w.key("compared").integer(static_cast<long long>(c.compared));
  // Named in the record's response unit: pp_um / pp_ppm, ...
  const std::string& u = c.response_unit;
  w.numbers({{"pp_" + u, c.pp},
             {"rms_" + u, c.rms},
             {"rms_pct", c.rms_pct},
             {"max_err_" + u, c.max_err}});
  w.key("flux_rms_pct");
  if (c.flux_rms_pct >= 0) {
    w.number(c.flux_rms_pct);
  } else {
    w.null();  // no flux column
  }
  w.key("failed").boolean(c.failed);
  w.key("error").string(c.error);
  w.key("overlay").string(c.overlay_file);
  w.key("response_unit").string(c.response_unit);
  // The record's drive span: drive_pp_A (current records) or drive_pp_kA_per_m (field records).
  w.key(c.drive_label.starts_with("H") ? "drive_pp_kA_per_m" : "drive_pp_A").number(c.drive_pp);
  // The loop's widths at 20/40/60/80 % of the measured span (null: a branch does not cross).
  const std::string wu = c.width_unit == "kA/m" ? "kA_per_m" : c.width_unit;
  for (const auto& [name, v] : {std::pair{"width_measured_", &c.width_measured},
                                std::pair{"width_simulated_", &c.width_simulated}}) {
    w.key(name + wu).begin_array(JsonLayout::Inline);
    for (double x : *v) {
      if (std::isfinite(x)) {
        w.number(x);
      } else {
        w.null();
      }
    }
    w.end_array();
  }
  w.key("quasi_static").boolean(c.condition.quasi_static);
  w.key("offset").string(offset_mode_name(c.condition.offset));
  // The constant the offset rule added to the simulated response (fitted or first_sample).
  w.key("offset_" + u).number(c.offset);
  if (c.flux_rms_pct >= 0) {
    w.key("flux_offset").string(offset_mode_name(c.condition.flux_offset));
    w.key("flux_offset_T").number(c.flux_offset_T);
  }
  w.end_object();
}

void write_target(JsonWriter& w, const TargetFit& t) {
  w.begin_object(JsonLayout::Inline);
  w.key("label").string(t.label);
  w.key("kind").string(t.kind);
  w.numbers({{"value", t.value},
             {"simulated", t.simulated},
             {"error_pct", t.error_pct},
             {"weight", t.weight}});
  w.key("failed").boolean(t.failed);
  w.end_object();
}

void write_history(JsonWriter& w, const HistoryEntry& h) {
  w.begin_object(JsonLayout::Inline);
  w.key("phase").string(h.phase);
  w.key("step").integer(h.step);
  w.key("evaluations").integer(h.evaluations);
  w.numbers(
      {{"best_rms_pct", h.best_rms_pct}, {"wall_s", h.wall_s}, {"evals_per_s", h.evals_per_s}});
  w.end_object();
}

}  // namespace

std::string stage_text(const StageEvaluations& se) {
  return fmt::format(
      "search {} in {:.1f} s, refinement {} in {:.1f} s, covariance {} in {:.1f} s, profile {} of "
      "{} in {:.1f} s{}",
      se.search, se.search_s, se.refine, se.refine_s, se.covariance, se.covariance_s, se.profile,
      se.profile_budget < 0 ? std::string("no limit")
                            : fmt::format("{} allowed", se.profile_budget),
      se.profile_s, se.reused > 0 ? fmt::format("; {} repeated points reused", se.reused) : "");
}

namespace {

// The fit report's head: command, inputs, the error, the search and its cost.
std::string markdown_summary(const IdentifyResult& r, const FitProvenance& p) {
  std::string s = "# gmasim identify: fit report\n\n";
  if (!p.command.empty()) s += fmt::format("Command: `{}`\n\n", p.command);
  s += fmt::format("- data: {}\n- fit spec: {}\n- start model: {}\n", data_label(r, p),
                   p.fit.empty() ? "-" : p.fit, p.start_model);
  s += fmt::format(
      "- **weighted RMS error {:.4g} %** of peak-to-peak (start {:.4g} %, after the "
      "GA {:.4g} %)\n",
      r.rms_pct, r.start_rms_pct, r.ga_rms_pct);
  s += fmt::format("- {}: {} rank(s) x {} islands x {} individuals, {} generations{}{}\n",
                   r.algorithm, r.ranks, r.islands, r.population, r.generations_done,
                   r.resumed ? " (resumed from a checkpoint)" : "",
                   r.interrupted ? ", **interrupted: best so far**" : "");
  s += fmt::format("- refinement: {}\n", r.refine_summary);
  s += fmt::format("- {} model evaluations ({}), {:.1f} s wall, GA {:.1f} evaluations/s\n",
                   r.evaluations, stage_text(r.stage_evaluations), r.wall_s, r.ga_evals_per_s);
  s += fmt::format("- the written point was found by the {}\n\n", r.best_found_by);
  return s;
}

// The parameters table with the intervals, and how they were computed.
std::string markdown_parameters(const IdentifyResult& r) {
  std::string s = "## Parameters\n\n";
  s += "95 % confidence intervals from the Jacobian of the normalised residuals at the optimum "
       "(central differences; cov = s^2 (J^T J)^-1 with s^2 from the residuals; log-scale "
       "parameters have multiplicative intervals). A parameter whose linearised interval is "
       "wider than its bounds is *not determined*: the data do not constrain it within the "
       "bounds, and its reported interval is the bounds. For a parameter on a bound, or whose "
       "linearised interval leaves the bounds, the linearisation cannot hold and the interval "
       "is the profile likelihood instead (u_j held at trial values, the others re-fitted, "
       "the range where the sum of squares stays within 3.84 s^2 of its minimum).\n\n";
  s += "| parameter | unit | start | fitted | 95 % CI | linearised | std. error | bounds | |\n";
  s += "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& fp : r.parameters) {
    std::string flag = fp.determined ? "" : "not determined";
    if (fp.at_bound) flag += flag.empty() ? "at a bound" : ", at a bound";
    s += fmt::format("| {} | {} | {:.6g} | {:.6g} | {} | {} | {:.3g} | [{:.4g}, {:.4g}]{} | {} |\n",
                     fp.name, fp.unit, fp.start, fp.value,
                     fp.determined || std::isnan(fp.ci_low)
                         ? ci_text(fp)
                         : fmt::format("[{:.6g}, {:.6g}] = bounds", fp.ci_low, fp.ci_high),
                     wald_text(fp), fp.std_error, fp.lower, fp.upper,
                     fp.scale == ParamScale::Log ? " log" : "", flag);
  }
  s += fmt::format("\n{}\n\n", r.covariance_note);
  return s;
}

std::string markdown_correlation(const IdentifyResult& r) {
  std::string s = "## Correlation matrix\n\n|   |";
  for (std::size_t j = 0; j < r.parameters.size(); ++j) s += fmt::format(" {} |", j + 1);
  s += "\n|---|";
  for (std::size_t j = 0; j < r.parameters.size(); ++j) s += "---|";
  s += "\n";
  for (std::size_t j = 0; j < r.correlation.size(); ++j) {
    s += fmt::format("| {} {} |", j + 1, r.parameters[j].name);
    for (double c : r.correlation[j]) s += fmt::format(" {:+.2f} |", c);
    s += "\n";
  }
  s += "\n|correlation| close to 1 means the data determine only a combination of the two "
       "parameters.\n\n";
  return s;
}

// The offsets a record's rules added, with units: "fitted -12.3 ppm", "flux fitted 0.01 T".
std::string offset_text(const ConditionFit& c) {
  std::string s = c.condition.offset == OffsetMode::Absolute
                      ? std::string("-")
                      : fmt::format("{} {:+.5g} {}", offset_mode_name(c.condition.offset), c.offset,
                                    c.response_unit);
  if (c.flux_rms_pct >= 0 && c.condition.flux_offset != OffsetMode::Absolute)
    s += fmt::format("; flux {} {:+.5g} T", offset_mode_name(c.condition.flux_offset),
                     c.flux_offset_T);
  return s;
}

// "I 8 A" or "H 120 kA/m": the record's drive span.
std::string drive_text(const ConditionFit& c) {
  const bool field = c.drive_label.starts_with("H");
  return fmt::format("{} {:.4g} {}", field ? "H" : "I", c.drive_pp, field ? "kA/m" : "A");
}

// Each condition's fit (in the record's response unit), and where its overlay is.
// The loops' widths, measured beside simulated, at the levels of kLoopWidthFractions.
std::string markdown_loop_widths(const IdentifyResult& r) {
  std::string s =
      "\n### Loop width\n\nThe loop's width (the drive between its falling and rising branches) "
      "at 20/40/60/80 % of the measured response's span, measured / simulated, in the drive's "
      "unit (kA/m of a field record, A of a current record); - where a branch does not cross "
      "the level.\n\n| condition | 20 % | 40 % | 60 % | 80 % |\n|---|---|---|---|---|\n";
  auto cell = [](double x) { return std::isfinite(x) ? fmt::format("{:.4g}", x) : "-"; };
  for (const auto& c : r.conditions) {
    if (c.failed) continue;
    s += "| " + c.label + " (" + c.width_unit + ")";
    for (std::size_t k = 0; k < kLoopWidthFractions.size(); ++k)
      s += " | " + cell(c.width_measured[k]) + " / " + cell(c.width_simulated[k]);
    s += " |\n";
  }
  return s;
}

std::string markdown_conditions(const IdentifyResult& r) {
  std::string s =
      "## Conditions\n\np-p, RMS, max err and offset are in the record's response unit: um of "
      "displacement_um, ppm of strain_ppm. The offset is the constant the record's offset rule "
      "added to the simulated response (`fitted`: the least-squares constant; `first_sample`: "
      "the shift aligning the first rows; `absolute`: none). f = 0: not periodic (or "
      "quasi-static). drive p-p: the record's current (I, A) or applied field (H, kA/m) over its "
      "samples.\n\n"
      "| condition | T [degC] | f [Hz] | drive p-p | weight | p-p | RMS | RMS [%] | max err | "
      "offset | flux RMS [%] |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : r.conditions) {
    if (c.failed) {
      s += fmt::format("| {} | {:g} | {:g} | {} | {:g} | - | failed: {} | | | | |\n", c.label,
                       c.condition.temperature_C, c.condition.frequency_Hz, drive_text(c), c.weight,
                       c.error);
      continue;
    }
    const std::string& u = c.response_unit;
    s += fmt::format(
        "| {} | {:g} | {:g} | {} | {:g} | {:.3f} {} | {:.4f} {} | {:.3f} | {:.4f} {} | {} | {} "
        "|\n",
        c.label, c.condition.temperature_C, c.condition.frequency_Hz, drive_text(c), c.weight, c.pp,
        u, c.rms, u, c.rms_pct, c.max_err, u, offset_text(c),
        c.flux_rms_pct >= 0 ? fmt::format("{:.3f}", c.flux_rms_pct) : "-");
  }
  s += markdown_loop_widths(r);
  s += "\nOverlays (measured vs simulated): `overlay_<condition>.csv`, drawn into "
       "`overlay_<condition>.png` by `python3 -m gmasim.command_figures identify <this "
       "directory>`.\n\n";
  return s;
}

std::string markdown_targets(const IdentifyResult& r) {
  std::string s =
      "## Scalar targets\n\n| target | kind | value | simulated | error [%] | weight |\n"
      "|---|---|---|---|---|---|\n";
  for (const auto& t : r.targets) {
    s += fmt::format("| {} | {} | {:.6g} | {} | {} | {:g} |\n", t.label, t.kind, t.value,
                     t.failed ? "failed" : fmt::format("{:.6g}", t.simulated),
                     t.failed ? "-" : fmt::format("{:+.3f}", t.error_pct), t.weight);
  }
  s += "\n";
  return s;
}

}  // namespace

std::string fitted_model_toml(const std::string& start_text, const ModelSpec& start,
                              const IdentifyResult& r, const FitProvenance& p) {
  const auto views = io_detail::split_lines(start_text);
  std::vector<std::string> lines(views.begin(), views.end());
  for (const auto& fp : r.parameters) {
    const auto it = start.params.find(fp.name);
    if (it == start.params.end() || it->second.line < 1 ||
        it->second.line > static_cast<long>(lines.size())) {
      throw std::runtime_error(fmt::format("fitted_model_toml: no source line for {}", fp.name));
    }
    std::string& line = lines[static_cast<std::size_t>(it->second.line - 1)];
    const std::string leaf = fp.name.substr(fp.name.rfind('.') + 1);
    const auto span = schema::value_span(line, leaf);
    if (!span) {
      throw std::runtime_error(fmt::format("fitted_model_toml: '{} =' not found on line {} of {}",
                                           leaf, it->second.line, start.source));
    }
    const std::size_t vbeg = span->begin, vend = span->end;
    const std::string old_comment = original_provenance(schema::trailing_comment(line));
    const bool simple = line.find('{') == std::string::npos;
    std::string ci = ci_text(fp);
    if (ci.front() == '[') ci = "95 % CI " + ci;
    if (r.interrupted) ci = "interrupted run, no interval";
    const std::string comment =
        fmt::format("identified: gmasim identify, data {}, {} (start {:.6g}){}",
                    p.data.empty() ? "targets" : p.data, ci, fp.start,
                    old_comment.empty()
                        ? ""
                        : fmt::format("; was {} ({})", toml_number(it->second.value), old_comment));
    if (simple) {
      line = line.substr(0, vbeg) + toml_number(fp.value) + "  # " + comment;
    } else {
      line = line.substr(0, vbeg) + toml_number(fp.value) + line.substr(vend);
    }
  }
  std::string head;
  head += fmt::format("# Calibrated by `gmasim identify` on {} (docs/identify.md).\n", utc_now());
  if (!p.command.empty()) head += fmt::format("# command: {}\n", p.command);
  head += fmt::format("# start model: {}\n", p.start_model.empty() ? start.source : p.start_model);
  head += fmt::format("# data: {}\n", p.data.empty() ? "none (scalar targets only)" : p.data);
  for (const auto& c : r.conditions)
    head += fmt::format("#   {} (weight {:g}): RMS {:.3f} % of p-p\n", c.path, c.weight, c.rms_pct);
  if (!p.fit.empty()) head += fmt::format("# fit spec: {}\n", p.fit);
  head += fmt::format("# fit: {} parameters, weighted RMS {:.4g} % (start {:.4g} %), {}{}\n",
                      r.parameters.size(), r.rms_pct, r.start_rms_pct,
                      r.interrupted ? "interrupted (best so far)" : "converged run",
                      p.report_dir.empty() ? "" : fmt::format("; report: {}", p.report_dir));
  head += "# Fitted values carry an 'identified:' provenance comment.\n#\n";
  std::string text = head;
  bool in_calibration = false;  // the start's [calibration] table is replaced by this fit's
  for (std::size_t i = earlier_run_header_lines(lines); i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (l.starts_with("[")) in_calibration = l.starts_with("[calibration]");
    if (!in_calibration) text += l + "\n";
  }
  if (!p.fitted_claims.empty()) {
    text +=
        "\n[calibration]  # the claims this model was fitted to (gmasim identify: the fit spec's "
        "claim targets and [[by_construction]] claims); gmasim reproduce counts every other "
        "claim as a prediction\nfitted_claims = [";
    for (std::size_t k = 0; k < p.fitted_claims.size(); ++k)
      text += fmt::format("{}\"{}\"", k == 0 ? "" : ", ", p.fitted_claims[k]);
    text += "]\n";
  }

  // The file must load and carry exactly the fitted values.
  const ModelSpec check = parse_model_spec(text, "fitted model");
  for (const auto& fp : r.parameters) {
    const double v = check.params.at(fp.name).value;
    if (!(std::fabs(v - fp.value) <= 1e-9 * std::max(1.0, std::fabs(fp.value)) ||
          std::fabs(v - fp.value) <= 1e-10 * std::fabs(fp.value))) {
      throw std::runtime_error(fmt::format("fitted_model_toml: {} reads back as {} instead of {}",
                                           fp.name, v, fp.value));
    }
  }
  (void)compile(check);
  return text;
}

// What each stage spent: evaluations (and the profile's budget, the reused points), wall time.
static void write_stages(JsonWriter& w, const StageEvaluations& se) {
  w.key("evaluations_by_stage").begin_object(JsonLayout::Inline);
  w.key("search").integer(se.search);
  w.key("refine").integer(se.refine);
  w.key("covariance").integer(se.covariance);
  w.key("profile").integer(se.profile);
  w.key("profile_budget");
  if (se.profile_budget >= 0) {
    w.integer(se.profile_budget);
  } else {
    w.null();  // no limit
  }
  w.key("reused").integer(se.reused);
  w.end_object();
  w.key("wall_s_by_stage").begin_object(JsonLayout::Inline);
  w.numbers({{"search", se.search_s},
             {"refine", se.refine_s},
             {"covariance", se.covariance_s},
             {"profile", se.profile_s}});
  w.end_object();
}

std::string fit_report_json(const IdentifyResult& r, const FitProvenance& p) {
  JsonWriter w;
  w.begin_object();
  w.key("gmasim_identify_report").integer(1);
  w.key("command").string(p.command);
  w.key("data").string(p.data);
  w.key("fit").string(p.fit);
  w.key("start_model").string(p.start_model);
  w.numbers(
      {{"rms_pct", r.rms_pct}, {"start_rms_pct", r.start_rms_pct}, {"ga_rms_pct", r.ga_rms_pct}});
  w.key("interrupted").boolean(r.interrupted);
  w.key("resumed").boolean(r.resumed);
  w.key("algorithm").begin_object(JsonLayout::Inline);
  w.key("name").string(r.algorithm);
  w.key("ranks").integer(r.ranks);
  w.key("islands").integer(r.islands);
  w.key("population").integer(r.population);
  w.key("generations").integer(r.generations_done);
  w.key("refine").string(r.refine_summary);
  w.end_object();
  w.key("evaluations").integer(r.evaluations);
  write_stages(w, r.stage_evaluations);
  w.key("best_found_by").string(r.best_found_by);
  w.key("wall_s").number(r.wall_s);
  w.key("ga_evals_per_s").number(r.ga_evals_per_s);
  w.key("parameters").begin_array();
  for (const auto& fp : r.parameters) {
    write_parameter(w, fp);
  }
  w.end_array();
  w.key("correlation").begin_array();
  for (const auto& row : r.correlation) {
    w.begin_array(JsonLayout::Inline);
    for (double c : row) w.number(c);
    w.end_array();
  }
  w.end_array();
  w.key("covariance").begin_object(JsonLayout::Inline);
  w.key("ok").boolean(r.covariance_ok);
  w.key("residuals").integer(static_cast<long long>(r.residual_count));
  w.key("residual_sigma_pct").number(r.residual_sigma);
  w.key("note").string(r.covariance_note);
  w.end_object();
  w.key("conditions").begin_array();
  for (const auto& c : r.conditions) {
    write_condition(w, c);
  }
  w.end_array();
  w.key("targets").begin_array();
  for (const auto& t : r.targets) {
    write_target(w, t);
  }
  w.end_array();
  w.key("history").begin_array();
  for (const auto& h : r.history) {
    write_history(w, h);
  }
  w.end_array();
  w.key("notes").begin_array(JsonLayout::Inline);
  for (const auto& n : r.notes) w.string(n);
  w.end_array();
  w.end_object();
  return w.text();
}

std::string fit_report_markdown(const IdentifyResult& r, const FitProvenance& p) {
  std::string s = markdown_summary(r, p);
  s += markdown_parameters(r);
  if (!r.correlation.empty()) s += markdown_correlation(r);
  if (!r.conditions.empty()) s += markdown_conditions(r);
  if (!r.targets.empty()) s += markdown_targets(r);
  s += "## Convergence\n\n`convergence.csv` (and `convergence.png`): best weighted RMS error "
       "against generations (GA) and iterations (refinement).\n";
  if (!r.notes.empty()) {
    s += "\n## Notes\n\n";
    for (const auto& n : r.notes) s += "- " + n + "\n";
  }
  return s;
}

std::string convergence_csv(const IdentifyResult& r) {
  std::string s = "phase,step,evaluations,best_rms_pct,wall_s,evals_per_s\n";
  for (const auto& h : r.history)
    s += fmt::format("{},{},{},{:.10g},{:.6g},{:.6g}\n", h.phase, h.step, h.evaluations,
                     h.best_rms_pct, h.wall_s, h.evals_per_s);
  return s;
}

}  // namespace gmasim
