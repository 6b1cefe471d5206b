// The report metadata of a request, from its table (gmasim/experiments/request_table.hpp): every
// row marked Meta, in the table's order, under its metadata key.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/request_table.hpp"

namespace gmasim::fields {

inline Cell meta_cell(double v) { return Cell(v); }
inline Cell meta_cell(int v) { return Cell(v); }
inline Cell meta_cell(bool v) { return Cell(v); }
inline Cell meta_cell(std::uint64_t v) { return Cell(static_cast<double>(v)); }
inline Cell meta_cell(BiasState v) {
  return Cell(v == BiasState::Anhysteretic ? "anhysteretic" : "initial_curve");
}

inline Cell meta_cell(CompensationAdjust v) { return Cell(compensation_adjust_name(v)); }

template <class R>
void add_request_meta(Report& report, const R& r) {
  for_each_field<R>([&](const auto& row) {
    if constexpr (requires { meta_cell(row.get(r)); }) {
      if (row.in_meta())
        report.meta.emplace_back(std::string(row.meta_name()), meta_cell(row.get(r)));
    }
  });
}

// Inserts (key, value) after the entry `after` (at the end when there is none): a result's
// number placed among the request's.
inline void insert_meta_after(Report& report, std::string_view after, std::string key, Cell value) {
  auto it = report.meta.begin();
  while (it != report.meta.end() && it->first != after) ++it;
  if (it != report.meta.end()) ++it;
  report.meta.emplace(it, std::move(key), std::move(value));
}

}  // namespace gmasim::fields
