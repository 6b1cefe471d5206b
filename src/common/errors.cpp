// Error message helpers: "file:line: message" and the divergence report.
#include "gmasim/errors.hpp"

#include <fmt/format.h>

#include <utility>

#include "gmasim/model/validate.hpp"

namespace gmasim {

std::string clip_error_message(const std::string& message) {
  return message.size() <= kMaxErrorChars ? message : clip_for_message(message, kMaxErrorChars);
}

std::string located(const std::string& file, long line, const std::string& message) {
  if (line > 0) return fmt::format("{}:{}: {}", file, line, message);
  return fmt::format("{}: {}", file, message);
}

namespace {

std::string divergence_message(double time_s, const std::string& rod, const std::string& quantity,
                               double value, const std::string& why) {
  if (rod.empty()) {
    return fmt::format("diverged at t = {:.9f} s: {} = {:g} ({})", time_s, quantity, value, why);
  }
  return fmt::format("diverged at t = {:.9f} s in {}: {} = {:g} ({})", time_s, rod, quantity, value,
                     why);
}

}  // namespace

DivergenceError::DivergenceError(double time_s_, std::string rod_, std::string quantity_,
                                 double value_, const std::string& why)
    : std::runtime_error(divergence_message(time_s_, rod_, quantity_, value_, why)),
      time_s(time_s_),
      rod(std::move(rod_)),
      quantity(std::move(quantity_)),
      value(value_) {}

std::string choice_list(std::span<const std::string_view> names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? " or " : ", ";
    out += names[i];
  }
  return out;
}

}  // namespace gmasim
