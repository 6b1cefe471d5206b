// Numbers the library's files share (one definition: the CI's unity builds join files).
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

namespace gmasim {

// "No value": a quantity a run could not measure, or a cell a table leaves empty.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The least-squares slope of y against x (same sizes, at least two distinct x; NaN otherwise).
inline double least_squares_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  const double den = n * sxx - sx * sx;
  return x.size() < 2 || x.size() != y.size() || !(den > 0) ? kNaN : (n * sxy - sx * sy) / den;
}

}  // namespace gmasim
