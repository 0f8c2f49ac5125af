// Nonparametric noise model from P steady-state periods (METHOD.md section 4).
#pragma once
#include <Eigen/Dense>
#include <complex>

namespace lptv {

// Sample means of the spectra and the (co)variances of those means, per line.
struct FrequencyData {
  Eigen::VectorXcd U, Y;    // mean spectra, lines 0..Lmax (X_l = fft(x)[l] / N)
  Eigen::VectorXd varU;     // variance of the mean of U, per line
  Eigen::VectorXd varY;     // variance of the mean of Y
  Eigen::VectorXcd covYU;   // E{dY conj(dU)} of the means
  int periods = 0;          // P (0 when the statistics came from elsewhere)

  int max_line() const { return static_cast<int>(U.size()) - 1; }
  // Throws std::invalid_argument naming the field when sizes differ, values are
  // not finite or variances are negative.
  void validate() const;
};

// u, y: P x N (one period per row, P >= 2). Lines 0..N/2.
FrequencyData frequency_data_from_periods(const Eigen::MatrixXd& u, const Eigen::MatrixXd& y);

// The same statistics from the periods' spectra: Up, Yp are P x (Lmax + 1), row p the spectrum
// of period p on lines 0..Lmax (fft(x_p)[l] / N), P >= 2. For callers with an FFT of their own
// (the Python package uses NumPy's, which transforms the P periods about three times as fast as
// Eigen's).
using PeriodSpectra = Eigen::Matrix<std::complex<double>, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
FrequencyData frequency_data_from_period_spectra(const Eigen::Ref<const PeriodSpectra>& Up,
                                                 const Eigen::Ref<const PeriodSpectra>& Yp);

}  // namespace lptv
