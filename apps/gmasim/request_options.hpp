// The CLI options of a request, generated from its table (gmasim/experiments/request_table.hpp):
// one option per row marked Cli, with the row's flag and help, the default shown from the struct's
// own initialiser. A list row (std::vector<double>) takes a list or range ("20,30" or "20:10:70",
// parse_list) and replaces the default only when given.
#pragma once

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/experiments/request_table.hpp"

namespace gmasim::cli {

template <class R>
class RequestOptions {
 public:
  // Adds every Cli row of R's table to `sub`, bound to `req` (which must outlive the parse). A
  // bool row is a flag. Lists::Comma binds a list row to CLI11's own comma-separated list (no
  // ranges), for commands that took their lists so before the table.
  enum class Lists { Ranges, Comma };
  void add(CLI::App* sub, R& req, Lists lists = Lists::Ranges) {
    fields::for_each_field<R>([&](const auto& row) {
      if (!row.in_cli()) return;
      using T = typename std::remove_cvref_t<decltype(row)>::Value;
      const std::string flag(row.cli), help(row.help);
      CLI::Option* o = nullptr;
      if constexpr (std::is_same_v<T, bool>) {
        options_.emplace_back(row.cli, sub->add_flag(flag, row.ref(req), help));
        return;
      } else if constexpr (std::is_same_v<T, std::vector<double>>) {
        if (lists == Lists::Comma) {
          o = sub->add_option(flag, row.ref(req), help)->delimiter(',')->capture_default_str();
          options_.emplace_back(row.cli, o);
          return;
        }
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

// The arguments every experiment subcommand holds: the model, the request with its table's
// options, --progress, --plot and --out.
template <class R>
struct ExperimentArgs {
  ModelArgs model;
  R req;
  RequestOptions<R> options;  // the request's table (gmasim/experiments/experiment_fields.hpp)
  std::string out;
  bool plot = false, progress = false;
};

struct ExperimentCommand {
  const char* name;         // the subcommand
  std::string description;  // its help
  const char* out;          // the default output directory
  const char* plot_help;    // --plot's help
  bool progress = true;     // offers --progress
};

// Registers an experiment subcommand: the model options, the request table's options, then
// extra(sub, args) for the command's own, then --progress, --plot, --out. run(args) runs it.
template <class Args, class Extra, class Run>
Runner add_experiment(CLI::App& app, const ExperimentCommand& c, Extra extra, Run run) {
  auto a = std::make_shared<Args>();
  a->out = c.out;
  auto* sub = app.add_subcommand(c.name, c.description);
  add_model_options(sub, a->model);
  a->options.add(sub, a->req);
  extra(sub, *a);
  if (c.progress)
    sub->add_flag("--progress", a->progress, "Progress on stderr even when it is not a terminal");
  sub->add_flag("--plot", a->plot, c.plot_help);
  sub->add_option("--out", a->out, "Output directory")->capture_default_str();
  return [a, sub, run]() -> int { return sub->parsed() ? run(*a) : -1; };
}

}  // namespace gmasim::cli
