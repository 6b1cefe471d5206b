// Internal: the one way gmasim parses TOML (model files, fit specs, manifests, claims).
#pragma once

#include <toml++/toml.h>

#include <string>
#include <string_view>

namespace gmasim::io_detail {

// guard_toml_text (text_io.hpp), then toml::parse; a syntax error becomes the InputError
// "<source>:<line>:<column>: TOML syntax error: <description>".
toml::table parse_toml(std::string_view text, const std::string& source);

}  // namespace gmasim::io_detail
