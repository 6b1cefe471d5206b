// Error types. Bad input is an InputError whose message starts with "file:line: ";
// numerical divergence is a DivergenceError naming time, rod and quantity.
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace gmasim {

// The message is clipped to kMaxErrorChars (in the middle, saying how much was left out), so
// an error never echoes a whole hostile input line (issue 8).
inline constexpr std::size_t kMaxErrorChars = 2000;
std::string clip_error_message(const std::string& message);

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message)
      : std::runtime_error(clip_error_message(message)) {}
  explicit InputError(const char* message) : InputError(std::string(message)) {}
};

// "file:line: message" (line omitted when 0).
std::string located(const std::string& file, long line, const std::string& message);

// The choices of a "must be ..." message: "a, b or c" ("a" for one, "" for none).
std::string choice_list(std::span<const std::string_view> names);

class DivergenceError : public std::runtime_error {
 public:
  DivergenceError(double time_s, std::string rod, std::string quantity, double value,
                  const std::string& why);
  // A run that diverged, reported by a caller (its own diagnosis already in `message`).
  explicit DivergenceError(const std::string& message)
      : std::runtime_error(message),
        time_s(std::numeric_limits<double>::quiet_NaN()),
        value(std::numeric_limits<double>::quiet_NaN()) {}
  double time_s;
  std::string rod;
  std::string quantity;
  double value;
};

}  // namespace gmasim
