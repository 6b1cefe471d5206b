#include "io/json.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace gmasim::io_detail {

std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20 || c == 0x7f) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        } else {
          out += ch;  // UTF-8 passes through unchanged
        }
    }
  }
  out += '"';
  return out;
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return fmt::format("{}", v);
}

void JsonWriter::put_indent(std::size_t level) { out_.append(2 * level, ' '); }

// The separator before the next member of the innermost container.
void JsonWriter::separate() {
  Level& l = stack_.back();
  if (l.inline_) {
    if (!l.empty) out_ += ", ";
  } else {
    out_ += l.empty ? "\n" : ",\n";
    put_indent(stack_.size());
  }
  l.empty = false;
}

void JsonWriter::before_value() {
  if (done_) throw std::logic_error("JsonWriter: a value after the document's end");
  if (stack_.empty()) return;  // the root
  if (stack_.back().object) {
    if (!have_key_) throw std::logic_error("JsonWriter: an object member without key()");
    have_key_ = false;  // key() wrote the separator
  } else {
    separate();
  }
}

JsonWriter& JsonWriter::key(std::string_view k) {
  if (stack_.empty() || !stack_.back().object || have_key_)
    throw std::logic_error("JsonWriter: key() outside an object or twice");
  separate();
  out_ += json_string(k);
  out_ += ": ";
  have_key_ = true;
  return *this;
}

JsonWriter& JsonWriter::open(char c, bool object, JsonLayout layout) {
  before_value();
  const bool in_inline = !stack_.empty() && stack_.back().inline_;
  stack_.push_back({object, in_inline || layout == JsonLayout::Inline});
  out_ += c;
  return *this;
}

JsonWriter& JsonWriter::close(char c, bool object) {
  if (stack_.empty() || stack_.back().object != object || have_key_)
    throw std::logic_error("JsonWriter: unbalanced end");
  const Level l = stack_.back();
  stack_.pop_back();
  if (!l.inline_ && !l.empty) {
    out_ += '\n';
    put_indent(stack_.size());
  }
  out_ += c;
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::number(double v) {
  before_value();
  out_ += json_number(v);
  return *this;
}
JsonWriter& JsonWriter::integer(long long v) {
  before_value();
  out_ += fmt::format("{}", v);
  return *this;
}
JsonWriter& JsonWriter::boolean(bool v) {
  before_value();
  out_ += v ? "true" : "false";
  return *this;
}
JsonWriter& JsonWriter::string(std::string_view s) {
  before_value();
  out_ += json_string(s);
  return *this;
}
JsonWriter& JsonWriter::null() {
  before_value();
  out_ += "null";
  return *this;
}

JsonWriter& JsonWriter::numbers(
    std::initializer_list<std::pair<std::string_view, double>> members) {
  for (const auto& [k, v] : members) key(k).number(v);
  return *this;
}

std::string JsonWriter::text() const {
  if (!done_) throw std::logic_error("JsonWriter: text() of an unfinished document");
  return out_ + "\n";
}

}  // namespace gmasim::io_detail
