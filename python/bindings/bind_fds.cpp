#include "lptv/fds.hpp"
#include "pybind11.hpp"

namespace {

py::dict simulate_py(const lptv::Model& model, const Eigen::MatrixXcd& U, const std::string& solver,
                     int lines_out, int guard, double tol, int max_guard) {
  lptv::SimulateOptions opt;
  opt.solver = lptv::solver_from_string(solver);
  opt.lines_out = lines_out;
  opt.guard = guard;
  opt.tol = tol;
  opt.max_guard = max_guard;
  lptv::SimulateResult r;
  {
    // The factorisation and solves touch no Python object.
    py::gil_scoped_release release;
    r = lptv::simulate(model, U, opt);
  }
  py::dict d;
  d["Y"] = py::cast(std::move(r.Y));  // moved into the array's owner: no copy of the output
  d["guard"] = r.guard;
  d["truncation_error"] = r.truncation_error;
  d["converged"] = r.converged;
  d["solver"] = lptv::solver_name(r.solver);
  d["condition"] = r.condition;
  d["condition_line"] = r.condition_line;
  return d;
}

Eigen::MatrixXcd htf_py(const lptv::Model& model, int L, const std::vector<int>& lines,
                        const std::string& solver) {
  py::gil_scoped_release release;  // pure C++ work
  lptv::Fds fds(model, L, lptv::solver_from_string(solver));
  return fds.htf_columns(lines);
}

Eigen::SparseMatrix<std::complex<double>> band_py(const lptv::Model& model, int L, bool a) {
  const lptv::Grid g = lptv::make_grid(model, L);
  return a ? lptv::build_A(model, g) : lptv::build_B(model, g);
}

}  // namespace

void bind_fds(py::module_& m) {
  m.def("simulate", &simulate_py, "model"_a, "U"_a, "solver"_a = "auto", "lines_out"_a = -1,
        "guard"_a = -1, "tol"_a = 1e-13, "max_guard"_a = -1);
  m.attr("FDS_WARN_CONDITION") = lptv::Fds::kWarnCondition;
  m.attr("FDS_MAX_CONDITION") = lptv::Fds::kMaxCondition;
  m.def("htf", &htf_py, "model"_a, "L"_a, "lines"_a, "solver"_a = "auto");
  m.def("band_matrix", &band_py, "model"_a, "L"_a, "a"_a = true);
  m.def("default_solver", [](bool discrete) { return lptv::solver_name(lptv::default_solver(discrete)); },
        "discrete"_a = false);
}
