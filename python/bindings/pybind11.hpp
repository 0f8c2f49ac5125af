// The one pybind11 include of the bindings.
#pragma once
#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace py = pybind11;
using namespace pybind11::literals;

void bind_model(py::module_& m);
void bind_multisine(py::module_& m);
void bind_multisine_design(py::module_& m);
void bind_fds(py::module_& m);
void bind_noise(py::module_& m);
void bind_structure(py::module_& m);
void bind_jacobian(py::module_& m);
void bind_likelihood(py::module_& m);
void bind_estimators(py::module_& m);
void bind_htf_estimate(py::module_& m);
void bind_distortion(py::module_& m);
void bind_moderation(py::module_& m);
void bind_record(py::module_& m);
void bind_floquet(py::module_& m);
void bind_mimo(py::module_& m);
