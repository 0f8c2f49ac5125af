#include "lptv/estimators.hpp"
#include "lptv/gsvd.hpp"
#include "lptv/jacobian.hpp"
#include "lptv/noise.hpp"
#include "pybind11.hpp"

namespace {

lptv::Structure make_structure(int na, int nb, std::vector<int> ka, std::vector<int> kb,
                               const std::vector<std::tuple<bool, int, Eigen::VectorXcd>>& known,
                               double w0, double ts) {
  lptv::Structure s;
  s.na = na;
  s.nb = nb;
  s.ka = std::move(ka);
  s.kb = std::move(kb);
  for (const auto& [is_a, order, coef] : known) s.known.push_back({is_a, order, coef});
  s.w0 = w0;
  s.ts = ts;
  return s;
}

}  // namespace

void bind_identify(py::module_& m) {
  py::class_<lptv::FrequencyData>(m, "FrequencyData")
      .def(py::init([](Eigen::VectorXcd U, Eigen::VectorXcd Y, Eigen::VectorXd varU, Eigen::VectorXd varY,
                       Eigen::VectorXcd covYU, int periods) {
             lptv::FrequencyData d{std::move(U), std::move(Y), std::move(varU), std::move(varY),
                                   std::move(covYU), periods};
             d.validate();
             return d;
           }),
           "U"_a, "Y"_a, "varU"_a, "varY"_a, "covYU"_a, "periods"_a = 0)
      .def_static("from_periods", [](const Eigen::MatrixXd& u, const Eigen::MatrixXd& y) {
        py::gil_scoped_release release;  // FFTs only
        return lptv::frequency_data_from_periods(u, y);
      }, "u"_a, "y"_a)
      .def_readonly("U", &lptv::FrequencyData::U)
      .def_readonly("Y", &lptv::FrequencyData::Y)
      .def_readonly("varU", &lptv::FrequencyData::varU)
      .def_readonly("varY", &lptv::FrequencyData::varY)
      .def_readonly("covYU", &lptv::FrequencyData::covYU)
      .def_readonly("periods", &lptv::FrequencyData::periods);

  py::class_<lptv::Parametrisation>(m, "Parametrisation")
      .def(py::init([](int na, int nb, std::vector<int> ka, std::vector<int> kb,
                       const std::vector<std::tuple<bool, int, Eigen::VectorXcd>>& known, double w0,
                       double ts) {
             return lptv::Parametrisation(make_structure(na, nb, ka, kb, known, w0, ts));
           }),
           "na"_a, "nb"_a, "ka"_a, "kb"_a, "known"_a, "w0"_a, "ts"_a = 0.0)
      .def_property_readonly("n_theta", &lptv::Parametrisation::n_theta)
      .def_property_readonly("n_eta", &lptv::Parametrisation::n_eta)
      .def_property_readonly("n_xi", &lptv::Parametrisation::n_xi)
      .def_property_readonly("has_known", &lptv::Parametrisation::has_known)
      .def_property_readonly("norm_index", &lptv::Parametrisation::norm_index)
      .def_property_readonly("T", &lptv::Parametrisation::T)
      .def_property_readonly("Text", &lptv::Parametrisation::Text)
      .def_property_readonly("d", &lptv::Parametrisation::d)
      .def_property_readonly("params", [](const lptv::Parametrisation& p) {
        std::vector<std::tuple<bool, int, int>> out;
        for (const auto& q : p.params()) out.emplace_back(q.is_a, q.order, q.k);
        return out;
      })
      .def("theta_from_xi", &lptv::Parametrisation::theta_from_xi, "xi"_a)
      .def("to_model", &lptv::Parametrisation::to_model, "theta"_a)
      .def("default_rows", &lptv::default_rows, "max_line"_a)
      .def("check_rows", &lptv::check_rows, "rows"_a, "max_line"_a);

  m.def("jacobian", &lptv::jacobian, "data"_a, "par"_a, "rows"_a);
  m.def("residue", &lptv::residue, "data"_a, "par"_a, "rows"_a, "theta"_a);
  m.def("residue_variance", &lptv::residue_variance, "data"_a, "par"_a, "rows"_a, "theta"_a);
  m.def("residue_variance_gradient", &lptv::residue_variance_gradient, "data"_a, "par"_a, "rows"_a,
        "theta"_a);
  m.def("column_covariance", &lptv::column_covariance, "data"_a, "par"_a, "rows"_a, "weights"_a);
  m.def("real_column_covariance", &lptv::real_column_covariance, "data"_a, "par"_a, "rows"_a,
        "weights"_a);
  m.def("weighted_r_factor", &lptv::weighted_r_factor, "data"_a, "par"_a, "rows"_a, "weights"_a);
  m.def("gsvd_pairs", [](const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
    const auto g = lptv::gsvd_pairs(A, B);
    return py::make_tuple(g.values, g.vectors, g.infinite);
  }, "A"_a, "B"_a);
  m.def("estimate", [](const lptv::FrequencyData& d, const lptv::Parametrisation& p,
                       const std::vector<int>& rows, const std::string& method, double tol, int max_iter) {
    lptv::EstimateOptions opt;
    opt.method = lptv::method_from_string(method);
    opt.tol = tol;
    opt.max_iter = max_iter;
    lptv::EstimateResult r;
    {
      py::gil_scoped_release release;  // the whole estimation is C++
      r = lptv::estimate(d, p, rows, opt);
    }
    py::dict out;
    out["theta"] = r.theta;
    out["eta"] = r.eta;
    out["iterations"] = r.iterations;
    out["converged"] = r.converged;
    out["cost"] = r.cost;
    out["cost_history"] = r.cost_history;
    out["singular_values"] = r.singular_values;
    out["noise_free"] = r.noise_free;
    return out;
  }, "data"_a, "par"_a, "rows"_a, "method"_a = "wgtls", "tol"_a = 1e-10, "max_iter"_a = 50);
}
