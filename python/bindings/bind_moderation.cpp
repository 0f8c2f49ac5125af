#include "lptv/moderation.hpp"
#include "pybind11.hpp"

void bind_moderation(py::module_& m) {
  m.attr("MODERATION_OUTLIER_RATE") = lptv::kModerationOutlierRate;
  m.attr("MODERATION_MAX_PRIOR_DOF") = lptv::kModerationMaxPriorDof;
  py::class_<lptv::ModeratedNoise>(
      m, "ModeratedNoise",
      "Noise (co)variances moderated across neighbouring lines (lptv::moderated_noise).")
      .def_readonly("data", &lptv::ModeratedNoise::data)
      .def_readonly("dof", &lptv::ModeratedNoise::dof)
      .def_readonly("prior_dof", &lptv::ModeratedNoise::prior_dof)
      .def_readonly("trend_residual_u", &lptv::ModeratedNoise::trend_residual_u)
      .def_readonly("trend_residual_y", &lptv::ModeratedNoise::trend_residual_y)
      .def_readonly("outliers", &lptv::ModeratedNoise::outliers)
      .def_readonly("half_width", &lptv::ModeratedNoise::half_width)
      .def_readonly("moderated", &lptv::ModeratedNoise::moderated)
      .def_readonly("own_weight", &lptv::ModeratedNoise::own_weight)
      .def_readonly("neighbour", &lptv::ModeratedNoise::neighbour)
      .def_readonly("source_varU", &lptv::ModeratedNoise::source_varU)
      .def_readonly("source_varY", &lptv::ModeratedNoise::source_varY)
      .def("error_covariance", &lptv::ModeratedNoise::error_covariance, "lines"_a,
           "Covariance of the relative sampling errors of the moderated variances on lines.");
  m.def(
      "moderated_noise",
      [](const lptv::FrequencyData& data, int half_width) {
        py::gil_scoped_release release;  // vector arithmetic over the lines, all C++
        return lptv::moderated_noise(data, half_width);
      },
      "data"_a, "half_width"_a,
      R"doc(The noise (co)variances of data moderated across the lines within +-half_width.

Parameters
----------
data : FrequencyData
    Spectra and noise statistics from P >= 2 periods (otherwise returned unchanged).
half_width : int
    The neighbours of a line: the lines within +-half_width (>= 1).

Returns
-------
ModeratedNoise
)doc");
  py::class_<lptv::ModeratedCovariances>(
      m, "ModeratedCovariances",
      "Covariance matrices of several channels moderated across neighbouring lines (lptv::moderated_covariances).")
      .def_readonly("covariance", &lptv::ModeratedCovariances::covariance)
      .def_readonly("dof", &lptv::ModeratedCovariances::dof)
      .def_readonly("prior_dof", &lptv::ModeratedCovariances::prior_dof)
      .def_readonly("outliers", &lptv::ModeratedCovariances::outliers)
      .def_readonly("half_width", &lptv::ModeratedCovariances::half_width)
      .def_readonly("moderated", &lptv::ModeratedCovariances::moderated)
      .def_readonly("own_weight", &lptv::ModeratedCovariances::own_weight)
      .def_readonly("neighbour", &lptv::ModeratedCovariances::neighbour);
  m.def(
      "moderated_covariances",
      [](const Eigen::MatrixXcd& C, int n_outputs, int periods, int half_width) {
        py::gil_scoped_release release;
        return lptv::moderated_covariances(C, n_outputs, periods, half_width);
      },
      "C"_a, "n_outputs"_a, "periods"_a, "half_width"_a,
      R"doc(The covariance matrices of the means of c channels (outputs first) moderated across lines.

Parameters
----------
C : complex array, shape ((L+1) c, c)
    Rows l c .. l c + c - 1: the covariance matrix of the mean [Y_l; U_l] on line l.
n_outputs : int
    ny, 1..c-1.
periods : int
    P (returned unchanged below 2).
half_width : int
    The neighbours of a line: the lines within +-half_width (>= 1).

Returns
-------
ModeratedCovariances
)doc");
  m.def("digamma", &lptv::digamma, "x"_a, "The digamma function psi(x), x > 0.");
  m.def("trigamma", &lptv::trigamma, "x"_a, "The trigamma function psi'(x), x > 0.");
  m.def("tetragamma", &lptv::tetragamma, "x"_a, "The tetragamma function psi''(x), x > 0.");
  m.def("trigamma_inverse", &lptv::trigamma_inverse, "x"_a, "y > 0 with trigamma(y) = x.");
  m.def("incomplete_beta", &lptv::incomplete_beta, "a"_a, "b"_a, "x"_a,
        "The regularized incomplete beta function I_x(a, b).");
  m.def("f_upper_quantile", &lptv::f_upper_quantile, "p"_a, "d1"_a, "d2"_a,
        "f with P(F(d1, d2) > f) = p.");
}
