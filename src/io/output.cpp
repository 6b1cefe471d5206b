// Output files: atomic writes, the output directory, timeseries.csv and metrics.json.
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"
#include "io/json.hpp"
#include "io/text_io.hpp"

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

// Writes content to a fresh temporary next to path, flushed and synced; returns its name.
std::string write_temporary(const std::string& path, const std::string& content) {
  const std::string tmp = fmt::format("{}.tmp.{}", path, static_cast<long>(::getpid()));
  auto fail = [&](int err, std::FILE* f) {
    if (f) std::fclose(f);
    std::remove(tmp.c_str());
    throw InputError(located(path, 0, fmt::format("cannot write output ({})", std::strerror(err))));
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

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  for (const auto& [path, content] : files) require_regular_destination(path);
  std::vector<std::string> tmps;
  try {
    for (const auto& [path, content] : files) tmps.push_back(write_temporary(path, content));
  } catch (...) {
    for (const auto& t : tmps) std::remove(t.c_str());
    throw;
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (std::rename(tmps[i].c_str(), files[i].first.c_str()) != 0) {
      const int err = errno;
      for (std::size_t j = i; j < tmps.size(); ++j) std::remove(tmps[j].c_str());
      throw InputError(
          located(files[i].first, 0, fmt::format("cannot write output ({})", std::strerror(err))));
    }
  }
  for (const auto& f : files) sync_directory_of(f.first);
}

std::string read_input_file(const std::string& path, const std::string& what) {
  return io_detail::read_text_file(path, what);
}

void ensure_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  const fs::path p = dir.empty() ? fs::path(".") : fs::path(dir);
  auto fail = [&](const std::string& reason) {
    throw InputError(located(dir, 0, fmt::format("output directory is not writable ({})", reason)));
  };
  std::error_code ec;
  fs::create_directories(p, ec);
  if (ec) fail(ec.message());
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

std::string json_string(std::string_view s) {
  return io_detail::json_string(s, io_detail::BackspaceFormFeed::Short);
}

using io_detail::json_number;

// Accumulates `"key": value` members of one object at one indentation.
class JsonObject {
 public:
  explicit JsonObject(int indent) : indent_(indent) {}
  void raw(std::string_view key, const std::string& value) {
    members_.push_back(fmt::format("{:{}}{}: {}", "", indent_ + 2, json_string(key), value));
  }
  void number(std::string_view key, double v) { raw(key, json_number(v)); }
  void integer(std::string_view key, long v) { raw(key, fmt::format("{}", v)); }
  void string(std::string_view key, std::string_view v) { raw(key, json_string(v)); }
  std::string str() const {
    if (members_.empty()) return "{}";
    std::string out = "{\n";
    for (std::size_t i = 0; i < members_.size(); ++i) {
      out += members_[i];
      out += i + 1 < members_.size() ? ",\n" : "\n";
    }
    out += fmt::format("{:{}}}}", "", indent_);
    return out;
  }

 private:
  int indent_;
  std::vector<std::string> members_;
};

std::string waveform_json(const Waveform& w, int indent) {
  JsonObject o(indent);
  switch (w.kind) {
    case WaveformKind::BiasedSine:
      o.string("kind", "biased_sine");
      o.number("pp_A", w.pp_A);
      o.number("min_A", w.min_A);
      o.number("frequency_Hz", w.frequency_Hz);
      break;
    case WaveformKind::DC:
      o.string("kind", "dc");
      o.number("level_A", w.level_A);
      break;
    case WaveformKind::Step:
      o.string("kind", "step");
      o.number("level_A", w.level_A);
      o.number("step_to_A", w.step_to_A);
      o.number("step_time_s", w.step_time_s);
      break;
    case WaveformKind::Chirp:
      o.string("kind", "chirp");
      o.number("offset_A", w.offset_A);
      o.number("amplitude_A", w.amplitude_A);
      o.number("f0_Hz", w.f0_Hz);
      o.number("f1_Hz", w.f1_Hz);
      o.number("duration_s", w.duration_s);
      break;
    case WaveformKind::Table:
      o.string("kind", "table");
      o.string("source", w.table_source);
      o.integer("points", static_cast<long>(w.table_t_s.size()));
      break;
  }
  return o.str();
}

std::string frozen_json(const Freeze& f) {
  const std::pair<const char*, bool> laws[] = {
      {"pm_mmf", f.pm_mmf},           {"permeability", f.permeability},
      {"resistivity", f.resistivity}, {"magnetisation", f.magnetisation},
      {"modulus", f.modulus},         {"sleeve_modulus", f.sleeve_modulus},
      {"geometry", f.geometry},
  };
  std::string out = "[";
  bool first = true;
  for (const auto& [name, frozen] : laws) {
    if (!frozen) continue;
    if (!first) out += ", ";
    out += json_string(name);
    first = false;
  }
  return out + "]";
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
  JsonObject o(0);
  o.string("status", r.diverged ? "diverged" : "ok");
  o.raw("error", r.error.empty() ? std::string("null") : json_string(r.error));
  o.string("model", m.spec.source);
  if (const auto it = m.spec.options.find("meta.name"); it != m.spec.options.end())
    o.string("model_name", it->second);
  o.number("temperature_C", s.temperature_C);
  o.raw("waveform", waveform_json(s.waveform, 2));
  if (s.waveform.periodic()) {
    o.number("periods", s.periods);
  } else {
    o.number("duration_s", s.duration_s);
  }
  o.number("dt_s", r.dt_s);
  o.integer("record_every", s.record_every);
  o.integer("steps", r.steps);
  o.number("wall_time_s", r.wall_time_s);
  o.raw("frozen", frozen_json(s.freeze));
  if (r.has_metrics) {
    JsonObject mo(2);
    mo.number("stroke_um", r.metrics.stroke_um);
    mo.number("hysteresis_um", r.metrics.hysteresis_um);
    mo.number("B_pp_T", r.metrics.B_pp_T);
    mo.number("y_mean_um", r.metrics.y_mean_um);
    mo.number("window_start_s", r.metrics.window_start_s);
    mo.number("window_end_s", r.metrics.window_end_s);
    if (r.step.valid) {
      mo.number("step_y_initial_um", r.step.y_initial_um);
      mo.number("step_y_final_um", r.step.y_final_um);
      mo.number("step_rise_time_s", r.step.rise_time_s);
      mo.number("step_overshoot_pct", r.step.overshoot_pct);
      mo.number("step_settling_time_s", r.step.settling_time_s);
    }
    o.raw("metrics", mo.str());
  }
  if (!r.quantities.empty()) {
    JsonObject qo(2);
    for (const auto& q : r.quantities) {
      JsonObject one(4);
      one.number("rms", q.rms);
      one.number("peak", q.peak);
      one.number("pp", q.pp);
      one.number("mean", q.mean);
      qo.raw(q.name, one.str());
    }
    o.raw("quantities", qo.str());
  }
  o.number("thermal_expansion_um", r.thermal_expansion_um);
  if (r.heating.rows() > 0) {
    // Self-heating: the end state of the network and its energy balance (self_heating.csv).
    JsonObject ho(2);
    const auto last = r.heating.rows() - 1;
    ho.number("thermal_step_s", r.heating.rows() > 1 ? r.heating.columns[0][1] : 0.0);
    ho.number("coil_C", r.heating.column("coil_C")[last]);
    ho.number("rods_C", r.heating.column("rods_C")[last]);
    ho.number("housing_C", r.heating.column("housing_C")[last]);
    // The first thermal step holds the virgin curve: the drift starts at the second.
    ho.number("stroke_start_um",
              r.heating.column("stroke_um")[std::min<std::size_t>(last, 2)]);
    ho.number("stroke_last_um", r.heating.column("stroke_um")[last]);
    ho.number("energy_in_J", r.energy_in_J);
    ho.number("energy_stored_J", r.energy_stored_J);
    ho.number("energy_out_J", r.energy_out_J);
    o.raw("self_heating", ho.str());
  }
  if (!timeseries_csv_text.empty()) {
    // Pairs this file with the timeseries.csv written with it (write_files_atomic).
    JsonObject to(2);
    to.integer("bytes", static_cast<long>(timeseries_csv_text.size()));
    to.string("fnv1a64", fnv1a64_hex(timeseries_csv_text));
    o.raw("timeseries_csv", to.str());
  }
  return o.str() + "\n";
}

std::vector<std::string> write_report_files(const std::string& dir, const std::string& stem,
                                            const Report& r) {
  namespace fs = std::filesystem;
  std::vector<std::string> paths;
  for (std::size_t i = 0; i < r.tables.size(); ++i) {
    const std::string name = i == 0 ? stem + ".csv" : stem + "_" + r.tables[i].name + ".csv";
    const std::string path = (fs::path(dir) / name).string();
    write_file_atomic(path, table_csv(r.tables[i]));
    paths.push_back(path);
  }
  const std::string json = (fs::path(dir) / (stem + ".json")).string();
  write_file_atomic(json, report_json(r));
  paths.push_back(json);
  return paths;
}

}  // namespace gmasim
