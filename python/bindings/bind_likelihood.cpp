#include "lptv/likelihood.hpp"
#include "pybind11.hpp"

void bind_likelihood(py::module_& m) {
  py::class_<lptv::ExactLikelihood>(m, "ExactLikelihood",
                                    "The exact residue likelihood V = r^T S^-1 r (METHOD.md eq. 17).")
      .def(py::init<const lptv::FrequencyData&, const lptv::Parametrisation&, std::vector<int>>(), "data"_a,
           "par"_a, "rows"_a)
      .def("cost", &lptv::ExactLikelihood::cost, "theta"_a, py::call_guard<py::gil_scoped_release>())
      .def("gradient", [](const lptv::ExactLikelihood& l, const Eigen::VectorXcd& theta) {
        py::gil_scoped_release release;
        return l.evaluate(theta).gradient;
      }, "theta"_a, "dV/dxi over every entry of xi")
      .def("denoised", [](const lptv::ExactLikelihood& l, const Eigen::VectorXcd& theta) {
        py::gil_scoped_release release;
        return l.evaluate(theta).denoised;
      }, "theta"_a, "the spectra nearest to the data that the model explains exactly")
      .def("fisher_information", &lptv::ExactLikelihood::fisher_information, "theta"_a,
           py::call_guard<py::gil_scoped_release>())
      .def("sandwich_covariance", &lptv::ExactLikelihood::sandwich_covariance, "theta"_a, "weights"_a,
           py::call_guard<py::gil_scoped_release>())
      .def(
          "second_order_meat",
          [](const lptv::ExactLikelihood& lik, const lptv::Parametrisation& par, const Eigen::VectorXcd& theta,
             const Eigen::VectorXd& weights) {
            return lptv::second_order_meat(lik.second_order_terms(theta, weights), par, theta);
          },
          "par"_a, "theta"_a, "weights"_a, py::call_guard<py::gil_scoped_release>(),
          "Cov(q - lambda CJ_W xi) over the free entries of xi: the second-order noise of WGTLS's "
          "estimating equation (METHOD.md section 10), one experiment.")
      .def("residue_covariance", &lptv::ExactLikelihood::residue_covariance, "theta"_a)
      .def("set_row_scale", &lptv::ExactLikelihood::set_row_scale, "scale"_a,
           "S = D S_line D with D = diag(scale), one entry per row in the caller's order (METHOD.md section 20).")
      .def_property_readonly("sorted_rows", &lptv::ExactLikelihood::sorted_rows)
      .def_property_readonly("half_bandwidth", &lptv::ExactLikelihood::half_bandwidth);
  m.def("cramer_rao_bound",
        py::overload_cast<const lptv::FrequencyData&, const lptv::Parametrisation&, const std::vector<int>&,
                          const Eigen::VectorXcd&>(&lptv::cramer_rao_bound),
        "noiseless"_a, "par"_a, "rows"_a, "theta"_a, py::call_guard<py::gil_scoped_release>());
  m.def("cramer_rao_bound_experiments",
        py::overload_cast<const std::vector<lptv::FrequencyData>&, const lptv::Parametrisation&,
                          const std::vector<std::vector<int>>&, const Eigen::VectorXcd&>(&lptv::cramer_rao_bound),
        "noiseless"_a, "par"_a, "rows"_a, "theta"_a, py::call_guard<py::gil_scoped_release>(),
        "The Cramer-Rao bound of several independent experiments: their informations add.");
  m.def("eta_covariance", &lptv::eta_covariance, "par"_a, "cov_free"_a);
}
