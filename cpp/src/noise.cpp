#include "lptv/noise.hpp"

#include <unsupported/Eigen/FFT>

#include <cmath>
#include <stdexcept>
#include <string>

#include "lptv/multisine.hpp"

namespace lptv {

void FrequencyData::validate() const {
  const Eigen::Index n = U.size();
  if (n < 1) throw std::invalid_argument("U must not be empty");
  auto same = [n](Eigen::Index m, const char* name) {
    if (m != n) {
      throw std::invalid_argument(std::string(name) + " must have " + std::to_string(n) +
                                  " lines like U, got " + std::to_string(m));
    }
  };
  same(Y.size(), "Y");
  same(varU.size(), "varU");
  same(varY.size(), "varY");
  same(covYU.size(), "covYU");
  if (!U.allFinite()) throw std::invalid_argument("U contains NaN or inf");
  if (!Y.allFinite()) throw std::invalid_argument("Y contains NaN or inf");
  if (!varU.allFinite() || (varU.array() < 0).any())
    throw std::invalid_argument("varU must be finite and >= 0");
  if (!varY.allFinite() || (varY.array() < 0).any())
    throw std::invalid_argument("varY must be finite and >= 0");
  if (!covYU.allFinite()) throw std::invalid_argument("covYU contains NaN or inf");
  if (noiseU.size() || noiseY.size()) {
    if (noiseU.cols() != n || noiseY.cols() != n || noiseU.rows() != noiseY.rows())
      throw std::invalid_argument("noiseU and noiseY must both have " + std::to_string(n) +
                                  " columns (lines) and the same rows (realisations)");
    if (!noiseU.allFinite() || !noiseY.allFinite())
      throw std::invalid_argument("noiseU, noiseY contain NaN or inf");
  }
}

FrequencyData frequency_data_from_periods(const Eigen::MatrixXd& u, const Eigen::MatrixXd& y) {
  if (u.rows() != y.rows() || u.cols() != y.cols()) {
    throw std::invalid_argument("u and y must have the same shape (P, N), got (" +
                                std::to_string(u.rows()) + ", " + std::to_string(u.cols()) +
                                ") and (" + std::to_string(y.rows()) + ", " +
                                std::to_string(y.cols()) + ")");
  }
  const int P = static_cast<int>(u.rows());
  if (P < 2) {
    throw std::invalid_argument("u, y: at least 2 periods are needed for a noise model, got " +
                                std::to_string(P));
  }
  if (u.cols() < 2) throw std::invalid_argument("u, y: a period needs at least 2 samples");
  if (!u.allFinite()) throw std::invalid_argument("u contains NaN or inf");
  if (!y.allFinite()) throw std::invalid_argument("y contains NaN or inf");
  const Eigen::Index N = u.cols(), nl = N / 2 + 1;
  PeriodSpectra Up(P, nl), Yp(P, nl);
  // One FFT object for every period (its plan and twiddles made once), half spectra only.
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  Eigen::VectorXd row(N);
  Eigen::VectorXcd X(nl);
  const double inv_n = 1.0 / double(N);
  for (int p = 0; p < P; ++p) {
    row = u.row(p).transpose();
    fft.fwd(X, row);
    Up.row(p) = X.head(nl).transpose() * inv_n;
    row = y.row(p).transpose();
    fft.fwd(X, row);
    Yp.row(p) = X.head(nl).transpose() * inv_n;
  }
  return frequency_data_from_period_spectra(Up, Yp);
}

FrequencyData frequency_data_from_period_spectra(const Eigen::Ref<const PeriodSpectra>& Up,
                                                 const Eigen::Ref<const PeriodSpectra>& Yp) {
  if (Up.rows() != Yp.rows() || Up.cols() != Yp.cols()) {
    throw std::invalid_argument("Up and Yp must have the same shape (P, lines), got (" +
                                std::to_string(Up.rows()) + ", " + std::to_string(Up.cols()) + ") and (" +
                                std::to_string(Yp.rows()) + ", " + std::to_string(Yp.cols()) + ")");
  }
  const int P = static_cast<int>(Up.rows());
  if (P < 2) {
    throw std::invalid_argument("u, y: at least 2 periods are needed for a noise model, got " +
                                std::to_string(P));
  }
  if (Up.cols() < 1) throw std::invalid_argument("Up, Yp: no lines");
  if (!Up.allFinite()) throw std::invalid_argument("Up contains NaN or inf");
  if (!Yp.allFinite()) throw std::invalid_argument("Yp contains NaN or inf");
  const Eigen::Index nl = Up.cols();
  FrequencyData d;
  d.periods = P;
  d.U = Up.colwise().mean().transpose();
  d.Y = Yp.colwise().mean().transpose();
  d.varU.resize(nl);
  d.varY.resize(nl);
  d.covYU.resize(nl);
  const double scale = 1.0 / (double(P) * double(P - 1));  // variance of the mean
  for (Eigen::Index l = 0; l < nl; ++l) {
    double vu = 0, vy = 0;
    std::complex<double> c = 0;
    for (int p = 0; p < P; ++p) {
      const std::complex<double> du = Up(p, l) - d.U[l], dy = Yp(p, l) - d.Y[l];
      vu += std::norm(du);
      vy += std::norm(dy);
      c += dy * std::conj(du);
    }
    d.varU[l] = vu * scale;
    d.varY[l] = vy * scale;
    d.covYU[l] = c * scale;
  }
  return d;
}

FrequencyData frequency_data_from_record_spectra(const Eigen::Ref<const PeriodSpectra>& Up,
                                                 const Eigen::Ref<const PeriodSpectra>& Yp,
                                                 const Eigen::Ref<const Eigen::VectorXcd>& Ur,
                                                 const Eigen::Ref<const Eigen::VectorXcd>& Yr, int n_per_period) {
  FrequencyData d = frequency_data_from_period_spectra(Up, Yp);  // the checks, the means
  const int P = d.periods;
  const Eigen::Index nl = Up.cols();
  const long N = n_per_period;
  if (N < 2 || N / 2 + 1 != nl) {
    throw std::invalid_argument("n_per_period: " + std::to_string(N) + " samples a period do not give the " +
                                std::to_string(nl) + " lines of Up");
  }
  const long nb = long(P) * N / 2 + 1;
  if (Ur.size() != nb || Yr.size() != nb) {
    throw std::invalid_argument("Ur, Yr must hold the " + std::to_string(nb) + " bins 0..P N / 2 of the record, got " +
                                std::to_string(Ur.size()) + " and " + std::to_string(Yr.size()));
  }
  if (!Ur.allFinite()) throw std::invalid_argument("Ur contains NaN or inf");
  if (!Yr.allFinite()) throw std::invalid_argument("Yr contains NaN or inf");
  const int Q = P - 1;
  d.noiseU.resize(Q, nl);
  d.noiseY.resize(Q, nl);
  // lines whose bins lie strictly inside the half spectrum: 1 .. Lmax - 1, and Lmax for odd N
  const Eigen::Index last = (N % 2 == 0) ? nl - 2 : nl - 1;
  const double rq = 1.0 / std::sqrt(double(Q));
  const int qlo = -((P + 1) / 2) + 1;  // -ceil(P/2) + 1
  d.noise_offset.resize(Q);
  for (int q = qlo, j = 0; q <= P / 2; ++q)
    if (q != 0) d.noise_offset[j++] = double(q) / double(P);
  d.noise_first = 1;
  d.noise_last = static_cast<int>(last);
  for (Eigen::Index l = 0; l < nl; ++l) {
    if (l >= 1 && l <= last) {
      int j = 0;
      for (int q = qlo; q <= P / 2; ++q) {
        if (q == 0) continue;
        const long b = long(l) * P + q;
        d.noiseU(j, l) = Ur[b] * rq;
        d.noiseY(j, l) = Yr[b] * rq;
        ++j;
      }
    } else {
      // Helmert contrasts h_j = (sum_{p<j} x_p - j x_j) / sqrt(j (j + 1)), j = 1..P-1: orthonormal,
      // sum_j |h_j|^2 = sum_p |x_p - mean|^2; scaled to the variance of the mean
      const double s = 1.0 / std::sqrt(double(P) * double(P - 1));
      std::complex<double> cu = 0, cy = 0;
      for (int jj = 1; jj < P; ++jj) {
        cu += Up(jj - 1, l);
        cy += Yp(jj - 1, l);
        const double h = 1.0 / std::sqrt(double(jj) * double(jj + 1));
        d.noiseU(jj - 1, l) = (cu - double(jj) * Up(jj, l)) * (h * s);
        d.noiseY(jj - 1, l) = (cy - double(jj) * Yp(jj, l)) * (h * s);
      }
    }
    double vu = 0, vy = 0;
    std::complex<double> c = 0;
    for (int j = 0; j < Q; ++j) {
      vu += std::norm(d.noiseU(j, l));
      vy += std::norm(d.noiseY(j, l));
      c += d.noiseY(j, l) * std::conj(d.noiseU(j, l));
    }
    d.varU[l] = vu;
    d.varY[l] = vy;
    d.covYU[l] = c;
  }
  return d;
}

}  // namespace lptv
