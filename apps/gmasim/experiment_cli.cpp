#include "experiment_cli.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim::cli {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

double parse_number(const std::string& item, const std::string& flag, const std::string& unit,
                    const std::string& text) {
  const std::string t = trim(item);
  char* end = nullptr;
  const double v = t.empty() ? 0.0 : std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v))
    throw InputError(fmt::format("{} '{}': '{}' is not a finite number [{}]", flag,
                                 clip_for_message(text), clip_for_message(t), unit));
  return v;
}

}  // namespace

std::vector<double> parse_list(const std::string& text, const std::string& flag,
                               const std::string& unit) {
  std::vector<double> out;
  if (trim(text).empty()) return out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = text.find(',', pos);
    const std::string item =
        text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    const std::size_t c1 = item.find(':');
    if (c1 == std::string::npos) {
      out.push_back(parse_number(item, flag, unit, text));
    } else {
      const std::size_t c2 = item.find(':', c1 + 1);
      if (c2 == std::string::npos)
        throw InputError(fmt::format("{} '{}': a range is start:step:stop [{}]", flag, text, unit));
      const double a = parse_number(item.substr(0, c1), flag, unit, text);
      const double step = parse_number(item.substr(c1 + 1, c2 - c1 - 1), flag, unit, text);
      const double b = parse_number(item.substr(c2 + 1), flag, unit, text);
      if (!(step > 0.0) || b < a)
        throw InputError(fmt::format("{} '{}': range {}: needs step > 0 and stop >= start [{}]",
                                     flag, text, trim(item), unit));
      const double span = std::floor((b - a) / step + 1e-9);
      if (!(span < kMaxListValues))
        throw InputError(fmt::format("{} '{}': range {} has {:.4g} values (limit {:g})", flag, text,
                                     trim(item), span + 1.0, kMaxListValues));
      const long n = checked_count(span, kMaxListValues, flag);
      for (long k = 0; k <= n; ++k) out.push_back(a + static_cast<double>(k) * step);
    }
    if (static_cast<double>(out.size()) > kMaxListValues)
      throw InputError(fmt::format("{}: more than {:g} values", flag, kMaxListValues));
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

ProgressFn stderr_progress(const std::string& label, bool force) {
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  if (!tty && !force) return {};
  const auto t0 = std::chrono::steady_clock::now();
  // Shown only for runs that last: nothing before 2 s have passed (unless forced), then the
  // count, the elapsed time and the remaining time extrapolated from the rate so far.
  // Throttled: a terminal's line is redrawn at most every 0.2 s, a pipe or file gets a line
  // at most every kPipeEvery_s (and the first and last), not one per 1 % of the run.
  constexpr double kPipeEvery_s = 2.0;
  auto shown = std::make_shared<double>(-1e9);
  return [label, tty, force, t0, shown](std::size_t done, std::size_t total) {
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (total <= 1) return;  // one job: nothing between start and end to show
    if (!force && el < 2.0 && done < total) return;
    if (done < total && el - *shown < (tty ? 0.2 : kPipeEvery_s)) return;
    *shown = el;
    const double eta =
        done > 0 ? el * static_cast<double>(total - done) / static_cast<double>(done) : 0.0;
    const std::string text =
        fmt::format("{}: {}/{} ({:.0f} %), {:.1f} s elapsed, ETA {:.1f} s", label, done, total,
                    total ? 100.0 * static_cast<double>(done) / total : 100.0, el, eta);
    // Serialised by the caller; a terminal gets one updating line, a pipe one line each.
    if (tty)
      std::fprintf(stderr, "\r%s\033[K%s", text.c_str(), done == total ? "\n" : "");
    else
      std::fprintf(stderr, "%s\n", text.c_str());
    std::fflush(stderr);
  };
}

std::vector<std::string> write_report(const std::string& dir, const std::string& stem,
                                      const Report& r) {
  return write_report_files(dir, stem, r);
}

// The installed package (<prefix>/share/gmasim/python), else the build tree's (<exe>/../python).
std::string python_package_path() {
  if (const char* env = std::getenv("GMASIM_PYTHONPATH"); env != nullptr) return env;
  const std::string installed = beside_executable("share/gmasim/python");
  return installed.empty() ? beside_executable("python") : installed;
}

std::string render_plot(const std::string& command, const std::string& dir) {
  PythonCommand c;
  c.python_path = python_package_path();
  c.module = "gmasim.command_figures";
  c.args = {command, dir};
  namespace fs = std::filesystem;
  const auto started = fs::file_time_type::clock::now();
  const int rc = run_python(c);
  if (rc == 127)
    throw InputError(fmt::format("--plot: cannot run {} (install python3-matplotlib)", c.python));
  if (rc != 0)
    throw InputError(fmt::format(
        "--plot: the figure renderer failed ({}); the data files are written", c.text()));
  // Every figure the renderer wrote, the command's own first (simulate --self-heating also
  // writes self_heating.png).
  const std::string own = (fs::path(dir) / (command + ".png")).string();
  std::vector<std::string> others;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".png" && e.path().string() != own &&
        e.last_write_time(ec) >= started)
      others.push_back(e.path().string());
  std::sort(others.begin(), others.end());
  return others.empty() ? own : fmt::format("{}, {}", own, fmt::join(others, ", "));
}

}  // namespace gmasim::cli
