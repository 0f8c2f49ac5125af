#include "lptv/estimators.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include "lptv/errors.hpp"
#include "lptv/gsvd.hpp"
#include "lptv/likelihood.hpp"
#include "rows.hpp"

extern "C" {
// LAPACK: singular values and right singular vectors of a general matrix.
void dgesvd_(const char* jobu, const char* jobvt, const int* m, const int* n, double* a, const int* lda,
             double* s, double* u, const int* ldu, double* vt, const int* ldvt, double* work,
             const int* lwork, int* info);
// LAPACK: QR of a triangular-pentagonal pair [A; B] (A upper triangular n x n).
void dtpqrt_(const int* m, const int* n, const int* l, const int* nb, double* a, const int* lda,
             double* b, const int* ldb, double* t, const int* ldt, double* work, int* info);
// LAPACK: QR of a general matrix, its reflectors blocked nb at a time (compact WY, LAPACK 3.4).
void dgeqrt_(const int* m, const int* n, const int* nb, double* a, const int* lda, double* t, const int* ldt,
             double* work, int* info);
}

namespace lptv {

Method method_from_string(const std::string& name) {
  if (name == "ls") return Method::LS;
  if (name == "tls") return Method::TLS;
  if (name == "gtls") return Method::GTLS;
  if (name == "wgtls") return Method::WGTLS;
  if (name == "sml") return Method::SML;
  throw std::invalid_argument("method must be 'ls', 'tls', 'gtls', 'wgtls' or 'sml', got '" + name + "'");
}

std::string method_name(Method m) {
  switch (m) {
    case Method::LS: return "ls";
    case Method::TLS: return "tls";
    case Method::GTLS: return "gtls";
    case Method::SML: return "sml";
    default: return "wgtls";
  }
}

namespace {

// QR of rows [begin, end) into an n x n upper-triangular R, block by block: each block B of
// real rows is folded into R by LAPACK's dtpqrt (QR of [R; B] exploiting R's triangle,
// blocked, on the BLAS), so the Jacobian is never held whole.
Eigen::MatrixXd r_factor_range(const FrequencyData& d, const Parametrisation& p,
                               const std::vector<int>& rows, const Eigen::VectorXd& weights,
                               size_t begin, size_t end) {
  const int n = p.n_xi();
  const auto entries = detail::text_entries(p);
  constexpr int kBlock = 1024;  // complex rows per block: 2 * 1024 real rows
  const int nb = std::min(n, 32);
  Eigen::MatrixXd B(2 * kBlock, n), T(nb, n), work(nb, n);
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, n);
  detail::RowPowers pw(p.structure());
  const detail::Lines X{d};
  std::vector<cd> jrow;
  Eigen::VectorXcd xrow(n);
  for (size_t b0 = begin; b0 < end; b0 += kBlock) {
    const int m = static_cast<int>(std::min<size_t>(kBlock, end - b0));
    for (int r = 0; r < m; ++r) {
      const int l = rows[b0 + r];
      pw.compute(l);
      detail::jacobian_text_row(p, X, pw, l, entries, jrow, xrow.data());
      const double sw = weights.size() ? std::sqrt(weights[b0 + r]) : 1.0;
      B.row(2 * r) = sw * xrow.real().transpose();
      B.row(2 * r + 1) = sw * xrow.imag().transpose();
    }
    const int mr = 2 * m, ldb = static_cast<int>(B.rows()), zero = 0;
    int info = 0;
    dtpqrt_(&mr, &n, &zero, &nb, R.data(), &n, B.data(), &ldb, T.data(), &nb, work.data(), &info);
    if (info != 0) throw NumericalError("QR of the Jacobian (dtpqrt) failed: info " + std::to_string(info));
  }
  return R.triangularView<Eigen::Upper>();
}

}  // namespace

Eigen::MatrixXd weighted_r_factor(const FrequencyData& d, const Parametrisation& p,
                                  const std::vector<int>& rows, const Eigen::VectorXd& weights) {
  if (weights.size() && weights.size() != static_cast<Eigen::Index>(rows.size())) {
    throw std::invalid_argument("weights must have one entry per row");
  }
  const int n = p.n_xi();
  Eigen::MatrixXd parts[2];
  // Two threads of ours each calling a multithreaded BLAS would oversubscribe the cores.
  const detail::SingleThreadedBlas guard(rows.size() >= 20000);
  const int used = detail::parallel_rows(rows.size(), [&](size_t begin, size_t end, int part) {
    parts[part] = r_factor_range(d, p, rows, weights, begin, end);
  });
  if (used == 1) return parts[0];
  // Merge the two triangles with one more small QR.
  Eigen::MatrixXd M(2 * n, n);
  M << parts[0], parts[1];
  Eigen::Ref<Eigen::MatrixXd> Mr = M;
  Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(Mr);
  return M.topRows(n).triangularView<Eigen::Upper>();
}

Eigen::MatrixXd real_column_covariance(const FrequencyData& d, const Parametrisation& p,
                                       const std::vector<int>& rows, const Eigen::VectorXd& weights) {
  const Eigen::MatrixXcd C = column_covariance(d, p, rows, weights);
  const Eigen::MatrixXd CJ =
      detail::real_congruence(p, detail::text_entries(p), [&](int a, int b) { return C(a, b); }, false);
  return 0.5 * (CJ + CJ.transpose());  // exact symmetry against rounding
}

namespace {

// Singular values of a square M (ascending) and the right singular vector of the smallest,
// by LAPACK's dgesvd (several times faster than a one-sided Jacobi SVD at these sizes).
std::pair<Eigen::VectorXd, Eigen::VectorXd> smallest_singular_vector(Eigen::MatrixXd M) {
  const int n = static_cast<int>(M.cols()), one = 1;
  Eigen::VectorXd s(n);
  Eigen::MatrixXd vt(n, n);
  double u = 0, query = 0;
  int info = 0, lwork = -1;
  dgesvd_("N", "A", &n, &n, M.data(), &n, s.data(), &u, &one, vt.data(), &n, &query, &lwork, &info);
  lwork = static_cast<int>(query);
  std::vector<double> work(static_cast<size_t>(std::max(lwork, 1)));
  dgesvd_("N", "A", &n, &n, M.data(), &n, s.data(), &u, &one, vt.data(), &n, work.data(), &lwork, &info);
  if (info != 0) throw NumericalError("SVD (dgesvd) failed: info " + std::to_string(info));
  return {s.reverse(), vt.row(n - 1).transpose()};
}

// The singular values of a square M, ascending (dgesvd without vectors: a third of the cost
// with them at 35 columns).
Eigen::VectorXd singular_values_of(Eigen::MatrixXd M) {
  const int n = static_cast<int>(M.cols()), one = 1;
  Eigen::VectorXd s(n);
  double u = 0, vt = 0, query = 0;
  int info = 0, lwork = -1;
  dgesvd_("N", "N", &n, &n, M.data(), &n, s.data(), &u, &one, &vt, &one, &query, &lwork, &info);
  lwork = static_cast<int>(query);
  std::vector<double> work(static_cast<size_t>(std::max(lwork, 1)));
  dgesvd_("N", "N", &n, &n, M.data(), &n, s.data(), &u, &one, &vt, &one, work.data(), &lwork, &info);
  if (info != 0) throw NumericalError("SVD (dgesvd) failed: info " + std::to_string(info));
  return s.reverse();
}

// The right singular vector of the smallest singular value of an upper-triangular M by inverse
// iteration, v <- (M^T M)^{-1} v through two triangular solves (2 n^2 flops a step against
// ~20 n^3 for dgesvd's vectors), from `start`. Each step shrinks the other directions by
// (sigma_1 / sigma_2)^2, so it is taken only when sigma_2 >= 2 sigma_1 (a factor <= 1/4 a
// step) and it stops when a step changes v by less than 8 eps, or when the change stops
// shrinking at rounding level; an empty result (no convergence in 60 steps) sends the caller
// to dgesvd. The triangular solves are backward stable, so the converged v is the singular
// vector to the accuracy dgesvd gives it (eps ||M|| / (sigma_2 - sigma_1)).
Eigen::VectorXd inverse_iteration(const Eigen::MatrixXd& M, Eigen::VectorXd v) {
  const auto U = M.triangularView<Eigen::Upper>();
  double nv = v.norm();
  if (!(nv > 0) || !v.allFinite()) return {};
  v /= nv;
  double prev = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 60; ++it) {
    Eigen::VectorXd z = U.transpose().solve(v);
    U.solveInPlace(z);
    const double nz = z.norm();
    if (!(nz > 0) || !std::isfinite(nz)) return {};
    z /= nz;
    if (z.dot(v) < 0) z = -z;
    const double change = (z - v).norm();
    v = z;
    if (change < 8 * std::numeric_limits<double>::epsilon()) return v;
    if (it >= 3 && change < 1e-12 && change > 0.5 * prev) return v;  // at rounding level
    prev = change;
  }
  return {};
}

}  // namespace

GtlsSolve gtls_from_r(const Eigen::MatrixXd& R, const Eigen::MatrixXd& CJ, const Eigen::VectorXd& start) {
  const Eigen::Index n = R.cols();
  Eigen::VectorXd scale(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double c = R.col(j).norm();
    scale[j] = c > 0 ? 1.0 / c : 1.0;
  }
  const Eigen::MatrixXd Rs = R * scale.asDiagonal();
  const Eigen::MatrixXd Cs = scale.asDiagonal() * CJ * scale.asDiagonal();
  GtlsSolve out;
  // Every column noisy (Cs positive definite and well conditioned): Cs = L L^T whitens the
  // pair, min ||Rs x|| / ||L^T x|| is the smallest singular value of Rs L^{-T}, x = L^{-T} v.
  // One Cholesky and one small SVD instead of an eigendecomposition and LAPACK's GSVD. The
  // whitening costs accuracy ~ eps cond(Cs), so it is taken only when cond(Cs) < 1e8 (by
  // the diagonal of L, a lower bound on sqrt(cond) that is sharp on these matrices; the
  // tests compare both routes with the reference at 1e-10).
  const Eigen::LLT<Eigen::MatrixXd> llt(Cs);
  if (llt.info() == Eigen::Success) {
    const Eigen::VectorXd dl = Eigen::MatrixXd(llt.matrixL()).diagonal();
    const double ratio = dl.minCoeff() / dl.maxCoeff();
    if (ratio * ratio > 1e-8) {
      // M = Rs L^{-T}: solve L M^T = Rs^T.
      // M is upper triangular (Rs and L^{-T} are). With a start (the previous WGTLS solve's
      // x, so v0 = L^T x / scale) and a gap, its smallest right singular vector is had by
      // inverse iteration and only the values by dgesvd.
      const Eigen::MatrixXd M = llt.matrixL().solve(Rs.transpose()).transpose();
      if (start.size() == n) {
        const Eigen::VectorXd sv = singular_values_of(M);
        if (n >= 2 && sv[1] >= 2.0 * sv[0]) {
          const Eigen::VectorXd v0 = llt.matrixU() * (start.array() / scale.array()).matrix();
          const Eigen::VectorXd v = inverse_iteration(M, v0);
          if (v.size() == n) {
            out.values = sv;
            out.x = scale.asDiagonal() * llt.matrixU().solve(v);
            return out;
          }
        }
      }
      const auto [sv, v] = smallest_singular_vector(M);
      out.values = sv;
      out.x = scale.asDiagonal() * llt.matrixU().solve(v);
      return out;
    }
  }
  // Some columns carry (almost) no noise: CJ^{1/2} as a square factor S with S^T S = Cs;
  // negative rounding-level eigenvalues of the (positive semidefinite) covariance are set to zero.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Cs);
  if (es.info() != Eigen::Success) throw NumericalError("eigendecomposition of the column covariance failed");
  // Eigenvalues at rounding level (|lambda| <= n eps max lambda) are directions without
  // noise: set to zero, so that the GSVD sees them as infinite pairs rather than as tiny
  // noise giving spurious finite generalised singular values.
  const double lmax = std::max(es.eigenvalues().maxCoeff(), 0.0);
  const double cut = double(n) * std::numeric_limits<double>::epsilon() * lmax;
  const Eigen::VectorXd lam = es.eigenvalues().unaryExpr([cut](double v) { return v > cut ? v : 0.0; });
  const Eigen::MatrixXd S = lam.cwiseSqrt().asDiagonal() * es.eigenvectors().transpose();
  const GeneralizedPairs g = gsvd_pairs(Rs, S);
  if (g.values.size() == 0) throw NumericalError("GSVD: no finite generalised singular value");
  out.x = scale.asDiagonal() * g.vectors.col(0);
  out.values = g.values;
  return out;
}

namespace {

struct Solved {
  Eigen::VectorXd x;
  Eigen::VectorXd values;
  double cost;
};

Solved solve_tls(const Eigen::MatrixXd& R) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullV);
  const Eigen::Index n = R.cols();
  Solved s;
  s.x = svd.matrixV().col(n - 1);
  s.values = svd.singularValues().reverse();
  s.cost = s.values[0] * s.values[0];
  return s;
}

Solved solve_ls(const Eigen::MatrixXd& R, int norm_index) {
  const Eigen::Index n = R.cols();
  Eigen::MatrixXd Rr(n, n - 1);
  for (Eigen::Index j = 0, c = 0; j < n; ++j)
    if (j != norm_index) Rr.col(c++) = R.col(j);
  const Eigen::VectorXd z = Rr.colPivHouseholderQr().solve(-R.col(norm_index));
  Solved s;
  s.x.resize(n);
  for (Eigen::Index j = 0, c = 0; j < n; ++j) s.x[j] = j == norm_index ? 1.0 : z[c++];
  s.cost = (R * s.x).squaredNorm();
  return s;
}

Solved solve_gtls(const Eigen::MatrixXd& R, const Eigen::MatrixXd& CJ,
                  const Eigen::VectorXd& start = Eigen::VectorXd()) {
  GtlsSolve g = gtls_from_r(R, CJ, start);
  return {g.x, g.values, g.values[0] * g.values[0]};
}

}  // namespace

namespace {

// The experiments of one fit, by reference: data and rows of each.
struct Experiments {
  std::vector<const FrequencyData*> d;
  std::vector<const std::vector<int>*> rows;
  size_t size() const { return d.size(); }
};

// One experiment's rows as WGTLS visits them at every iteration: the residue variance for
// theta, the R factor of the weighted real Jacobian and CJ_W for weights w. The Jacobian does
// not depend on theta and C_l (METHOD.md section 6) not on the weights, so below
// kCacheRows rows (and 64 MB) both are built once: the real Jacobian J (2m x n, rows Re, Im
// of each line) and, per row, the entries of C_l that can be nonzero (pairs of parameters of
// one harmonic k: ne = sum_k |group_k|^2). Then an iteration is
//   var e_l = Re sum_e C_l[e] conj(theta_a) theta_b   (one gemv over the cached entries),
//   C = sum_l w_l C_l                                  (one gemv),
//   CJ_W = Re(Text^H C Text)                           (Text's nonzeros, listed once),
//   R = qr(diag(sqrt w) J)                             (LAPACK's dgeqrt, blocks of kQrBlock),
// the same arithmetic as the functions above (which build it row by row) in another order.
// Larger problems use those functions (two threads, O(block) memory).
class WeightedRows {
 public:
  static constexpr size_t kCacheRows = 20000;  // where parallel_rows starts splitting
  static constexpr size_t kCacheBytes = size_t(64) << 20;
  // dgeqrt's block of reflectors. dgeqrf leaves matrices of fewer than 128 columns to the
  // unblocked dgeqr2 (one rank-1 update per column, dger); dgeqrt with blocks of 8 applies
  // them to the trailing columns as matrix products: the paper's 486 x 36 Jacobian in 60
  // instead of 83 us (OpenBLAS, one thread; 59-64 us for blocks of 4-16). The same R to rounding.
  static constexpr int kQrBlock = 8;

  WeightedRows(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows, bool full = false)
      : d_(d), p_(p), rows_(rows) {
    if (full && has_row_noise(d)) {  // the rows' noise from the realisations (METHOD.md section 20)
      full_ = true;
      rn_ = row_noise(d, p, rows);
    }
    const auto by_k = detail::params_by_harmonic(p);
    size_t ne = 0;
    for (const auto& g : by_k) ne += g.size() * g.size();
    const size_t m = rows.size(), n = static_cast<size_t>(p.n_xi());
    const size_t bytes = m * (2 * n * sizeof(double) + ne * sizeof(cd));
    if (m == 0 || m >= kCacheRows || bytes > kCacheBytes) return;
    cached_ = true;
    for (const auto& g : by_k)
      for (int a : g)
        for (int b : g) pairs_.push_back({a, b});
    // CJ(i, j) += Re(conj(T(a, i)) T(b, j) C(a, b)) for every listed entry (a, b).
    const auto text = detail::text_entries(p);
    std::vector<std::vector<std::pair<int, cd>>> trow(static_cast<size_t>(p.n_theta()));
    for (const auto& t : text) trow[static_cast<size_t>(t.p)].push_back({t.c, t.v});
    for (size_t e = 0; e < pairs_.size(); ++e)
      for (const auto& [i, ti] : trow[static_cast<size_t>(pairs_[e].first)])
        for (const auto& [j, tj] : trow[static_cast<size_t>(pairs_[e].second)])
          to_cj_.push_back({static_cast<int>(e), i, j, std::conj(ti) * tj});
    const detail::Lines X{d};
    detail::RowPowers pw(p.structure());
    std::vector<cd> jrow, f;
    Eigen::VectorXcd xrow(static_cast<Eigen::Index>(n));
    J_.resize(static_cast<Eigen::Index>(2 * m), static_cast<Eigen::Index>(n));
    C_.resize(static_cast<Eigen::Index>(ne), static_cast<Eigen::Index>(m));
    for (size_t r = 0; r < m; ++r) {
      const int l = rows[r];
      pw.compute(l);
      detail::jacobian_text_row(p, X, pw, l, text, jrow, xrow.data());
      J_.row(static_cast<Eigen::Index>(2 * r)) = xrow.real().transpose();
      J_.row(static_cast<Eigen::Index>(2 * r + 1)) = xrow.imag().transpose();
      Eigen::Index e = 0;  // the entries come in the order of pairs_
      detail::noise_block_entries(p, X, pw, l, by_k, f,
                                  [&](int, int, cd v) { C_(e++, static_cast<Eigen::Index>(r)) = v; });
    }
    B_.resize(J_.rows(), J_.cols());
    const size_t nb = static_cast<size_t>(qr_block());
    T_.resize(std::max<size_t>(1, nb * n));
    work_.resize(std::max<size_t>(1, nb * n));
  }

  Eigen::VectorXd variance(const Eigen::VectorXcd& theta) const {
    if (full_) return row_noise_variance(d_, p_, rows_, rn_, theta);
    if (!cached_) return residue_variance(d_, p_, rows_, theta);
    Eigen::VectorXcd z(static_cast<Eigen::Index>(pairs_.size()));
    for (size_t e = 0; e < pairs_.size(); ++e) z[static_cast<Eigen::Index>(e)] = std::conj(theta[pairs_[e].first]) * theta[pairs_[e].second];
    // Re(C^T z) = Cr^T zr - Ci^T zi: C as real (2 ne x m), z as (zr, -zi) interleaved.
    const Eigen::Map<const Eigen::MatrixXd> Cr(reinterpret_cast<const double*>(C_.data()), 2 * C_.rows(), C_.cols());
    Eigen::VectorXd zz(2 * z.size());
    for (Eigen::Index e = 0; e < z.size(); ++e) {
      zz[2 * e] = z[e].real();
      zz[2 * e + 1] = -z[e].imag();
    }
    return Cr.transpose() * zz;
  }

  Eigen::MatrixXd r_factor(const Eigen::VectorXd& w) const {
    if (!cached_) return weighted_r_factor(d_, p_, rows_, w);
    const Eigen::Index m = static_cast<Eigen::Index>(rows_.size()), n = J_.cols();
    if (w.size()) {
      for (Eigen::Index r = 0; r < m; ++r) {
        const double sw = std::sqrt(w[r]);
        B_.row(2 * r) = sw * J_.row(2 * r);
        B_.row(2 * r + 1) = sw * J_.row(2 * r + 1);
      }
    } else {
      B_ = J_;
    }
    int mm = static_cast<int>(B_.rows()), nn = static_cast<int>(n), nb = qr_block(), info = 0;
    dgeqrt_(&mm, &nn, &nb, B_.data(), &mm, T_.data(), &nb, work_.data(), &info);
    if (info != 0) throw NumericalError("QR of the Jacobian (dgeqrt) failed: info " + std::to_string(info));
    if (B_.rows() >= n) return B_.topRows(n).triangularView<Eigen::Upper>();
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, n);  // fewer real rows than columns
    R.topRows(B_.rows()) = B_.triangularView<Eigen::Upper>();
    return R;
  }

  Eigen::MatrixXd column_covariance(const Eigen::VectorXd& w) const {
    if (full_) return full_real_column_covariance(d_, p_, rows_, rn_, w);
    if (!cached_) return real_column_covariance(d_, p_, rows_, w);
    const Eigen::Map<const Eigen::MatrixXd> Cr(reinterpret_cast<const double*>(C_.data()), 2 * C_.rows(), C_.cols());
    const Eigen::VectorXd c = Cr * w;  // (Re, Im) of sum_l w_l C_l[e], interleaved
    const Eigen::Index n = J_.cols();
    Eigen::MatrixXd CJ = Eigen::MatrixXd::Zero(n, n);
    for (const auto& t : to_cj_) CJ(t.i, t.j) += t.c.real() * c[2 * t.e] - t.c.imag() * c[2 * t.e + 1];
    return 0.5 * (CJ + CJ.transpose());
  }

 private:
  struct ToCj {
    int e, i, j;
    cd c;
  };
  const FrequencyData& d_;
  const Parametrisation& p_;
  const std::vector<int>& rows_;
  bool cached_ = false;
  bool full_ = false;
  RowNoise rn_;
  std::vector<std::pair<int, int>> pairs_;  // (a, b) of each entry of C_l
  std::vector<ToCj> to_cj_;
  Eigen::MatrixXd J_;   // 2m x n real Jacobian
  Eigen::MatrixXcd C_;  // ne x m: the entries of C_l, one column per row
  mutable Eigen::MatrixXd B_;
  mutable std::vector<double> T_, work_;  // dgeqrt's block reflectors and workspace
  // dgeqrt needs 1 <= nb <= min(rows, columns)
  int qr_block() const {
    return std::max(1, std::min<int>({kQrBlock, static_cast<int>(J_.rows()), static_cast<int>(J_.cols())}));
  }
};

// R of the stacked real Jacobian: one experiment's own R, or the R factors of several
// experiments (each n x n) stacked and reduced by one more small QR.
Eigen::MatrixXd stacked_r_factor(const std::vector<WeightedRows>& x, const Parametrisation& p,
                                 const std::vector<Eigen::VectorXd>& w) {
  if (x.size() == 1) return x[0].r_factor(w[0]);
  const int n = p.n_xi();
  Eigen::MatrixXd M(static_cast<Eigen::Index>(x.size()) * n, n);
  for (size_t e = 0; e < x.size(); ++e) M.middleRows(static_cast<Eigen::Index>(e) * n, n) = x[e].r_factor(w[e]);
  Eigen::Ref<Eigen::MatrixXd> Mr = M;
  Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(Mr);
  return M.topRows(n).triangularView<Eigen::Upper>();
}

// CJ_W summed over the experiments (independent noise: the expectations add).
Eigen::MatrixXd summed_column_covariance(const std::vector<WeightedRows>& x, const std::vector<Eigen::VectorXd>& w) {
  Eigen::MatrixXd CJ = x[0].column_covariance(w[0]);
  for (size_t e = 1; e < x.size(); ++e) CJ += x[e].column_covariance(w[e]);
  return CJ;
}

EstimateResult estimate_experiments(const Experiments& x, const Parametrisation& p, const EstimateOptions& opt) {
  const size_t E = x.size();
  if (E == 0) throw std::invalid_argument("experiments: the list is empty");
  size_t n_rows = 0;
  for (size_t e = 0; e < E; ++e) {
    x.d[e]->validate();
    if (E == 1) {
      check_rows(p, *x.rows[e], x.d[e]->max_line());
    } else {
      check_row_lines(p.structure(), *x.rows[e], x.d[e]->max_line());
    }
    n_rows += x.rows[e]->size();
  }
  if (E > 1 && 2 * static_cast<long long>(n_rows) <= p.n_xi() - 1) {
    throw std::invalid_argument("the orders and harmonic counts leave " + std::to_string(p.n_xi() - 1) +
                                " free parameters for " + std::to_string(2 * n_rows) +
                                " real equations over all experiments (" + std::to_string(n_rows) +
                                " lines): use more lines or fewer harmonics / lower orders");
  }
  if (!(opt.tol > 0)) throw std::invalid_argument("tol must be > 0");
  if (opt.max_iter < 0) throw std::invalid_argument("max_iter must be >= 0");
  // The dense work here is on n_xi x n_xi matrices (tens of columns), where a multithreaded
  // BLAS only adds synchronisation: on a loaded two-core machine OpenBLAS's spinning threads
  // made single WGTLS fits of the paper's example take 300-600 ms instead of 10 ms.
  const detail::SingleThreadedBlas guard(true);
  EstimateResult res;
  auto finish = [&](const Solved& s) {
    res.theta = p.theta_from_xi(s.x);
    res.eta = p.eta_from_xi(s.x);
    res.singular_values = s.values;
    res.cost = s.cost;
  };
  std::vector<WeightedRows> wr;
  wr.reserve(E);
  for (size_t e = 0; e < E; ++e) wr.emplace_back(*x.d[e], p, *x.rows[e], opt.full_rows);
  std::vector<Eigen::VectorXd> w(E);
  const Eigen::MatrixXd R = stacked_r_factor(wr, p, w);
  if (opt.method == Method::LS) {
    finish(solve_ls(R, p.norm_index()));
    return res;
  }
  if (opt.method == Method::TLS) {
    finish(solve_tls(R));
    return res;
  }
  for (size_t e = 0; e < E; ++e) w[e] = Eigen::VectorXd::Ones(x.rows[e]->size());
  const Eigen::MatrixXd CJ = summed_column_covariance(wr, w);
  if (CJ.cwiseAbs().maxCoeff() == 0.0) {
    // No noise anywhere: the noise-weighted problems have no weight to apply and
    // reduce to TLS, which is exact on noise-free data.
    res.noise_free = true;
    finish(solve_tls(R));
    return res;
  }
  Solved solved = solve_gtls(R, CJ);
  finish(solved);
  if (opt.method == Method::GTLS) return res;

  res.converged = false;
  std::vector<Eigen::VectorXd> v(E);
  // SML only starts from the WGTLS estimate: its Gauss-Newton steps converge from any
  // consistent start, so WGTLS is stopped at a relative change of 1e-6 (each further
  // WGTLS solve costs as much as a Gauss-Newton step and moves the start by less than SML's
  // first step moves it).
  const double wgtls_tol = opt.method == Method::SML ? std::max(opt.tol, 1e-6) : opt.tol;
  for (int it = 1; it <= opt.max_iter; ++it) {
    double vmax = -std::numeric_limits<double>::infinity();
    bool finite = true;
    for (size_t e = 0; e < E; ++e) {
      v[e] = wr[e].variance(res.theta);
      vmax = std::max(vmax, v[e].maxCoeff());
      finite = finite && v[e].allFinite();
    }
    if (!(vmax > 0) || !finite) {
      throw NumericalError("WGTLS: the residue variance is not positive at iteration " +
                           std::to_string(it));
    }
    // Rows whose residue carries (numerically) no noise get the largest finite weight
    // rather than an infinite one.
    const double floor = vmax * 1e-14;
    for (size_t e = 0; e < E; ++e) w[e] = v[e].cwiseMax(floor).cwiseInverse();
    const Eigen::MatrixXd Rw = stacked_r_factor(wr, p, w);
    const Eigen::MatrixXd CJw = summed_column_covariance(wr, w);
    const Eigen::VectorXcd prev = res.theta;
    solved = solve_gtls(Rw, CJw, solved.x);
    finish(solved);
    res.iterations = it;
    res.cost_history.push_back(res.cost);
    const double change = (res.theta - prev).norm() / res.theta.norm();
    if (change < wgtls_tol) {
      res.converged = true;
      break;
    }
  }
  if (opt.method == Method::SML) {
    // The exact likelihood from the WGTLS estimate: WGTLS is consistent, so the start is
    // close and the Gauss-Newton steps of the refinement are short.
    ExactFit fit;
    // The rows' noise from the realisations: S = D S_line D with D at the start, then once more
    // at the estimate (D changes with theta to second order near the fixed point).
    const bool scaled = opt.full_rows && std::all_of(x.d.begin(), x.d.end(), [](const FrequencyData* d) {
      return has_row_noise(*d);
    });
    const int passes = scaled ? 2 : 1;
    Eigen::VectorXcd start = res.theta;
    int total_iter = 0;
    for (int pass = 0; pass < passes; ++pass) {
      if (E == 1) {
        ExactLikelihood lik(*x.d[0], p, *x.rows[0]);
        if (scaled) lik.set_row_scale(row_noise_scale(*x.d[0], p, *x.rows[0], start));
        fit = minimise_exact_cost(lik, p, start, opt.tol, opt.max_iter);
      } else {
        std::vector<ExactLikelihood> liks;
        for (size_t e = 0; e < E; ++e) {
          liks.emplace_back(*x.d[e], p, *x.rows[e], ExactLikelihood::PartOfSeveral{});
          if (scaled) liks.back().set_row_scale(row_noise_scale(*x.d[e], p, *x.rows[e], start));
        }
        fit = minimise_exact_cost(liks, p, start, opt.tol, opt.max_iter);
      }
      total_iter += fit.iterations;
      start = fit.theta;
    }
    fit.iterations = total_iter;
    const double scale = 1.0 / (2.0 * static_cast<double>(n_rows));
    res.theta = fit.theta;
    res.eta = p.eta_from_xi(fit.xi);
    res.start_iterations = res.iterations;
    res.iterations = fit.iterations;
    res.converged = fit.converged;
    res.cost = fit.cost * scale;
    res.information = fit.information;
    res.cost_history.clear();
    for (double c : fit.cost_history) res.cost_history.push_back(c * scale);
  }
  return res;
}

}  // namespace

EstimateResult estimate(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                        const EstimateOptions& opt) {
  return estimate_experiments(Experiments{{&d}, {&rows}}, p, opt);
}

EstimateResult estimate(const std::vector<FrequencyData>& experiments, const Parametrisation& p,
                        const std::vector<std::vector<int>>& rows, const EstimateOptions& opt) {
  if (rows.size() != experiments.size()) {
    throw std::invalid_argument("rows must give one list of rows per experiment (" +
                                std::to_string(experiments.size()) + "), got " + std::to_string(rows.size()));
  }
  Experiments x;
  for (size_t e = 0; e < experiments.size(); ++e) {
    x.d.push_back(&experiments[e]);
    x.rows.push_back(&rows[e]);
  }
  return estimate_experiments(x, p, opt);
}

}  // namespace lptv
