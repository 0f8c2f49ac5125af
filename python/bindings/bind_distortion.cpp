#include "lptv/distortion.hpp"
#include "pybind11.hpp"

void bind_distortion(py::module_& m) {
  py::class_<lptv::DistortionLines>(
      m, "DistortionLines",
      "Per output line: the regression of the realisations' Y_j on the excited lines within "
      "+-Kh (lptv::distortion_lines).")
      .def_readonly("lines", &lptv::DistortionLines::lines)
      .def_readonly("excited", &lptv::DistortionLines::excited)
      .def_readonly("branches", &lptv::DistortionLines::branches)
      .def_readonly("realisations", &lptv::DistortionLines::realisations)
      .def_readonly("signal", &lptv::DistortionLines::signal)
      .def_readonly("total", &lptv::DistortionLines::total)
      .def_readonly("noise", &lptv::DistortionLines::noise)
      .def_readonly("dof", &lptv::DistortionLines::dof)
      .def_readonly("regressors", &lptv::DistortionLines::regressors)
      .def_readonly("bla", &lptv::DistortionLines::bla)
      .def_readonly("bla_var", &lptv::DistortionLines::bla_var);
  m.def(
      "distortion_lines",
      [](Eigen::MatrixXcd U, Eigen::MatrixXcd Y, Eigen::MatrixXd varU, Eigen::MatrixXd varY,
         Eigen::MatrixXcd covYU, std::vector<int> excited, int branches) {
        lptv::DistortionInput in{std::move(U), std::move(Y), std::move(varU), std::move(varY),
                                 std::move(covYU), std::move(excited), branches};
        py::gil_scoped_release release;  // one small least-squares problem per line, all C++
        return lptv::distortion_lines(in);
      },
      "U"_a, "Y"_a, "varU"_a, "varY"_a, "covYU"_a, "excited"_a, "branches"_a,
      R"doc(Noise, residual variance and BLA per output line from M random-phase realisations.

Parameters
----------
U, Y : ndarray, shape (M, L + 1), complex
    Period-mean spectra of each realisation on lines 0..L.
varU, varY : ndarray, shape (M, L + 1), float
    Noise variances of those means.
covYU : ndarray, shape (M, L + 1), complex
    E{dY conj(dU)} of the means.
excited : list of int
    Excited lines, ascending, within 1..L.
branches : int
    Kh: line j regresses on the excited lines c (and conjugates -c) with |j - c| <= Kh.

Returns
-------
DistortionLines
)doc");
}
