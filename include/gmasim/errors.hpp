// Error types. Bad input is an InputError whose message starts with "file:line: ";
// numerical divergence is a DivergenceError naming time, rod and quantity.
#pragma once

#include <stdexcept>
#include <string>

namespace gmasim {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "file:line: message" (line omitted when 0).
std::string located(const std::string& file, long line, const std::string& message);

class DivergenceError : public std::runtime_error {
 public:
  DivergenceError(double time_s, std::string rod, std::string quantity, double value,
                  const std::string& why);
  double time_s;
  std::string rod;
  std::string quantity;
  double value;
};

}  // namespace gmasim
