// The band-row kernel: the entries A_{l,i} = sum_n c_{n,l-i} s_i^n of the band matrices of
// METHOD.md eq. (5) (B likewise), one place for the FDS (a column of A or B per line) and the
// residue, Jacobian and likelihood kernels (a row per line). One place means one sequence of
// floating-point operations: the same line gives the same bits in the simulator and in the
// estimators. Inline so that the per-line loops inline it (the FDS spends its build time
// here); private to the library (namespace detail), shared with the in-tree benchmarks.
#pragma once
#include <Eigen/Dense>
#include <algorithm>
#include <complex>
#include <vector>

#include "lptv/model.hpp"
#include "lptv/structure.hpp"

namespace lptv {

struct Grid;  // fds.hpp

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

// The complex case with the product written out: the same operations, hence the same bits for
// finite operands, as std::complex's operator*, without the NaN recovery GCC attaches to each
// product (a branch and a library call that kept this loop from being unrolled; the small
// band kernel of the FDS spends a third of its time here).
inline cd band_entry(const cd* c, const cd* pw, int order) {
  double re = 0.0, im = 0.0;
  for (int n = 0; n <= order; ++n) {
    const double a = c[n].real(), b = c[n].imag(), x = pw[n].real(), y = pw[n].imag();
    re += a * x - b * y;
    im += a * y + b * x;
  }
  return {re, im};
}

// Continuous time, s = j w: s^n = j^n w^n. With the coefficients taken times j^n (exact: a
// swap of parts and signs; times_j_powers) and the real powers w^n (real_powers: the same
// product chain as the imaginary or real part of line_powers' s^n, so the same bits up to
// sign), band_entry_ct sums c_n j^n w^n as a complex times a real per term. Each term of
// band_entry, a x - b y with one of x, y = +-0, is then the same number, so the entries equal
// band_entry's under == (an exact zero may differ in sign) with a quarter of the
// multiplications and no branch. The FDS builds its continuous-time rows with it; the
// estimators' rows keep band_entry (the tests hold the FDS's solution bitwise to build_A's).
inline void times_j_powers(const cd* c, int order, cd* out) {
  for (int n = 0; n <= order; ++n) {
    const double a = c[n].real(), b = c[n].imag();
    switch (n & 3) {
      case 0: out[n] = cd(a, b); break;
      case 1: out[n] = cd(-b, a); break;
      case 2: out[n] = cd(-a, -b); break;
      default: out[n] = cd(b, -a); break;
    }
  }
}

inline void real_powers(double w, int order, double* t) {
  t[0] = 1.0;
  for (int n = 1; n <= order; ++n) t[n] = t[n - 1] * w;
}

// t[0] = 1 (real_powers): the sum starts at cj[0], the same number as 0 + cj[0] 1 (an exact
// zero may differ in sign), one product and one sum fewer per part.
inline cd band_entry_ct(const cd* cj, const double* t, int order) {
  double re = cj[0].real(), im = cj[0].imag();
  for (int n = 1; n <= order; ++n) {
    re += cj[n].real() * t[n];
    im += cj[n].imag() * t[n];
  }
  return {re, im};
}

// A of a continuous-time model in LAPACK band storage (kl = ku = Ka, kl more rows of pivoting
// workspace): ab[(2 Ka + k) + j * ldab] = A_{j+k,j}. Defined in fds.cpp, whose band solver
// factorises it; declared here so that the benchmarks' bare band LU factorises the same array.
std::vector<cd> band_storage_A(const Model& m, const Grid& g);

// The row kernels' side: s_i^n for the 2K+1 lines i = l - k (k = -K..K) that row l uses,
// n = 0..max(na, nb).
class RowPowers {
 public:
  explicit RowPowers(const Structure& s)
      : w0_(s.w0), ts_(s.ts), K_(s.kmax()), order_(std::max(s.na, s.nb)),
        pw_(static_cast<size_t>(2 * K_ + 1) * (order_ + 1)) {}
  void compute(int l) {
    for (int k = -K_; k <= K_; ++k) line_powers(line_variable(w0_, ts_, l - k), order_, out(k));
  }
  // s_{l-k}^0 .. s_{l-k}^order.
  const cd* line(int k) const { return &pw_[static_cast<size_t>(K_ + k) * (order_ + 1)]; }
  cd operator()(int k, int n) const { return line(k)[n]; }
  int K() const { return K_; }

 private:
  cd* out(int k) { return &pw_[static_cast<size_t>(K_ + k) * (order_ + 1)]; }
  double w0_, ts_;
  int K_, order_;
  std::vector<cd> pw_;
};

// theta laid out as Model holds coefficients, K = the structure's kmax on both sides: a is
// (na+1) x (2K+1), b is (nb+1) x (2K+1), zero where a coefficient has fewer harmonics. A zero
// term leaves a sum unchanged (up to the sign of an exact zero), so the entries equal the sums
// over the parameters alone, bit for bit.
struct HarmonicCoefficients {
  Eigen::MatrixXcd a, b;
};

inline HarmonicCoefficients by_harmonic(const Parametrisation& p, const Eigen::VectorXcd& theta) {
  const Structure& s = p.structure();
  const int K = s.kmax();
  HarmonicCoefficients c{Eigen::MatrixXcd::Zero(s.na + 1, 2 * K + 1),
                         Eigen::MatrixXcd::Zero(s.nb + 1, 2 * K + 1)};
  for (int q = 0; q < p.n_theta(); ++q) {
    const Param& pr = p.params()[q];
    (pr.is_a ? c.a : c.b)(pr.order, K + pr.k) = theta[q];
  }
  return c;
}

// A_{l,i} and B_{l,i} for i = l - k, k = -K..K (index K + k), from row l's powers.
inline void band_row(const HarmonicCoefficients& c, const RowPowers& pw, std::vector<cd>& A,
                     std::vector<cd>& B) {
  const int K = pw.K(), na = static_cast<int>(c.a.rows()) - 1, nb = static_cast<int>(c.b.rows()) - 1;
  A.resize(2 * K + 1);
  B.resize(2 * K + 1);
  for (int k = -K; k <= K; ++k) {
    A[K + k] = band_entry(c.a.col(K + k).data(), pw.line(k), na);
    B[K + k] = band_entry(c.b.col(K + k).data(), pw.line(k), nb);
  }
}

}  // namespace detail
}  // namespace lptv
