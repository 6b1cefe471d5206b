// gmasim.paper_claims(): the paper's numbers of the built-in claims (data/claims.toml, compiled
// into the library) as rows shaped like claims.json's, without our values, for the figures of
// single commands (gmasim.command_figures marks them beside our curves).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>

#include "bindings.hpp"
#include "gmasim/experiments/claims.hpp"

namespace py = pybind11;

namespace gmasim::py_bind {

void bind_paper_claims(py::module_& mod) {
  mod.def(
      "paper_claims",
      [] {
        auto num = [](double v) { return std::isnan(v) ? py::object(py::none()) : py::float_(v); };
        py::list rows;
        for (const auto& c : builtin_claims().claims) {
          py::dict d;
          d["id"] = c.id;
          d["claim"] = c.claim;
          d["source"] = c.source;
          d["kind"] = c.kind;
          d["paper"] = num(c.paper);
          d["unit"] = c.unit;
          d["ours"] = py::none();
          d["pass"] = py::none();
          d["result"] = "paper";
          d["temperature_C"] = num(c.condition.temperature_C);
          d["reference_temperature_C"] = num(c.condition.reference_temperature_C);
          d["current_pp_A"] = num(c.condition.current_pp_A);
          d["frequency_Hz"] = num(c.condition.frequency_Hz);
          d["amplitude_um"] = num(c.condition.amplitude_um);
          rows.append(d);
        }
        return rows;
      },
      "The paper's numbers of the built-in claims (data/claims.toml): a list of dicts shaped "
      "like the rows of claims.json (id, claim, source, kind, paper, unit and the condition) "
      "with ours, pass = None and result = 'paper'");
}

}  // namespace gmasim::py_bind
