// Internal: reading text input files (model files, waveform and measurement CSVs, manifests,
// checkpoints): the whole file, CSV cells, numeric cells. Not part of the public API.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace gmasim::io_detail {

// What a failed read does in read_text_file.
enum class OnReadError {
  Throw,       // InputError "<path>: cannot read <what> (<strerror>)"
  KeepPartial  // return the text read so far (the checkpoint reader's behaviour)
};

// The whole file at `path`. Throws InputError "<path>: cannot open <what> (<strerror>)" if
// it cannot be opened.
std::string read_text_file(const std::string& path, std::string_view what,
                           OnReadError on_read_error = OnReadError::Throw);

// The lines of `text` without their '\n' (and, with StripCR::Yes, without a '\r' before it):
// "a\nb\n" and "a\nb" are {"a", "b"}, "" is {}. Views into `text`; line i + 1 of a file
// is element i. The one line splitter of model files, fitted models and claim notes.
enum class StripCR { No, Yes };
std::vector<std::string_view> split_lines(std::string_view text, StripCR strip_cr = StripCR::No);

// `s` without leading and trailing spaces, tabs and carriage returns.
std::string_view trim(std::string_view s);

// The comma-separated cells of one CSV line, each trimmed (no quoting).
std::vector<std::string_view> split_cells(std::string_view line);

// Why a cell is not a finite number.
enum class CellError { None, Empty, NonNumeric, OutOfRange, NaN, Inf };

// Parses the whole of `cell` into `v` (from_chars; a leading '+' is accepted as strtod
// would). Anything but CellError::None leaves `v` unspecified.
CellError parse_finite(std::string_view cell, double& v);

// Guards toml++ 3.3 (Debian 12) against inputs it mishandles (issue 8): a table header whose
// first key character is not a key character (`[[[1]]]`, `[&`, `[[=`, `[Π]`: assertion
// failures and undefined behaviour upstream, marzer/tomlplusplus#294, #301), a line at the
// top level that starts with a character no key starts with, and NUL bytes. Scans strings,
// comments and multi-line arrays as TOML does; throws InputError "<source>:<line>: ...".
// Call before toml::parse on any user text.
void guard_toml_text(std::string_view text, const std::string& source);

}  // namespace gmasim::io_detail
