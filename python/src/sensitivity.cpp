// Binding of run_sensitivity (gmasim/experiments/sensitivity.hpp); the Python entry point with its
// docstring is gmasim.sensitivity (python/gmasim/_sensitivity.py), which shapes the arrays.
#include "gmasim/experiments/sensitivity.hpp"

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/claims.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "request_args.hpp"

namespace py = pybind11;

namespace gmasim::py_bind {
namespace {

py::list matrix(const std::vector<std::vector<double>>& rows) {
  py::list out;
  for (const auto& r : rows) out.append(to_numpy(r));
  return out;
}

py::dict identifiability_dict(const SensitivityResult& r) {
  const Identifiability& id = r.identifiability;
  py::dict d;
  d["quantities"] = id.quantities;
  d["excluded"] = id.excluded;
  d["jacobian"] = matrix(id.jacobian);
  d["column_norm"] = to_numpy(id.column_norm);
  std::vector<double> s;
  std::vector<std::vector<double>> v;
  std::vector<bool> near, weak;
  std::vector<std::string> text;
  for (const auto& dir : id.directions) {
    s.push_back(dir.singular_value);
    v.push_back(dir.components);
    near.push_back(dir.near_null);
    weak.push_back(dir.weak);
    text.push_back(direction_text(dir, r.parameters));
  }
  d["singular_values"] = to_numpy(s);
  d["directions"] = matrix(v);
  d["near_null"] = near;
  d["weak"] = weak;
  d["combinations"] = text;
  d["correlation"] = matrix(id.correlation);
  d["std_dev"] = to_numpy(id.std_dev);
  d["rank"] = id.rank;
  d["condition"] = id.condition;
  return d;
}

py::dict result_dict(const SensitivityResult& r) {
  py::dict d;
  std::vector<std::string> pn, pu, steps, qn, qu, qk, qsrc;
  std::vector<double> pv, ps, qv, qs;
  for (const auto& p : r.parameters) {
    pn.push_back(p.name);
    pu.push_back(p.unit);
    pv.push_back(p.value);
    ps.push_back(p.scale);
    steps.push_back(p.step == StepKind::Log ? "log" : "absolute");
  }
  for (const auto& q : r.quantities) {
    qn.push_back(q.name);
    qu.push_back(q.unit);
    qv.push_back(q.value);
    qs.push_back(q.scale);
    qk.push_back(q.kind == QuantityKind::Claim    ? "claim"
                 : q.kind == QuantityKind::Metric ? "metric"
                                                  : "function");
    qsrc.push_back(q.scale_source);
  }
  std::vector<std::vector<double>> dl, ds, sl, ss, dis;
  std::vector<std::vector<std::string>> flags;
  for (const auto& row : r.entries) {
    dl.emplace_back();
    ds.emplace_back();
    sl.emplace_back();
    ss.emplace_back();
    dis.emplace_back();
    flags.emplace_back();
    for (const auto& e : row) {
      dl.back().push_back(e.derivative_large);
      ds.back().push_back(e.derivative_small);
      sl.back().push_back(e.scaled_large);
      ss.back().push_back(e.scaled_small);
      dis.back().push_back(e.disagreement);
      flags.back().push_back(entry_flag_name(e.flag));
    }
  }
  d["parameters"] = pn;
  d["parameter_units"] = pu;
  d["parameter_values"] = to_numpy(pv);
  d["parameter_scales"] = to_numpy(ps);
  d["steps"] = steps;
  d["quantities"] = qn;
  d["quantity_units"] = qu;
  d["quantity_kinds"] = qk;
  d["quantity_values"] = to_numpy(qv);
  d["quantity_scales"] = to_numpy(qs);
  d["quantity_scale_sources"] = qsrc;
  d["derivative"] = matrix(dl);
  d["derivative_small"] = matrix(ds);
  d["scaled"] = matrix(sl);
  d["scaled_small"] = matrix(ss);
  d["disagreement"] = matrix(dis);
  d["flags"] = flags;
  d["identifiability"] = identifiability_dict(r);
  d["step_large"] = r.settings.step_large;
  d["step_small"] = r.settings.step_small;
  d["evaluations"] = r.evaluations;
  d["threads"] = r.threads;
  d["wall_time_s"] = r.wall_time_s;
  return d;
}

}  // namespace

void bind_sensitivity(py::module_& mod) {
  // The settings' keyword arguments and defaults are the Python rows of their table
  // (gmasim/experiments/experiment_fields.hpp); gmasim.sensitivity() passes them on.
  def_request<SensitivitySettings>(
      mod, "_sensitivity", "run_sensitivity; use gmasim.sensitivity()",
      [](const Model& m, const SensitivitySettings& settings,
         const std::vector<std::string>& params, const std::vector<double>& scales,
         const std::vector<std::string>& only, const std::string& claims_file, bool use_metrics) {
        SensitivityRequest r;
        static_cast<SensitivitySettings&>(r) = settings;
        if (params.size() != scales.size())
          throw InputError("sensitivity: params and scales differ in length");
        for (std::size_t k = 0; k < params.size(); ++k)
          r.parameters.push_back({params[k], scales[k]});
        ClaimsData claims = claims_file.empty() ? builtin_claims() : load_claims(claims_file);
        r.claims = &claims;
        if (!use_metrics) r.metrics.clear();
        r.only = only;
        SensitivityResult res;
        {
          py::gil_scoped_release release;
          res = run_sensitivity(m, r);
        }
        return result_dict(res);
      },
      Extra<std::vector<std::string>>{"params", {}}, Extra<std::vector<double>>{"scales", {}},
      Extra<std::vector<std::string>>{"only", {}}, Extra<std::string>{"claims_file", ""},
      Extra<bool>{"use_metrics", true});
  mod.def("_sensitivity_defaults", &request_defaults<SensitivitySettings>,
          "The settings of sensitivity() and their defaults, from the C++ table");
  mod.def(
      "_model_parameters",
      [](const Model& m) {
        std::vector<std::string> out;
        for (const auto& p : model_parameters(m.spec)) out.push_back(p.name);
        return out;
      },
      py::arg("model"), "The parameters of sensitivity(params='all')");
}

}  // namespace gmasim::py_bind
