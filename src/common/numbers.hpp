// Numbers the library's files share (one definition: the CI's unity builds join files).
#pragma once

#include <limits>

namespace gmasim {

// "No value": a quantity a run could not measure, or a cell a table leaves empty.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace gmasim
