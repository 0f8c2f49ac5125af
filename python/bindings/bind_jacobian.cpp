#include "lptv/gsvd.hpp"
#include "lptv/jacobian.hpp"
#include "pybind11.hpp"

void bind_jacobian(py::module_& m) {
  m.def("jacobian", &lptv::jacobian, "data"_a, "par"_a, "rows"_a);
  m.def("residue", &lptv::residue, "data"_a, "par"_a, "rows"_a, "theta"_a);
  m.def("residue_variance", &lptv::residue_variance, "data"_a, "par"_a, "rows"_a, "theta"_a);
  m.def("residue_variance_gradient", &lptv::residue_variance_gradient, "data"_a, "par"_a, "rows"_a,
        "theta"_a);
  m.def("column_covariance", &lptv::column_covariance, "data"_a, "par"_a, "rows"_a, "weights"_a);
  m.def("gsvd_pairs", [](const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
    const auto g = lptv::gsvd_pairs(A, B);
    return py::make_tuple(g.values, g.vectors, g.infinite);
  }, "A"_a, "B"_a);
}
