#include "lptv/htf_estimate.hpp"
#include "pybind11.hpp"

void bind_htf_estimate(py::module_& m) {
  py::class_<lptv::HtfEstimate>(m, "HtfEstimate", "Nonparametric HTF branches (lptv::htf_estimate).")
      .def_readonly("lines", &lptv::HtfEstimate::lines)
      .def_readonly("branches", &lptv::HtfEstimate::branches)
      .def_readonly("G", &lptv::HtfEstimate::G)
      .def_readonly("variance", &lptv::HtfEstimate::variance)
      .def_readonly("branch_statistic", &lptv::HtfEstimate::branch_statistic);
  m.def("htf_estimate", &lptv::htf_estimate, "data"_a, "excited"_a, "branches"_a);
  m.def("excited_lines", &lptv::excited_lines, "data"_a, "ratio"_a = 100.0);
}
