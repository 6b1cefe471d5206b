#include "common/toml_io.hpp"

#include <fmt/format.h>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"

namespace gmasim::io_detail {

toml::table parse_toml(std::string_view text, const std::string& source) {
  guard_toml_text(text, source);
  try {
    return toml::parse(text, std::string_view(source));
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", source, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
}

}  // namespace gmasim::io_detail
