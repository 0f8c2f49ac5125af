// The band-row kernel: the entries A_{l,i} = sum_n c_{n,l-i} s_i^n of the band matrices of
// METHOD.md eq. (5) (B likewise), one place for the FDS (a column of A or B per line) and the
// residue, Jacobian and likelihood kernels (a row per line). One place means one sequence of
// floating-point operations: the same line gives the same bits in the simulator and in the
// estimators. Inline so that the per-line loops inline it (the FDS spends its build time
// here); private to the library (namespace detail), shared with the in-tree benchmarks.
#pragma once
#include <Eigen/Dense>
#include <complex>
#include <vector>

#include "lptv/model.hpp"

namespace lptv {

namespace detail {

// s_i of line i: j i w0 in continuous time (ts == 0), the forward shift exp(j i w0 ts) in
// discrete time.
inline cd line_variable(double w0, double ts, int line) {
  const double w = w0 * line;
  return ts > 0 ? std::polar(1.0, w * ts) : cd(0.0, w);
}

// pw[n] = s^n for n = 0..order, each from the one before. line_power gives the same product
// chain for one n, so both give identical bits.
template <class T>
inline void line_powers(T s, int order, T* pw) {
  pw[0] = T(1);
  for (int n = 1; n <= order; ++n) pw[n] = pw[n - 1] * s;
}

template <class T>
inline T line_power(T s, int n) {
  T p(1);
  for (int i = 0; i < n; ++i) p *= s;
  return p;
}

// sum_{n=0}^{order} c[n] pw[n]: one band entry, c the coefficients of one harmonic by order
// (a column of Model::a() / b(), contiguous in Eigen's column-major storage), pw the powers of
// the entry's column line. The FDS calls it per column (one set of powers, entries
// M_{i+k,i} for k = -K..K) straight from its loops: staging a column's entries in a buffer
// first made apply_B about 20 % slower. T = double serves the magnitude sums of the FDS's
// conditioning check.
template <class T>
inline T band_entry(const T* c, const T* pw, int order) {
  T v(0);
  for (int n = 0; n <= order; ++n) v += c[n] * pw[n];
  return v;
}

}  // namespace detail
}  // namespace lptv
