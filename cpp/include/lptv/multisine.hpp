// Random-phase multisines (METHOD.md section 2) and the spectrum <-> time-signal
// conversions with the project's scaling X_l = fft(x)[l] / N.
#pragma once
#include <Eigen/Dense>
#include <complex>
#include <vector>

namespace lptv {

// One-sided spectrum on lines 0..n_samples/2 of sum_l A_l cos(l w0 t + phi_l):
// X_l = A_l / 2 exp(j phi_l) (X_0 = A_0 cos(phi_0) on DC).
Eigen::VectorXcd multisine_spectrum(const std::vector<int>& lines, const Eigen::VectorXd& amplitudes,
                                    const Eigen::VectorXd& phases, int n_samples);

// One period of the real signal with one-sided spectrum X (lines 0..L, L <= N/2),
// sampled at N points: x[t] = sum_{l=-L}^{L} X_l exp(j 2 pi l t / N).
Eigen::VectorXd time_signal(const Eigen::VectorXcd& X, int n_samples);

// One-sided spectrum (lines 0..N/2) of one period x of N samples: fft(x)[l] / N.
Eigen::VectorXcd spectrum(const Eigen::VectorXd& x);

// max |x| / rms(x).
double crest_factor(const Eigen::VectorXd& x);

}  // namespace lptv
