// The checkpoint file: a versioned text format with every island's population (decision
// vectors and fitness, 17 significant digits: exact round trip), the seeds, the champion
// and the convergence history. Written atomically (write_file_atomic) by rank 0.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"
#include "identify/checkpoint_text.hpp"
#include "internal.hpp"

namespace gmasim::identify_detail {
namespace {

constexpr const char* kMagic = "gmasim-identify-checkpoint";

void hash_values(std::string& s, const std::vector<double>& v) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (double d : v) {
    unsigned char b[sizeof(double)];
    std::memcpy(b, &d, sizeof d);
    for (unsigned char c : b) {
      h ^= c;
      h *= 0x100000001b3ULL;
    }
  }
  s += fmt::format("{:016x};", h);
}

// The magic line, the fingerprints, the layout and the search state up to best_u.
void read_header(LineReader& in, Checkpoint& c) {
  const std::string head = in.next();
  if (head.rfind(kMagic, 0) != 0) in.fail("not a gmasim identify checkpoint");
  const double version = in.nums(head.substr(std::strlen(kMagic)), 1)[0];
  if (version != 1.0) in.fail(fmt::format("version {:g} is not supported (expected 1)", version));
  c.version = 1;
  c.fp.parameters = in.expect("fp_parameters");
  c.fp.data = in.expect("fp_data");
  c.fp.settings = in.expect("fp_settings");
  c.fp.layout = in.expect("fp_layout");
  c.algorithm = in.expect("algorithm");
  // Limits: far above any run (the CLI's own limits), far below a forged count.
  c.ranks = static_cast<int>(in.integer("ranks", 1, 4096));
  c.islands = static_cast<int>(in.integer("islands", 1, 4096));
  c.population = static_cast<int>(in.integer("population", 1, 1e6));
  c.dim = static_cast<int>(in.integer("dim", 1, 10000));
  c.seed = static_cast<unsigned>(in.integer("seed", 0, 4294967295.0));
  c.generation = static_cast<int>(in.integer("generation", 0, 1e9));
  c.evaluations = in.integer("evaluations", 0, 1e15);
  c.wall_s = in.finite("wall_s", 0.0);
  c.best_f = in.finite("best_f", 0.0);  // a weighted RMS [%]: finite, >= 0
  c.best_u = in.nums(in.expect("best_u"), static_cast<std::size_t>(c.dim));
  in.unit_vector(c.best_u, "best_u");
}

// "phase step evaluations best_rms_pct wall_s evals_per_s"
HistoryEntry read_history_entry(LineReader& in) {
  const std::string l = in.next();
  const auto sp = l.find(' ');
  if (sp == std::string::npos) in.fail("bad history line");
  const auto v = in.nums(l.substr(sp + 1), 5);
  for (double x : v)
    if (!(std::isfinite(x) && x >= 0.0))
      in.fail(fmt::format("history: {:g} is not a finite value >= 0", x));
  // The step and the evaluation count become integers: in range first (found by
  // fuzz_checkpoint: 1.1e88 converted to int).
  if (!(v[0] <= 1e9 && v[1] <= 1e15 && v[0] == std::floor(v[0]) && v[1] == std::floor(v[1])))
    in.fail(fmt::format("history: step {:g} / evaluations {:g}: not a count in range", v[0], v[1]));
  const std::string phase = l.substr(0, sp);
  if (phase != "ga" && phase != "refine")
    in.fail(fmt::format("history: unknown phase '{}'", phase));
  return {phase, static_cast<int>(v[0]), static_cast<long>(v[1]), v[2], v[3], v[4]};
}

// Island i: "island i seed S size P", then P lines "fitness x_1 .. x_dim".
IslandPopulation read_island(LineReader& in, int i, int population, int dim) {
  const std::string il = in.next();
  long v[3] = {0, 0, 0};
  if (std::sscanf(il.c_str(), "island %ld seed %ld size %ld", &v[0], &v[1], &v[2]) != 3)
    in.fail(fmt::format("expected 'island N seed S size P', got '{}'", il));
  if (static_cast<int>(v[0]) != i) in.fail(fmt::format("expected island {}", i));
  // Every island holds the whole population: an empty or short island cannot be
  // restored (pagmo's algorithms need the population they were configured for).
  if (v[2] != population)
    in.fail(fmt::format("island {} has {} individuals; the population is {}", i, v[2], population));
  if (v[1] < 0 || v[1] > 4294967295L)
    in.fail(fmt::format("island {}: seed {} out of range", i, v[1]));
  IslandPopulation ip;
  ip.seed = static_cast<unsigned>(v[1]);
  const auto size = static_cast<std::size_t>(v[2]);
  for (std::size_t k = 0; k < size; ++k) {
    const auto row = in.nums(in.next(), static_cast<std::size_t>(dim) + 1);
    if (!(std::isfinite(row[0]) && row[0] >= 0.0))
      in.fail(fmt::format("island {} individual {}: fitness {:g} is not a finite value >= 0", i, k,
                          row[0]));
    ip.f.push_back(row[0]);
    ip.x.emplace_back(row.begin() + 1, row.end());
    in.unit_vector(ip.x.back(), "individual");
  }
  return ip;
}

}  // namespace

Fingerprints fingerprints(const Objective& obj, const IdentifyOptions& o, int ranks) {
  Fingerprints fp;
  std::string p;
  const auto& fit = obj.fit();
  for (std::size_t j = 0; j < obj.dim(); ++j) {
    const auto& fpar = fit.parameters[j];
    p += fmt::format("{}|{:.17g}|{:.17g}|{};", obj.names()[j], fpar.lower, fpar.upper,
                     fpar.scale == ParamScale::Log ? "log" : "linear");
  }
  fp.parameters = fnv_hex(p);
  std::string d;
  for (const auto& m : obj.data().items) {
    const auto& c = m.condition;
    d += fmt::format("{}|{}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{};",
                     std::filesystem::path(m.path).filename().string(), m.t_s.size(), m.weight,
                     c.temperature_C, c.frequency_Hz, c.current_pp_A, c.current_min_A,
                     c.compare_from_s, c.current_source);
    // The keys of issue 9 item 7 only when they are not the defaults, so that checkpoints
    // of current/displacement records written before them still resume.
    if (m.drive_kind != DriveInput::Current || m.response_kind != ResponseOutput::Displacement ||
        c.quasi_static || !c.rod.empty() || c.precycles != 0 || c.offset != OffsetMode::Absolute ||
        c.flux_offset != OffsetMode::Absolute)
      d += fmt::format("{}|{}|{}|{}|{}|{}|{};", m.drive_column(), m.response_column(),
                       c.quasi_static, c.rod, c.precycles, offset_mode_name(c.offset),
                       offset_mode_name(c.flux_offset));
    hash_values(d, m.t_s);
    hash_values(d, m.drive);
    hash_values(d, m.response);
    hash_values(d, m.flux_T);
  }
  fp.data = fnv_hex(d);
  const auto& s = obj.settings();
  std::string st = fmt::format("{:.17g}|{:.17g}|{:.17g}|{:.17g};", s.dt_s, s.steps_per_period,
                               s.flux_weight, s.target_periods);
  if (s.quasi_static_increments != ObjectiveSettings{}.quasi_static_increments)
    st += fmt::format("qs{:.17g};", s.quasi_static_increments);
  for (const auto& t : fit.targets) {
    st += fmt::format("{}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{:.17g}|{:.17g};",
                      target_kind_name(t.kind), t.temperature_C, t.reference_temperature_C,
                      t.current_pp_A, t.current_min_A, t.frequency_Hz, t.bias_A, t.value, t.weight,
                      t.scale);
  }
  fp.settings = fnv_hex(st);
  fp.layout = fmt::format("{}-r{}-i{}-p{}-k{}-m{}-x{}-s{}", o.algorithm, ranks, o.islands,
                          o.population, o.migrate_every, o.migrants,
                          o.mpi_every > 0 ? o.mpi_every : o.migrate_every, o.seed);
  return fp;
}

std::string islands_text(const std::vector<IslandPopulation>& islands) {
  std::string s;
  for (std::size_t i = 0; i < islands.size(); ++i) {
    const auto& isl = islands[i];
    s += fmt::format("island {} seed {} size {}\n", i, isl.seed, isl.x.size());
    for (std::size_t k = 0; k < isl.x.size(); ++k)
      s += fmt::format("{:.17g} {}\n", isl.f[k], numbers(isl.x[k]));
  }
  return s;
}

std::string checkpoint_text(const Checkpoint& c, const std::vector<std::string>& rank_blocks) {
  std::string s = fmt::format("{} {}\n", kMagic, c.version);
  s += fmt::format("fp_parameters {}\nfp_data {}\nfp_settings {}\nfp_layout {}\n", c.fp.parameters,
                   c.fp.data, c.fp.settings, c.fp.layout);
  s += fmt::format("algorithm {}\nranks {}\nislands {}\npopulation {}\ndim {}\nseed {}\n",
                   c.algorithm, c.ranks, c.islands, c.population, c.dim, c.seed);
  s += fmt::format("generation {}\nevaluations {}\nwall_s {:.17g}\n", c.generation, c.evaluations,
                   c.wall_s);
  s += fmt::format("best_f {:.17g}\nbest_u {}\n", c.best_f, numbers(c.best_u));
  s += fmt::format("history {}\n", c.history.size());
  for (const auto& h : c.history) {
    s += fmt::format("{} {} {} {:.17g} {:.17g} {:.17g}\n", h.phase, h.step, h.evaluations,
                     h.best_rms_pct, h.wall_s, h.evals_per_s);
  }
  for (std::size_t r = 0; r < rank_blocks.size(); ++r) {
    s += fmt::format("rank {}\n", r);
    s += rank_blocks[r];
  }
  s += "end\n";
  return s;
}

Checkpoint read_checkpoint(const std::string& path) {
  // A read error is not reported as such: the text read so far is parsed, and a short one
  // fails as a damaged checkpoint.
  const std::string text =
      io_detail::read_text_file(path, "checkpoint", io_detail::OnReadError::KeepPartial);
  LineReader in{path, {}, 0};
  std::istringstream ss(text);
  for (std::string l; std::getline(ss, l);) in.lines.push_back(l);

  Checkpoint c;
  read_header(in, c);
  const long nh = in.integer("history", 0, 1e7);
  for (long k = 0; k < nh; ++k) c.history.push_back(read_history_entry(in));
  for (int r = 0; r < c.ranks; ++r) {
    if (in.integer("rank", 0, 4096) != r) in.fail(fmt::format("expected rank {}", r));
    std::vector<IslandPopulation> isl;
    for (int i = 0; i < c.islands; ++i) isl.push_back(read_island(in, i, c.population, c.dim));
    c.rank_islands.push_back(std::move(isl));
  }
  if (in.next() != "end") in.fail("missing 'end' line");
  // Text after 'end' is not ours: a second checkpoint appended (cat a b > c) or a file
  // overwritten in place. Resuming from the first copy would hide it.
  while (in.pos < in.lines.size()) {
    const std::string& l = in.lines[in.pos++];
    if (l.find_first_not_of(" \t\r") != std::string::npos)
      in.fail(
          fmt::format("text after the 'end' line ('{}'): a second checkpoint appended, or "
                      "another file's text; resume from a checkpoint gmasim wrote whole",
                      clip_for_message(l)));
  }
  return c;
}

void check_compatible(const Checkpoint& c, const Fingerprints& fp, const std::string& path) {
  auto fail = [&](const std::string& what) {
    throw InputError(located(path, 0,
                             fmt::format("cannot resume: the checkpoint was written for {}; resume "
                                         "with the same data, fit spec, model and flags",
                                         what)));
  };
  if (c.fp.parameters != fp.parameters) fail("other fitted parameters or bounds");
  if (c.fp.data != fp.data) fail("other measurement data");
  if (c.fp.settings != fp.settings) fail("other objective settings or targets");
  if (c.fp.layout != fp.layout) {
    fail(
        fmt::format("another algorithm layout ({} ; now {}: algorithm, ranks, islands, "
                    "population, migration, seed)",
                    c.fp.layout, fp.layout));
  }
}

}  // namespace gmasim::identify_detail
