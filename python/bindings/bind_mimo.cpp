#include "lptv/mimo.hpp"
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
}
