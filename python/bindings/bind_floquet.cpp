#include "lptv/floquet.hpp"
#include "pybind11.hpp"

void bind_floquet(py::module_& m) {
  py::class_<lptv::Floquet>(m, "Floquet", "Characteristic multipliers and Floquet exponents (lptv::floquet).")
      .def_readonly("multipliers", &lptv::Floquet::multipliers)
      .def_readonly("exponents", &lptv::Floquet::exponents)
      .def_readonly("error_estimate", &lptv::Floquet::error_estimate)
      .def_readonly("spectral_radius", &lptv::Floquet::spectral_radius)
      .def_readonly("is_stable", &lptv::Floquet::is_stable)
      .def_readonly("truncation", &lptv::Floquet::truncation)
      .def_readonly("harmonics", &lptv::Floquet::harmonics)
      .def_readonly("convergence", &lptv::Floquet::convergence)
      .def_readonly("method", &lptv::Floquet::method);
  m.def("floquet", [](const lptv::Model& model, double tol, int min_truncation, int max_truncation) {
    lptv::FloquetOptions opt;
    opt.tol = tol;
    opt.min_truncation = min_truncation;
    opt.max_truncation = max_truncation;
    py::gil_scoped_release release;  // the eigenvalue problems are C++ only
    return lptv::floquet(model, opt);
  }, "model"_a, "tol"_a = 1e-11, "min_truncation"_a = 8, "max_truncation"_a = 256,
        "Multipliers and exponents of the homogeneous equation (see lptv.floquet for the documented API).");
  py::class_<lptv::FloquetSensitivity>(m, "FloquetSensitivity",
                                       "Floquet exponents with their first-order sensitivity to a(t) (lptv::floquet_sensitivity).")
      .def_readonly("floquet", &lptv::FloquetSensitivity::floquet)
      .def_readonly("gradient", &lptv::FloquetSensitivity::gradient)
      .def_readonly("condition", &lptv::FloquetSensitivity::condition);
  m.def("floquet_sensitivity", [](const lptv::Model& model, double tol, int min_truncation, int max_truncation) {
    lptv::FloquetOptions opt;
    opt.tol = tol;
    opt.min_truncation = min_truncation;
    opt.max_truncation = max_truncation;
    py::gil_scoped_release release;  // the eigenvalue problems are C++ only
    return lptv::floquet_sensitivity(model, opt);
  }, "model"_a, "tol"_a = 1e-11, "min_truncation"_a = 8, "max_truncation"_a = 256,
        "Floquet exponents with d lambda_i / d a_{n,h} (gradient[i], (na+1) x (2Ka+1)) and each eigenvalue's\n"
        "condition number (see lptv.floquet of an identification result).");
  m.def("floquet_mimo", [](const lptv::MimoModel& model, double tol, int min_truncation, int max_truncation) {
    lptv::FloquetOptions opt;
    opt.tol = tol;
    opt.min_truncation = min_truncation;
    opt.max_truncation = max_truncation;
    py::gil_scoped_release release;  // the eigenvalue problems are C++ only
    return lptv::floquet(model, opt);
  }, "model"_a, "tol"_a = 1e-11, "min_truncation"_a = 8, "max_truncation"_a = 256,
        "Multipliers and exponents of the matrix system (see lptv.floquet for the documented API).");
  m.def("monodromy_mimo", py::overload_cast<const lptv::MimoModel&, int>(&lptv::monodromy), "model"_a, "steps"_a,
        py::call_guard<py::gil_scoped_release>(),
        "Monodromy matrix of the matrix system's state form by products (Magnus steps and Richardson, or the\n"
        "one-step matrices in discrete time).");
  m.def("mimo_row_degrees", &lptv::row_degrees, "model"_a, "The row degrees d_p of A(t, s).");
  m.def("mimo_state_matrix", &lptv::state_matrix_at, "model"_a, "t"_a,
        "The state (one-step) matrix of the matrix system's observer form at time t.");
  py::class_<lptv::ProductRadius>(m, "ProductRadius",
                                  "The spectral radius of the monodromy matrix by products (lptv::product_spectral_radius).")
      .def_readonly("settled", &lptv::ProductRadius::settled)
      .def_readonly("rho", &lptv::ProductRadius::rho)
      .def_readonly("steps", &lptv::ProductRadius::steps)
      .def_readonly("reason", &lptv::ProductRadius::reason);
  m.def("product_spectral_radius", &lptv::product_spectral_radius, "model"_a, "first_steps"_a, "max_steps"_a,
        py::call_guard<py::gil_scoped_release>(),
        "Monodromy products with first_steps, 2 first_steps, ... steps until two successive spectral radii\n"
        "differ by less than a tenth of their distance to 1 (lptv.floquet.stability_check's first route).");
  m.def("monodromy", py::overload_cast<const lptv::Model&, int>(&lptv::monodromy), "model"_a, "steps"_a, py::call_guard<py::gil_scoped_release>(),
        "Monodromy matrix by the product of matrix exponentials (continuous time, `steps` Magnus steps\n"
        "and Richardson) or of the one-step companion matrices (discrete time).");
}
