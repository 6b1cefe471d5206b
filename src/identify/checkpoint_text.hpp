// Internal: the text of the search checkpoints (identify's, design's): a hash for their
// fingerprints, numbers at 17 significant digits (an exact round trip) and a line reader whose
// every failure names the file and the line as a damaged checkpoint.
#pragma once

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim::identify_detail {

inline std::string fnv_hex(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return fmt::format("{:016x}", h);
}

inline std::string numbers(const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) s += ' ';
    s += fmt::format("{:.17g}", v[i]);
  }
  return s;
}

struct LineReader {
  std::string path;
  std::vector<std::string> lines;
  std::size_t pos = 0;

  [[noreturn]] void fail(const std::string& msg) const {
    throw InputError(
        located(path, static_cast<long>(pos), fmt::format("damaged checkpoint: {}", msg)));
  }
  std::string next() {
    if (pos >= lines.size()) fail("unexpected end of file");
    return lines[pos++];
  }
  // "key rest"
  std::string expect(const std::string& key) {
    const std::string l = next();
    if (l.rfind(key + " ", 0) != 0 && l != key)
      fail(fmt::format("expected '{}', got '{}'", key, l));
    return l.size() > key.size() ? l.substr(key.size() + 1) : std::string();
  }
  std::vector<double> nums(const std::string& s, std::size_t expected) {
    std::vector<double> v;
    const char* p = s.data();
    const char* e = s.data() + s.size();
    while (p < e) {
      while (p < e && *p == ' ') ++p;
      if (p >= e) break;
      double d = 0;
      const auto r = std::from_chars(p, e, d);
      if (r.ec != std::errc()) fail(fmt::format("not a number in '{}'", s));
      v.push_back(d);
      p = r.ptr;
    }
    if (expected != static_cast<std::size_t>(-1) && v.size() != expected)
      fail(fmt::format("expected {} numbers, got {}", expected, v.size()));
    return v;
  }
  // An integer field in [lo, hi] (a forged or damaged value never becomes a count).
  long integer(const std::string& key, double lo, double hi) {
    const auto v = nums(expect(key), 1);
    if (!(v[0] >= lo && v[0] <= hi && v[0] == std::floor(v[0])))
      fail(fmt::format("{} {:g}: must be an integer in [{:g}, {:g}]", key, v[0], lo, hi));
    return static_cast<long>(v[0]);
  }
  double finite(const std::string& key, double lo) {
    const double v = nums(expect(key), 1)[0];
    if (!(std::isfinite(v) && v >= lo))
      fail(fmt::format("{} {:g}: must be finite and >= {:g}", key, v, lo));
    return v;
  }
  // A point of the unit cube of the search space, as the GA writes it.
  void unit_vector(const std::vector<double>& u, const char* what) {
    for (double x : u)
      if (!(x >= 0.0 && x <= 1.0))
        fail(fmt::format("{}: coordinate {:g} is outside [0, 1]", what, x));
  }
};

}  // namespace gmasim::identify_detail
