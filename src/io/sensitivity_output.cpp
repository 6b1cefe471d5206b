// The files of `gmasim sensitivity` (gmasim/experiments/sensitivity.hpp): sensitivity.csv (long
// format), sensitivity.json and identifiability.json. docs/experiments.md, "Sensitivity".
#include <fmt/format.h>

#include <cmath>
#include <string_view>
#include <type_traits>

#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/sensitivity.hpp"
#include "gmasim/io/io.hpp"
#include "io/json.hpp"

namespace gmasim {
namespace {

using io_detail::JsonLayout;
using io_detail::JsonWriter;

const char* step_name(StepKind k) { return k == StepKind::Log ? "log" : "absolute"; }

const char* kind_name(QuantityKind k) {
  switch (k) {
    case QuantityKind::Claim:
      return "claim";
    case QuantityKind::Metric:
      return "metric";
    case QuantityKind::Function:
      return "function";
  }
  return "?";
}

// The unit of d q / d ln p ("um") or d q / d p ("um/(N)").
std::string derivative_unit(const QuantityInfo& q, const ParameterInfo& p) {
  if (p.step == StepKind::Log) return q.unit;
  return fmt::format("{}/({})", q.unit, p.unit);
}

// The Meta rows of the settings' table (gmasim/experiments/experiment_fields.hpp), in its order;
// a dotted key ("steps.large") is a member of an inline object ("steps").
void write_request_settings(JsonWriter& w, const SensitivitySettings& s) {
  std::string_view group;
  fields::for_each_field<SensitivitySettings>([&](const auto& row) {
    if (!row.in_meta()) return;
    const std::string_view key = row.meta_name();
    const std::size_t dot = key.find('.');
    const std::string_view g =
        dot == std::string_view::npos ? std::string_view{} : key.substr(0, dot);
    if (g != group) {
      if (!group.empty()) w.end_object();
      if (!g.empty()) w.key(g).begin_object(JsonLayout::Inline);
      group = g;
    }
    w.key(g.empty() ? key : key.substr(dot + 1));
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(row.get(s))>, bool>)
      w.boolean(row.get(s));
    else
      w.number(static_cast<double>(row.get(s)));
  });
  if (!group.empty()) w.end_object();
}

void write_settings(JsonWriter& w, const SensitivityResult& r, const std::string& model) {
  w.key("model").string(model);
  write_request_settings(w, r.settings);
  w.key("evaluations").integer(r.evaluations);
  w.key("work_items").integer(r.runs);
  w.key("threads").integer(r.threads);
  w.key("wall_time_s").number(r.wall_time_s);
}

void write_parameters(JsonWriter& w, const SensitivityResult& r) {
  w.key("parameters").begin_array();
  for (const auto& p : r.parameters) {
    w.begin_object(JsonLayout::Inline);
    w.key("name").string(p.name).key("unit").string(p.unit).key("value").number(p.value);
    w.key("step").string(step_name(p.step)).key("scale").number(p.scale);
    w.key("rule").string(p.rule);
    w.end_object();
  }
  w.end_array();
}

void write_quantities(JsonWriter& w, const SensitivityResult& r) {
  w.key("quantities").begin_array();
  for (const auto& q : r.quantities) {
    w.begin_object(JsonLayout::Inline);
    w.key("name").string(q.name).key("kind").string(kind_name(q.kind));
    w.key("unit").string(q.unit).key("value").number(q.value);
    w.key("scale").number(q.scale).key("scale_source").string(q.scale_source);
    w.key("note").string(q.note);
    w.end_object();
  }
  w.end_array();
}

void write_entry(JsonWriter& w, const SensitivityEntry& e, const QuantityInfo& q,
                 const ParameterInfo& p) {
  w.begin_object(JsonLayout::Inline);
  w.key("derivative").number(e.derivative_large);
  w.key("derivative_small").number(e.derivative_small);
  w.key("unit").string(derivative_unit(q, p));
  w.key("per").string(p.step == StepKind::Log ? "ln p" : "p");
  w.key("scaled").number(e.scaled_large).key("scaled_small").number(e.scaled_small);
  w.key("per_scale").number(e.scaled_large / q.scale);
  w.key("disagreement").number(e.disagreement);
  w.key("flag").string(entry_flag_name(e.flag));
  if (!e.message.empty()) w.key("message").string(e.message);
  w.end_object();
}

}  // namespace

std::string sensitivity_csv(const SensitivityResult& r) {
  Table t;
  t.name = "sensitivity";
  t.columns = {"quantity",
               "quantity_unit",
               "kind",
               "quantity_value",
               "quantity_scale",
               "parameter",
               "parameter_unit",
               "parameter_value",
               "step",
               "derivative_unit",
               "derivative_h_large",
               "derivative_h_small",
               "scaled_h_large",
               "scaled_h_small",
               "per_scale",
               "disagreement",
               "flag",
               "message"};
  for (std::size_t i = 0; i < r.quantities.size(); ++i)
    for (std::size_t j = 0; j < r.parameters.size(); ++j) {
      const QuantityInfo& q = r.quantities[i];
      const ParameterInfo& p = r.parameters[j];
      const SensitivityEntry& e = r.entries[i][j];
      t.rows.push_back({q.name, q.unit, kind_name(q.kind), q.value, q.scale, p.name, p.unit,
                        p.value, step_name(p.step), derivative_unit(q, p), e.derivative_large,
                        e.derivative_small, e.scaled_large, e.scaled_small,
                        e.scaled_large / q.scale, e.disagreement, entry_flag_name(e.flag),
                        e.message});
    }
  return table_csv(t);
}

std::string sensitivity_json(const SensitivityResult& r, const std::string& model) {
  JsonWriter w;
  w.begin_object();
  w.key("command").string("sensitivity");
  write_settings(w, r, model);
  write_parameters(w, r);
  write_quantities(w, r);
  w.key("entries").begin_object();
  for (std::size_t i = 0; i < r.quantities.size(); ++i) {
    w.key(r.quantities[i].name).begin_object();
    for (std::size_t j = 0; j < r.parameters.size(); ++j) {
      w.key(r.parameters[j].name);
      write_entry(w, r.entries[i][j], r.quantities[i], r.parameters[j]);
    }
    w.end_object();
  }
  w.end_object();
  w.key("flagged").begin_array();
  for (std::size_t i = 0; i < r.quantities.size(); ++i)
    for (std::size_t j = 0; j < r.parameters.size(); ++j) {
      const SensitivityEntry& e = r.entries[i][j];
      if (e.flag == EntryFlag::Ok) continue;
      w.begin_object(JsonLayout::Inline);
      w.key("quantity").string(r.quantities[i].name).key("parameter").string(r.parameters[j].name);
      w.key("flag").string(entry_flag_name(e.flag)).key("message").string(e.message);
      w.end_object();
    }
  w.end_array();
  w.end_object();
  return w.text();
}

std::string identifiability_json(const SensitivityResult& r, const std::string& model) {
  const Identifiability& id = r.identifiability;
  JsonWriter w;
  w.begin_object();
  w.key("command").string("sensitivity");
  w.key("model").string(model);
  w.key("parameters").begin_array(JsonLayout::Inline);
  for (const auto& p : r.parameters) w.string(p.name);
  w.end_array();
  w.key("coordinates").begin_array(JsonLayout::Inline);
  for (const auto& p : r.parameters)
    w.string(p.step == StepKind::Log ? "ln p" : fmt::format("p / {:g}", p.scale));
  w.end_array();
  w.key("quantities").begin_array(JsonLayout::Inline);
  for (const auto& q : id.quantities) w.string(q);
  w.end_array();
  w.key("excluded").begin_array();
  for (const auto& q : id.excluded) w.string(q);
  w.end_array();
  w.key("jacobian_per_tolerance").begin_array();
  for (const auto& row : id.jacobian) {
    w.begin_array(JsonLayout::Inline);
    for (double v : row) w.number(v);
    w.end_array();
  }
  w.end_array();
  w.key("column_norm").begin_array(JsonLayout::Inline);
  for (double v : id.column_norm) w.number(v);
  w.end_array();
  w.key("rank").integer(id.rank);
  w.key("condition").number(id.condition);
  w.key("directions").begin_array();
  for (const auto& d : id.directions) {
    w.begin_object(JsonLayout::Inline);
    w.key("singular_value").number(d.singular_value).key("ratio").number(d.ratio);
    w.key("near_null").boolean(d.near_null).key("weak").boolean(d.weak);
    w.key("combination").string(direction_text(d, r.parameters));
    w.key("components").begin_array();
    for (double c : d.components) w.number(c);
    w.end_array();
    w.end_object();
  }
  w.end_array();
  w.key("std_dev").begin_array(JsonLayout::Inline);
  for (double v : id.std_dev) w.number(v);
  w.end_array();
  w.key("correlation").begin_array();
  for (const auto& row : id.correlation) {
    w.begin_array(JsonLayout::Inline);
    for (double v : row) w.number(v);
    w.end_array();
  }
  w.end_array();
  w.end_object();
  return w.text();
}

}  // namespace gmasim
