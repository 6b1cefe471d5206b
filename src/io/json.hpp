// Internal: the one JSON writer of the library. metrics.json (io/output.cpp), the experiment
// reports and claims.json (experiments/report.cpp) and fit_report.json (identify/report.cpp)
// are all written through JsonWriter. Not part of the public API.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace gmasim::io_detail {

// `s` as a quoted JSON string: '"' and '\' escaped, backspace, form feed, newline, carriage
// return and tab by their short escapes, the other control characters and DEL as \u00XX;
// UTF-8 passes through unchanged.
std::string json_string(std::string_view s);

// The shortest text that reads back to the same double; null for NaN and Inf (JSON has
// neither).
std::string json_number(double v);

// JSON text, written as it is built. A container is Block (one member a line, indented two
// spaces a nesting level; an empty one is {} or []) or Inline (members on one line separated
// by ", "; anything inside an Inline container is Inline too). Inside an object, each value
// is preceded by key(). Misuse (a value without its key, unbalanced ends) is a logic error:
// std::logic_error.
//
//   JsonWriter w;
//   w.begin_object().key("a").number(1.5).key("xs").begin_array(JsonLayout::Inline);
//   w.number(1).number(2).end_array().end_object();
//   w.text()  // "{\n  \"a\": 1.5,\n  \"xs\": [1, 2]\n}\n"
enum class JsonLayout { Block, Inline };

class JsonWriter {
 public:
  JsonWriter& begin_object(JsonLayout layout = JsonLayout::Block) {
    return open('{', true, layout);
  }
  JsonWriter& end_object() { return close('}', true); }
  JsonWriter& begin_array(JsonLayout layout = JsonLayout::Block) {
    return open('[', false, layout);
  }
  JsonWriter& end_array() { return close(']', false); }
  JsonWriter& key(std::string_view k);

  JsonWriter& number(double v);      // json_number
  JsonWriter& integer(long long v);  // exact, for counts
  JsonWriter& boolean(bool v);
  JsonWriter& string(std::string_view s);
  JsonWriter& null();
  // Object members "key": number, in the order given (a table of results reads as one).
  JsonWriter& numbers(std::initializer_list<std::pair<std::string_view, double>> members);

  // The document, with a final newline. Throws std::logic_error if a container is open.
  std::string text() const;

 private:
  struct Level {
    bool object, inline_, empty = true;
  };
  JsonWriter& open(char c, bool object, JsonLayout layout);
  JsonWriter& close(char c, bool object);
  void separate();
  void before_value();
  void put_indent(std::size_t level);

  std::string out_;
  std::vector<Level> stack_;
  bool have_key_ = false;
  bool done_ = false;
};

}  // namespace gmasim::io_detail
