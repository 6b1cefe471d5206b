// Synthetic measurements (gmasim identify synthesize): biased-sine records simulated by a
// known model with the objective's own rules, with Gaussian noise (docs/identify.md).
#include <fmt/format.h>

#include <cmath>
#include <cstdint>

#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/identify/synthetic_fields.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "identify/record_run.hpp"

namespace gmasim {
namespace {

void check_request(const SyntheticRequest& r) {
  validate(r.objective);  // the rules identify applies to the same settings
  if (r.samples_per_period < 8)
    throw InputError(fmt::format("samples per period {} (--samples-per-period): must be >= 8",
                                 r.samples_per_period));
  // One range, stated whole: from the demagnetised state the first period is not compared
  const bool first_skipped = r.precycles == 0 && r.initial_state == InitialState::Demagnetised;
  const double lowest = first_skipped ? 1.5 : 1.0;
  if (!(r.periods >= lowest && r.periods <= kMaxPeriods))
    throw InputError(fmt::format(
        "periods (--periods) = {:g}: must be in [{:g}, {:g}] ({})", r.periods, lowest, kMaxPeriods,
        first_skipped ? "a whole loop after the first period, which a "
                        "record from the demagnetised state does not compare"
                      : "one whole loop"));
  require_in(r.current_min_A, -kMaxCurrent_A, kMaxCurrent_A, "current minimum", "A");
  require_in(r.noise_pct, 0.0, 100.0, "noise", "%");
  require_in(r.flux_noise_pct, 0.0, 100.0, "flux noise", "%");
  require_in(r.response_offset, -1e6, 1e6, "response offset");
  if (r.precycles < 0 || r.precycles > kMaxPrecycles)
    throw InputError(fmt::format("precycles {}: must be in [0, {}]", r.precycles, kMaxPrecycles));
  for (double T : r.temperatures_C) require_finite(T, "temperature", "degC");
  for (double pp : r.currents_pp_A)  // identify refuses a record of 0 A p-p: so must this
    if (!(pp > 0.0 && pp <= 2.0 * kMaxCurrent_A))
      throw InputError(fmt::format(
          "current peak-to-peak {:g} A (--currents): must be in (0, {:g}] A (identify refuses "
          "a record without current)",
          pp, 2.0 * kMaxCurrent_A));
  for (double f : r.frequencies_Hz) {
    require_positive(f, "frequency", "Hz");
    require_in(f, 0.0, kMaxFrequency_Hz, "frequency", "Hz");
  }
  (void)checked_count(r.periods * r.samples_per_period, kMaxRecordedRows, "samples per record");
  (void)checked_count(static_cast<double>(r.temperatures_C.size()) *
                          static_cast<double>(r.currents_pp_A.size()) *
                          static_cast<double>(r.frequencies_Hz.size()),
                      kMaxListValues, "synthetic records");
  fields::check_request_fields(r);  // every row's rule (gmasim/identify/synthetic_fields.hpp)
}

// Gaussian noise from splitmix64 and Box-Muller: the same numbers on every platform.
class Noise {
 public:
  explicit Noise(std::uint64_t seed) : state_(0x9E3779B97F4A7C15ULL ^ seed) {}
  double gauss() {
    const double u1 = next_u01(), u2 = next_u01();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * physics::kPi * u2);
  }

 private:
  double next_u01() {
    state_ += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return (static_cast<double>(z >> 11) + 0.5) * 0x1.0p-53;
  }
  std::uint64_t state_;
};

// The record's conditions, times and drive (the biased sine at the sample times); a
// quasi-static record numbers its samples instead of timing them.
Measurement record_skeleton(const SyntheticRequest& r, double T, double pp, double f) {
  Measurement m;
  auto& c = m.condition;
  c.temperature_C = T;
  c.quasi_static = r.quasi_static;
  c.rod = r.rod;
  c.precycles = r.precycles;
  c.initial_state = r.initial_state;
  c.offset = r.offset;
  // A record that starts on its loop (pre-cycled, or from a given remanence) compares every
  // sample; one from the demagnetised state skips its first period.
  const bool on_loop = r.precycles > 0 || r.initial_state != InitialState::Demagnetised;
  m.response_kind = r.response;
  if (r.quasi_static) {
    c.compare_from_s = on_loop ? 0.0 : r.samples_per_period;  // sample index
    c.label = fmt::format("T{:g}_I{:g}_qs", T, pp);
  } else {
    c.frequency_Hz = f;
    c.current_pp_A = pp;
    c.current_min_A = r.current_min_A;
    c.compare_from_s = on_loop ? 0.0 : 1.0 / f;
    c.label = fmt::format("T{:g}_I{:g}_f{:g}", T, pp, f);
  }
  m.path = c.label + ".csv";
  const Waveform w = biased_sine(pp, f, r.current_min_A);
  const long n = std::lround(r.periods * r.samples_per_period);
  for (long k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) / (f * r.samples_per_period);
    m.t_s.push_back(r.quasi_static ? static_cast<double>(k) : t);
    m.drive.push_back(w.current_at(t));
  }
  return m;
}

// Simulates the record with the truth and writes what the instruments read, with noise.
void measure(const Model& truth, const SyntheticRequest& r, Noise& noise, Measurement& m) {
  std::vector<double> y, B, H;
  {
    const Conditions cond = make_conditions(truth, m.condition.temperature_C);
    const State st0 = make_state(truth, cond, identify_detail::record_initial_current(m));
    identify_detail::run_record(truth, cond, st0, m, r.objective, y, r.with_flux ? &B : nullptr,
                                &H);
  }
  if (r.drive == DriveInput::Field) {  // what a Hall probe on the rod reads
    m.drive = H;
    m.drive_kind = DriveInput::Field;
  }
  const double sy = r.noise_pct / 100.0 * peak_to_peak(y);
  m.response = y;
  for (double& v : m.response) v += sy * noise.gauss();
  if (r.offset == OffsetMode::FirstSample) {
    const double first = m.response.front();
    for (double& v : m.response) v -= first;
  } else if (r.offset == OffsetMode::Fitted) {
    for (double& v : m.response) v += r.response_offset;
  }
  if (r.with_flux) {
    const double sb = r.flux_noise_pct / 100.0 * peak_to_peak(B);
    m.flux_T = B;
    for (double& v : m.flux_T) v += sb * noise.gauss();
  }
}

}  // namespace

MeasurementSet synthesize_measurements(const Model& truth, const SyntheticRequest& r) {
  check_request(r);
  MeasurementSet set;
  Noise noise(r.seed);
  // A quasi-static record has no frequency: one record per (temperature, current).
  const std::vector<double> freqs = r.quasi_static ? std::vector<double>{1.0} : r.frequencies_Hz;
  // Every record named before any is simulated: two conditions that print alike (8 and
  // 8.0000001 A, or a value listed twice) wrote one file twice and listed it twice.
  for (double T : r.temperatures_C)
    for (double pp : r.currents_pp_A)
      for (double f : freqs) set.items.push_back(record_skeleton(r, T, pp, f));
  for (std::size_t i = 0; i < set.items.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (set.items[j].path == set.items[i].path)
        throw InputError(fmt::format(
            "identify synthesize: two records are both named {} (conditions are named to 6 "
            "significant digits): give distinct --temperatures, --currents and --frequencies",
            set.items[i].path));
  for (Measurement& m : set.items) measure(truth, r, noise, m);
  return set;
}

}  // namespace gmasim
