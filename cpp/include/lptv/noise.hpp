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
  // Realisations of the noise of the means (METHOD.md section 20): row q of noiseU and noiseY is
  // one draw of every line's noise, scaled so that sum_q |noiseU(q, l)|^2 = varU[l] (and so on
  // for varY and covYU). Empty unless the statistics were formed from them
  // (frequency_data_from_record_spectra); with them the rows' noise can hold the terms between
  // lines and between input and output that the per-line (co)variances drop.
  Eigen::Matrix<std::complex<double>, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> noiseU, noiseY;
  // Realisation q lies at line l + noise_offset[q] (the record's bin l P + q, offset q / P) on
  // the lines noise_first..noise_last; the other lines' realisations (Helmert contrasts of the
  // periods) are not the same draws and hold no terms between lines.
  Eigen::VectorXd noise_offset;
  int noise_first = 0, noise_last = -1;

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

// The statistics from the whole record's spectrum (METHOD.md section 20): Up, Yp as above (P x
// (Lmax + 1), the periods' spectra, for the means and the lines 0 and N/2), Ur, Yr the DFT of the
// P periods concatenated on the bins 0 .. floor(P N / 2), scaled by 1 / (P N), N = n_per_period.
// Bin l P is the mean of line l; the P - 1 bins l P + q (q = -ceil(P/2) + 1 .. floor(P/2), q != 0)
// between the lines hold the noise alone, and the boundary terms of a response that does not
// repeat telescope in them as they do in the mean. Lines 1 .. Lmax - 1 (and Lmax for odd N)
// take their (co)variances from those bins, lines 0 and N/2 from the periods (Helmert contrasts:
// the sample (co)variances of section 4); noiseU, noiseY hold the P - 1 realisations.
FrequencyData frequency_data_from_record_spectra(const Eigen::Ref<const PeriodSpectra>& Up,
                                                 const Eigen::Ref<const PeriodSpectra>& Yp,
                                                 const Eigen::Ref<const Eigen::VectorXcd>& Ur,
                                                 const Eigen::Ref<const Eigen::VectorXcd>& Yr, int n_per_period);

}  // namespace lptv
