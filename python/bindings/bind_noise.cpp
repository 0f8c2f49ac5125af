#include "lptv/noise.hpp"
#include <stdexcept>
#include <string>

#include "pybind11.hpp"

void bind_noise(py::module_& m) {
  py::class_<lptv::FrequencyData>(m, "FrequencyData",
                                  "Mean spectra on lines 0..Lmax and the (co)variances of the means.")
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
      .def_static("from_period_spectra", [](const Eigen::Ref<const lptv::PeriodSpectra>& Up,
                                            const Eigen::Ref<const lptv::PeriodSpectra>& Yp) {
        return lptv::frequency_data_from_period_spectra(Up, Yp);
      }, "Up"_a, "Yp"_a,
        "The statistics of from_periods from the periods' spectra: Up, Yp of shape (P, lines), row p "
        "the spectrum of period p (fft / N) on lines 0..Lmax.")
      .def_static("from_record_spectra", [](const Eigen::Ref<const lptv::PeriodSpectra>& Up,
                                            const Eigen::Ref<const lptv::PeriodSpectra>& Yp,
                                            const Eigen::Ref<const Eigen::VectorXcd>& Ur,
                                            const Eigen::Ref<const Eigen::VectorXcd>& Yr, int n_per_period) {
        return lptv::frequency_data_from_record_spectra(Up, Yp, Ur, Yr, n_per_period);
      }, "Up"_a, "Yp"_a, "Ur"_a, "Yr"_a, "n_per_period"_a,
        "The statistics from the record's bins between the lines (METHOD.md section 20): Up, Yp the "
        "periods' spectra (P, lines), Ur, Yr the rfft of the P periods concatenated / (P N).")
      .def_static("with_realisations", [](const lptv::FrequencyData& d, const lptv::PeriodSpectra& nU,
                                          const lptv::PeriodSpectra& nY, const lptv::FrequencyData& like) {
        lptv::FrequencyData out = d;
        out.noiseU = nU;
        out.noiseY = nY;
        out.noise_offset = like.noise_offset;
        out.noise_first = like.noise_first;
        out.noise_last = like.noise_last;
        out.validate();
        if (out.noiseU.rows() != like.noiseU.rows())
          throw std::invalid_argument("noiseU, noiseY must have the realisations of like (" +
                                      std::to_string(like.noiseU.rows()) + " rows)");
        return out;
      }, "data"_a, "noiseU"_a, "noiseY"_a, "like"_a,
        "A copy of data with the noise realisations noiseU, noiseY on the lines and offsets of like's.")
      .def_readonly("noiseU", &lptv::FrequencyData::noiseU)
      .def_readonly("noiseY", &lptv::FrequencyData::noiseY)
      .def_readonly("noise_offset", &lptv::FrequencyData::noise_offset)
      .def_readonly("noise_first", &lptv::FrequencyData::noise_first)
      .def_readonly("noise_last", &lptv::FrequencyData::noise_last)
      .def_readonly("U", &lptv::FrequencyData::U)
      .def_readonly("Y", &lptv::FrequencyData::Y)
      .def_readonly("varU", &lptv::FrequencyData::varU)
      .def_readonly("varY", &lptv::FrequencyData::varY)
      .def_readonly("covYU", &lptv::FrequencyData::covYU)
      .def_readonly("periods", &lptv::FrequencyData::periods)
      .def_property_readonly("max_line", &lptv::FrequencyData::max_line);
}
