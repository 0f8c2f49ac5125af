// The FDS's one-pass band solve on half the grid (METHOD.md section 3, "half the grid"). A
// real model has conjugate-symmetric coefficients, so A_{-l,-i} = conj(A_{l,i}); a real input
// has U_{-l} = conj(U_l), and the solution then has Y_{-l} = conj(Y_l). Lines 0..L carry all
// of it: rows l = L..K of A, written in the unknowns Y_0..Y_L, are ordinary band rows; rows
// 0..K-1 also hold conj(Y_1..Y_K). The small band kernel eliminates Y_L down to Y_2K from the
// top (rows L..K), the 2K rows left form a real system of 4K - 1 unknowns (Re Y_0; Re and Im
// of Y_1..Y_2K-1) solved densely, and one back substitution gives the rest: half the rows,
// half the work of the full grid.
//
// The conditioning check's right-hand side is the full grid's (Fds::condition) with its unit
// phases exp(j g l) taken by line instead of by grid index: on the grid -L..L the two differ
// by the constant factor exp(j g L), so the solution's magnitudes are the same, and by line it
// is conjugate-symmetric like the rest. Since A maps conjugate-symmetric vectors to
// conjugate-symmetric ones and j times them to j times them, A^-1 has the same size on both:
// the symmetric right-hand side probes all of it.
//
// Private to the library; fds.cpp decides when to use it and owns the check's decision.
#pragma once
#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "lptv/fds.hpp"
#include "lptv/model.hpp"

namespace lptv {
namespace detail {

// The unit phase step of the conditioning check's right-hand side (the golden angle).
constexpr double kCheckPhaseStep = 2.399963229728653;

// Whether solve_folded applies to the model on the grid: continuous time, at least 2K + 1
// lines each side, 1 <= K (= Ka) <= SmallBandLU::kMaxK.
bool can_fold(const Model& m, const Grid& g);
// Whether the full-grid input is conjugate-symmetric about line 0, exactly (U_0 real), as
// simulate builds it from one-sided spectra.
bool real_input(const Grid& g, const Eigen::MatrixXcd& U_full);

// The conditioning check's row magnitude m_l = sum_k sum_n |a_{n,k}| |w0 (l - k)|^n (k = -K..K,
// the row's columns on lines l - k), shared by the half-grid and the full-grid routes.
// For |l| >= K every column line lies on l's side of line 0 and m_l is a polynomial in |l|,
// sum_m p_m |l|^m with p_m = sum_k sum_{n>=m} |a_{n,k}| w0^n C(n,m) (-+k)^(n-m) (the sign of k
// that of -l): na multiply-adds per row instead of (2K+1)(na+1). It differs from the direct sum
// by rounding (a few units in its last places): the check only needs its size.
class CheckMagnitude {
 public:
  CheckMagnitude(const Eigen::MatrixXd& absa, double w0)  // absa = |a|: (na+1) x (2K+1)
      : absa_(absa), K_(static_cast<int>(absa.cols() - 1) / 2), na_(static_cast<int>(absa.rows()) - 1),
        pos_(na_ + 1, 0.0), neg_(na_ + 1, 0.0) {
    for (int k = -K_; k <= K_; ++k) {
      double w0n = 1.0;
      for (int n = 0; n <= na_; ++n, w0n *= w0) {
        double binom = 1.0, mk = 1.0;  // C(n, mm) and (-k)^(n-mm), mm from n down
        for (int mm = n; mm >= 0; --mm) {
          const double v = absa_(n, K_ + k) * w0n * binom;
          pos_[mm] += v * mk;                           // l >= K: (w0 (l - k))^n
          neg_[mm] += ((n - mm) % 2 ? -v : v) * mk;     // l <= -K: (w0 (|l| + k))^n
          binom = binom * mm / (n - mm + 1);
          mk *= -k;
        }
      }
    }
  }
  // m_l for |l| >= K (na: the model's order, a constant where the caller has one).
  double far(int l, int na) const {
    const std::vector<double>& p = l >= 0 ? pos_ : neg_;
    const double x = std::abs(l);
    double v = p[na];
    for (int n = na - 1; n >= 0; --n) v = v * x + p[n];
    return v;
  }
  // The direct sum over the row's columns c = lo..hi (grid indices or lines alike: only the
  // difference row - c matters), t(c) the real powers of column c's line variable.
  template <class Powers>
  double direct(int row, int lo, int hi, int na, const Powers& t) const {
    double mag = 0;
    for (int c = lo; c <= hi; ++c) {
      const double* c_abs = absa_.data() + static_cast<size_t>(K_ + row - c) * (na + 1);
      const double* tc = t(c);  // |s_c|^n = |w_c^n|
      double v = 0.0;
      for (int n = 0; n <= na; ++n) v += c_abs[n] * std::abs(tc[n]);
      mag += v;
    }
    return mag;
  }

 private:
  Eigen::MatrixXd absa_;
  int K_, na_;
  std::vector<double> pos_, neg_;
};

// One-sided input: row l is line l (U_0 real), lines beyond the last row are zero.
using HalfInput = Eigen::Ref<const Eigen::MatrixXcd>;

struct FoldedSolution {
  Eigen::MatrixXcd Y;      // lines 0..L (the negative lines are their conjugates); empty with `full`
  double condition = 0.0;  // max |x| of the check's solution
  int where = 0;           // its grid index (a line >= 0)
  // max |Y_lq|^2 over the solution (re^2 + im^2, as Eigen's abs2), NaN or inf where Y has a NaN
  // or an inf (or where a square overflows): taken in the pass that writes Y, so that the
  // caller's size and finiteness checks need no pass of their own.
  double peak2 = 0.0;
};

// Y = A^-1 B U on the grid with the check. Throws ZeroPivot (band_kernel.hpp) with the grid
// index of the first exactly zero pivot. With `full` (g.N x U.cols(), sized by the caller) the
// solution goes there on the whole grid, grid index L + l for line l, instead of into Y.
FoldedSolution solve_folded(const Model& m, const Grid& g, const HalfInput& U,
                            Eigen::MatrixXcd* full = nullptr);

}  // namespace detail
}  // namespace lptv
