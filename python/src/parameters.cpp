// gmasim.parameter_table(): the C++ parameter table (gmasim/model/parameters.hpp) as Python data.
#include "gmasim/model/parameters.hpp"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace gmasim::py_bind {

void bind_parameters(py::module_& mod) {
  mod.def(
      "parameter_table",
      [] {
        py::list rows;
        for (const auto& p : parameter_table()) {
          py::dict d;
          d["table"] = std::string(group_def(p.group).path);
          d["key"] = std::string(p.key);
          d["unit"] = std::string(p.unit);
          d["rule"] = row_rule_text(p);
          d["doc"] = std::string(p.doc);
          d["default"] = p.default_value ? py::object(py::float_(*p.default_value)) : py::none();
          d["lands_in"] = std::string(p.lands_in);
          rows.append(d);
        }
        for (const auto& o : option_table()) {
          py::dict d;
          py::list words;
          for (const auto& c : o.choices) words.append(std::string(c.word));
          d["table"] = "options";
          d["key"] = std::string(o.key);
          d["unit"] = "option";
          d["rule"] = words;
          d["doc"] = std::string(o.doc);
          d["default"] = py::none();
          d["lands_in"] = std::string(o.lands_in);
          rows.append(d);
        }
        return rows;
      },
      "Every key a model file may hold: [{'table', 'key', 'unit', 'rule', 'doc', 'default', "
      "'lands_in'}] (the C++ parameter table; docs/parameters.md). For options, 'rule' is the "
      "list of allowed words.");
}

}  // namespace gmasim::py_bind
