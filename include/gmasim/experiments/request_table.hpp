// One table per experiment request (issue 21, item 3), in the manner of the parameter table
// (src/model/parameters.cpp) and kFreezeSwitches: a row per field with its Python keyword, unit,
// rule, CLI option, help and report metadata key. The default is the struct's own member
// initialiser (read from R{}), so it is typed once. From the rows are generated:
//   - the CLI options (apps/gmasim/request_options.hpp: add_request_options),
//   - the Python keyword arguments and their defaults (python/src/request_args.hpp),
//   - the report metadata (add_request_meta below; src/experiments/report.cpp),
//   - a check of every row's rule (check_request_fields), after the experiment's own checks.
// The tables themselves: gmasim/experiments/experiment_fields.hpp (and the other requests'
// headers).
#pragma once

#include <cstdint>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace gmasim::fields {

// What a row's value must satisfy (for a list: every element).
enum class Check : unsigned char { Any, Finite, Positive, NonNegative, Range };
struct Rule {
  Check check = Check::Finite;
  double lo = 0.0, hi = 0.0;  // Range: lo <= v <= hi (integers and counts included)
};
inline constexpr Rule any() { return {Check::Any}; }
inline constexpr Rule finite() { return {Check::Finite}; }
inline constexpr Rule positive() { return {Check::Positive}; }
inline constexpr Rule nonnegative() { return {Check::NonNegative}; }
inline constexpr Rule in(double lo, double hi) { return {Check::Range, lo, hi}; }

// Where a row appears: a CLI option, a Python keyword argument, a report metadata entry.
enum Where : unsigned { Cli = 1u, Python = 2u, Meta = 4u, All = 7u };

template <class R, class T>
struct Field {
  using Request = R;
  using Value = T;
  std::string_view name;  // the Python keyword; the metadata key unless meta_key is given
  std::string_view unit;  // "degC", "A", "-" ...
  Rule rule;
  std::string_view cli;   // "--f-min" ("" when not a CLI option)
  std::string_view help;  // the CLI option's help
  unsigned where = All;
  std::string_view meta_key;  // "" : name
  T& (*ref)(R&) = nullptr;

  const T& get(const R& r) const { return ref(const_cast<R&>(r)); }  // read only
  T default_value() const {
    R r{};
    return ref(r);
  }
  constexpr std::string_view meta_name() const { return meta_key.empty() ? name : meta_key; }
  constexpr bool in_cli() const { return (where & Cli) != 0u; }
  constexpr bool in_python() const { return (where & Python) != 0u; }
  constexpr bool in_meta() const { return (where & Meta) != 0u; }
};

// A row: field<R>(name, unit, rule, cli, help, where, GMASIM_REF(R, path) [, meta_key]).
template <class R, class F>
constexpr auto field(std::string_view name, std::string_view unit, Rule rule, std::string_view cli,
                     std::string_view help, unsigned where, F ref, std::string_view meta_key = {}) {
  using T = std::remove_reference_t<decltype(ref(std::declval<R&>()))>;
  return Field<R, T>{name, unit, rule, cli, help, where, meta_key, +ref};
}
#define GMASIM_REF(R, path) \
  [](R & r_) -> auto& { return r_.path; }

// Specialised per request with `static constexpr auto rows = std::tuple{field<R>(...), ...};`
// and `static constexpr std::string_view experiment = "sweep";`.
template <class R>
struct RequestFields;

template <class R>
using Rows = std::remove_cvref_t<decltype(RequestFields<R>::rows)>;

template <class R, class F>
void for_each_field(F&& f) {
  std::apply([&](const auto&... row) { (f(row), ...); }, RequestFields<R>::rows);
}

// The index of the row named `name` in R's table (a compile error when there is none).
template <class R>
constexpr std::size_t row_index(std::string_view name) {
  std::size_t found = std::tuple_size_v<Rows<R>>, i = 0;
  std::apply([&](const auto&... row) { ((found = row.name == name ? i : found, ++i), ...); },
             RequestFields<R>::rows);
  if (found == std::tuple_size_v<Rows<R>>) throw "no such row";  // not constant: a compile error
  return found;
}

// Row I of the table of S (GMASIM_NESTED: the row by name) as a row of R, which holds its S at
// member `Inner` (a request made of another's fields: name, unit, rule, option and help are the
// inner row's, spelled once), shown in `where` under `meta_key` ("": the inner row's key).
template <class R, auto Inner, class S, std::size_t I>
constexpr auto nested_row(unsigned where, std::string_view meta_key = {}) {
  const auto& row = std::get<I>(RequestFields<S>::rows);
  using T = typename std::remove_cvref_t<decltype(row)>::Value;
  constexpr auto ref = [](R& r) -> T& { return std::get<I>(RequestFields<S>::rows).ref(r.*Inner); };
  return Field<R, T>{row.name,
                     row.unit,
                     row.rule,
                     row.cli,
                     row.help,
                     where,
                     meta_key.empty() ? row.meta_name() : meta_key,
                     +ref};
}
#define GMASIM_NESTED(R, member, S, name, ...) \
  ::gmasim::fields::nested_row<R, &R::member, S, ::gmasim::fields::row_index<S>(name)>(__VA_ARGS__)

// The value's rule: throws InputError "<name> (<cli>) = <v> <unit>: <rule>".
void check_rule(double v, const Rule& rule, std::string_view name, std::string_view cli,
                std::string_view unit);

template <class T>
void check_value(const T& v, const Rule& rule, std::string_view name, std::string_view cli,
                 std::string_view unit) {
  if constexpr (std::is_same_v<T, std::vector<double>>) {
    for (double x : v) check_rule(x, rule, name, cli, unit);
  } else if constexpr (std::is_arithmetic_v<T>) {
    check_rule(static_cast<double>(v), rule, name, cli, unit);
  }
}

// Every row's rule on r. The experiments call it after their own checks (which keep their
// messages), so a field no check names is still checked before it becomes a count or a size.
template <class R>
void check_request_fields(const R& r) {
  for_each_field<R>(
      [&](const auto& row) { check_value(row.get(r), row.rule, row.name, row.cli, row.unit); });
}

}  // namespace gmasim::fields
