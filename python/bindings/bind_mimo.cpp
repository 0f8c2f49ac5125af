#include "lptv/mimo.hpp"
#include "lptv/mimo_estimators.hpp"
#include "pybind11.hpp"

namespace {

py::dict simulate_mimo_py(const lptv::MimoModel& model, const Eigen::MatrixXcd& U, const std::string& solver,
                          int lines_out, int guard, double tol, int max_guard) {
  lptv::SimulateOptions opt;
  opt.solver = lptv::solver_from_string(solver);
  opt.lines_out = lines_out;
  opt.guard = guard;
  opt.tol = tol;
  opt.max_guard = max_guard;
  lptv::MimoSimulateResult r;
  {
    py::gil_scoped_release release;  // the factorisations and solves touch no Python object
    r = lptv::simulate_mimo(model, U, opt);
  }
  py::dict d;
  d["Y"] = py::cast(std::move(r.Y));
  d["guard"] = r.guard;
  d["truncation_error"] = r.truncation_error;
  d["converged"] = r.converged;
  d["solver"] = lptv::solver_name(r.solver);
  d["condition"] = r.condition;
  d["condition_line"] = r.condition_line;
  return d;
}

Eigen::MatrixXcd mimo_htf_py(const lptv::MimoModel& model, int L, const std::vector<int>& lines,
                             const std::string& solver) {
  py::gil_scoped_release release;  // pure C++ work
  const lptv::MimoFds fds(model, L, lptv::solver_from_string(solver));
  return fds.htf_columns(lines);
}

Eigen::SparseMatrix<std::complex<double>> mimo_band_py(const lptv::MimoModel& model, int L, bool a) {
  const lptv::Grid g = lptv::make_grid(model, L);
  return a ? lptv::build_mimo_A(model, g) : lptv::build_mimo_B(model, g);
}

using SpectraTuple = std::tuple<Eigen::MatrixXcd, Eigen::MatrixXcd, Eigen::MatrixXcd, std::vector<int>>;

std::vector<lptv::MimoSpectra> spectra_of(const std::vector<SpectraTuple>& data) {
  std::vector<lptv::MimoSpectra> out;
  for (const auto& t : data) {
    lptv::MimoSpectra d;
    d.Y = std::get<0>(t);
    d.U = std::get<1>(t);
    d.C = std::get<2>(t);
    d.rows = std::get<3>(t);
    out.push_back(std::move(d));
  }
  return out;
}

lptv::MimoEstimate wgtls_py(const std::vector<SpectraTuple>& data, const lptv::MimoStructure& s, double tol,
                            int max_iter, bool weighted) {
  const auto d = spectra_of(data);
  py::gil_scoped_release release;  // pure C++ work on copies
  return lptv::mimo_wgtls(d, s, tol, max_iter, weighted);
}

lptv::MimoEstimate sml_py(const std::vector<SpectraTuple>& data, const lptv::MimoStructure& s,
                          const Eigen::VectorXd& xi0, double tol, int max_iter) {
  const auto d = spectra_of(data);
  py::gil_scoped_release release;  // pure C++ work on copies
  return lptv::mimo_sml(d, s, xi0, tol, max_iter);
}

Eigen::MatrixXd fisher_py(const std::vector<SpectraTuple>& data, const lptv::MimoStructure& s,
                          const Eigen::VectorXd& xi) {
  const auto d = spectra_of(data);
  py::gil_scoped_release release;  // pure C++ work on copies
  return lptv::mimo_fisher(d, s, xi);
}

Eigen::MatrixXd sandwich_py(const std::vector<SpectraTuple>& data, const lptv::MimoStructure& s,
                            const Eigen::VectorXd& xi) {
  const auto d = spectra_of(data);
  py::gil_scoped_release release;  // pure C++ work on copies
  return lptv::mimo_sandwich(d, s, xi);
}

py::tuple residues_py(const SpectraTuple& data, const lptv::MimoStructure& s, const Eigen::VectorXd& xi) {
  const auto d = spectra_of({data});
  Eigen::MatrixXcd e, Ce;
  lptv::mimo_residues(d[0], s, xi, e, Ce);
  return py::make_tuple(e, Ce);
}

lptv::MimoFit fit_py(const std::vector<SpectraTuple>& data, const lptv::MimoStructure& s, const std::string& method,
                     double tol, int max_iter, bool covariance) {
  const auto d = spectra_of(data);
  py::gil_scoped_release release;  // pure C++ work on copies
  return lptv::mimo_fit(d, s, method, tol, max_iter, covariance);
}

lptv::MimoStructure make_structure(int ny, int nu, const Eigen::MatrixXi& ka, const Eigen::MatrixXi& kb, double w0,
                                   double ts) {
  lptv::MimoStructure s;
  s.ny = ny;
  s.nu = nu;
  s.ka = ka;
  s.kb = kb;
  s.w0 = w0;
  s.ts = ts;
  return s;
}

}  // namespace

void bind_mimo(py::module_& m) {
  py::class_<lptv::MimoModel>(m, "MimoModel",
                              "Validated matrix LPTV model (see lptv.MimoModel for the documented API).")
      .def(py::init<Eigen::MatrixXcd, Eigen::MatrixXcd, int, int, double, double>(), "a"_a, "b"_a,
           "n_outputs"_a, "n_inputs"_a, "w0"_a, "ts"_a = 0.0)
      .def_property_readonly("a", &lptv::MimoModel::a)
      .def_property_readonly("b", &lptv::MimoModel::b)
      .def_property_readonly("n_outputs", &lptv::MimoModel::n_outputs)
      .def_property_readonly("n_inputs", &lptv::MimoModel::n_inputs)
      .def_property_readonly("na", &lptv::MimoModel::na)
      .def_property_readonly("nb", &lptv::MimoModel::nb)
      .def_property_readonly("ka", &lptv::MimoModel::ka)
      .def_property_readonly("kb", &lptv::MimoModel::kb)
      .def_property_readonly("w0", &lptv::MimoModel::w0)
      .def_property_readonly("ts", &lptv::MimoModel::ts)
      .def("samples_per_period", &lptv::MimoModel::samples_per_period)
      .def("a_at", &lptv::MimoModel::a_at, "t"_a, "entries of A_n(t): array (len(t), (na+1) ny ny)")
      .def("b_at", &lptv::MimoModel::b_at, "t"_a, "entries of B_m(t): array (len(t), (nb+1) ny nu)");
  m.def("simulate_mimo", &simulate_mimo_py, "model"_a, "U"_a, "solver"_a = "auto", "lines_out"_a = -1,
        "guard"_a = -1, "tol"_a = 1e-13, "max_guard"_a = -1);
  m.def("mimo_htf", &mimo_htf_py, "model"_a, "L"_a, "lines"_a, "solver"_a = "auto");
  m.def("mimo_band_matrix", &mimo_band_py, "model"_a, "L"_a, "a"_a = true);

  py::class_<lptv::MimoStructure>(m, "MimoStructure",
                                  "Row-uniform structure of a MIMO fit: ka (na+1) x ny, kb (nb+1) x nu.")
      .def(py::init(&make_structure), "ny"_a, "nu"_a, "ka"_a, "kb"_a, "w0"_a, "ts"_a = 0.0)
      .def_readonly("ny", &lptv::MimoStructure::ny)
      .def_readonly("nu", &lptv::MimoStructure::nu);
  py::class_<lptv::MimoEstimate>(m, "MimoEstimate", "A MIMO WGTLS or SML estimate (see lptv.mimo_fit).")
      .def_readonly("xi", &lptv::MimoEstimate::xi)
      .def_readonly("singular_values", &lptv::MimoEstimate::singular_values)
      .def_readonly("information", &lptv::MimoEstimate::information)
      .def_readonly("cost", &lptv::MimoEstimate::cost)
      .def_readonly("iterations", &lptv::MimoEstimate::iterations)
      .def_readonly("converged", &lptv::MimoEstimate::converged)
      .def_readonly("noise_free", &lptv::MimoEstimate::noise_free);
  py::class_<lptv::MimoFit>(m, "MimoFit", "One MIMO fit: estimate, covariance (free entries), residues.")
      .def_readonly("estimate", &lptv::MimoFit::estimate)
      .def_readonly("covariance", &lptv::MimoFit::covariance)
      .def_readonly("residues", &lptv::MimoFit::residues)
      .def_readonly("residue_covariance", &lptv::MimoFit::residue_covariance);
  m.def("mimo_fit", &fit_py, "data"_a, "structure"_a, "method"_a, "tol"_a, "max_iter"_a, "covariance"_a = true,
        "WGTLS ('gtls', 'wgtls') or SML ('sml') from WGTLS with the covariance and the residues, the rows' terms "
        "formed once");
  m.def("mimo_wgtls", &wgtls_py, "data"_a, "structure"_a, "tol"_a, "max_iter"_a, "weighted"_a = true,
        "WGTLS with vector residues and A_na,0 = I; data: list of (Y, U, C, rows), C of shape ((L+1)(ny+nu), ny+nu)");
  m.def("mimo_sml", &sml_py, "data"_a, "structure"_a, "xi0"_a, "tol"_a, "max_iter"_a,
        "Levenberg-Marquardt on the rows' exact likelihood from xi0");
  m.def("mimo_fisher", &fisher_py, "data"_a, "structure"_a, "xi"_a, "Fisher information over the free entries");
  m.def("mimo_sandwich", &sandwich_py, "data"_a, "structure"_a, "xi"_a, "WGTLS's first-order sandwich covariance");
  m.def("mimo_residues", &residues_py, "data"_a, "structure"_a, "xi"_a,
        "(residues rows x ny, their covariances (rows ny) x ny) of one experiment");
  m.def("mimo_free_indices", &lptv::mimo_free_indices, "structure"_a);
}
