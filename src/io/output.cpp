// Output files: atomic writes, the output directory, timeseries.csv and metrics.json.
#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "io/json.hpp"

namespace gmasim {

// ---------------------------------------------------------------------------------------
// Files
// ---------------------------------------------------------------------------------------
namespace {

// The destination must be absent or a regular file: never replace a device, a FIFO, a
// socket or a directory with an output (`--out /dev/null` would become a regular file).
void require_regular_destination(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;  // absent (or a dangling link): fine
  if (S_ISREG(st.st_mode)) return;
  const char* kind = S_ISDIR(st.st_mode)    ? "a directory"
                     : S_ISCHR(st.st_mode)  ? "a character device"
                     : S_ISBLK(st.st_mode)  ? "a block device"
                     : S_ISFIFO(st.st_mode) ? "a FIFO"
                     : S_ISSOCK(st.st_mode) ? "a socket"
                                            : "not a regular file";
  throw InputError(located(path, 0,
                           fmt::format("cannot write output: the destination is {}; gmasim "
                                       "writes only regular files (choose another --out)",
                                       kind)));
}

// The temporaries being written, for remove_pending_temporaries() (a signal handler): fixed
// slots, a path is complete before its slot is marked used (issue 19, item 5).
constexpr int kPendingSlots = 64;
struct PendingSlot {
  std::atomic<bool> used{false};
  char path[4096] = {};
};
PendingSlot g_pending[kPendingSlots];
std::mutex g_pending_mu;

class PendingTemporary {
 public:
  explicit PendingTemporary(const std::string& path) {
    if (path.size() >= sizeof(g_pending[0].path)) return;
    const std::lock_guard<std::mutex> lock(g_pending_mu);
    for (int i = 0; i < kPendingSlots; ++i) {
      if (g_pending[i].used.load(std::memory_order_relaxed)) continue;
      std::memcpy(g_pending[i].path, path.c_str(), path.size() + 1);
      g_pending[i].used.store(true, std::memory_order_release);
      slot_ = i;
      return;
    }
  }
  ~PendingTemporary() { release(); }
  void release() {
    if (slot_ < 0) return;
    const std::lock_guard<std::mutex> lock(g_pending_mu);
    g_pending[slot_].used.store(false, std::memory_order_release);
    slot_ = -1;
  }
  PendingTemporary(const PendingTemporary&) = delete;
  PendingTemporary& operator=(const PendingTemporary&) = delete;

 private:
  int slot_ = -1;
};

// Temporaries "<name>.tmp.<pid>" of `path` left by a process that no longer exists (killed
// with SIGKILL, or by the power): removed before a new one is written (issue 19, item 5).
void remove_stale_temporaries(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const std::string prefix = p.filename().string() + ".tmp.";
  std::error_code ec;
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!name.starts_with(prefix) || name.size() == prefix.size()) continue;
    // "<pid>" (older gmasim) or "<pid>.<n>"
    const std::string rest = name.substr(prefix.size());
    const std::string digits = rest.substr(0, rest.find('.'));
    const std::string tail = rest.substr(digits.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos ||
        digits.size() > 9 ||
        (!tail.empty() &&
         (tail.size() < 2 || tail.find_first_not_of("0123456789", 1) != std::string::npos)))
      continue;
    const long pid = std::stol(digits);
    if (pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == -1 && errno == ESRCH) {
      std::error_code rm;
      fs::remove(it->path(), rm);
    }
  }
}

// "(File too large: the file size limit, ulimit -f, is 102400 bytes)" and the like.
std::string write_error_text(int err) {
  if (err != EFBIG) return std::strerror(err);
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_FSIZE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
    return fmt::format("{}: the file size limit (ulimit -f) is {} bytes", std::strerror(err),
                       static_cast<unsigned long long>(rl.rlim_cur));
  return std::strerror(err);
}

// Writes content to a fresh temporary next to path, flushed and synced; returns its name. The
// temporary is registered while it is written, so that a signal handler can remove it.
std::string write_temporary(const std::string& path, const std::string& content) {
  remove_stale_temporaries(path);
  // "<path>.tmp.<pid>.<n>": unique per process and per call, so that threads writing the same
  // file at once never share a temporary.
  static std::atomic<unsigned long> counter{0};
  const std::string tmp = fmt::format("{}.tmp.{}.{}", path, static_cast<long>(::getpid()),
                                      counter.fetch_add(1, std::memory_order_relaxed));
  PendingTemporary pending(tmp);
  auto fail = [&](int err, std::FILE* f) {
    if (f) std::fclose(f);
    std::remove(tmp.c_str());
    throw InputError(
        located(path, 0, fmt::format("cannot write output ({})", write_error_text(err))));
  };
  std::FILE* f = std::fopen(tmp.c_str(), "wbx");  // x: never follow or reuse an existing name
  if (!f && errno == EEXIST) {
    std::remove(tmp.c_str());  // a stale temporary of a killed run with our pid
    f = std::fopen(tmp.c_str(), "wbx");
  }
  if (!f) fail(errno, nullptr);
  if (!content.empty() && std::fwrite(content.data(), 1, content.size(), f) != content.size())
    fail(errno, f);
  if (std::fflush(f) != 0) fail(errno, f);
  if (::fsync(::fileno(f)) != 0) fail(errno, f);
  if (std::fclose(f) != 0) fail(errno, nullptr);
  return tmp;
}

void sync_directory_of(const std::string& path) {
  // Make the renames durable; a failure here leaves complete files, so it is not reported.
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace

void write_file_atomic(const std::string& path, const std::string& content) {
  write_files_atomic({{path, content}});
}

// An exclusive flock() on each directory the set is renamed into, held while the temporaries
// are renamed: two runs writing one set into one directory (two `simulate --out o`) rename
// theirs one after the other, so the set that stays is one run's, never a mix (issue 19,
// item 5). A directory that cannot be opened is not locked (the renames report the problem).
class DirectoryLocks {
 public:
  explicit DirectoryLocks(const std::vector<std::pair<std::string, std::string>>& files) {
    std::vector<std::string> dirs;
    for (const auto& f : files) {
      std::filesystem::path d = std::filesystem::path(f.first).parent_path();
      dirs.push_back(d.empty() ? "." : d.string());
    }
    std::sort(dirs.begin(), dirs.end());  // one order for every process: no deadlock
    dirs.erase(std::unique(dirs.begin(), dirs.end()), dirs.end());
    for (const auto& d : dirs) {
      const int fd = ::open(d.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
      if (fd < 0) continue;
      while (::flock(fd, LOCK_EX) != 0 && errno == EINTR) {
      }
      fds_.push_back(fd);
    }
  }
  ~DirectoryLocks() {
    for (const int fd : fds_) ::close(fd);  // closing releases the lock
  }
  DirectoryLocks(const DirectoryLocks&) = delete;
  DirectoryLocks& operator=(const DirectoryLocks&) = delete;

 private:
  std::vector<int> fds_;
};

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  for (const auto& [path, content] : files) require_regular_destination(path);
  std::vector<std::string> tmps;
  std::vector<std::unique_ptr<PendingTemporary>> pending;  // until renamed or removed
  try {
    for (const auto& [path, content] : files) {
      tmps.push_back(write_temporary(path, content));
      pending.push_back(std::make_unique<PendingTemporary>(tmps.back()));
    }
  } catch (...) {
    for (const auto& t : tmps) std::remove(t.c_str());
    throw;
  }
  const DirectoryLocks locks(files);
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (std::rename(tmps[i].c_str(), files[i].first.c_str()) != 0) {
      const int err = errno;
      for (std::size_t j = i; j < tmps.size(); ++j) std::remove(tmps[j].c_str());
      throw InputError(
          located(files[i].first, 0, fmt::format("cannot write output ({})", std::strerror(err))));
    }
    pending[i]->release();
  }
  for (const auto& f : files) sync_directory_of(f.first);
}

void remove_pending_temporaries() noexcept {
  for (auto& slot : g_pending)
    if (slot.used.load(std::memory_order_acquire)) ::unlink(slot.path);
}

std::string read_input_file(const std::string& path, const std::string& what) {
  return io_detail::read_text_file(path, what);
}

namespace {
std::mutex g_created_mutex;
std::vector<std::string> g_created_dirs;  // by ensure_output_dir, in creation order (parents first)
}  // namespace

void remove_created_output_dirs_if_empty() {
  const std::lock_guard<std::mutex> lock(g_created_mutex);
  // in reverse creation order: a child before its parent; rmdir leaves a non-empty one
  for (auto it = g_created_dirs.rbegin(); it != g_created_dirs.rend(); ++it)
    (void)::rmdir(it->c_str());
  g_created_dirs.clear();
}

void ensure_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  if (dir.empty())
    throw InputError(
        "output directory '' (empty): name a directory (--out DIR; '.' for the current one)");
  const fs::path p(dir);
  auto fail = [&](const std::string& reason) {
    throw InputError(located(dir, 0, fmt::format("output directory is not writable ({})", reason)));
  };
  std::error_code ec;
  // Created one component at a time, and recorded (canonical) only where mkdir(2) made it: a
  // path such as new/../existing/sub must never record `existing` (it exists once `new` does),
  // nor a directory another process made in between.
  const fs::path abs = fs::absolute(p, ec);
  if (ec) fail(ec.message());
  fs::path cur;
  for (const fs::path& part : abs) {
    cur /= part;
    if (part == "." || part == ".." || cur == cur.root_path()) continue;
    if (::mkdir(cur.c_str(), 0777) == 0) {
      const fs::path made = fs::canonical(cur, ec);
      if (!ec) {
        const std::lock_guard<std::mutex> lock(g_created_mutex);
        g_created_dirs.push_back(made.string());
      }
      ec.clear();
    } else if (errno != EEXIST) {
      fail(std::strerror(errno));
    }
  }
  if (!fs::is_directory(p, ec)) fail(ec ? ec.message() : "not a directory");
  const fs::path probe = p / fmt::format(".gmasim-write-test.{}", static_cast<long>(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) fail(std::strerror(errno));
  ::close(fd);
  if (::unlink(probe.c_str()) != 0) fail(std::strerror(errno));
}

// ---------------------------------------------------------------------------------------
// timeseries.csv
// ---------------------------------------------------------------------------------------
std::string timeseries_csv(const TimeSeries& ts) {
  if (ts.columns.size() != ts.names.size())
    throw std::invalid_argument("timeseries_csv: names and columns differ in number");
  const std::size_t rows = ts.rows();
  for (std::size_t c = 0; c < ts.columns.size(); ++c) {
    if (ts.columns[c].size() != rows) {
      throw std::invalid_argument(
          fmt::format("timeseries_csv: column '{}' has {} rows, expected {}", ts.names[c],
                      ts.columns[c].size(), rows));
    }
  }
  fmt::memory_buffer out;
  for (std::size_t c = 0; c < ts.names.size(); ++c) {
    if (c > 0) out.push_back(',');
    fmt::format_to(std::back_inserter(out), "{}", ts.names[c]);
  }
  out.push_back('\n');
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < ts.columns.size(); ++c) {
      if (c > 0) out.push_back(',');
      fmt::format_to(std::back_inserter(out), "{:.10g}", ts.columns[c][r]);
    }
    out.push_back('\n');
  }
  return fmt::to_string(out);
}

// ---------------------------------------------------------------------------------------
// metrics.json
// ---------------------------------------------------------------------------------------
namespace {

using io_detail::JsonWriter;

void write_waveform(JsonWriter& w, const Waveform& wf) {
  w.begin_object();
  switch (wf.kind) {
    case WaveformKind::BiasedSine:
      w.key("kind").string("biased_sine");
      w.numbers({{"pp_A", wf.pp_A}, {"min_A", wf.min_A}, {"frequency_Hz", wf.frequency_Hz}});
      break;
    case WaveformKind::DC:
      w.key("kind").string("dc");
      w.key("level_A").number(wf.level_A);
      break;
    case WaveformKind::Step:
      w.key("kind").string("step");
      w.numbers(
          {{"level_A", wf.level_A}, {"step_to_A", wf.step_to_A}, {"step_time_s", wf.step_time_s}});
      break;
    case WaveformKind::Chirp:
      w.key("kind").string("chirp");
      w.numbers({{"offset_A", wf.offset_A},
                 {"amplitude_A", wf.amplitude_A},
                 {"f0_Hz", wf.f0_Hz},
                 {"f1_Hz", wf.f1_Hz},
                 {"duration_s", wf.duration_s}});
      break;
    case WaveformKind::Table:
      w.key("kind").string("table");
      w.key("source").string(wf.table_source);
      w.key("points").integer(static_cast<long long>(wf.table_t_s.size()));
      break;
  }
  w.end_object();
}

// Self-heating: the end state of the network and its energy balance (self_heating.csv).
void write_self_heating(JsonWriter& w, const Result& r) {
  const auto last = r.heating.rows() - 1;
  w.key("self_heating").begin_object();
  w.numbers({{"thermal_step_s", r.heating.rows() > 1 ? r.heating.columns[0][1] : 0.0},
             {"coil_C", r.heating.column("coil_C")[last]},
             {"rods_C", r.heating.column("rods_C")[last]},
             {"housing_C", r.heating.column("housing_C")[last]}});
  // The first thermal step holds the virgin curve: the drift starts at the second.
  w.numbers({{"stroke_start_um", r.heating.column("stroke_um")[std::min<std::size_t>(last, 2)]},
             {"stroke_last_um", r.heating.column("stroke_um")[last]},
             {"energy_in_J", r.energy_in_J},
             {"energy_stored_J", r.energy_stored_J},
             {"energy_out_J", r.energy_out_J}});
  w.end_object();
}

// The energy ledgers over the metrics window (gmasim/model/energy.hpp), as mean powers [W], and
// the coil's terminal quantities.
void write_energy(JsonWriter& w, const Model& m, const Result& r) {
  const auto& e = r.energy;
  const double T = e.duration_s;
  w.key("energy").begin_object();
  w.numbers({{"window_s", T}});
  w.key("magnetic").begin_object();
  w.numbers({{"coil_input_W", e.coil_J / T},
             {"magnet_work_W", e.magnet_J / T},
             {"stored_change_W", (e.d_circuit_J + e.d_series_J + e.d_material_J) / T},
             {"hysteresis_W", e.hysteresis_J / T},
             {"eddy_W", e.eddy_J / T},
             {"residual_W", e.magnetic_residual_J / T},
             {"residual_rel", e.magnetic_residual_rel}});
  w.key("rods").begin_object();
  for (std::size_t i = 0; i < e.rod_hysteresis_J.size() && i < m.rods.size(); ++i) {
    w.key(m.rods[i].name).begin_object();
    w.numbers({{"hysteresis_W", e.rod_hysteresis_J[i] / T}, {"eddy_W", e.rod_eddy_J[i] / T}});
    w.end_object();
  }
  w.end_object();
  w.end_object();
  w.key("mechanical").begin_object();
  w.numbers({{"force_work_W", e.force_work_J / T},
             {"stiffness_work_W", e.stiffness_work_J / T},
             {"stored_change_W", (e.d_kinetic_J + e.d_elastic_J) / T},
             {"damping_W", e.damping_J / T},
             {"residual_W", e.mechanical_residual_J / T},
             {"residual_rel", e.mechanical_residual_rel}});
  w.end_object();
  w.numbers({{"coupling_fraction", e.coupling_fraction}});
  const auto& c = r.coil;
  w.key("coil").begin_object();
  w.numbers({{"resistance_ohm", c.resistance_ohm},
             {"current_rms_A", c.current_rms_A},
             {"voltage_rms_V", c.voltage_rms_V},
             {"voltage_peak_V", c.voltage_peak_V},
             {"power_mean_W", c.power_mean_W},
             {"power_peak_W", c.power_peak_W},
             {"copper_W", c.copper_W},
             {"apparent_VA", c.apparent_VA}});
  w.end_object();
  w.end_object();
}

}  // namespace

std::string fnv1a64_hex(std::string_view data) {
  std::uint64_t h = 14695981039346656037ull;
  for (const unsigned char c : data) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return fmt::format("{:016x}", h);
}

std::string metrics_json(const Result& r, const SimulationSettings& s, const Model& m,
                         std::string_view timeseries_csv_text) {
  JsonWriter w;
  w.begin_object();
  w.key("status").string(r.diverged ? "diverged" : "ok");
  w.key("error");
  if (r.error.empty()) {
    w.null();
  } else {
    w.string(r.error);
  }
  w.key("model").string(m.spec.source);
  if (const auto it = m.spec.meta.find("meta.name"); it != m.spec.meta.end())
    w.key("model_name").string(it->second);
  // The values set after loading (--set, ModelSpec::set), as "key=value" in the key's unit.
  w.key("set").begin_array(io_detail::JsonLayout::Inline);
  for (const auto& [key, p] : m.spec.params)
    if (p.assigned) w.string(fmt::format("{}={:g}", key, p.value));
  w.end_array();
  w.key("temperature_C").number(s.temperature_C);
  w.key("waveform");
  write_waveform(w, s.waveform);
  if (s.waveform.periodic()) {
    w.key("periods").number(s.periods);
  } else {
    w.key("duration_s").number(s.duration_s);
  }
  w.key("dt_s").number(r.dt_s);
  w.key("record_every").integer(s.record_every);
  w.key("steps").integer(r.steps);
  w.key("wall_time_s").number(r.wall_time_s);
  w.key("frozen").begin_array(io_detail::JsonLayout::Inline);
  for (const auto& name : frozen_names(s.freeze)) w.string(name);
  w.end_array();
  if (r.has_metrics) {
    w.key("metrics").begin_object();
    for (const MetricRow& row : kMetricRows) w.key(row.name).number(r.metrics.*row.member);
    if (r.step.valid) {
      w.numbers({{"step_y_initial_um", r.step.y_initial_um},
                 {"step_y_final_um", r.step.y_final_um},
                 {"step_rise_time_s", r.step.rise_time_s},
                 {"step_overshoot_pct", r.step.overshoot_pct},
                 {"step_settling_time_s", r.step.settling_time_s}});
    }
    w.end_object();
  }
  if (!r.quantities.empty()) {
    w.key("quantities").begin_object();
    for (const auto& q : r.quantities) {
      w.key(q.name).begin_object();
      w.numbers({{"rms", q.rms}, {"peak", q.peak}, {"pp", q.pp}, {"mean", q.mean}});
      w.end_object();
    }
    w.end_object();
  }
  // The thermal offset of the output (eq. 21, vs T_ref) at the end and start of the run, its
  // change over the run, and the offset drift against the stroke (gmasim simulate warns when
  // the drift exceeds the stroke).
  w.key("thermal_expansion_um").number(r.thermal_expansion_um);
  w.key("thermal_expansion_start_um").number(r.thermal_expansion_start_um);
  w.key("thermal_drift_over_run_um").number(r.thermal_expansion_um - r.thermal_expansion_start_um);
  if (r.has_metrics)
    w.key("drift_to_stroke")
        .number(r.metrics.stroke_um > 0.0 ? std::fabs(r.thermal_expansion_um) / r.metrics.stroke_um
                                          : 0.0);
  if (r.has_energy) write_energy(w, m, r);
  if (r.heating.rows() > 0) write_self_heating(w, r);
  if (!timeseries_csv_text.empty()) {
    // Pairs this file with the timeseries.csv written with it (write_files_atomic).
    w.key("timeseries_csv").begin_object();
    w.key("bytes").integer(static_cast<long long>(timeseries_csv_text.size()));
    w.key("fnv1a64").string(fnv1a64_hex(timeseries_csv_text));
    w.end_object();
  }
  w.end_object();
  return w.text();
}

std::vector<std::string> write_report_files(const std::string& dir, const std::string& stem,
                                            const Report& r) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::string>> files;  // one set: renamed together
  for (std::size_t i = 0; i < r.tables.size(); ++i) {
    const std::string name = i == 0 ? stem + ".csv" : stem + "_" + r.tables[i].name + ".csv";
    files.emplace_back((fs::path(dir) / name).string(), table_csv(r.tables[i]));
  }
  files.emplace_back((fs::path(dir) / (stem + ".json")).string(), report_json(r));
  write_files_atomic(files);
  std::vector<std::string> paths;
  for (const auto& f : files) paths.push_back(f.first);
  return paths;
}

}  // namespace gmasim
