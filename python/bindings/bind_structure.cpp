#include "lptv/model.hpp"
#include "lptv/structure.hpp"
#include "pybind11.hpp"

namespace {

using KnownList = std::vector<std::tuple<bool, int, Eigen::VectorXcd>>;

lptv::Structure make_structure(int na, int nb, std::vector<int> ka, std::vector<int> kb, const KnownList& known,
                               double w0, double ts) {
  lptv::Structure s;
  s.na = na;
  s.nb = nb;
  s.ka = std::move(ka);
  s.kb = std::move(kb);
  for (const auto& [is_a, order, coef] : known) s.known.push_back({is_a, order, coef});
  s.w0 = w0;
  s.ts = ts;
  s.validate();
  return s;
}

}  // namespace

void bind_structure(py::module_& m) {
  py::class_<lptv::Structure>(m, "Structure",
                              "Orders, harmonic counts per coefficient, known coefficients, w0 and ts.")
      .def(py::init(&make_structure), "na"_a, "nb"_a, "ka"_a, "kb"_a, "known"_a, "w0"_a, "ts"_a = 0.0)
      .def_readonly("na", &lptv::Structure::na)
      .def_readonly("nb", &lptv::Structure::nb)
      .def_readonly("ka", &lptv::Structure::ka)
      .def_readonly("kb", &lptv::Structure::kb)
      .def_readonly("w0", &lptv::Structure::w0)
      .def_readonly("ts", &lptv::Structure::ts)
      .def_property_readonly("kmax", &lptv::Structure::kmax)
      .def_static("of", &lptv::Structure::of, "model"_a, "The model's own orders and harmonic counts.");

  py::class_<lptv::Parametrisation>(m, "Parametrisation")
      .def(py::init([](int na, int nb, std::vector<int> ka, std::vector<int> kb, const KnownList& known,
                       double w0, double ts) {
             return lptv::Parametrisation(make_structure(na, nb, std::move(ka), std::move(kb), known, w0, ts));
           }),
           "na"_a, "nb"_a, "ka"_a, "kb"_a, "known"_a, "w0"_a, "ts"_a = 0.0)
      .def(py::init<const lptv::Structure&>(), "structure"_a)
      .def_property_readonly("structure", &lptv::Parametrisation::structure)
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
      .def_property_readonly("eta_names", &lptv::Parametrisation::eta_names)
      .def_property_readonly("free_indices", &lptv::Parametrisation::free_indices)
      .def("theta_from_xi", &lptv::Parametrisation::theta_from_xi, "xi"_a)
      .def("xi_from_theta", &lptv::Parametrisation::xi_from_theta, "theta"_a)
      .def("theta_from_model", &lptv::Parametrisation::theta_from_model, "model"_a)
      .def("to_model", &lptv::Parametrisation::to_model, "theta"_a)
      .def("default_rows", &lptv::default_rows, "max_line"_a)
      .def("check_rows", &lptv::check_rows, "rows"_a, "max_line"_a);
}
