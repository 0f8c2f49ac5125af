#include "lptv/model.hpp"
#include "pybind11.hpp"

void bind_model(py::module_& m) {
  py::class_<lptv::Model>(m, "Model", "Validated LPTV model (see lptv.Model for the documented API).")
      .def(py::init<Eigen::MatrixXcd, Eigen::MatrixXcd, double, double>(), "a"_a, "b"_a, "w0"_a,
           "ts"_a = 0.0)
      .def_property_readonly("a", &lptv::Model::a)
      .def_property_readonly("b", &lptv::Model::b)
      .def_property_readonly("na", &lptv::Model::na)
      .def_property_readonly("nb", &lptv::Model::nb)
      .def_property_readonly("ka", &lptv::Model::ka)
      .def_property_readonly("kb", &lptv::Model::kb)
      .def_property_readonly("w0", &lptv::Model::w0)
      .def_property_readonly("ts", &lptv::Model::ts)
      .def("samples_per_period", &lptv::Model::samples_per_period)
      .def("a_at", &lptv::Model::a_at, "t"_a, "a_n(t) on a time grid: array (len(t), na+1)")
      .def("b_at", &lptv::Model::b_at, "t"_a, "b_m(t) on a time grid: array (len(t), nb+1)");
}
