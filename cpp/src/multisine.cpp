#include "lptv/multisine.hpp"

#include <unsupported/Eigen/FFT>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lptv {

// A period longer than the largest simulation grid (2^26 lines each side, fds.cpp) cannot be
// simulated; refusing it here also keeps the FFT's buffers (about 56 bytes a sample) in memory
// instead of failing the allocation.
static void check_n_samples(int n_samples) {
  constexpr int kMaxSamples = 2 * (1 << 26) + 1;
  if (n_samples < 1) throw std::invalid_argument("n_samples must be >= 1, got " + std::to_string(n_samples));
  if (n_samples > kMaxSamples) {
    const double gb = 56.0 * static_cast<double>(n_samples) / 1e9;
    throw std::invalid_argument("n_samples = " + std::to_string(n_samples) + " is too large (at most " +
                                std::to_string(kMaxSamples) + ", the largest simulation grid): the " +
                                "signal and its FFT would take about " +
                                std::to_string(static_cast<long long>(gb + 0.5)) + " GB");
  }
}

Eigen::VectorXcd multisine_spectrum(const std::vector<int>& lines, const Eigen::VectorXd& amplitudes,
                                    const Eigen::VectorXd& phases, int n_samples) {
  check_n_samples(n_samples);
  if (amplitudes.size() != static_cast<Eigen::Index>(lines.size()) ||
      phases.size() != static_cast<Eigen::Index>(lines.size())) {
    throw std::invalid_argument("amplitudes and phases must have one entry per line");
  }
  if (!amplitudes.allFinite() || !phases.allFinite()) {
    throw std::invalid_argument("amplitudes and phases must be finite");
  }
  const int half = n_samples / 2;
  Eigen::VectorXcd X = Eigen::VectorXcd::Zero(half + 1);
  for (size_t i = 0; i < lines.size(); ++i) {
    const int l = lines[i];
    if (l < 0 || l > half) {
      throw std::invalid_argument("lines: line " + std::to_string(l) + " is outside 0.." +
                                  std::to_string(half) + " (n_samples/2)");
    }
    if (l == 0 || (n_samples % 2 == 0 && l == half)) {
      X[l] += amplitudes[i] * std::cos(phases[i]);  // a real line holds the full cosine
    } else {
      X[l] += 0.5 * amplitudes[i] * std::polar(1.0, phases[i]);
    }
  }
  return X;
}

Eigen::VectorXd time_signal(const Eigen::VectorXcd& X, int n_samples) {
  check_n_samples(n_samples);
  if (!X.allFinite()) throw std::invalid_argument("X contains NaN or inf");
  const int half = n_samples / 2;
  if (X.size() < 1 || X.size() - 1 > half) {
    throw std::invalid_argument("X must have between 1 and n_samples/2+1 lines");
  }
  if (n_samples == 1) return Eigen::VectorXd::Constant(1, X[0].real());  // Eigen's FFT needs N >= 2
  std::vector<std::complex<double>> full(n_samples, 0.0);
  for (Eigen::Index l = 0; l < X.size(); ++l) {
    full[l] += X[l];
    if (l > 0 && !(n_samples % 2 == 0 && l == half)) full[n_samples - l] += std::conj(X[l]);
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> x;
  fft.inv(x, full);  // Eigen's inverse divides by N; undo it for our scaling
  Eigen::VectorXd out(n_samples);
  for (int t = 0; t < n_samples; ++t) out[t] = x[t].real() * n_samples;
  return out;
}

Eigen::VectorXcd spectrum(const Eigen::VectorXd& x) {
  const int n = static_cast<int>(x.size());
  if (n < 1) throw std::invalid_argument("x must not be empty");
  if (!x.allFinite()) throw std::invalid_argument("x contains NaN or inf");
  if (n == 1) return Eigen::VectorXcd::Constant(1, x[0]);  // Eigen's FFT needs N >= 2
  Eigen::FFT<double> fft;
  std::vector<double> in(x.data(), x.data() + n);
  std::vector<std::complex<double>> X;
  fft.fwd(X, in);
  Eigen::VectorXcd out(n / 2 + 1);
  for (int l = 0; l <= n / 2; ++l) out[l] = X[l] / double(n);
  return out;
}

double crest_factor(const Eigen::VectorXd& x) {
  const double rms = std::sqrt(x.squaredNorm() / double(x.size()));
  if (!(rms > 0)) throw std::invalid_argument("crest factor of a zero signal is undefined");
  return x.cwiseAbs().maxCoeff() / rms;
}

}  // namespace lptv
