// The width of a hysteresis loop at fractions of its response span (gmasim/identify/identify.hpp:
// loop_widths; identify's report, docs/identify.md "Loop width").
#include <cmath>
#include <limits>

#include "gmasim/identify/identify.hpp"

namespace gmasim {

std::array<double, 4> loop_widths(std::span<const double> x, std::span<const double> y, double lo,
                                  double hi) {
  std::array<double, 4> out;
  out.fill(std::numeric_limits<double>::quiet_NaN());
  const std::size_t n = std::min(x.size(), y.size());
  if (n < 3 || !(hi > lo)) return out;
  double xmax = 0.0, xmin = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    xmax = std::max(xmax, x[i]);
    xmin = std::min(xmin, x[i]);
  }
  const double side = xmax >= -xmin ? 1.0 : -1.0;  // the half with the largest magnitude
  for (std::size_t k = 0; k < kLoopWidthFractions.size(); ++k) {
    const double L = lo + kLoopWidthFractions[k] * (hi - lo);
    double up = 0.0, down = 0.0;
    int n_up = 0, n_down = 0;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const double a = y[i] - L, b = y[i + 1] - L;
      if (!(a * b <= 0.0) || a == b || x[i] == x[i + 1]) continue;
      const double xc = x[i] + (x[i + 1] - x[i]) * (a / (a - b));
      if (side * xc < 0.0) continue;
      if (x[i + 1] > x[i]) {
        up += xc;
        ++n_up;
      } else {
        down += xc;
        ++n_down;
      }
    }
    if (n_up > 0 && n_down > 0) out[k] = std::fabs(down / n_down - up / n_up);
  }
  return out;
}

}  // namespace gmasim
