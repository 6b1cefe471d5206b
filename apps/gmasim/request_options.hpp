// The CLI options of a request, generated from its table (gmasim/request_table.hpp): one option
// per row marked Cli, with the row's flag and help, the default shown from the struct's own
// initialiser. A list row (std::vector<double>) takes a list or range ("20,30" or "20:10:70",
// parse_list) and replaces the default only when given.
#pragma once

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <deque>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "experiment_cli.hpp"
#include "gmasim/request_table.hpp"

namespace gmasim::cli {

template <class R>
class RequestOptions {
 public:
  // Adds every Cli row of R's table to `sub`, bound to `req` (which must outlive the parse).
  void add(CLI::App* sub, R& req) {
    fields::for_each_field<R>([&](const auto& row) {
      if (!row.in_cli()) return;
      using T = typename std::remove_cvref_t<decltype(row)>::Value;
      const std::string flag(row.cli), help(row.help);
      CLI::Option* o = nullptr;
      if constexpr (std::is_same_v<T, std::vector<double>>) {
        auto& text = lists_.emplace_back(
            ListOption{fmt::format("{:g}", fmt::join(row.default_value(), ",")), nullptr,
                       [&req, row](const std::string& s) {
                         row.ref(req) = parse_list(s, std::string(row.cli), std::string(row.unit));
                       }});
        o = sub->add_option(flag, text.text, help);
        text.option = o;
      } else {
        o = sub->add_option(flag, row.ref(req), help);
      }
      o->capture_default_str();
      options_.emplace_back(row.cli, o);
    });
  }
  // The list options given on the command line, parsed into the request.
  void apply() const {
    for (const auto& l : lists_)
      if (l.option->count() > 0) l.parse(l.text);
  }
  CLI::Option* option(std::string_view cli) const {
    for (const auto& [name, o] : options_)
      if (name == cli) return o;
    return nullptr;
  }

 private:
  struct ListOption {
    std::string text;
    CLI::Option* option = nullptr;
    std::function<void(const std::string&)> parse;
  };
  std::deque<ListOption> lists_;  // stable addresses: CLI11 binds to `text`
  std::vector<std::pair<std::string_view, CLI::Option*>> options_;
};

}  // namespace gmasim::cli
