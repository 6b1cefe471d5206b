#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim::py_bind {
pybind11::array_t<double> to_numpy(const std::vector<double>& v);
pybind11::dict series_dict(const TimeSeries& ts);
pybind11::dict metrics_dict(const Metrics& m);
void bind_experiments(pybind11::module_& mod);  // experiments.cpp
void bind_stepper(pybind11::module_& mod);      // stepper.cpp: Stepper, __version__
void bind_parameters(pybind11::module_& mod);   // parameters.cpp: parameter_table()
void bind_sensitivity(pybind11::module_& mod);  // sensitivity.cpp: _sensitivity
// paper_claims.cpp: paper_claims()
void bind_paper_claims(pybind11::module_& mod);
}  // namespace gmasim::py_bind
