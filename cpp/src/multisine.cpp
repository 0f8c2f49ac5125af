#include "lptv/multisine.hpp"

#include <unsupported/Eigen/FFT>
#include <algorithm>
#include <cmath>
#include <limits>
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

// ---- Excitation design (METHOD.md section 2)

Eigen::VectorXd schroeder_phases(const Eigen::VectorXd& amplitudes) {
  if (amplitudes.size() == 0) throw std::invalid_argument("amplitudes must not be empty");
  if (!amplitudes.allFinite()) throw std::invalid_argument("amplitudes must be finite");
  const double total = amplitudes.squaredNorm();
  if (!(total > 0)) throw std::invalid_argument("amplitudes must not all be zero");
  const Eigen::Index F = amplitudes.size();
  Eigen::VectorXd phi(F);
  // phi_k = -2 pi sum_{i<k} (k - i) p_i, accumulated as a running sum of running sums.
  double cum = 0.0, acc = 0.0;
  for (Eigen::Index k = 0; k < F; ++k) {
    phi[k] = -2.0 * M_PI * acc;
    cum += amplitudes[k] * amplitudes[k] / total;
    acc += cum;
    phi[k] = std::remainder(phi[k], 2.0 * M_PI);
  }
  return phi;
}

namespace {

// The design problem on the evaluation grid of M = N * oversample points.
struct CrestProblem {
  std::vector<int> lines;
  Eigen::VectorXd amplitudes;
  std::vector<bool> real;  // DC or the Nyquist line of N: the phase stays
  int N = 0, M = 0;
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> X, G;
  std::vector<double> x, g;
  int evaluations = 0;

  CrestProblem(const std::vector<int>& ln, const Eigen::VectorXd& amp, int n_samples, int oversample)
      : lines(ln), amplitudes(amp), real(ln.size()), N(n_samples), M(n_samples * oversample) {
    fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
    fft.SetFlag(Eigen::FFT<double>::Unscaled);
    X.assign(M / 2 + 1, 0.0);
    for (size_t i = 0; i < lines.size(); ++i) real[i] = lines[i] == 0 || (N % 2 == 0 && 2 * lines[i] == N);
  }

  // x on the grid, as sum_l A_l cos(2 pi l n / M + phi_l).
  void signal(const Eigen::VectorXd& phases) {
    std::fill(X.begin(), X.end(), std::complex<double>(0.0));
    for (size_t i = 0; i < lines.size(); ++i) {
      const int l = lines[i];
      if (real[i]) {
        const double a = amplitudes[i] * std::cos(phases[i]);
        // DC and the grid's own Nyquist line hold the full cosine; the Nyquist line of N on
        // a finer grid is an ordinary line, A cos(phi) cos(pi n / oversample).
        X[l] += (l == 0 || 2 * l == M) ? a : 0.5 * a;
      } else {
        X[l] += 0.5 * amplitudes[i] * std::polar(1.0, phases[i]);
      }
    }
    if (M == 1) {
      x.assign(1, X[0].real());
      return;
    }
    // Eigen's half-spectrum inverse counts X_1..X_{M/2-1} twice (the conjugate half) and
    // takes only the real part of X_0 and X_{M/2}: exactly the real signal above.
    fft.inv(x, X, M);
  }

  double crest(const Eigen::VectorXd& phases) {
    signal(phases);
    double peak = 0.0, ss = 0.0;
    for (double v : x) {
      peak = std::max(peak, std::abs(v));
      ss += v * v;
    }
    return peak / std::sqrt(ss / M);
  }

  // log of the L_p norm (as a mean) and its gradient; also the L_inf crest factor of x.
  double objective(const Eigen::VectorXd& phases, int p, Eigen::VectorXd* grad, double* crest_out) {
    ++evaluations;
    signal(phases);
    double m = 0.0, ss = 0.0;
    for (double v : x) {
      m = std::max(m, std::abs(v));
      ss += v * v;
    }
    if (!(m > 0)) throw std::invalid_argument("amplitudes must not all be zero");
    if (crest_out) *crest_out = m / std::sqrt(ss / M);
    // r = x / max|x| in [-1, 1]: r^p cannot overflow for any p.
    g.resize(x.size());
    double S = 0.0;
    for (size_t n = 0; n < x.size(); ++n) {
      const double r = x[n] / m;
      const double rp1 = std::pow(r, p - 1);  // odd integer power: keeps the sign
      g[n] = rp1;
      S += rp1 * r;
    }
    const double f = std::log(m) + std::log(S / M) / p;
    if (grad) {
      grad->setZero(static_cast<Eigen::Index>(lines.size()));
      if (M == 1) return f;
      fft.fwd(G, g);  // G_l = sum_n g_n exp(-j 2 pi l n / M)
      // d x_n / d phi_l = -A_l sin(2 pi l n / M + phi_l); sum_n g_n sin(theta_n + phi) =
      // Im(exp(j phi) conj(G_l)).
      for (size_t i = 0; i < lines.size(); ++i) {
        if (real[i]) continue;
        const std::complex<double> e = std::polar(1.0, phases[i]) * std::conj(G[lines[i]]);
        (*grad)[i] = -amplitudes[i] * e.imag() / (m * S);
      }
    }
    return f;
  }
};

void check_design_input(const std::vector<int>& lines, const Eigen::VectorXd& amplitudes,
                        const Eigen::VectorXd& phases, int n_samples) {
  check_n_samples(n_samples);
  if (lines.empty()) throw std::invalid_argument("lines must not be empty");
  if (amplitudes.size() != static_cast<Eigen::Index>(lines.size()) ||
      phases.size() != static_cast<Eigen::Index>(lines.size())) {
    throw std::invalid_argument("amplitudes and phases must have one entry per line");
  }
  if (!amplitudes.allFinite() || !phases.allFinite()) {
    throw std::invalid_argument("amplitudes and phases must be finite");
  }
  std::vector<int> sorted(lines);
  std::sort(sorted.begin(), sorted.end());
  if (sorted.front() < 0 || sorted.back() > n_samples / 2) {
    throw std::invalid_argument("lines must lie in 0.." + std::to_string(n_samples / 2) + " (n_samples/2)");
  }
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
    throw std::invalid_argument("lines must be distinct");
  }
  if (!(amplitudes.cwiseAbs().maxCoeff() > 0)) throw std::invalid_argument("amplitudes must not all be zero");
}

int auto_oversample(const std::vector<int>& lines, int n_samples, int oversample) {
  if (oversample < 0) throw std::invalid_argument("oversample must be >= 0 (0: automatic)");
  if (oversample > 0) {
    if (static_cast<long long>(oversample) * n_samples > (1LL << 27)) {
      throw std::invalid_argument("oversample * n_samples must be at most 2^27");
    }
    return oversample;
  }
  const long long top = *std::max_element(lines.begin(), lines.end());
  const long long need = 16 * std::max(top, 1LL);
  const long long os = std::max(1LL, (need + n_samples - 1) / n_samples);
  return static_cast<int>(std::min(os, std::max(1LL, (1LL << 27) / n_samples)));
}

}  // namespace

double lp_norm_log(const std::vector<int>& lines, const Eigen::VectorXd& amplitudes,
                   const Eigen::VectorXd& phases, int n_samples, int oversample, int p,
                   Eigen::VectorXd* gradient) {
  check_design_input(lines, amplitudes, phases, n_samples);
  if (p < 2 || p % 2 != 0) throw std::invalid_argument("p must be an even integer >= 2");
  CrestProblem prob(lines, amplitudes, n_samples, auto_oversample(lines, n_samples, oversample));
  return prob.objective(phases, p, gradient, nullptr);
}

CrestResult minimize_crest_factor(const std::vector<int>& lines, const Eigen::VectorXd& amplitudes,
                                  const Eigen::VectorXd& initial_phases, int n_samples,
                                  const CrestOptions& options) {
  check_design_input(lines, amplitudes, initial_phases, n_samples);
  if (options.max_p < 4 || (options.max_p & (options.max_p - 1)) != 0 || options.max_p > (1 << 20)) {
    throw std::invalid_argument("max_p must be a power of two in 4..2^20");
  }
  if (options.iterations_per_p < 0) throw std::invalid_argument("iterations_per_p must be >= 0");
  CrestResult res;
  res.oversample = auto_oversample(lines, n_samples, options.oversample);
  CrestProblem prob(lines, amplitudes, n_samples, res.oversample);
  const Eigen::Index F = initial_phases.size();
  Eigen::VectorXd x = initial_phases;
  res.initial_crest_factor = prob.crest(x);
  res.crest_factor = res.initial_crest_factor;
  res.phases = x;
  auto keep = [&](double c, const Eigen::VectorXd& ph) {
    if (c < res.crest_factor) {
      res.crest_factor = c;
      res.phases = ph;
    }
  };
  constexpr int kMemory = 8;
  Eigen::VectorXd g(F), gn(F), d(F), xn(F), q(F);
  for (int p = 4; p <= options.max_p; p *= 2) {
    // L-BFGS (two-loop recursion) with an Armijo backtracking line search.
    std::vector<Eigen::VectorXd> S, Y;
    double c = 0.0;
    double f = prob.objective(x, p, &g, &c);
    keep(c, x);
    for (int it = 0; it < options.iterations_per_p; ++it) {
      q = g;
      std::vector<double> alpha(S.size());
      for (int i = static_cast<int>(S.size()) - 1; i >= 0; --i) {
        alpha[i] = S[i].dot(q) / Y[i].dot(S[i]);
        q -= alpha[i] * Y[i];
      }
      const double gmax = g.cwiseAbs().maxCoeff();
      if (!(gmax > 0)) break;
      if (S.empty()) {
        q *= 0.1 / gmax;  // a first step of 0.1 rad on the steepest phase
      } else {
        q *= S.back().dot(Y.back()) / Y.back().squaredNorm();
      }
      for (size_t i = 0; i < S.size(); ++i) {
        const double beta = Y[i].dot(q) / Y[i].dot(S[i]);
        q += (alpha[i] - beta) * S[i];
      }
      d = -q;
      if (!(g.dot(d) < 0)) {  // not a descent direction: restart from the gradient
        S.clear();
        Y.clear();
        d = -g * (0.1 / gmax);
      }
      double t = 1.0, fn = 0.0;
      for (;;) {
        xn = x + t * d;
        fn = prob.objective(xn, p, &gn, &c);
        keep(c, xn);
        if (fn <= f + 1e-4 * t * g.dot(d) || t < 1e-10) break;
        t *= 0.5;
      }
      const Eigen::VectorXd s = xn - x, y = gn - g;
      if (y.dot(s) > 1e-300) {
        S.push_back(s);
        Y.push_back(y);
        if (static_cast<int>(S.size()) > kMemory) {
          S.erase(S.begin());
          Y.erase(Y.begin());
        }
      }
      const bool done = std::abs(fn - f) < 1e-13;
      x = xn;
      f = fn;
      g = gn;
      if (done) break;
    }
    res.best_per_p.push_back(res.crest_factor);
  }
  for (Eigen::Index i = 0; i < F; ++i) res.phases[i] = std::remainder(res.phases[i], 2.0 * M_PI);
  res.evaluations = prob.evaluations;
  return res;
}

}  // namespace lptv
