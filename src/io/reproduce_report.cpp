// Outputs of `gmasim reproduce`: report.md, the claims, every experiment's data (the
// experiments' own report tables, CSV + JSON), and the figures (rendered by the Python
// package gmasim.report_figures from those CSVs).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/io/io.hpp"

namespace gmasim {
namespace {

std::string model_line(const ReproduceResult& r) {
  return fmt::format("Model: `{}`; readings: {}. The whole study took {:.1f} s.\n\n",
                     r.model_source, r.model_readings, r.wall_time_s);
}

// Every experiment's report tables (dir/data/*.csv|json), the loops, and the claims.
void write_study_data(const Model& m, const ReproduceResult& r, const std::filesystem::path& dir) {
  const std::string data = (dir / "data").string();
  ensure_output_dir(data);
  write_report_files(data, "sweep_10Hz", sweep_report(m, r.sweep_10Hz_request, r.sweep_10Hz));
  write_report_files(data, "sweep_dynamic",
                     sweep_report(m, r.sweep_dynamic_request, r.sweep_dynamic));
  write_report_files(data, "frf", frf_report(m, r.frf_request, r.frf));
  // The +-1 A stepped sine of the resonance-amplitude claim (section 3.4)
  write_report_files(data, "frf_large", frf_report(m, r.frf_large_request, r.frf_large));
  write_report_files(data, "track", track_report(m, r.track_request, r.track));
  write_report_files(data, "ablate", ablate_report(m, r.ablate_request, r.ablate));
  write_report_files(data, "params", params_report(m, r.params_request, r.params));
  write_report_files(data, "thermal", thermal_report(m, r.thermal));
  write_file_atomic((std::filesystem::path(data) / "loops_8A_10Hz.csv").string(),
                    timeseries_csv(r.loops));
  write_report_files(dir.string(), "claims", claims_report(r.claims));
}

// The figures, rendered from the CSVs by the Python package (python_exe empty: not
// rendered), and how report.md shows one: the image, or its caption and why it is missing.
class Figures {
 public:
  Figures(const std::string& dir, const std::string& python_exe, const std::string& python_path) {
    if (python_exe.empty()) {
      note_ = "(figures not rendered: --no-figures)";
      return;
    }
    PythonCommand c;
    c.python = python_exe;
    c.python_path = python_path;
    c.module = "gmasim.report_figures";
    c.args = {dir};
    c.stdout_to_stderr = true;  // our standard output is the command's summary
    const int rc = run_python(c);
    rendered_ = rc == 0;
    if (!rendered_) {
      note_ = fmt::format("(figure rendering failed: `{}` exited with {})", c.text(), rc);
      std::fprintf(stderr, "gmasim: warning: %s; report.md shows the captions only\n",
                   note_.substr(1, note_.size() - 2).c_str());
    }
  }

  std::string operator()(const std::string& stem, const std::string& caption) const {
    return rendered_ ? fmt::format("![{0}](figures/{1}.png)\n\n*{0}* ([SVG](figures/{1}.svg))\n\n",
                                   caption, stem)
                     : fmt::format("*{}* {}\n\n", caption, note_);
  }

 private:
  bool rendered_ = false;
  std::string note_;
};

// One line per FRF curve: first resonance, bandwidth and modes beside the paper's.
std::string frf_lines(const ReproduceResult& r) {
  std::string md;
  for (const auto& c : r.frf.curves) {
    std::string modes;
    for (double f : c.mode_frequencies_Hz)
      modes += fmt::format("{}{:.0f}", modes.empty() ? "" : ", ", f);
    md += fmt::format(
        "- {:g} degC: first resonance in the band {} (paper {:g} Hz), -3 dB bandwidth {:.0f} Hz "
        "(paper > {:g} Hz), modes of eq. 15 at the bias point: {} Hz\n",
        c.temperature_C,
        c.first_resonance_Hz > 0 ? fmt::format("{:.0f} Hz", c.first_resonance_Hz)
                                 : std::string("none"),
        r.frf.paper_first_resonance_Hz, c.bandwidth_3dB_Hz, r.frf.paper_bandwidth_Hz, modes);
  }
  return md;
}

// report.md: the claims, then each experiment with its figures and data files.
std::string report_markdown(const ReproduceResult& r, const Figures& fig) {
  std::string md;
  md += "# gmasim reproduction of the MCTD paper\n\n";
  md += model_line(r);
  md +=
      "## Claims\n\nOne row per number of the paper that READING-NOTES lists, beside ours "
      "(`claims.csv`, `claims.json`).\n\n";
  md += claims_markdown(r.claims);
  md += fig("claims",
            "Every applicable claim: ours / paper, green when it passes, red when it fails");
  md += "\n## Temperature sweep at 10 Hz (Fig. 12-14)\n\n";
  md += fig("loops_8A_10Hz", "Hysteresis loops y(I) at 8 A, 10 Hz, coloured by temperature");
  md += fig("sweep_10Hz", "Stroke, hysteresis and flux density against temperature, 10 Hz");
  md +=
      "Data: `data/sweep_10Hz.csv`, `data/sweep_dynamic.csv` (100/200/400 Hz), "
      "`data/loops_8A_10Hz.csv`.\n\n";
  md += "## Frequency response (Fig. 15)\n\n";
  md += frf_lines(r);
  md += "\n";
  md += fig(
      "frf",
      "Bode plot, current to displacement: stepped sine (markers) and small-signal linearisation "
      "(lines)");
  md += "Data: `data/frf*.csv`. How it is measured: docs/experiments.md.\n\n";
  md += "## Closed-loop tracking (Fig. 16)\n\n";
  md += fig("track", "RMS tracking error against temperature, PID kp 0.2, ki 0.03, kd 0.007");
  md += "## Stroke at 20-150 degC (Fig. 18) and parameters against temperature (Fig. 19)\n\n";
  md += fig("retention", "Stroke retention against temperature, 10 Hz");
  md +=
      fig("params_vs_temperature", "mu_G, rho_G, M_G, E_G and E_t against temperature, 8 A 10 Hz");
  md += "## Ablation (Fig. 20)\n\n";
  md += fig("ablate",
            "Change of the output when one temperature law is frozen at 20 degC, 6 A, 70 degC");
  md += fmt::format(
      "## Thermal expansion (eq. 21)\n\n{:.3f} um/degC (paper: model {:g}, measured {:g}).\n",
      r.thermal.um_per_C, r.thermal.paper_model_um_per_C, r.thermal.paper_measured_um_per_C);
  return md;
}

}  // namespace

std::string write_reproduce_outputs(const Model& m, const ReproduceResult& r,
                                    const std::string& dir_s, const std::string& python_exe,
                                    const std::string& python_path) {
  ensure_output_dir(dir_s);
  const std::filesystem::path dir(dir_s);
  write_study_data(m, r, dir);
  const Figures figures(dir.string(), python_exe, python_path);
  const std::string md = report_markdown(r, figures);
  write_file_atomic((dir / "report.md").string(), md);
  return md;
}

std::vector<std::pair<std::string, std::string>> load_claim_notes(const std::string& path) {
  const std::string text = io_detail::read_text_file(path, "claim notes");
  std::vector<std::pair<std::string, std::string>> notes;
  std::size_t line_no = 0;
  bool in_note = false;
  for (const std::string_view line : io_detail::split_lines(text)) {
    ++line_no;
    if (line.starts_with("### ")) {
      const std::string id(io_detail::trim(line.substr(4)));
      if (id.empty() || id.find_first_of(" \t") != std::string::npos)
        throw InputError(fmt::format("{}:{}: a '### ' heading must name one claim id, got '{}'",
                                     path, line_no, id));
      for (const auto& n : notes)
        if (n.first == id)
          throw InputError(fmt::format("{}:{}: claim '{}' is explained twice", path, line_no, id));
      notes.emplace_back(id, std::string());
      in_note = true;
    } else if (in_note) {
      notes.back().second += std::string(line) + "\n";
    }
  }
  for (auto& n : notes) {
    const auto last = n.second.find_last_not_of(" \t\r\n");
    n.second.erase(last == std::string::npos ? 0 : last + 1);
    const auto first = n.second.find_first_not_of(" \t\r\n");
    n.second.erase(0, first == std::string::npos ? n.second.size() : first);
  }
  return notes;
}

std::vector<std::string> unexplained_failures(
    const std::vector<Claim>& claims,
    const std::vector<std::pair<std::string, std::string>>& notes) {
  std::vector<std::string> out;
  for (const auto& c : claims) {
    if (!c.applicable || c.pass) continue;
    bool found = false;
    for (const auto& n : notes) found = found || (n.first == c.id && !n.second.empty());
    if (!found) out.push_back(c.id);
  }
  return out;
}

void write_reproduction_doc(const ReproduceResult& r, const std::vector<ComparedModel>& compared,
                            const std::string& doc_path, const std::string& out_dir,
                            const std::vector<std::pair<std::string, std::string>>& notes) {
  namespace fs = std::filesystem;
  const fs::path doc(doc_path);
  const fs::path doc_dir = doc.parent_path().empty() ? fs::path(".") : doc.parent_path();
  const fs::path fig_src = fs::path(out_dir) / "figures";
  const fs::path fig_dst = doc_dir / "figures";
  const bool figures = fs::exists(fig_src / "loops_8A_10Hz.png");
  std::error_code same_ec;
  // --doc in the --out directory: the figures are already where the doc refers to them.
  if (figures && !fs::equivalent(fig_src, fig_dst, same_ec)) {
    ensure_output_dir(fig_dst.string());
    for (const auto& e : fs::directory_iterator(fig_src))
      if (e.path().extension() == ".png")
        fs::copy_file(e.path(), fig_dst / e.path().filename(),
                      fs::copy_options::overwrite_existing);
  }
  std::string md = "# Reproduction of the MCTD paper\n\n";
  md += "*Generated by `gmasim reproduce --doc docs/reproduction.md` (do not edit by hand).*\n\n";
  md += model_line(r);
  md +=
      "Each row is one number of the paper from READING-NOTES, beside ours, with the tolerance "
      "that decides "
      "pass or fail. Claims that need the paper's measurements are marked n/a.\n\n";
  md += claims_markdown(r.claims);
  // Every failing claim with its physical explanation (--doc-notes).
  std::string why;
  for (const auto& c : r.claims) {
    if (!c.applicable || c.pass) continue;
    std::string text = "*No explanation recorded.*";
    for (const auto& n : notes)
      if (n.first == c.id && !n.second.empty()) text = n.second;
    why += fmt::format("### {} ({})\n\n{}\n\n", c.id, c.claim, text);
  }
  if (!why.empty()) md += "\n## Why the failing claims fail\n\n" + why;
  md += comparison_markdown(compared);
  if (figures) {
    md +=
        "\n## Figures\n\nThe paper's numbers are the diamonds (green: the claim passes, red: it "
        "fails).\n\n";
    for (const char* f : {"claims", "loops_8A_10Hz", "sweep_10Hz", "frf", "track", "retention",
                          "params_vs_temperature", "ablate"})
      md += fmt::format("![{0}](figures/{0}.png)\n\n", f);
  }
  write_file_atomic(doc_path, md);
}

}  // namespace gmasim
