// Helpers of the model-file tests: a frozen copy of the MDMA model file to edit, and the
// file:line of expected problems.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "gmasim/io/io.hpp"
#include "test_util.hpp"

namespace gmasim_test {

// The loader tests edit a frozen copy of the MDMA model file (tests/data/model_fixture.toml),
// so that recalibrating models/mdma.toml does not move their expected lines and values.
inline std::string builtin_text() {
  std::ifstream in(std::string(GMASIM_SOURCE_DIR) + "/tests/data/model_fixture.toml");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_FALSE(ss.str().empty()) << "tests/data/model_fixture.toml is missing";
  return ss.str();
}
inline gmasim::ModelSpec fixture_spec() {
  return gmasim::parse_model_spec(builtin_text(),
                                  std::string(gmasim::kBuiltinModelName) + " (built-in)");
}

// Replaces the single occurrence of `from` (the test fails if it is not unique).
inline std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "not found: " << from;
  if (pos == std::string::npos) return text;
  EXPECT_EQ(text.find(from, pos + 1), std::string::npos) << "not unique: " << from;
  return text.replace(pos, from.size(), to);
}

// 1-based line of the first occurrence of `needle` in `text`.
inline long line_of(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  EXPECT_NE(pos, std::string::npos) << "not found: " << needle;
  if (pos == std::string::npos) return -1;
  return 1 +
         static_cast<long>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

inline std::string parse_error(const std::string& text, const std::string& name = "bad.toml") {
  return input_error([&] { (void)gmasim::parse_model_spec(text, name); });
}

inline std::string at(const std::string& file, long line) {
  return file + ":" + std::to_string(line) + ": ";
}

}  // namespace gmasim_test
