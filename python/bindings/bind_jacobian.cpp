#include "lptv/gsvd.hpp"
#include "lptv/jacobian.hpp"
#include "lptv/likelihood.hpp"
#include "pybind11.hpp"

void bind_jacobian(py::module_& m) {
  m.def("jacobian", &lptv::jacobian, "data"_a, "par"_a, "rows"_a);
  m.def("residue", &lptv::residue, "data"_a, "par"_a, "rows"_a, "theta"_a);
  m.def("residue_variance", &lptv::residue_variance, "data"_a, "par"_a, "rows"_a, "theta"_a);
  m.def("residue_variance_gradient", &lptv::residue_variance_gradient, "data"_a, "par"_a, "rows"_a,
        "theta"_a);
  m.def("column_covariance", &lptv::column_covariance, "data"_a, "par"_a, "rows"_a, "weights"_a);
  m.def("full_residue_variance",
        py::overload_cast<const lptv::FrequencyData&, const lptv::Parametrisation&, const std::vector<int>&,
                          const Eigen::VectorXcd&>(&lptv::full_residue_variance),
        "data"_a, "par"_a, "rows"_a, "theta"_a,
        "var e_l from the data's noise realisations, each row at its bins' own frequencies (METHOD.md section 20); "
        "eq. 15 on rows that read a line without realisations.");
  m.def("full_real_column_covariance", [](const lptv::FrequencyData& d, const lptv::Parametrisation& p,
                                          const std::vector<int>& rows, const Eigen::VectorXd& w) {
    return lptv::full_real_column_covariance(d, p, rows, lptv::row_noise(d, p, rows), w);
  }, "data"_a, "par"_a, "rows"_a, "weights"_a);
  m.def("row_noise_scale",
        py::overload_cast<const lptv::FrequencyData&, const lptv::Parametrisation&, const std::vector<int>&,
                          const Eigen::VectorXcd&>(&lptv::row_noise_scale),
        "data"_a, "par"_a, "rows"_a, "theta"_a);
  m.def("row_noise_variance",
        py::overload_cast<const lptv::FrequencyData&, const lptv::Parametrisation&, const std::vector<int>&,
                          const Eigen::VectorXcd&>(&lptv::row_noise_variance),
        "data"_a, "par"_a, "rows"_a, "theta"_a,
        "The rows' variances the record's routes weigh by: eq. 15 times row_noise_scale^2 (METHOD.md section 20).");
  m.def("has_row_noise", &lptv::has_row_noise, "data"_a);
  m.def("gsvd_pairs", [](const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
    const auto g = lptv::gsvd_pairs(A, B);
    return py::make_tuple(g.values, g.vectors, g.infinite);
  }, "A"_a, "B"_a);
}
