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

namespace lptv {

// ---- Excitation design: crest-factor minimisation (METHOD.md section 2, "Designing the excitation")

// Schroeder's phases for the amplitudes A_1..A_F of F lines taken in the given order:
// phi_k = -2 pi sum_{i<k} (k - i) A_i^2 / sum A^2 (flat amplitudes: -pi k (k - 1) / F).
Eigen::VectorXd schroeder_phases(const Eigen::VectorXd& amplitudes);

struct CrestOptions {
  // Samples per period on which the peak is taken: n_samples * oversample; 0 picks the
  // smallest factor with at least 16 samples per period of the highest excited line (the peak
  // of the band-limited continuous signal then lies within 2 % of the sampled one).
  int oversample = 0;
  // The L_p norms minimised in turn: p = 4, 8, ..., max_p (a power of two >= 4).
  int max_p = 1024;
  // L-BFGS iterations per p at most: the cost is bounded by
  // iterations_per_p * log2(max_p / 2) * (a few FFTs of n_samples * oversample points).
  int iterations_per_p = 100;
};

struct CrestResult {
  Eigen::VectorXd phases;       // the phases of the smallest crest factor met
  double crest_factor = 0;      // max |x| / rms(x) on the evaluation grid, at those phases
  double initial_crest_factor = 0;
  int oversample = 1;           // the factor used
  int evaluations = 0;          // objective evaluations (one inverse and one forward FFT each)
  std::vector<double> best_per_p;  // the smallest crest factor after each p (p = 4, 8, ...)
};

// Minimises the crest factor of sum_l A_l cos(l w0 t + phi_l) over the phases of the lines
// that are not real (DC and, for even N, the Nyquist line keep theirs): L-BFGS on the log of
// the L_p norm for p = 4, 8, ..., max_p, each from the last one's phases (Guillaume et al.,
// IEEE Trans. Instrum. Meas. 40(6), 1991, minimise L_p norms of growing p towards L_inf),
// keeping the phases of the smallest L_inf crest factor seen at any evaluation.
CrestResult minimize_crest_factor(const std::vector<int>& lines, const Eigen::VectorXd& amplitudes,
                                  const Eigen::VectorXd& initial_phases, int n_samples,
                                  const CrestOptions& options = {});

// The objective: log ||x||_p (x on n_samples * oversample points, the norm as a mean) and,
// when gradient is given, its gradient with respect to the phases (zero on real lines).
double lp_norm_log(const std::vector<int>& lines, const Eigen::VectorXd& amplitudes,
                   const Eigen::VectorXd& phases, int n_samples, int oversample, int p,
                   Eigen::VectorXd* gradient = nullptr);

}  // namespace lptv
