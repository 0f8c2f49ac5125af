#include "lptv/likelihood.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "lptv/errors.hpp"
#include "lptv/estimators.hpp"
#include "lptv/jacobian.hpp"
#include "rows.hpp"

extern "C" {
// BLAS: C = alpha op(A) op(B) + beta C.
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc);
}

namespace lptv {

namespace {

using detail::mul;

// Real 2 x 4 map of one band entry (coefficient a on Y_i, -b on U_i) onto [Re e, Im e] from
// the noise of physical line m = |i| in the layout [Re Y, Im Y, Re U, Im U]. A conjugate
// line (i < 0) enters through conj(X_m). At DC the imaginary parts carry no noise (their
// covariance is zero) but the map keeps them, so that r = M x equals the complex residue
// even for a DC line with a (rounding-level) imaginary part.
void entry_map(cd a, cd b, bool conjugate, double G[2][4]) {
  const cd c[2] = {a, -b};
  for (int s = 0; s < 2; ++s) {
    const double re = c[s].real(), im = c[s].imag();
    double* g0 = &G[0][2 * s];
    double* g1 = &G[1][2 * s];
    if (!conjugate) {  // c (x + j y)
      g0[0] = re; g0[1] = -im;
      g1[0] = im; g1[1] = re;
    } else {  // c (x - j y)
      g0[0] = re; g0[1] = im;
      g1[0] = im; g1[1] = -re;
    }
  }
}

// Cov(n_m), 4 x 4 (METHOD.md section 10).
void line_covariance(const FrequencyData& d, int m, double C[4][4]) {
  const double cy = d.varY[m], cu = d.varU[m];
  const cd c = d.covYU[m];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) C[i][j] = 0.0;
  if (m == 0) {  // real line: full variances on the real parts
    C[0][0] = cy;
    C[2][2] = cu;
    C[0][2] = C[2][0] = c.real();
    return;
  }
  C[0][0] = C[1][1] = 0.5 * cy;
  C[2][2] = C[3][3] = 0.5 * cu;
  C[0][2] = C[2][0] = C[1][3] = C[3][1] = 0.5 * c.real();  // E{ReY ReU} = E{ImY ImU}
  C[1][2] = C[2][1] = 0.5 * c.imag();                      // E{ImY ReU}
  C[0][3] = C[3][0] = -0.5 * c.imag();                     // E{ReY ImU}
}

}  // namespace

// Per sorted row r and harmonic k (index r * (2K+1) + K + k): the physical line, the map G
// and H = Cov(n_m) G^T; the lower band of L (S = L L^T) column by column, Lb(i - j, j).
struct ExactLikelihood::Factor {
  struct Entry {
    int m;
    double G[2][4];
    double H[4][2];
  };
  std::vector<Entry> e;
  Eigen::MatrixXd Lb;
  Eigen::VectorXd r;  // the real residue, sorted-row order
};

ExactLikelihood::ExactLikelihood(const FrequencyData& d, const Parametrisation& p, std::vector<int> rows)
    : d_(d), p_(p) {
  d_.validate();
  check_rows(p_, rows, d_.max_line());
  init(rows);
}

ExactLikelihood::ExactLikelihood(const FrequencyData& d, const Parametrisation& p, std::vector<int> rows,
                                 PartOfSeveral)
    : d_(d), p_(p) {
  d_.validate();
  check_row_lines(p_.structure(), rows, d_.max_line());
  init(rows);
}

void ExactLikelihood::init(const std::vector<int>& rows) {
  order_.resize(rows.size());
  std::iota(order_.begin(), order_.end(), 0);
  std::sort(order_.begin(), order_.end(), [&](int a, int b) { return rows[a] < rows[b]; });
  sorted_.resize(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) sorted_[i] = rows[order_[i]];
  K_ = p_.structure().kmax();
  // Sorted rows i < j share a line only if rows[j] - rows[i] <= 2K (or, through a conjugate
  // line, rows[i] + rows[j] <= 2K, which implies it): j - i <= 2K, 2 real rows each.
  kd_ = 2 * (2 * K_) + 1;
}

ExactLikelihood::Factor ExactLikelihood::factor(const Eigen::VectorXcd& theta) const {
  if (theta.size() != p_.n_theta()) throw std::invalid_argument("theta has the wrong size");
  const int R = static_cast<int>(sorted_.size()), W = 2 * K_ + 1, n = 2 * R;
  Factor f;
  f.e.resize(static_cast<size_t>(R) * W);
  f.r = Eigen::VectorXd::Zero(n);
  const detail::Lines X{d_};
  const detail::HarmonicCoefficients c = detail::by_harmonic(p_, theta);
  detail::RowPowers pw(p_.structure());
  std::vector<cd> A, B;
  for (int r = 0; r < R; ++r) {
    pw.compute(sorted_[r]);
    detail::band_row(c, pw, A, B);
    for (int k = -K_; k <= K_; ++k) {
      const int i = sorted_[r] - k;
      Factor::Entry& en = f.e[static_cast<size_t>(r) * W + K_ + k];
      en.m = std::abs(i);
      entry_map(A[K_ + k], B[K_ + k], i < 0, en.G);
      double C[4][4];
      line_covariance(d_, en.m, C);
      for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 2; ++c) {
          double s = 0;
          for (int b = 0; b < 4; ++b) s += C[a][b] * en.G[c][b];
          en.H[a][c] = s;
        }
      if (scale_.size()) {
        const double sr = scale_[r];
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 4; ++b) en.G[a][b] *= sr;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 2; ++b) en.H[a][b] *= sr;
      }
      const cd v = mul(A[K_ + k], X.Y(i)) - mul(B[K_ + k], X.U(i));
      f.r[2 * r] += v.real();
      f.r[2 * r + 1] += v.imag();
    }
  }
  if (diagonal()) {
    factor_diagonal(f);
    return f;
  }
  // S in lower band storage: block (r, r') for r' = r..r+2K, from the entries of both rows
  // on the same physical line (row r' uses line m directly at k' = l' - m, and through its
  // conjugate at k' = l' + m).
  f.Lb = Eigen::MatrixXd::Zero(kd_ + 1, n);
  for (int r = 0; r < R; ++r) {
    for (int r2 = r; r2 < std::min(R, r + 2 * K_ + 1); ++r2) {
      double blk[2][2] = {{0, 0}, {0, 0}};
      for (int k = -K_; k <= K_; ++k) {
        const Factor::Entry& a = f.e[static_cast<size_t>(r) * W + K_ + k];
        for (int sgn = 0; sgn < 2; ++sgn) {
          if (sgn == 1 && a.m == 0) break;
          const int k2 = sorted_[r2] + (sgn == 0 ? -1 : 1) * a.m;
          if (std::abs(k2) > K_) continue;
          const Factor::Entry& b = f.e[static_cast<size_t>(r2) * W + K_ + k2];
          if (b.m != a.m) continue;
          for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) {
              double s = 0;
              for (int c = 0; c < 4; ++c) s += a.G[i][c] * b.H[c][j];
              blk[i][j] += s;
            }
        }
      }
      // Entries (2r + i, 2r2 + j) with 2r2 + j >= 2r + i go to the lower band at (row 2r2 + j,
      // column 2r + i), by symmetry.
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          const int col = 2 * r + i, row = 2 * r2 + j;
          if (row >= col) f.Lb(row - col, col) = blk[i][j];
        }
    }
  }
  // Banded Cholesky in place: O(n kd^2). (LAPACK's dpbtrf is slower at these bandwidths,
  // kd = 4K + 1: it calls the BLAS once per column.)
  const double smax = f.Lb.row(0).maxCoeff();
  for (int j = 0; j < n; ++j) {
    double djj = f.Lb(0, j);
    for (int k = std::max(0, j - kd_); k < j; ++k) djj -= f.Lb(j - k, k) * f.Lb(j - k, k);
    if (!(djj > 1e-13 * smax) || !std::isfinite(djj)) {
      const int row = sorted_[j / 2];
      throw NumericalError("the residue covariance is singular at row (line) " + std::to_string(row) +
                           ": the lines it uses carry (almost) no noise, so the likelihood is undefined"
                           " (use method='wgtls')");
    }
    const double ljj = std::sqrt(djj);
    f.Lb(0, j) = ljj;
    for (int i = j + 1; i <= std::min(n - 1, j + kd_); ++i) {
      double s = f.Lb(i - j, j);
      for (int k = std::max(0, i - kd_); k < j; ++k) s -= f.Lb(i - k, k) * f.Lb(j - k, k);
      f.Lb(i - j, j) = s / ljj;
    }
  }
  return f;
}

// K = 0 (an LTI structure): each row uses its own line l >= 1 only (never a conjugate, never
// DC), so S is block diagonal, the 2 x 2 block G H of each row, and so is its Cholesky
// factor. The band route computes the same numbers: its entries between rows are exact
// zeros, and every operation with them (x - 0 * y, x - 0) returns x; this route skips the
// band's bookkeeping (the pairs of rows, the window sums). Lb keeps the band layout
// (Lb(1, 2r + 1) = 0), so that everything reading the factor reads it as before.
bool ExactLikelihood::diagonal() const { return K_ == 0 && detail::diagonal_likelihood_setting(); }

void ExactLikelihood::factor_diagonal(Factor& f) const {
  const int R = static_cast<int>(sorted_.size()), n = 2 * R;
  f.Lb.resize(2, n);
  for (int r = 0; r < R; ++r) {
    const Factor::Entry& a = f.e[static_cast<size_t>(r)];
    double blk[2][2];
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        double s = 0;
        for (int c = 0; c < 4; ++c) s += a.G[i][c] * a.H[c][j];
        blk[i][j] = 0.0 + s;  // the band route's sum over the one shared line
      }
    f.Lb(0, 2 * r) = blk[0][0];
    f.Lb(1, 2 * r) = blk[0][1];
    f.Lb(0, 2 * r + 1) = blk[1][1];
    f.Lb(1, 2 * r + 1) = 0.0;
  }
  const double smax = f.Lb.row(0).maxCoeff();
  for (int r = 0; r < R; ++r) {
    for (int h = 0; h < 2; ++h) {
      const int j = 2 * r + h;
      double djj = f.Lb(0, j);
      if (h == 1) djj -= f.Lb(1, j - 1) * f.Lb(1, j - 1);
      if (!(djj > 1e-13 * smax) || !std::isfinite(djj)) {
        throw NumericalError("the residue covariance is singular at row (line) " + std::to_string(sorted_[r]) +
                             ": the lines it uses carry (almost) no noise, so the likelihood is undefined"
                             " (use method='wgtls')");
      }
      const double ljj = std::sqrt(djj);
      f.Lb(0, j) = ljj;
      if (h == 0) f.Lb(1, j) = f.Lb(1, j) / ljj;
    }
  }
}

namespace {

// X <- L^{-1} X, L lower banded (Lb(i - j, j)). One column: in place. Several: on the
// transpose, so that each elimination step updates contiguous rows of X (a column-major X's
// rows are strided).
void forward_solve(const Eigen::MatrixXd& Lb, int kd, Eigen::Ref<Eigen::MatrixXd> X) {
  const Eigen::Index n = Lb.cols();
  if (kd == 1 && detail::diagonal_likelihood_setting()) {
    // K = 0: 2 x 2 blocks (Lb(1, 2r + 1) = 0), row pairs in place; the band loop's operations
    // on them (its step across blocks subtracts 0 * x).
    const Eigen::Index m = X.cols();
    for (Eigen::Index j = 0; j + 1 < n; j += 2) {
      const double l0 = Lb(0, j), l1 = Lb(1, j), l2 = Lb(0, j + 1);
      for (Eigen::Index c = 0; c < m; ++c) {
        const double x0 = X(j, c) / l0;
        X(j, c) = x0;
        X(j + 1, c) = (X(j + 1, c) - l1 * x0) / l2;
      }
    }
    return;
  }
  if (X.cols() == 1) {
    double* x = X.data();
    for (Eigen::Index j = 0; j < n; ++j) {
      const double xj = x[j] / Lb(0, j);
      x[j] = xj;
      const Eigen::Index last = std::min<Eigen::Index>(n - 1, j + kd);
      const double* l = &Lb(0, j);
      for (Eigen::Index i = j + 1; i <= last; ++i) x[i] -= l[i - j] * xj;
    }
    return;
  }
  Eigen::MatrixXd Xt = X.transpose();
  for (Eigen::Index j = 0; j < n; ++j) {
    Xt.col(j) /= Lb(0, j);
    const Eigen::Index last = std::min<Eigen::Index>(n - 1, j + kd);
    for (Eigen::Index i = j + 1; i <= last; ++i) Xt.col(i) -= Lb(i - j, j) * Xt.col(j);
  }
  X = Xt.transpose();
}

// x <- L^{-T} x.
void backward_solve(const Eigen::MatrixXd& Lb, int kd, Eigen::VectorXd& x) {
  const Eigen::Index n = Lb.cols();
  if (kd == 1 && detail::diagonal_likelihood_setting()) {  // K = 0: 2 x 2 blocks
    for (Eigen::Index j = n - 2; j >= 0; j -= 2) {
      x[j + 1] = x[j + 1] / Lb(0, j + 1);
      x[j] = (x[j] - Lb(1, j) * x[j + 1]) / Lb(0, j);
    }
    return;
  }
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    double s = x[j];
    const Eigen::Index last = std::min<Eigen::Index>(n - 1, j + kd);
    for (Eigen::Index i = j + 1; i <= last; ++i) s -= Lb(i - j, j) * x[i];
    x[j] = s / Lb(0, j);
  }
}

}  // namespace

double ExactLikelihood::cost(const Eigen::VectorXcd& theta) const {
  Factor f = factor(theta);
  forward_solve(f.Lb, kd_, f.r);
  return f.r.squaredNorm();
}

Eigen::MatrixXd ExactLikelihood::real_jacobian(const FrequencyData& x) const {
  // dr/dxi = [Re; Im] of J Text, rows interleaved; J[l, q] = +-s^n X_{l-k}, through Text's
  // nonzeros (one or two per row), not a dense product.
  const detail::Lines X{x};
  const auto text = detail::text_entries(p_);
  const int R = static_cast<int>(sorted_.size());
  Eigen::MatrixXd out(2 * R, p_.n_xi());
  detail::RowPowers pw(p_.structure());
  std::vector<cd> j;
  Eigen::RowVectorXcd jt(p_.n_xi());
  for (int r = 0; r < R; ++r) {
    pw.compute(sorted_[r]);
    detail::jacobian_text_row(p_, X, pw, sorted_[r], text, j, jt.data());
    out.row(2 * r) = jt.real();
    out.row(2 * r + 1) = jt.imag();
  }
  return out;
}

// With S = D S_line D (D fixed) and r = M x: dV = 2 q^T dM x - 2 (D q)^T dM Cov M^T (D q), and the
// scaled entries give x0 = x - Cov M^T D q, so row r's part of the gradient is the Jacobian at
// x - d_r (x - x0): (1 - d_r) J_r(x) + d_r J_r(x0) (the Jacobian is linear in the spectra).
Eigen::MatrixXd ExactLikelihood::scaled_jacobian(const FrequencyData& x0) const {
  Eigen::MatrixXd J = real_jacobian(x0);
  if (!scale_.size()) return J;
  const Eigen::MatrixXd Jx = real_jacobian(d_);
  for (Eigen::Index r = 0; r < scale_.size(); ++r) {
    const double s = scale_[r];
    J.middleRows(2 * r, 2) = s * J.middleRows(2 * r, 2) + (1.0 - s) * Jx.middleRows(2 * r, 2);
  }
  return J;
}

void ExactLikelihood::set_row_scale(const Eigen::VectorXd& scale) {
  if (scale.size() == 0) {
    scale_.resize(0);
    return;
  }
  if (scale.size() != static_cast<Eigen::Index>(sorted_.size()))
    throw std::invalid_argument("scale must have one entry per row");
  if (!scale.allFinite() || (scale.array() <= 0).any())
    throw std::invalid_argument("scale must be finite and > 0");
  scale_.resize(scale.size());
  for (size_t i = 0; i < sorted_.size(); ++i) scale_[static_cast<Eigen::Index>(i)] = scale[order_[i]];
}

ExactLikelihood::Evaluation ExactLikelihood::evaluate(const Eigen::VectorXcd& theta) const {
  return evaluate(factor(theta), true);
}

ExactLikelihood::Evaluation ExactLikelihood::evaluate(const Factor& f, bool whiten) const {
  Evaluation ev;
  ev.whitened = f.r;
  forward_solve(f.Lb, kd_, ev.whitened);
  ev.cost = ev.whitened.squaredNorm();
  Eigen::VectorXd q = ev.whitened;
  backward_solve(f.Lb, kd_, q);
  // x0 = x - Cov(n) M^T q, line by line over the entries that touch each line.
  ev.denoised = d_;
  if (diagonal()) {  // K = 0: row r touches line sorted_[r] alone (rows are distinct)
    const int R = static_cast<int>(sorted_.size());
    for (int r = 0; r < R; ++r) {
      const Factor::Entry& en = f.e[static_cast<size_t>(r)];
      double z[4];
      for (int a = 0; a < 4; ++a) z[a] = 0.0 + (en.H[a][0] * q[2 * r] + en.H[a][1] * q[2 * r + 1]);
      ev.denoised.Y[en.m] -= cd(z[0], z[1]);
      ev.denoised.U[en.m] -= cd(z[2], z[3]);
    }
    ev.jacobian = scaled_jacobian(ev.denoised);
    if (!whiten) return ev;
    forward_solve(f.Lb, kd_, ev.jacobian);
    ev.gradient = 2.0 * ev.jacobian.transpose() * ev.whitened;
    return ev;
  }
  std::vector<std::array<double, 4>> z(d_.max_line() + 1, {0.0, 0.0, 0.0, 0.0});
  const int R = static_cast<int>(sorted_.size()), W = 2 * K_ + 1;
  std::vector<char> touched(d_.max_line() + 1, 0);
  for (int r = 0; r < R; ++r)
    for (int k = 0; k < W; ++k) {
      const Factor::Entry& en = f.e[static_cast<size_t>(r) * W + k];
      for (int a = 0; a < 4; ++a) z[en.m][a] += en.H[a][0] * q[2 * r] + en.H[a][1] * q[2 * r + 1];
      touched[en.m] = 1;
    }
  for (int m = 0; m <= d_.max_line(); ++m) {
    if (!touched[m]) continue;
    ev.denoised.Y[m] -= cd(z[m][0], z[m][1]);
    ev.denoised.U[m] -= cd(z[m][2], z[m][3]);
  }
  ev.jacobian = scaled_jacobian(ev.denoised);
  if (!whiten) return ev;  // the Jacobian at x0, not whitened; no gradient
  forward_solve(f.Lb, kd_, ev.jacobian);
  ev.gradient = 2.0 * ev.jacobian.transpose() * ev.whitened;
  return ev;
}

namespace {

Eigen::MatrixXd free_columns(const Eigen::MatrixXd& J, const std::vector<int>& free) {
  Eigen::MatrixXd out(J.rows(), static_cast<Eigen::Index>(free.size()));
  for (size_t c = 0; c < free.size(); ++c) out.col(static_cast<Eigen::Index>(c)) = J.col(free[c]);
  return out;
}

}  // namespace

Eigen::MatrixXd symmetric_inverse(const Eigen::MatrixXd& F, const char* what) {
  Eigen::LDLT<Eigen::MatrixXd> ldlt(F);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
    throw NumericalError(std::string(what) + " is singular: the parameters are not identifiable "
                         "from these data (too many harmonics or orders, or too few excited lines)");
  }
  // Positive pivots do not make an inverse: below a reciprocal condition of one rounding unit it
  // has no correct digit (variances of -1e32 were seen at a non-converged, degenerate estimate).
  const double rc = ldlt.rcond();
  if (!(rc > std::numeric_limits<double>::epsilon())) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1e", rc);
    throw NumericalError(std::string(what) + " is numerically singular (reciprocal condition " + buf +
                         "): the estimate sits where the parameters are not identifiable (a fit that did "
                         "not converge, or a degenerate structure)");
  }
  const Eigen::MatrixXd inv = ldlt.solve(Eigen::MatrixXd::Identity(F.rows(), F.cols()));
  return 0.5 * (inv + inv.transpose());
}

Eigen::MatrixXd ExactLikelihood::fisher_information(const Eigen::VectorXcd& theta) const {
  if (scale_.size()) {
    // The information takes the Jacobian at the denoised spectra x0 alone: the gradient's
    // (1 - d_r) J_r(x) holds the data's noise, whose square would add E{dJ^T S^-1 dJ} to it.
    const Factor f = factor(theta);
    Eigen::MatrixXd J = real_jacobian(evaluate(f, false).denoised);
    forward_solve(f.Lb, kd_, J);
    const Eigen::MatrixXd Jw = free_columns(J, p_.free_indices());
    return Jw.transpose() * Jw;
  }
  const Evaluation ev = evaluate(theta);
  const Eigen::MatrixXd Jw = free_columns(ev.jacobian, p_.free_indices());
  return Jw.transpose() * Jw;
}

Eigen::MatrixXd ExactLikelihood::sandwich_covariance(const Eigen::VectorXcd& theta,
                                                     const Eigen::VectorXd& weights) const {
  const SandwichTerms t = sandwich_terms(theta, weights);
  return sandwich_from_terms(t.bread, t.meat);
}

Eigen::MatrixXd sandwich_from_terms(const Eigen::MatrixXd& bread, const Eigen::MatrixXd& meat) {
  const Eigen::MatrixXd Hinv = symmetric_inverse(bread, "the weighted information matrix");
  const Eigen::MatrixXd cov = Hinv * meat * Hinv;
  return 0.5 * (cov + cov.transpose());
}

ExactLikelihood::SandwichTerms ExactLikelihood::sandwich_terms(const Eigen::VectorXcd& theta,
                                                               const Eigen::VectorXd& weights) const {
  const int R = static_cast<int>(sorted_.size());
  if (weights.size() != R) throw std::invalid_argument("weights must have one entry per row");
  const Factor f = factor(theta);
  Eigen::MatrixXd J = free_columns(scale_.size() ? real_jacobian(evaluate(f, false).denoised)
                                                 : evaluate(f, false).jacobian, p_.free_indices());
  // H = J^T W J and J^T W S W J = (L^T W J)^T (L^T W J), both symmetric (rank updates, half
  // the flops of a product). Built on the transposes (columns = real rows), so that L^T is
  // applied to contiguous vectors: Xt = (W J)^T, column j of (L^T W J)^T = sum_i L(i, j) Xt(:, i).
  const Eigen::Index n = 2 * R, nc = J.cols();
  Eigen::MatrixXd Xt = J.transpose();
  Eigen::MatrixXd St(nc, n);  // sqrt(W) J, transposed
  for (int r = 0; r < R; ++r) {
    const double w = weights[order_[r]];
    const double sw = std::sqrt(std::max(w, 0.0));
    St.middleCols(2 * r, 2) = sw * Xt.middleCols(2 * r, 2);
    Xt.middleCols(2 * r, 2) *= w;
  }
  Eigen::MatrixXd LtWJt(nc, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::Index last = std::min<Eigen::Index>(n - 1, j + kd_);
    auto col = LtWJt.col(j);
    col = f.Lb(0, j) * Xt.col(j);
    for (Eigen::Index i = j + 1; i <= last; ++i) col += f.Lb(i - j, j) * Xt.col(i);
  }
  SandwichTerms t;
  t.meat = Eigen::MatrixXd::Zero(nc, nc);
  t.meat.selfadjointView<Eigen::Lower>().rankUpdate(LtWJt);
  t.meat.triangularView<Eigen::StrictlyUpper>() = t.meat.transpose();
  if (weights.minCoeff() >= 0) {
    t.bread = Eigen::MatrixXd::Zero(nc, nc);
    t.bread.selfadjointView<Eigen::Lower>().rankUpdate(St);
    t.bread.triangularView<Eigen::StrictlyUpper>() = t.bread.transpose();
  } else {  // weights of any sign (not a fit's): the plain product
    t.bread = Xt * J;
  }
  return t;
}

ExactLikelihood::SecondOrderTerms& ExactLikelihood::SecondOrderTerms::operator+=(const SecondOrderTerms& o) {
  qq += o.qq;
  qr += o.qr;
  rr += o.rr;
  cj += o.cj;
  return *this;
}

// Row pairs (r, r2) that read one signed line i (row r at harmonic k = l - i, row r2 at
// k2 = l2 - i; lines i and -i are different noise for a circular line, conjugates of each
// other). With f_q = +-s_i^n the Jacobian's factor of theta_q and E_qq2 = E{conj(dX^q_i) dX^q2_i}
// (var Y, var U or the cross-covariance, by the sides of q and q2), Isserlis' theorem for
// circular Gaussian noise gives, over ordered pairs of rows,
//   Cov(Q_q, Q_q2)  = sum w_l w_l' E{conj(dJ_lq) dJ_l'q2} S_ll'     (Q = sum_l w_l conj(dJ_l) e_l)
//   Cov(Q_q, R)     = sum w_l w_l' E{conj(dJ_lq) e_l'} S_ll'
//   Var(R)          = sum w_l w_l' |S_ll'|^2
//   E{Q_q Q_q2}     = sum w_l w_l' g_q(l, l') g_q2(l', l),  g_q(l, l') = E{conj(dJ_lq) e_l'}
// with S_ll' = E{e_l conj(e_l')} (METHOD.md section 10). Real xi coordinates: q = Re(Text^H Q),
// so Cov(q) = Re(Text^H Cov(Q) Text + Text^H E{Q Q^T} conj(Text)) / 2 and
// Cov(q, R) = Re(Text^H Cov(Q, R)). E{Q Q^T} is a sum of outer products of the columns g(l, l')
// and w_l w_l' g(l', l), gathered per row offset l' - l (their harmonics depend on it alone) and
// multiplied out in blocks.
ExactLikelihood::SecondOrderTerms ExactLikelihood::second_order_terms(const Eigen::VectorXcd& theta,
                                                                     const Eigen::VectorXd& weights) const {
  if (theta.size() != p_.n_theta()) throw std::invalid_argument("theta has the wrong size");
  const int R = static_cast<int>(sorted_.size()), W = 2 * K_ + 1, nt = p_.n_theta();
  if (weights.size() != R) throw std::invalid_argument("weights must have one entry per row");
  const Structure& st = p_.structure();
  const detail::Lines X{d_};
  const detail::HarmonicCoefficients hc = detail::by_harmonic(p_, theta);
  detail::RowPowers pw(st);
  // theta's entries ordered by harmonic (the rows of E{Q Q^T}'s blocks are ranges of it).
  const std::vector<std::vector<int>> group = detail::params_by_harmonic(p_);
  std::vector<int> perm, gstart(static_cast<size_t>(W) + 1);
  for (int kk = 0; kk < W; ++kk) {
    gstart[static_cast<size_t>(kk)] = static_cast<int>(perm.size());
    for (int q : group[static_cast<size_t>(kk)]) perm.push_back(q);
  }
  gstart[static_cast<size_t>(W)] = nt;
  // Per sorted row r and harmonic k (slot r W + K + k): the band entries a = A_{l,i}, b = B_{l,i}
  // of the signed line i = l - k, its noise (co)variances, and per parameter x of harmonic k
  // (in perm order from gstart[K + k]) f_x = +-s_i^n, uY_x = conj(f_x) E{conj(dX^x) dY_i},
  // uU_x = conj(f_x) E{conj(dX^x) dU_i}.
  struct Slot {
    cd a, b, cyu;
    double vy, vu;
  };
  std::vector<Slot> slot(static_cast<size_t>(R) * W);
  std::vector<cd> fx(static_cast<size_t>(R) * nt), uY(static_cast<size_t>(R) * nt), uU(static_cast<size_t>(R) * nt);
  std::vector<char> isa(static_cast<size_t>(nt));
  for (int x = 0; x < nt; ++x) isa[static_cast<size_t>(x)] = p_.params()[static_cast<size_t>(perm[static_cast<size_t>(x)])].is_a;
  std::vector<double> w(static_cast<size_t>(R));
  std::vector<cd> A, B;
  for (int r = 0; r < R; ++r) {
    pw.compute(sorted_[r]);
    detail::band_row(hc, pw, A, B);
    for (int k = -K_; k <= K_; ++k) {
      const int i = sorted_[r] - k;
      Slot& s = slot[static_cast<size_t>(r) * W + K_ + k];
      s.a = A[static_cast<size_t>(K_ + k)];
      s.b = B[static_cast<size_t>(K_ + k)];
      s.vy = X.varY(i);
      s.vu = X.varU(i);
      s.cyu = X.covYU(i);
      for (int x = gstart[static_cast<size_t>(K_ + k)]; x < gstart[static_cast<size_t>(K_ + k + 1)]; ++x) {
        const Param& pr = p_.params()[static_cast<size_t>(perm[static_cast<size_t>(x)])];
        const cd f = (pr.is_a ? 1.0 : -1.0) * pw(k, pr.order);
        const size_t at = static_cast<size_t>(r) * nt + x;
        fx[at] = f;
        uY[at] = std::conj(f) * (pr.is_a ? cd(s.vy, 0.0) : s.cyu);
        uU[at] = std::conj(f) * (pr.is_a ? std::conj(s.cyu) : cd(s.vu, 0.0));
      }
    }
    w[static_cast<size_t>(r)] = std::max(weights[order_[r]], 0.0);
  }
  // E{Q Q^T} = sum over ordered row pairs (l, l') of w w' g(l, l') g(l', l)^T, symmetric: the
  // pair (l', l) adds the transpose of (l, l')'s term, so E{Q Q^T} = P0 + P + P^T with P over
  // the pairs l < l' and P0 over l = l'. For l' - l = delta >= 0, g(l, l') lives on the
  // harmonics k with |delta + k| <= K, g(l', l) on those with |k - delta| <= K: one buffer of
  // columns per delta, multiplied out when full.
  constexpr int kCap = 64;
  // Real arithmetic: with Ga = Ar + j Ai, Gb = Br + j Bi, Ga Gb^T = [Ar Ai] [Br -Bi]^T
  // + j [Ar Ai] [Bi Br]^T, one real product of A = [Ar Ai] and B = [[Br -Bi]; [Bi Br]].
  struct Buffer {
    int a0 = 0, na = 0, b0 = 0, nb = 0, used = 0;
    Eigen::MatrixXd A, B;  // na x 2 kCap; 2 nb x 2 kCap
    void add_a(int row, int col, cd v) {
      A(row, col) += v.real();
      A(row, kCap + col) += v.imag();
    }
    void add_b(int row, int col, cd v) {
      B(row, col) += v.real();
      B(row, kCap + col) -= v.imag();
      B(nb + row, col) += v.imag();
      B(nb + row, kCap + col) += v.real();
    }
  };
  std::vector<Buffer> buf(static_cast<size_t>(2 * K_ + 1));
  for (int delta = 0; delta <= 2 * K_; ++delta) {
    Buffer& bf = buf[static_cast<size_t>(delta)];
    const int ka0 = -K_, ka1 = K_ - delta, kb0 = delta - K_, kb1 = K_;
    bf.a0 = gstart[static_cast<size_t>(K_ + ka0)];
    bf.na = gstart[static_cast<size_t>(K_ + ka1 + 1)] - bf.a0;
    bf.b0 = gstart[static_cast<size_t>(K_ + kb0)];
    bf.nb = gstart[static_cast<size_t>(K_ + kb1 + 1)] - bf.b0;
    bf.A = Eigen::MatrixXd::Zero(bf.na, 2 * kCap);
    bf.B = Eigen::MatrixXd::Zero(2 * bf.nb, 2 * kCap);
  }
  Eigen::MatrixXd Pri = Eigen::MatrixXd::Zero(nt, 2 * nt), Pri0 = Eigen::MatrixXd::Zero(nt, 2 * nt);  // [Re Im], perm order
  // The buffers' products by the BLAS's dgemm (the estimators' LAPACK comes with it; at these
  // sizes its vector kernels take a third of the time of Eigen's portable ones), one thread,
  // into the [Re Im] blocks of the target directly.
  const detail::SingleThreadedBlas single(true);
  auto flush = [&](Buffer& bf, bool diagonal) {
    if (bf.used == 0) return;
    Eigen::MatrixXd& target = diagonal ? Pri0 : Pri;
    const int m = bf.na, n = bf.nb, k = 2 * kCap, lda = bf.na, ldb = 2 * bf.nb, ldc = nt;
    const double one = 1.0;
    dgemm_("N", "T", &m, &n, &k, &one, bf.A.data(), &lda, bf.B.data(), &ldb, &one, &target(bf.a0, bf.b0), &ldc);
    dgemm_("N", "T", &m, &n, &k, &one, bf.A.data(), &lda, bf.B.data() + bf.nb, &ldb, &one,
           &target(bf.a0, nt + bf.b0), &ldc);
    bf.A.leftCols(bf.used).setZero();
    bf.A.middleCols(kCap, bf.used).setZero();
    bf.B.leftCols(bf.used).setZero();
    bf.B.middleCols(kCap, bf.used).setZero();
    bf.used = 0;
  };
  Eigen::MatrixXcd G = Eigen::MatrixXcd::Zero(nt, nt), Gd = Eigen::MatrixXcd::Zero(nt, nt);  // perm order
  Eigen::VectorXcd tau = Eigen::VectorXcd::Zero(nt);
  double rr = 0;
  for (int r = 0; r < R; ++r) {
    const int l = sorted_[r];
    for (int r2 = r; r2 < std::min(R, r + 2 * K_ + 1); ++r2) {
      const int l2 = sorted_[r2], delta = l2 - l;
      if (delta > 2 * K_) break;
      const int klo = std::max(-K_, -K_ - delta), khi = std::min(K_, K_ - delta);  // l reads i = l - k, l2 reads it too
      cd S(0.0, 0.0);  // E{e_l conj(e_l2)} over the signed lines both rows read
      for (int k = klo; k <= khi; ++k) {
        const Slot& s1 = slot[static_cast<size_t>(r) * W + K_ + k];
        const Slot& s2 = slot[static_cast<size_t>(r2) * W + K_ + k + delta];
        S += s1.vy * mul(s1.a, std::conj(s2.a)) - mul(mul(s1.a, std::conj(s2.b)), s1.cyu) -
             mul(mul(s1.b, std::conj(s2.a)), std::conj(s1.cyu)) + s1.vu * mul(s1.b, std::conj(s2.b));
      }
      const double ww = w[static_cast<size_t>(r)] * w[static_cast<size_t>(r2)];
      rr += (r == r2 ? 1.0 : 2.0) * ww * std::norm(S);
      const cd wS = ww * S;
      Buffer& fwd = buf[static_cast<size_t>(delta)];
      const int cf = fwd.used;
      Eigen::MatrixXcd& target = (r == r2) ? Gd : G;
      for (int k = klo; k <= khi; ++k) {
        const int k2 = k + delta;
        const Slot& s1 = slot[static_cast<size_t>(r) * W + K_ + k];
        const Slot& s2 = slot[static_cast<size_t>(r2) * W + K_ + k2];
        const int x0 = gstart[static_cast<size_t>(K_ + k)], x1 = gstart[static_cast<size_t>(K_ + k + 1)];
        const int y0 = gstart[static_cast<size_t>(K_ + k2)], y1 = gstart[static_cast<size_t>(K_ + k2 + 1)];
        const cd* uY1 = &uY[static_cast<size_t>(r) * nt];
        const cd* uU1 = &uU[static_cast<size_t>(r) * nt];
        const cd* uY2 = &uY[static_cast<size_t>(r2) * nt];
        const cd* uU2 = &uU[static_cast<size_t>(r2) * nt];
        const cd* f2 = &fx[static_cast<size_t>(r2) * nt];
        for (int y = y0; y < y1; ++y) {  // E{conj(dJ_lx) dJ_l2y} S: Y- or U-side moments by y's side
          const cd wf = mul(wS, f2[y]);
          const cd* u1 = isa[static_cast<size_t>(y)] ? uY1 : uU1;
          for (int x = x0; x < x1; ++x) target(x, y) += mul(wf, u1[x]);
        }
        for (int x = x0; x < x1; ++x) {  // dJ on row l, the residue on row l2: g_x(l, l2)
          const cd g = mul(s2.a, uY1[x]) - mul(s2.b, uU1[x]);
          tau[x] += mul(wS, g);
          fwd.add_a(x - fwd.a0, cf, g);
          if (r == r2) fwd.add_b(x - fwd.b0, cf, ww * g);
        }
        if (r != r2) {  // dJ on row l2, the residue on row l: g_y(l2, l); S_{l2 l} = conj(S_{l l2})
          for (int y = y0; y < y1; ++y) {
            const cd g = mul(s1.a, uY2[y]) - mul(s1.b, uU2[y]);
            tau[y] += mul(std::conj(wS), g);
            fwd.add_b(y - fwd.b0, cf, ww * g);
          }
        }
      }
      if (++fwd.used == kCap) flush(fwd, delta == 0);
    }
  }
  for (int delta = 0; delta <= 2 * K_; ++delta) flush(buf[static_cast<size_t>(delta)], delta == 0);
  // Back to theta's order (pos: theta's index -> its place in perm order), then to real xi
  // coordinates through Text's nonzeros: Gamma = G + G^H + Gd, Pi = P + P^T + P0.
  std::vector<int> pos(static_cast<size_t>(nt));
  for (int i = 0; i < nt; ++i) pos[static_cast<size_t>(perm[static_cast<size_t>(i)])] = i;
  const std::vector<detail::TextEntry> text = detail::text_entries(p_);
  SecondOrderTerms t;
  const Eigen::MatrixXd tg = detail::real_congruence(p_, text, [&](int a, int b) {
    const int i = pos[static_cast<size_t>(a)], j = pos[static_cast<size_t>(b)];
    return G(i, j) + std::conj(G(j, i)) + Gd(i, j);
  }, false);
  const Eigen::MatrixXd tp = detail::real_congruence(p_, text, [&](int a, int b) {
    const int i = pos[static_cast<size_t>(a)], j = pos[static_cast<size_t>(b)];
    return cd(Pri(i, j) + Pri(j, i) + Pri0(i, j), Pri(i, nt + j) + Pri(j, nt + i) + Pri0(i, nt + j));
  }, true);
  t.qq = 0.5 * (tg + tp);
  t.qq = (0.5 * (t.qq + t.qq.transpose())).eval();
  t.qr = Eigen::VectorXd::Zero(p_.n_xi());
  for (const detail::TextEntry& e : text) t.qr[e.c] += mul(std::conj(e.v), tau[pos[static_cast<size_t>(e.p)]]).real();
  t.rr = rr;
  std::vector<int> rows(sorted_.size());  // the caller's order, as the weights are
  for (size_t r = 0; r < sorted_.size(); ++r) rows[static_cast<size_t>(order_[r])] = sorted_[r];
  t.cj = real_column_covariance(d_, p_, rows, weights.cwiseMax(0.0));
  return t;
}

Eigen::MatrixXd second_order_meat(const ExactLikelihood::SecondOrderTerms& t, const Parametrisation& p,
                                  const Eigen::VectorXcd& theta) {
  const Eigen::VectorXd xi = p.xi_from_theta(theta);
  const Eigen::VectorXd cx = t.cj * xi;
  const double xcx = xi.dot(cx);
  const Eigen::VectorXd v = xcx > 0 ? Eigen::VectorXd(cx / xcx) : Eigen::VectorXd::Zero(xi.size());
  Eigen::MatrixXd M = t.qq - t.qr * v.transpose() - v * t.qr.transpose() + t.rr * v * v.transpose();
  const std::vector<int> free = p.free_indices();
  const Eigen::Index nf = static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd out(nf, nf);
  for (Eigen::Index a = 0; a < nf; ++a)
    for (Eigen::Index b = 0; b < nf; ++b) out(a, b) = 0.5 * (M(free[a], free[b]) + M(free[b], free[a]));
  return out;
}

namespace {

// Levenberg-Marquardt on V. `trial(theta)` factors S and gives the cost (a pair: the
// factors, the cost: what a trial step needs); `complete(t)` gives from it the whitened residue
// and the whitened Jacobian (of one experiment, or of several stacked), so the Jacobian is
// built only at accepted steps and S is factored once per step. A step whose predicted
// decrease of V is at rounding level (8 eps V) is not tried: V is at its minimum to
// rounding, and raising lambda up to 1e12 to find that out took up to 15 evaluations.
template <class Trial, class Complete>
ExactFit minimise(const Trial& trial, const Complete& complete, const Parametrisation& p,
                  const Eigen::VectorXcd& theta0, double tol, int max_iter) {
  const std::vector<int> free = p.free_indices();
  const int nf = static_cast<int>(free.size());
  ExactFit fit;
  fit.xi = p.xi_from_theta(theta0);
  fit.theta = p.theta_from_xi(fit.xi);
  fit.xi = p.xi_from_theta(fit.theta);  // normalised
  ExactLikelihood::Evaluation ev = complete(trial(fit.theta));
  auto half_gradient = [&](const ExactLikelihood::Evaluation& e, Eigen::MatrixXd& J) {
    J = free_columns(e.jacobian, free);
    return Eigen::VectorXd(J.transpose() * e.whitened);
  };
  Eigen::MatrixXd J;
  Eigen::VectorXd g = half_gradient(ev, J);
  double lambda = 1e-3;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  for (int it = 1; it <= max_iter; ++it) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(J.cols(), J.cols());
    H.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
    H.triangularView<Eigen::StrictlyUpper>() = H.transpose();
    const Eigen::VectorXd D = H.diagonal().cwiseMax(kEps * H.diagonal().maxCoeff());
    bool accepted = false;
    Eigen::VectorXd step, xi_t;
    Eigen::VectorXcd theta_t;
    ExactLikelihood::Evaluation ev_t;
    bool at_rounding = false;
    while (lambda < 1e12) {
      Eigen::MatrixXd Hl = H;
      Hl.diagonal() += lambda * D;
      step = Hl.ldlt().solve(-g);
      // V(xi + s) ~ V + 2 g^T s + s^T H s (g the half gradient): the predicted decrease.
      const double predicted = -(2.0 * g.dot(step) + step.dot(H * step));
      if (!(predicted > 8 * kEps * ev.cost)) {
        at_rounding = true;
        break;
      }
      xi_t = fit.xi;
      for (int c = 0; c < nf; ++c) xi_t[free[c]] += step[c];
      try {
        theta_t = p.theta_from_xi(xi_t);
        auto t = trial(theta_t);
        if (t.second <= ev.cost) {
          ev_t = complete(t);
          accepted = true;
          break;
        }
      } catch (const NumericalError&) {  // a step into a region where S is singular
      }
      lambda *= 10;
    }
    if (at_rounding) {
      fit.converged = true;
      break;
    }
    if (!accepted) {  // no step lowers V: a minimum to rounding
      fit.converged = true;
      break;
    }
    double xnorm = 0;
    for (int c = 0; c < nf; ++c) xnorm += fit.xi[free[c]] * fit.xi[free[c]];
    const double rel_step = step.norm() / std::max(std::sqrt(xnorm), 1e-300);
    const double decrease = ev.cost - ev_t.cost;
    fit.xi = xi_t;
    fit.theta = theta_t;
    ev = std::move(ev_t);
    g = half_gradient(ev, J);
    fit.iterations = it;
    fit.cost_history.push_back(ev.cost);
    lambda = std::max(lambda / 10, 1e-12);
    // The step is below tol, or V changes only at rounding level with a small step.
    if (rel_step < tol || (decrease <= 8 * kEps * ev.cost && rel_step < 1e-6)) {
      fit.converged = true;
      break;
    }
  }
  fit.cost = ev.cost;
  fit.information = J.transpose() * J;
  return fit;
}

}  // namespace

ExactFit minimise_exact_cost(const ExactLikelihood& lik, const Parametrisation& p,
                             const Eigen::VectorXcd& theta0, double tol, int max_iter) {
  // A trial: S factored at theta (first) and the cost there (second).
  using Factored = std::pair<ExactLikelihood::Factor, double>;
  auto trial = [&](const Eigen::VectorXcd& theta) {
    Factored t{lik.factor(theta), 0.0};
    Eigen::VectorXd r = t.first.r;
    forward_solve(t.first.Lb, lik.kd_, r);
    t.second = r.squaredNorm();
    return t;
  };
  auto complete = [&](const Factored& t) { return lik.evaluate(t.first, true); };
  return minimise(trial, complete, p, theta0, tol, max_iter);
}

ExactFit minimise_exact_cost(const std::vector<ExactLikelihood>& liks, const Parametrisation& p,
                             const Eigen::VectorXcd& theta0, double tol, int max_iter) {
  if (liks.empty()) throw std::invalid_argument("experiments: the list is empty");
  if (liks.size() == 1) return minimise_exact_cost(liks[0], p, theta0, tol, max_iter);
  // S block diagonal over the experiments: the whitened residues and Jacobians stack.
  using FactoredAll = std::pair<std::vector<ExactLikelihood::Factor>, double>;
  auto trial = [&](const Eigen::VectorXcd& theta) {
    FactoredAll t{{}, 0.0};
    for (const ExactLikelihood& lik : liks) {
      t.first.push_back(lik.factor(theta));
      Eigen::VectorXd r = t.first.back().r;
      forward_solve(t.first.back().Lb, lik.kd_, r);
      t.second += r.squaredNorm();
    }
    return t;
  };
  auto complete = [&](const FactoredAll& t) {
    std::vector<ExactLikelihood::Evaluation> parts;
    Eigen::Index rows = 0;
    for (size_t e = 0; e < liks.size(); ++e) {
      parts.push_back(liks[e].evaluate(t.first[e], true));
      rows += parts.back().whitened.size();
    }
    ExactLikelihood::Evaluation ev;
    ev.whitened.resize(rows);
    ev.jacobian.resize(rows, parts[0].jacobian.cols());
    Eigen::Index at = 0;
    for (const auto& e : parts) {
      ev.cost += e.cost;
      ev.whitened.segment(at, e.whitened.size()) = e.whitened;
      ev.jacobian.middleRows(at, e.jacobian.rows()) = e.jacobian;
      at += e.whitened.size();
    }
    return ev;
  };
  return minimise(trial, complete, p, theta0, tol, max_iter);
}

Eigen::MatrixXd ExactLikelihood::residue_covariance(const Eigen::VectorXcd& theta) const {
  const Factor f = factor(theta);
  const Eigen::Index n = f.Lb.cols();
  const Eigen::Index kd = kd_;
  // S = L L^T with L lower banded (kd sub-diagonals, L(i, c) = Lb(i - c, c)): S is banded too,
  // S(i, j) = sum of L(i, c) L(j, c) over c in [i - kd, j] for j <= i <= j + kd (O(n kd^2)).
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = j; i <= std::min<Eigen::Index>(n - 1, j + kd); ++i) {
      double sum = 0.0;
      for (Eigen::Index c = std::max<Eigen::Index>(0, i - kd); c <= j; ++c) sum += f.Lb(i - c, c) * f.Lb(j - c, c);
      S(i, j) = sum;
      S(j, i) = sum;
    }
  }
  return S;
}

Eigen::MatrixXd eta_covariance(const Parametrisation& p, const Eigen::MatrixXd& cov_free) {
  const std::vector<int> free = p.free_indices();
  if (cov_free.rows() != static_cast<Eigen::Index>(free.size()) || cov_free.cols() != cov_free.rows()) {
    throw std::invalid_argument("cov_free must be square with one row per free parameter");
  }
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(p.n_eta(), p.n_eta());
  for (size_t a = 0; a < free.size(); ++a)
    for (size_t b = 0; b < free.size(); ++b)
      if (free[a] < p.n_eta() && free[b] < p.n_eta()) out(free[a], free[b]) = cov_free(a, b);
  return out;
}

Eigen::MatrixXd cramer_rao_bound(const FrequencyData& noiseless, const Parametrisation& p,
                                 const std::vector<int>& rows, const Eigen::VectorXcd& theta) {
  const ExactLikelihood lik(noiseless, p, rows);
  return eta_covariance(p, symmetric_inverse(lik.fisher_information(theta), "the Fisher information"));
}

Eigen::MatrixXd cramer_rao_bound(const std::vector<FrequencyData>& noiseless, const Parametrisation& p,
                                 const std::vector<std::vector<int>>& rows, const Eigen::VectorXcd& theta) {
  if (noiseless.empty()) throw std::invalid_argument("noiseless: the list of experiments is empty");
  if (rows.size() != noiseless.size()) {
    throw std::invalid_argument("rows must give one list of rows per experiment (" +
                                std::to_string(noiseless.size()) + "), got " + std::to_string(rows.size()));
  }
  long long total = 0;
  for (const auto& r : rows) total += static_cast<long long>(r.size());
  if (2 * total <= p.n_xi() - 1) {
    throw std::invalid_argument("the orders and harmonic counts leave " + std::to_string(p.n_xi() - 1) +
                                " free parameters for " + std::to_string(2 * total) +
                                " real equations over all experiments");
  }
  Eigen::MatrixXd F;
  for (size_t e = 0; e < noiseless.size(); ++e) {
    const ExactLikelihood lik(noiseless[e], p, rows[e], ExactLikelihood::PartOfSeveral{});
    const Eigen::MatrixXd Fe = lik.fisher_information(theta);
    if (e == 0) F = Fe; else F += Fe;
  }
  return eta_covariance(p, symmetric_inverse(F, "the Fisher information"));
}

}  // namespace lptv
