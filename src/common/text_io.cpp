#include "common/text_io.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim::io_detail {

namespace {
constexpr int kFifoWaitSeconds = 10;  // a FIFO's writer must start within this
}  // namespace

std::string read_text_file(const std::string& path, std::string_view what,
                           OnReadError on_read_error) {
  // Opened without blocking, then read blocking: open(2) of a FIFO that nobody writes waited for
  // ever (mkfifo ff; gmasim model check ff). A FIFO waits for its writer's first bytes (or its
  // close) at most kFifoWaitSeconds, then is refused; a pipe with a writer (--waveform <(...))
  // and a writer that opens a moment later (producer > ff &) are read whole.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  std::FILE* f = nullptr;
  if (fd >= 0) {
    struct stat st {};
    if (::fstat(fd, &st) == 0 && S_ISFIFO(st.st_mode)) {
      pollfd pfd{fd, POLLIN, 0};
      int rc = 0;
      do rc = ::poll(&pfd, 1, kFifoWaitSeconds * 1000);
      while (rc < 0 && errno == EINTR);
      if (rc == 0) {
        ::close(fd);
        throw InputError(located(
            path, 0,
            fmt::format("{} is a FIFO that nobody wrote to within {} s: start its writer first, "
                        "or give a regular file",
                        what, kFifoWaitSeconds)));
      }
    }
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags >= 0) (void)::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    f = ::fdopen(fd, "rb");
    if (!f) {
      const int e = errno;
      ::close(fd);
      errno = e;
    }
  }
  if (!f) {
    throw InputError(
        located(path, 0, fmt::format("cannot open {} ({})", what, std::strerror(errno))));
  }
  std::string text;
  char buf[1 << 14];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    text.append(buf, n);
    if (text.size() > kMaxInputBytes) {  // /dev/zero, a runaway pipe, a wrong file
      std::fclose(f);
      throw InputError(located(path, 0,
                               fmt::format("{} is larger than {} MiB: not a gmasim input (limit "
                                           "kMaxInputBytes, docs/reliability.md)",
                                           what, kMaxInputBytes >> 20)));
    }
  }
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (failed && on_read_error == OnReadError::Throw) {
    throw InputError(
        located(path, 0, fmt::format("cannot read {} ({})", what, std::strerror(err))));
  }
  return text;
}

std::vector<std::string_view> split_lines(std::string_view text, StripCR strip_cr) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    auto end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    auto line = text.substr(start, end - start);
    if (strip_cr == StripCR::Yes && line.ends_with('\r')) line.remove_suffix(1);
    lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> split_cells(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return cells;
}

CellError parse_finite(std::string_view cell, double& v) {
  if (cell.empty()) return CellError::Empty;
  const std::string_view digits = cell.starts_with('+') ? cell.substr(1) : cell;
  // One sign only: "+-1" is not a number (from_chars after the '+' would read -1).
  if (digits.size() != cell.size() && (digits.starts_with('-') || digits.starts_with('+')))
    return CellError::NonNumeric;
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (ec != std::errc() || ptr != digits.data() + digits.size())
    return ec == std::errc::result_out_of_range ? CellError::OutOfRange : CellError::NonNumeric;
  if (std::isnan(v)) return CellError::NaN;
  if (std::isinf(v)) return CellError::Inf;
  return CellError::None;
}

namespace {

bool is_bare_key_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

std::string shown(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x21 && u < 0x7f) return fmt::format("'{}'", c);
  return fmt::format("byte 0x{:02x}", static_cast<unsigned>(u));
}

// The scan of guard_toml_text, one character at a time: the line, whether a string is open
// (and which kind), and the [ and { nesting inside values.
class TomlGuard {
 public:
  TomlGuard(std::string_view text, const std::string& source)
      : text_(text), n_(text.size()), source_(source) {}

  void run() {
    for (i_ = 0; i_ < n_; ++i_) {
      const char c = text_[i_];
      if (c == '\0') fail("NUL byte: not a text file");
      if (c == '\n') {
        new_line();
        continue;
      }
      if (str_ != Str::None) {
        string_char(c);
        continue;
      }
      if (line_start_ && depth_ == 0) {
        if (c == ' ' || c == '\t' || c == '\r') continue;
        line_start_ = false;
        if (c == '[') {
          table_header();
          continue;
        }
        if (!(is_bare_key_char(c) || c == '"' || c == '\'' || c == '#'))
          fail(fmt::format("expected a key, a [table] or a comment; a key cannot start with {}",
                           shown(c)));
      }
      line_start_ = false;
      value_char(c);
    }
  }

 private:
  enum class Str { None, Basic, Literal, MlBasic, MlLiteral };

  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(located(source_, line_, why));
  }

  void new_line() {
    ++line_;
    line_start_ = true;
    if (str_ == Str::Basic || str_ == Str::Literal) str_ = Str::None;  // toml++ reports it
  }

  // Inside a string: an escape (basic strings) or the closing quote(s).
  void string_char(char c) {
    const bool basic = str_ == Str::Basic || str_ == Str::MlBasic;
    if (basic && c == '\\') {
      if (i_ + 1 < n_ && text_[i_ + 1] != '\n') ++i_;  // skip the escaped character
      return;
    }
    if (c != (basic ? '"' : '\'')) return;
    if (str_ == Str::Basic || str_ == Str::Literal) {
      str_ = Str::None;
    } else if (text_.substr(i_, 3) == (basic ? "\"\"\"" : "'''")) {
      str_ = Str::None;
      i_ += 2;
    }
  }

  // A table header at the start of a line: [key] or [[key]].
  void table_header() {
    std::size_t j = i_ + 1;
    if (j < n_ && text_[j] == '[') ++j;
    while (j < n_ && (text_[j] == ' ' || text_[j] == '\t')) ++j;
    if (j >= n_ || !(is_bare_key_char(text_[j]) || text_[j] == '"' || text_[j] == '\''))
      fail(fmt::format(
          "malformed table header: a key cannot start with {}",
          j >= n_ || text_[j] == '\n' ? std::string("the end of the line") : shown(text_[j])));
    // The rest of the header (quoted keys may hold brackets) is toml++'s to check.
    skip_to_line_end();
  }

  void skip_to_line_end() {
    while (i_ + 1 < n_ && text_[i_ + 1] != '\n') ++i_;
  }

  // A string opens at a quote: multi-line after three of them.
  void open_string(std::string_view triple, Str single, Str multi) {
    if (text_.substr(i_, 3) == triple) {
      str_ = multi;
      i_ += 2;
    } else {
      str_ = single;
    }
  }

  // A character outside strings, after a line's first one.
  void value_char(char c) {
    switch (c) {
      case '#':
        skip_to_line_end();
        break;
      case '"':
        open_string("\"\"\"", Str::Basic, Str::MlBasic);
        break;
      case '\'':
        open_string("'''", Str::Literal, Str::MlLiteral);
        break;
      case '[':
      case '{':
        ++depth_;
        break;
      case ']':
      case '}':
        if (depth_ > 0) --depth_;
        break;
      default:
        break;
    }
  }

  const std::string_view text_;
  const std::size_t n_;
  const std::string& source_;
  std::size_t i_ = 0;
  Str str_ = Str::None;
  int depth_ = 0;  // [ and { nesting inside values
  long line_ = 1;
  bool line_start_ = true;
};

}  // namespace

void guard_toml_text(std::string_view text, const std::string& source) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // UTF-8 byte-order mark
  TomlGuard(text, source).run();
}

}  // namespace gmasim::io_detail
