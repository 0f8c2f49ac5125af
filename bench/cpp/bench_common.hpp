// What the benchmark executables share: the paper-like example and a timer.
#pragma once
#include <Eigen/Dense>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <random>
#include <vector>

#include "lptv/model.hpp"
#include "lptv/multisine.hpp"

namespace bench {

using lptv::cd;

// The paper-like example of python/lptv/examples.py (paper_model, paper_multisine): the
// numbers below are copies of PAPER_W0, PAPER_N, PAPER_DC and PAPER_HARMONICS there and must
// be kept in step with them.
constexpr double kW0 = 0.04;
constexpr int kSamples = 2048;
// Harmonics k = 1, 2, 3 of a0, a1, a2, b0, b1 (harmonic -k is the conjugate); DC values 1.
const cd kHarmonics[5][3] = {
    {{0.15, 0.09}, {-0.06, 0.06}, {0.03, -0.045}},    // a0
    {{0.12, -0.06}, {0.045, 0.03}, {-0.03, 0.015}},   // a1
    {{-0.09, 0.06}, {0.03, -0.06}, {0.024, 0.018}},   // a2
    {{0.18, 0.06}, {-0.09, -0.03}, {0.03, 0.03}},     // b0
    {{-0.12, 0.09}, {0.06, 0.045}, {-0.03, -0.03}},   // b1
};

inline lptv::Model paper_model() {
  Eigen::MatrixXcd a(3, 7), b(2, 7);
  for (int row = 0; row < 5; ++row) {
    Eigen::MatrixXcd& c = row < 3 ? a : b;
    const int n = row < 3 ? row : row - 3;
    c(n, 3) = 1.0;
    for (int k = 1; k <= 3; ++k) {
      c(n, 3 + k) = kHarmonics[row][k - 1];
      c(n, 3 - k) = std::conj(kHarmonics[row][k - 1]);
    }
  }
  return lptv::Model(a, b, kW0);
}

// Lines 10, 20, ..., 240 with amplitude sqrt(2/24) (rms 1); phases from a seeded generator
// (not the same phases as numpy's generator in paper_multisine: the statistics are).
inline Eigen::VectorXcd paper_input(unsigned seed, int n_samples = kSamples) {
  std::vector<int> lines;
  for (int l = 10; l <= 240; l += 10) lines.push_back(l);
  const Eigen::Index n = static_cast<Eigen::Index>(lines.size());
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> phase(0.0, 2 * M_PI);
  Eigen::VectorXd amp = Eigen::VectorXd::Constant(n, std::sqrt(2.0 / double(n)));
  Eigen::VectorXd ph(n);
  for (Eigen::Index i = 0; i < n; ++i) ph[i] = phase(gen);
  return lptv::multisine_spectrum(lines, amp, ph, n_samples);
}

// Median wall time in seconds of `reps` calls of f (after one warm-up call).
template <class F>
double median_time(int reps, F&& f) {
  f();
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Shortest wall time in seconds of `reps` calls of f (after one warm-up call): on a shared
// machine the fastest run is the one least disturbed by other work.
template <class F>
double min_time(int reps, F&& f) {
  f();
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// max |Y - Yref| / max |Yref| over the first `lines` + 1 rows.
inline double rel_error(const Eigen::VectorXcd& Y, const Eigen::VectorXcd& Yref, int lines) {
  const double peak = Yref.head(lines + 1).cwiseAbs().maxCoeff();
  return (Y.head(lines + 1) - Yref.head(lines + 1)).cwiseAbs().maxCoeff() / peak;
}

inline double db(double x) { return 20.0 * std::log10(std::max(x, 1e-300)); }

// Argument i of the command line as an integer in [lo, hi], `def` where it is absent; anything
// else ends the program with a one-line message and exit status 2.
inline long int_arg(int argc, char** argv, int i, long def, long lo, long hi, const char* name, const char* usage) {
  if (i >= argc) return def;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(argv[i], &end, 10);
  if (end == argv[i] || *end || errno || v < lo || v > hi) {
    std::fprintf(stderr, "%s: argument %d must be an integer from %ld to %ld, got '%s' (usage: %s)\n", name, i, lo,
                 hi, argv[i], usage);
    std::exit(2);
  }
  return v;
}

// Runs a benchmark's body; an exception ends it with one line naming the benchmark and the cause
// (exit status 1), instead of std::terminate's report.
template <class F>
int guarded_main(const char* name, F&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 1;
  }
}

}  // namespace bench
