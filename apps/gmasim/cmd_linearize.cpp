// gmasim linearize: the small-signal plant current -> displacement (and -> the induction coil's
// B) at a temperature and bias, as a state space (issue 40 item 1; docs/experiments.md, "The
// plant as a state space"): linearize.json and a CSV per matrix, and linearize.mat (MATLAB v5,
// written by matio, Debian's libmatio) that MATLAB's and Octave's `ss(A, B, C, D)` take as is.
#include <fmt/format.h>
#include <matio.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/mechanics/state_space.hpp"

namespace gmasim::cli {
namespace {

// One real matrix (row-major in, column-major out) as a MATLAB variable.
void write_matrix(mat_t* file, const char* name, const std::vector<double>& row_major, int rows,
                  int cols) {
  std::vector<double> col_major(row_major.size());
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j)
      col_major[static_cast<std::size_t>(j * rows + i)] =
          row_major[static_cast<std::size_t>(i * cols + j)];
  std::size_t dims[2] = {static_cast<std::size_t>(rows), static_cast<std::size_t>(cols)};
  matvar_t* v = Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, col_major.data(), 0);
  if (!v || Mat_VarWrite(file, v, MAT_COMPRESSION_NONE) != 0) {
    if (v) Mat_VarFree(v);
    throw std::runtime_error(fmt::format("linearize: matio could not write {}", name));
  }
  Mat_VarFree(v);
}

// A, B, C, D and the operating point as MATLAB v5 (temporary file, then rename).
void write_mat(const std::string& path, const StateSpace& ss) {
  const std::string tmp = path + ".tmp";
  mat_t* file = Mat_CreateVer(tmp.c_str(), nullptr, MAT_FT_MAT5);
  if (!file) throw InputError(fmt::format("linearize: cannot create {}", tmp));
  const int n = ss.n_states, p = ss.n_outputs;
  try {
    write_matrix(file, "A", ss.A, n, n);
    write_matrix(file, "B", ss.B, n, 1);
    write_matrix(file, "C", ss.C, p, n);
    write_matrix(file, "D", ss.D, p, 1);
    for (const StateSpace& b : ss.blocks) {  // the blocks: A_stack, ..., A_mount, ...
      const std::string k = b.input == "q" ? "_mount" : "_stack";
      const int bn = b.n_states, bp = b.n_outputs;
      write_matrix(file, ("A" + k).c_str(), b.A, bn, bn);
      write_matrix(file, ("B" + k).c_str(), b.B, bn, 1);
      write_matrix(file, ("C" + k).c_str(), b.C, bp, bn);
      write_matrix(file, ("D" + k).c_str(), b.D, bp, 1);
    }
    write_matrix(file, "temperature_C", {ss.temperature_C}, 1, 1);
    write_matrix(file, "bias_A", {ss.bias_A}, 1, 1);
  } catch (...) {
    Mat_Close(file);
    std::filesystem::remove(tmp);
    throw;
  }
  Mat_Close(file);
  std::filesystem::rename(tmp, path);
}

std::string complex_text(std::complex<double> z) {
  const double f = std::abs(z) / (2.0 * M_PI), zeta = -z.real() / std::abs(z);
  if (z.imag() == 0.0) return fmt::format("{:.6g} 1/s (real; {:.4g} Hz)", z.real(), f);
  return fmt::format("{:.6g} {:+.6g}j 1/s ({:.4g} Hz, zeta {:.3g})", z.real(), z.imag(), f, zeta);
}

}  // namespace

Runner add_linearize(CLI::App& app) {
  auto model = std::make_shared<ModelArgs>();
  auto out = std::make_shared<std::string>("out/linearize");
  auto T = std::make_shared<double>(20.0);
  auto bias = std::make_shared<double>(1.0);
  auto amplitude = std::make_shared<double>(0.0);
  auto freqs = std::make_shared<std::string>("10,100,1000");
  auto* sub = app.add_subcommand(
      "linearize",
      "The small-signal plant current -> displacement (and -> the induction coil's B) about a DC "
      "bias, as a state space x' = A x + B dI, y = C x + D dI with named states in SI units, its "
      "poles, zeros and DC gain. Writes linearize.json, linearize_{A,B,C,D,states,poles,zeros}.csv "
      "and linearize.mat (MATLAB v5: A, B, C, D for ss())");
  add_model_options(sub, *model);
  sub->add_option("--temperature", *T, "Operating temperature [degC]")->capture_default_str();
  sub->add_option("--bias", *bias, "DC bias current [A] (1 A: the FRF's)")->capture_default_str();
  sub->add_option("--amplitude", *amplitude,
                  "Large signal: the describing function at this current amplitude about the bias "
                  "[A] (the stepped sine of gmasim frf --amplitude), beside the small-signal "
                  "response; 0: none")
      ->capture_default_str();
  sub->add_option("--frequencies", *freqs,
                  "The describing function's frequencies [Hz]: list or start:step:stop")
      ->capture_default_str();
  sub->add_option("--out", *out, "Output directory")->capture_default_str();
  return [=]() -> int {
    if (!sub->parsed()) return -1;
    const Model m = load_model_args(*model);
    prepare_output_dir(*out, {"linearize"}, model_inputs(*model));
    const StateSpace ss = linearize_plant(m, *T, *bias);
    std::vector<DescribingPoint> df;
    if (*amplitude != 0.0)
      df = describing_function(m, ss, *amplitude, parse_list(*freqs, "--frequencies", "Hz"));
    auto files = write_report(*out, "linearize",
                              linearize_report(m, ss, df.empty() ? nullptr : &df, *amplitude));
    const std::string mat = (std::filesystem::path(*out) / "linearize.mat").string();
    write_mat(mat, ss);
    files.push_back(mat);
    fmt::print("gmasim linearize  model: {}\n", model_label(*model));
    fmt::print("  {} degC, bias {} A: {} states ({}), input dI [A], outputs {}\n", ss.temperature_C,
               ss.bias_A, ss.n_states, fmt::join(ss.states, ", "), fmt::join(ss.outputs, ", "));
    if (ss.blocks.size() > 1)
      fmt::print(
          "  split at the sensor mount: stack ({} states; current -> y_stack, q) and mount "
          "({} states; q -> dy): {}\n",
          ss.blocks[0].n_states, ss.blocks[1].n_states, ss.interconnection);
    fmt::print("  DC gain: {:.6g} um/A", 1e6 * ss.dc_gain(0));
    if (ss.n_outputs > 1) fmt::print(", B {:.6g} mT/A", 1e3 * ss.dc_gain(1));
    fmt::print("\n  poles:\n");
    for (const auto& p : ss.poles()) fmt::print("    {}\n", complex_text(p));
    fmt::print("  zeros (y):\n");
    for (const auto& z : ss.zeros(0)) fmt::print("    {}\n", complex_text(z));
    if (!df.empty()) {
      fmt::print(
          "  describing function at +-{:g} A about the bias (stepped sine), beside the "
          "small signal:\n  {:>10} {:>12} {:>10} {:>14} {:>12} {:>7}\n",
          *amplitude, "f Hz", "|Y/I| um/A", "phase deg", "small um/A", "small deg", "ratio");
      for (const auto& p : df)
        fmt::print("  {:10.4g} {:12.5g} {:10.2f} {:14.5g} {:12.2f} {:7.3f}\n", p.f_Hz,
                   p.gain_um_per_A, p.phase_deg, p.small_signal_gain_um_per_A,
                   p.small_signal_phase_deg, p.gain_um_per_A / p.small_signal_gain_um_per_A);
    }
    fmt::print("  wrote {}\n", fmt::join(files, ", "));
    return 0;
  };
}

}  // namespace gmasim::cli
