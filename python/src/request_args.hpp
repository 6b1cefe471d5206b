// Python functions over a request, their keyword arguments generated from its table
// (gmasim/experiments/request_table.hpp): one argument per row marked Python, in the table's order,
// with the row's name and the struct's own default, then the function's extra arguments (not fields
// of the request). pybind11 sees an ordinary typed signature, so the docstring's first line names
// every argument with its type and default as before.
#pragma once

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstddef>
#include <tuple>
#include <utility>

#include "gmasim/experiments/request_table.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim::py_bind {

// An argument of the Python function that is not a field of the request.
template <class T>
struct Extra {
  const char* name;
  T value;  // its default
};

namespace request_args_detail {

template <class R>
constexpr std::size_t python_count() {
  std::size_t n = 0;
  std::apply([&](const auto&... row) { ((n += row.in_python() ? 1u : 0u), ...); },
             fields::RequestFields<R>::rows);
  return n;
}

// The indices of the Python rows in the table.
template <class R>
constexpr auto python_indices() {
  std::array<std::size_t, python_count<R>()> out{};
  std::size_t k = 0, i = 0;
  std::apply(
      [&](const auto&... row) { ((row.in_python() ? void(out[k++] = i++) : void(i++)), ...); },
      fields::RequestFields<R>::rows);
  return out;
}

template <class R>
inline constexpr auto kPythonRows = python_indices<R>();

template <class R, std::size_t I>
using Value = typename std::tuple_element_t<I, fields::Rows<R>>::Value;

template <class R, std::size_t I>
pybind11::arg_v row_arg() {
  const auto& row = std::get<I>(fields::RequestFields<R>::rows);
  return pybind11::arg(row.name.data()) = row.default_value();
}

template <class R, class Run, class... E, std::size_t... K>
void def_request(pybind11::module_& mod, const char* name, const char* doc, Run run,
                 std::index_sequence<K...>, const Extra<E>&... extras) {
  constexpr const auto& idx = kPythonRows<R>;
  mod.def(
      name,
      [run](const Model& m, Value<R, idx[K]>... v, E... e) {
        R r;
        ((std::get<idx[K]>(fields::RequestFields<R>::rows).ref(r) = std::move(v)), ...);
        return run(m, r, std::move(e)...);
      },
      pybind11::arg("model"), row_arg<R, idx[K]>()...,
      (pybind11::arg(extras.name) = extras.value)..., doc);
}

}  // namespace request_args_detail

// mod.<name>(model, <the request's Python rows>..., <extras>...) -> run(model, request, extras...).
template <class R, class Run, class... E>
void def_request(pybind11::module_& mod, const char* name, const char* doc, Run run,
                 const Extra<E>&... extras) {
  request_args_detail::def_request<R>(
      mod, name, doc, run, std::make_index_sequence<request_args_detail::kPythonRows<R>.size()>{},
      extras...);
}

// {name: default} of the request's Python rows, in the table's order (for a Python wrapper that
// passes them on: its signature and docstring).
template <class R>
pybind11::dict request_defaults() {
  pybind11::dict d;
  fields::for_each_field<R>([&](const auto& row) {
    if (row.in_python()) d[pybind11::str(row.name.data(), row.name.size())] = row.default_value();
  });
  return d;
}

}  // namespace gmasim::py_bind
