// Parse errors that name the word and the rule (issue 19, item 11): an unknown command or flag
// gets the nearest known one suggested (CLI11 has no such thing), a value that is not a number
// is told which number (and unit) the flag takes.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim::cli {
namespace {

// Levenshtein distance with adjacent transpositions (optimal string alignment).
std::size_t edit_distance(const std::string& a, const std::string& b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1, 0));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i)
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

// The known word nearest to `word`: within a third of its length (at least 2 edits), or a
// known word that starts with it or that it starts with.
std::optional<std::string> nearest(const std::string& word, const std::vector<std::string>& known) {
  std::optional<std::string> best;
  std::size_t best_d = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& k : known) {
    std::size_t d = edit_distance(word, k);
    if (word.size() >= 3 && (k.starts_with(word) || word.starts_with(k)))
      d = std::min<std::size_t>(d, 1);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

std::vector<std::string> subcommand_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* s : app.get_subcommands([](const CLI::App*) { return true; }))
    if (!s->get_name().empty()) names.push_back(s->get_name());
  return names;
}

std::vector<std::string> flag_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* o : app.get_options())
    for (const auto& l : o->get_lnames()) names.push_back("--" + l);
  return names;
}

std::string command_path(const CLI::App& app) {
  std::vector<std::string> parts;
  for (const CLI::App* a = &app; a != nullptr && a->get_parent() != nullptr; a = a->get_parent())
    parts.insert(parts.begin(), a->get_name());
  return parts.empty() ? std::string("gmasim")
                       : "gmasim " + fmt::format("{}", fmt::join(parts, " "));
}

const CLI::Option* find_flag(const CLI::App* app, const std::string& name) {
  for (; app != nullptr; app = app->get_parent())
    if (const CLI::Option* o = app->get_option_no_throw(name)) return o;
  return nullptr;
}

// Walks the arguments as CLI11 would, far enough to find the first word that is neither a
// command nor a flag of the command it follows; the message for it, or nullopt.
std::optional<std::string> unknown_word(const CLI::App& root, int argc, char** argv,
                                        const CLI::App** where) {
  const CLI::App* cur = &root;
  for (int i = 1; i < argc; ++i) {
    const std::string tok = argv[i];
    if (tok == "--") break;
    if (tok.starts_with("--")) {
      const std::string name = tok.substr(0, tok.find('='));
      if (const CLI::Option* o = find_flag(cur, name)) {
        if (o->get_items_expected_min() > 0 && tok.find('=') == std::string::npos)
          ++i;  // its value
        continue;
      }
      const auto near = nearest(name, flag_names(*cur));
      return fmt::format("{}: unknown flag {}{}; `{} --help` lists its flags", command_path(*cur),
                         clip_for_message(name, 60),
                         near ? fmt::format(" (did you mean {}?)", *near) : std::string(),
                         command_path(*cur));
    }
    if (tok.starts_with("-")) continue;  // -h, a negative number: CLI11's business
    const auto subs = subcommand_names(*cur);
    if (std::find(subs.begin(), subs.end(), tok) != subs.end()) {
      cur = cur->get_subcommand(tok);
      *where = cur;
      continue;
    }
    if (subs.empty()) continue;  // a positional argument (model check FILE)
    const auto near = nearest(tok, subs);
    return fmt::format("{}: unknown command '{}'{}; the commands are: {}", command_path(*cur),
                       clip_for_message(tok, 60),
                       near ? fmt::format(" (did you mean '{}'?)", *near) : std::string(),
                       fmt::join(subs, ", "));
  }
  return std::nullopt;
}

// "[degC]" at the end of a help text: the unit the flag takes.
std::string unit_of(const CLI::Option& o) {
  const std::string d = o.get_description();
  const auto close = d.rfind(']');
  const auto open = close == std::string::npos ? std::string::npos : d.rfind('[', close);
  if (open == std::string::npos) return "";
  const std::string u = d.substr(open + 1, close - open - 1);
  return u == "-" ? std::string() : u;
}

}  // namespace

std::string parse_error_message(const CLI::App& app, const CLI::ParseError& e, int argc,
                                char** argv) {
  const CLI::App* where = &app;
  if (auto word = unknown_word(app, argc, argv, &where)) return *word;
  // "Could not convert: --flag = value" (CLI11's ConversionError). No std::regex: libstdc++'s
  // recursion overflows the stack on a 100 kB value.
  const std::string what = e.what();
  const std::string head = "Could not convert: ";
  const auto eq = what.find(" = ");
  if (what.starts_with(head) && eq != std::string::npos) {
    const std::string flag = what.substr(head.size(), eq - head.size());
    const std::string value = what.substr(eq + 3);
    const CLI::Option* o = flag.starts_with("--") ? find_flag(where, flag) : nullptr;
    if (o != nullptr) {
      const bool integer = o->get_type_name().find("INT") != std::string::npos;
      const bool is_unsigned = o->get_type_name().find("UINT") != std::string::npos;
      const std::string unit = unit_of(*o);
      // a whole number the flag's type cannot hold: say so, not "not a whole number"
      std::size_t digits = value.starts_with('-') || value.starts_with('+') ? 1 : 0;
      const bool whole = integer && value.size() > digits &&
                         value.find_first_not_of("0123456789", digits) == std::string::npos;
      if (whole)
        return fmt::format("{} {}: out of range ({})", flag, clip_for_message(value, 60),
                           value.starts_with('-')
                               ? (is_unsigned ? "must be >= 0"
                                              : "too small for the flag; see --help for its range")
                               : "too large for the flag; see --help for its range");
      return fmt::format(
          "{} '{}': not {}{}; e.g. {} {}", flag, clip_for_message(value, 60),
          integer ? "a whole number" : "a number",
          unit.empty() ? std::string() : fmt::format(" (in {}, without the unit)", unit), flag,
          integer ? "10" : "20");
    }
  }
  return what;
}

}  // namespace gmasim::cli
