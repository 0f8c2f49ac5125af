#include <optional>

#include "lptv/record.hpp"
#include "pybind11.hpp"

void bind_record(py::module_& m) {
  py::class_<lptv::RecordFit>(m, "RecordFit", "One record with its transient (lptv::fit_record).")
      .def_readonly("eta", &lptv::RecordFit::eta, "xi with xi[norm_index] = 1")
      .def_readonly("theta", &lptv::RecordFit::theta)
      .def_readonly("covariance", &lptv::RecordFit::covariance,
                    "of eta: the inverse Fisher information of the output error at the estimate")
      .def_readonly("transient", &lptv::RecordFit::transient,
                    "c_1..c_n of T(z) = sum c_j z^j; continuous time c_0..c_d of sum c_j (j w ts)^j")
      .def_readonly("transient_std", &lptv::RecordFit::transient_std)
      .def_readonly("start", &lptv::RecordFit::start, "[free eta, c] from the weighted equation error")
      .def_readonly("noise_var", &lptv::RecordFit::noise_var)
      .def_readonly("noise_dof", &lptv::RecordFit::noise_dof)
      .def_readonly("Y_fit", &lptv::RecordFit::Y_fit)
      .def_readonly("cost", &lptv::RecordFit::cost)
      .def_readonly("dof", &lptv::RecordFit::dof)
      .def_readonly("converged", &lptv::RecordFit::converged)
      .def_readonly("iterations", &lptv::RecordFit::iterations, "Levenberg-Marquardt iterations of the last fit")
      .def_readonly("evaluations", &lptv::RecordFit::evaluations, "factorisations of A, all fits")
      .def_readonly("fits", &lptv::RecordFit::fits);
  m.def(
      "fit_record",
      [](const lptv::Parametrisation& p, Eigen::VectorXcd U, Eigen::VectorXcd Y, int periods, std::vector<int> lines,
         bool transient, std::optional<Eigen::VectorXd> noise_var, int noise_width, int reweightings,
         int max_iterations, double tol, double ts, int transient_degree) {
        lptv::RecordData d{std::move(U), std::move(Y), periods, std::move(lines), ts};
        lptv::RecordOptions opt;
        opt.transient = transient;
        opt.transient_degree = transient_degree;
        if (noise_var) {
          opt.noise = lptv::RecordNoise::Given;
          opt.noise_var = std::move(*noise_var);
        }
        opt.noise_width = noise_width;
        opt.reweightings = reweightings;
        opt.max_iterations = max_iterations;
        opt.tol = tol;
        py::gil_scoped_release release;  // factorisations and solves on the record's grid, all C++
        return lptv::fit_record(p, d, opt);
      },
      "par"_a, "U"_a, "Y"_a, "periods"_a, "lines"_a, "transient"_a = true, "noise_var"_a = py::none(),
      "noise_width"_a = 10, "reweightings"_a = 2, "max_iterations"_a = 100, "tol"_a = 1e-12, "ts"_a = 0.0,
      "transient_degree"_a = -1,
      R"doc(An LPTV model and the transient term fitted to one record (METHOD.md section 17).

Parameters
----------
par : Parametrisation
    The structure: discrete time (its ts the record's sample time), or continuous time (ts = 0)
    with the record's sample time in ``ts``.
U, Y : ndarray, shape (N,), complex
    The record's DFT on all N = periods N0 lines: X_l = fft(x)[l] / N.
periods : int
    L, whole parameter periods in the record.
lines : list of int
    The lines fitted, ascending, within 1..(N-1)/2.
transient : bool
    Fit T(z) = sum_{j=1}^{n} c_j z^j, n = max(na, nb); continuous time
    T = sum_{j=0}^{d} c_j (j w_l ts)^j.
noise_var : ndarray, optional
    E|V_l|^2 per fitted line; None: from the fit's residual, each line's over its share
    1 - h_l (h_l its leverage), averaged over 2 noise_width + 1 lines, then the fit repeated
    ``reweightings`` times.
noise_width, reweightings : int
max_iterations : int
    Levenberg-Marquardt iterations per fit.
tol : float
    Relative tolerance of the cost's decrease, the step and the gradient's cosine.
ts : float
    Continuous time: the record's sample time (> 0); discrete time: 0 or the structure's ts.
transient_degree : int
    Continuous time: d (>= n - 1), -1 for n + 1; discrete time: -1 only.

Returns
-------
RecordFit
)doc");
  m.def(
      "record_prediction",
      [](const lptv::Parametrisation& p, Eigen::VectorXcd U, int periods, const Eigen::VectorXd& eta_free,
         const Eigen::VectorXd& c, double ts, int transient_degree) {
        lptv::RecordData d{U, U, periods, {1}, ts};
        py::gil_scoped_release release;
        return lptv::record_prediction(p, d, eta_free, c, transient_degree);
      },
      "par"_a, "U"_a, "periods"_a, "eta_free"_a, "c"_a, "ts"_a = 0.0, "transient_degree"_a = -1,
      "Y_hat = A^-1 (B U - T(c)) on all N lines of the record's grid (continuous time: the lines -M..M, "
      "M = (N - 1) // 2, at index l + M; eta_free: the free parameters).");
  m.def(
      "record_regression",
      [](const lptv::Parametrisation& p, Eigen::VectorXcd U, Eigen::VectorXcd Y, int periods, std::vector<int> lines,
         bool transient, double ts, int transient_degree) {
        lptv::RecordData d{std::move(U), std::move(Y), periods, std::move(lines), ts};
        const lptv::RecordRegression r = lptv::record_regression(p, d, transient, transient_degree);
        return py::make_tuple(r.M, r.e0);
      },
      "par"_a, "U"_a, "Y"_a, "periods"_a, "lines"_a, "transient"_a = true, "ts"_a = 0.0, "transient_degree"_a = -1,
      "The equation error on the lines, E = M x + e0 for x = [free eta, c]: (M, e0).");
}
