// METHOD.md section 19: WGTLS and SML with vector residues. The route is that of
// python/lptv/reference/mimo_fit.py's equations, computed per row: regressors phi_l shared by
// every output's equation (row-uniform structure), their noise Cphi_l (entries of one harmonic
// read one line), the per-line residue covariance C_{e,l} = Theta^T conj(Cphi_l) conj(Theta),
// and for SML the rows' full covariance C_E (a Hermitian band of half bandwidth (2K+1) ny - 1)
// factored by a band Cholesky.
#include "lptv/mimo_estimators.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lptv/errors.hpp"

namespace lptv {
namespace {

using cd = std::complex<double>;
using Eigen::MatrixXcd;
using Eigen::MatrixXd;
using Eigen::VectorXcd;
using Eigen::VectorXd;

constexpr double kVarianceFloor = 1e-14;  // as the single-output weights' floor

struct Params {
  int ny = 1, nu = 1, na = 0, nphi = 0, nrow = 0, K = 0;
  std::vector<int> is_a, order, col, k, channel;
  MatrixXcd T;
  std::vector<std::vector<std::pair<int, cd>>> tcols;  // T's nonzeros per column (one or two)
  std::vector<int> fixed_row;
  double w0 = 1.0, ts = 0.0;
  int nxi() const { return ny * nrow; }
  int nc() const { return ny + nu; }
  cd s(int i) const { return ts > 0 ? std::exp(cd(0.0, w0 * i * ts)) : cd(0.0, w0 * i); }
};

cd ipow(cd x, int n) {
  cd r(1.0, 0.0);
  for (int j = 0; j < n; ++j) r *= x;
  return r;
}

Params make_params(const MimoStructure& st) {
  if (st.ny < 1 || st.nu < 1) throw std::invalid_argument("structure: ny and nu must be positive");
  if (st.ka.rows() < 1 || st.ka.cols() != st.ny || st.kb.rows() < 1 || st.kb.cols() != st.nu)
    throw std::invalid_argument("structure: ka must be (na+1) x ny and kb (nb+1) x nu");
  if (st.ka.minCoeff() < 0 || st.kb.minCoeff() < -1)
    throw std::invalid_argument("structure: harmonic counts must be non-negative (kb: -1 for an absent entry)");
  if (!(st.w0 > 0) || !std::isfinite(st.w0) || !(st.ts >= 0) || !std::isfinite(st.ts))
    throw std::invalid_argument("structure: w0 must be positive and ts non-negative");
  Params p;
  p.ny = st.ny;
  p.nu = st.nu;
  p.na = static_cast<int>(st.ka.rows()) - 1;
  p.w0 = st.w0;
  p.ts = st.ts;
  p.K = std::max(st.ka.maxCoeff(), st.kb.maxCoeff());
  std::vector<std::vector<std::pair<int, cd>>> cols;
  auto add = [&](bool a, int n, int c, int K) {
    const int base = static_cast<int>(p.is_a.size());
    for (int k = -K; k <= K; ++k) {
      p.is_a.push_back(a);
      p.order.push_back(n);
      p.col.push_back(c);
      p.k.push_back(k);
      p.channel.push_back(a ? c : p.ny + c);
    }
    if (a && n == p.na) p.fixed_row.push_back(static_cast<int>(cols.size()));
    cols.push_back({{base + K, cd(1, 0)}});
    for (int k = 1; k <= K; ++k) {
      cols.push_back({{base + K + k, cd(1, 0)}, {base + K - k, cd(1, 0)}});
      cols.push_back({{base + K + k, cd(0, 1)}, {base + K - k, cd(0, -1)}});
    }
  };
  for (int n = 0; n <= p.na; ++n)
    for (int q = 0; q < p.ny; ++q) add(true, n, q, st.ka(n, q));
  for (int m = 0; m < st.kb.rows(); ++m)
    for (int r = 0; r < p.nu; ++r)
      if (st.kb(m, r) >= 0) add(false, m, r, st.kb(m, r));  // -1: B_m has no entry in column r
  p.nphi = static_cast<int>(p.is_a.size());
  p.nrow = static_cast<int>(cols.size());
  p.T = MatrixXcd::Zero(p.nphi, p.nrow);
  for (int j = 0; j < p.nrow; ++j)
    for (const auto& e : cols[j]) p.T(e.first, j) = e.second;
  p.tcols = cols;
  return p;
}

MatrixXcd theta_of(const Params& p, const VectorXd& xi) {
  const Eigen::Map<const MatrixXd> X(xi.data(), p.nrow, p.ny);
  return p.T * X.cast<cd>();
}

struct Prep {
  const MimoSpectra* d = nullptr;
  MatrixXcd Phi, Psi;
  std::vector<MatrixXcd> Cphi, Cpsi;
  int R() const { return static_cast<int>(d->rows.size()); }
};

// A row l <= K reads line 0 and the conjugates of lines 1..K-l: line i < 0 of a real signal's
// spectrum is conj(line -i), with noise covariance conj(C_{-i}) (rows.hpp's Lines, one channel).
cd signed_line(const MatrixXcd& X, int i, Eigen::Index col) { return i >= 0 ? X(i, col) : std::conj(X(-i, col)); }

cd signed_cov(const MimoSpectra& d, int c, int i, int a, int b) {
  return i >= 0 ? d.C(static_cast<Eigen::Index>(i) * c + a, b) : std::conj(d.C(static_cast<Eigen::Index>(-i) * c + a, b));
}

MatrixXcd regressors(const Params& p, const std::vector<int>& rows, const MatrixXcd& Y, const MatrixXcd& U) {
  MatrixXcd Phi(rows.size(), p.nphi);
  for (size_t r = 0; r < rows.size(); ++r)
    for (int j = 0; j < p.nphi; ++j) {
      const int i = rows[r] - p.k[j];
      const cd x = p.is_a[j] ? signed_line(Y, i, p.col[j]) : -signed_line(U, i, p.col[j]);
      Phi(r, j) = ipow(p.s(i), p.order[j]) * x;
    }
  return Phi;
}

void check(const std::vector<MimoSpectra>& data, const Params& p) {
  if (data.empty()) throw std::invalid_argument("data: no experiment");
  for (size_t e = 0; e < data.size(); ++e) {
    const MimoSpectra& d = data[e];
    const std::string where = "data[" + std::to_string(e) + "]";
    const Eigen::Index L1 = d.Y.rows();
    if (d.Y.cols() != p.ny || d.U.cols() != p.nu || d.U.rows() != L1 || d.C.rows() != L1 * p.nc() ||
        d.C.cols() != p.nc())
      throw std::invalid_argument(where + ": Y must be (L+1) x ny, U (L+1) x nu, C (L+1)(ny+nu) x (ny+nu)");
    if (!d.Y.allFinite() || !d.U.allFinite() || !d.C.allFinite())
      throw std::invalid_argument(where + ": the spectra or covariances contain NaN or inf");
    if (d.rows.empty()) throw std::invalid_argument(where + ".rows: no row");
    for (size_t r = 0; r < d.rows.size(); ++r) {
      if (d.rows[r] < 1 || d.rows[r] + p.K > L1 - 1)
        throw std::invalid_argument(where + ".rows: line " + std::to_string(d.rows[r]) +
                                    " is not a row: rows are lines 1..L - K (K = " + std::to_string(p.K) + ")");
      if (r > 0 && d.rows[r] <= d.rows[r - 1]) throw std::invalid_argument(where + ".rows: must increase");
    }
  }
}

Prep prepare(const MimoSpectra& d, const Params& p) {
  Prep x;
  x.d = &d;
  x.Phi = regressors(p, d.rows, d.Y, d.U);
  x.Psi = x.Phi * p.T;
  const int R = x.R(), c = p.nc();
  x.Cphi.assign(R, MatrixXcd::Zero(p.nphi, p.nphi));
  x.Cpsi.resize(R);
  std::vector<cd> f(p.nphi);
  for (int r = 0; r < R; ++r) {
    for (int j = 0; j < p.nphi; ++j)
      f[j] = (p.is_a[j] ? 1.0 : -1.0) * ipow(p.s(d.rows[r] - p.k[j]), p.order[j]);
    for (int a = 0; a < p.nphi; ++a)
      for (int b = 0; b < p.nphi; ++b) {
        if (p.k[a] != p.k[b]) continue;
        const int i = d.rows[r] - p.k[a];
        x.Cphi[r](a, b) = std::conj(f[a]) * f[b] * signed_cov(d, c, i, p.channel[b], p.channel[a]);
      }
    // T^H Cphi T through T's one or two nonzeros per column
    MatrixXcd& Cp = x.Cpsi[r];
    Cp.resize(p.nrow, p.nrow);
    for (int i = 0; i < p.nrow; ++i)
      for (int j = 0; j < p.nrow; ++j) {
        cd v(0.0, 0.0);
        for (const auto& a : p.tcols[i])
          for (const auto& b : p.tcols[j]) v += std::conj(a.second) * x.Cphi[r](a.first, b.first) * b.second;
        Cp(i, j) = v;
      }
  }
  return x;
}

std::vector<MatrixXcd> line_covariances(const Prep& x, const MatrixXcd& Th) {
  // C_{e,l} = Theta^T conj(Cphi_l) conj(Theta), explicit loops over the small blocks
  const Eigen::Index n = Th.rows(), ny = Th.cols();
  std::vector<MatrixXcd> out(x.R());
  MatrixXcd v(n, ny);
  for (int r = 0; r < x.R(); ++r) {
    const MatrixXcd& Cp = x.Cphi[r];
    for (Eigen::Index q = 0; q < ny; ++q)
      for (Eigen::Index a = 0; a < n; ++a) {
        cd acc(0.0, 0.0);
        for (Eigen::Index b = 0; b < n; ++b) acc += std::conj(Cp(a, b) * Th(b, q));
        v(a, q) = acc;
      }
    MatrixXcd& C = out[r];
    C.resize(ny, ny);
    for (Eigen::Index pp = 0; pp < ny; ++pp)
      for (Eigen::Index q = 0; q < ny; ++q) {
        cd acc(0.0, 0.0);
        for (Eigen::Index a = 0; a < n; ++a) acc += Th(a, pp) * v(a, q);
        C(pp, q) = acc;
      }
  }
  return out;
}

std::vector<MatrixXcd> weights(const std::vector<MatrixXcd>& Ce) {
  std::vector<Eigen::SelfAdjointEigenSolver<MatrixXcd>> es;
  double top = 0.0;
  for (const auto& c : Ce) {
    es.emplace_back(c);
    top = std::max(top, es.back().eigenvalues().maxCoeff());
  }
  if (!(top > 0) || !std::isfinite(top))
    throw NumericalError("the residue covariance is not positive: the data carry no noise on the rows");
  std::vector<MatrixXcd> W(Ce.size());
  for (size_t r = 0; r < Ce.size(); ++r) {
    const VectorXd lam = es[r].eigenvalues().cwiseMax(kVarianceFloor * top);
    const MatrixXcd& V = es[r].eigenvectors();
    W[r] = V * lam.cwiseInverse().asDiagonal() * V.adjoint();
  }
  return W;
}

// The whitened real rows [Re; Im] of one experiment (appended to J) and its CJ_W (added to CJ).
void whitened(const Prep& x, const Params& p, const std::vector<MatrixXcd>* W, MatrixXd& J, Eigen::Index& at,
              MatrixXd& CJ) {
  const int R = x.R(), ny = p.ny, nr = p.nrow;
  const Eigen::Index half = J.rows() / 2;
  for (int r = 0; r < R; ++r) {
    MatrixXcd M = MatrixXcd::Identity(ny, ny);
    if (W) {
      Eigen::LLT<MatrixXcd> llt((*W)[r]);
      M = llt.matrixL().adjoint();  // M^H M = W: M e is the whitened residue
    }
    for (int q = 0; q < ny; ++q) {
      for (int pp = 0; pp < ny; ++pp) {
        const cd m = M(q, pp);
        for (int i = 0; i < nr; ++i) {
          const cd v = m * x.Psi(r, i);
          J(at, pp * nr + i) = v.real();
          J(half + at, pp * nr + i) = v.imag();
        }
      }
      ++at;
    }
    for (int pp = 0; pp < ny; ++pp)
      for (int qq = 0; qq < ny; ++qq) {
        const cd w = W ? (*W)[r](pp, qq) : cd(pp == qq ? 1.0 : 0.0, 0.0);
        if (w == cd(0, 0)) continue;
        CJ.block(pp * nr, qq * nr, nr, nr) += w.real() * x.Cpsi[r].real() - w.imag() * x.Cpsi[r].imag();
      }
  }
}

VectorXd normalise(const MatrixXd& V, const Params& p) {
  const int ny = p.ny, d = ny * ny;
  MatrixXd Nm(d, V.cols());
  VectorXd c = VectorXd::Zero(d);
  for (int pp = 0; pp < ny; ++pp)
    for (int q = 0; q < ny; ++q) {
      Nm.row(pp * ny + q) = V.row(pp * p.nrow + p.fixed_row[q]);
      c(pp * ny + q) = pp == q ? 1.0 : 0.0;
    }
  Eigen::FullPivLU<MatrixXd> lu(Nm);
  if (!lu.isInvertible())
    throw NumericalError("the normalisation A_na,0 = I cannot be applied: the leading matrix's mean is singular "
                         "in the subspace of the smallest singular values (the structure does not describe the "
                         "data: an order too low or too high for some output, or harmonic counts the data "
                         "cannot determine)");
  return V * lu.solve(c);
}

// The d right generalised singular vectors of (Jx, CJ^{1/2}) of the smallest values and all
// values ascending; CJ null: TLS.
void subspace(const MatrixXd& Jx, const MatrixXd* CJ, int d, MatrixXd& V, VectorXd& values) {
  const Eigen::Index n = Jx.cols();
  VectorXd sc(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double nrm = Jx.col(j).norm();
    sc(j) = nrm > 0 ? 1.0 / nrm : 1.0;
  }
  const MatrixXd A = Jx * sc.asDiagonal();
  MatrixXd R;
  if (A.rows() > n) {
    Eigen::HouseholderQR<MatrixXd> qr(A);
    R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  } else {
    R = A;
  }
  if (!CJ) {
    Eigen::JacobiSVD<MatrixXd> svd(R, Eigen::ComputeFullV);
    V = sc.asDiagonal() * svd.matrixV().rightCols(d);
    values = svd.singularValues().reverse();
    return;
  }
  MatrixXd Cs = sc.asDiagonal() * (*CJ) * sc.asDiagonal();
  Cs = 0.5 * (Cs + Cs.transpose()).eval();
  Eigen::LLT<MatrixXd> llt(Cs);
  if (llt.info() != Eigen::Success) {
    // Some directions carry no noise (an input measured without noise): they have no
    // denominator, so they are eliminated by least squares (the GSVD's infinite values) and the
    // ratio is minimised over the noisy directions z, whitened by CJ_W's eigenvalues there.
    Eigen::SelfAdjointEigenSolver<MatrixXd> es(Cs);
    const VectorXd& lam = es.eigenvalues();
    const double cut = static_cast<double>(n) * std::numeric_limits<double>::epsilon() * lam.maxCoeff();
    std::vector<Eigen::Index> i1, i2;
    for (Eigen::Index j = 0; j < n; ++j) (lam(j) > cut ? i1 : i2).push_back(j);
    if (static_cast<int>(i1.size()) < d)
      throw NumericalError("the column covariance CJ_W has fewer noisy directions than the equivalent models");
    MatrixXd B1(n, i1.size()), A2(R.rows(), i2.size());
    for (size_t j = 0; j < i1.size(); ++j) B1.col(j) = es.eigenvectors().col(i1[j]) / std::sqrt(lam(i1[j]));
    for (size_t j = 0; j < i2.size(); ++j) A2.col(j) = R * es.eigenvectors().col(i2[j]);
    const MatrixXd A1 = R * B1;
    Eigen::ColPivHouseholderQR<MatrixXd> qr2(A2);
    const MatrixXd Qa = MatrixXd(qr2.householderQ()).leftCols(qr2.rank());
    const MatrixXd P = A1 - Qa * (Qa.transpose() * A1);
    Eigen::JacobiSVD<MatrixXd> svd(P, Eigen::ComputeFullV);
    const MatrixXd Z = svd.matrixV().rightCols(d);
    const MatrixXd Y2 = -qr2.solve(MatrixXd(A1 * Z));
    MatrixXd X = B1 * Z;
    for (size_t j = 0; j < i2.size(); ++j) X += es.eigenvectors().col(i2[j]) * Y2.row(j);
    V = sc.asDiagonal() * X;
    values = svd.singularValues().reverse();
    return;
  }
  const MatrixXd M = llt.matrixL().solve(R.transpose()).transpose();  // R Lc^-T
  Eigen::JacobiSVD<MatrixXd> svd(M, Eigen::ComputeFullV);
  V = sc.asDiagonal() * llt.matrixU().solve(MatrixXd(svd.matrixV().rightCols(d)));
  values = svd.singularValues().reverse();
}

bool all_zero(const std::vector<MimoSpectra>& data) {
  for (const auto& d : data)
    if (d.C.cwiseAbs().maxCoeff() != 0.0) return false;
  return true;
}

// A Hermitian band matrix in lower band storage, ab(i - j, j) = A(i, j) for 0 <= i - j <= u,
// and its Cholesky factor A = L L^H in the same storage: O(n u^2) to factor, O(n u) per solve.
struct HermitianBand {
  MatrixXcd ab;
  int u = 0;
  Eigen::Index n() const { return ab.cols(); }
  cd at(Eigen::Index i, Eigen::Index j) const { return ab(i - j, j); }  // i >= j, i - j <= u
  MatrixXcd multiply(const MatrixXcd& X) const {  // A X
    MatrixXcd Y = MatrixXcd::Zero(X.rows(), X.cols());
    for (Eigen::Index j = 0; j < n(); ++j)
      for (Eigen::Index i = j; i <= std::min<Eigen::Index>(n() - 1, j + u); ++i) {
        const cd a = at(i, j);
        Y.row(i) += a * X.row(j);
        if (i != j) Y.row(j) += std::conj(a) * X.row(i);
      }
    return Y;
  }
};

struct BandChol {
  HermitianBand L;
  void factor(const HermitianBand& A) {
    const int u = A.u;
    const Eigen::Index n = A.n();
    L.u = u;
    L.ab = MatrixXcd::Zero(u + 1, n);
    for (Eigen::Index j = 0; j < n; ++j) {
      const Eigen::Index lo = std::max<Eigen::Index>(0, j - u);
      double s = A.at(j, j).real();
      for (Eigen::Index k = lo; k < j; ++k) s -= std::norm(L.at(j, k));
      if (!(s > 0) || !std::isfinite(s))
        throw NumericalError("the residue covariance of the rows is not positive definite");
      const double djj = std::sqrt(s);
      L.ab(0, j) = djj;
      const Eigen::Index hi = std::min<Eigen::Index>(n - 1, j + u);
      for (Eigen::Index i = j + 1; i <= hi; ++i) {
        cd v = A.at(i, j);
        for (Eigen::Index k = std::max<Eigen::Index>(lo, i - u); k < j; ++k) v -= L.at(i, k) * std::conj(L.at(j, k));
        L.ab(i - j, j) = v / djj;
      }
    }
  }
  MatrixXcd solve(MatrixXcd B) const {  // A^-1 B
    const Eigen::Index n = L.n();
    const int u = L.u;
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index k = std::max<Eigen::Index>(0, i - u); k < i; ++k) B.row(i) -= L.at(i, k) * B.row(k);
      B.row(i) /= L.at(i, i).real();
    }
    for (Eigen::Index i = n - 1; i >= 0; --i) {
      for (Eigen::Index k = i + 1; k <= std::min<Eigen::Index>(n - 1, i + u); ++k)
        B.row(i) -= std::conj(L.at(k, i)) * B.row(k);
      B.row(i) /= L.at(i, i).real();
    }
    return B;
  }
};

// G[r][K + k] = [AA_{l,l-k}, -BB_{l,l-k}] (ny x (ny + nu)), stored one above the other in one
// matrix: block (r (2K+1) + K + k) of ny rows.
struct BandBlocks {
  MatrixXcd m;
  int ny = 1, width = 1;
  Eigen::Block<const MatrixXcd> operator()(int r, int kk) const {
    return m.block((static_cast<Eigen::Index>(r) * width + kk) * ny, 0, ny, m.cols());
  }
};

BandBlocks band_blocks(const Params& p, const MatrixXcd& Th, const std::vector<int>& rows) {
  BandBlocks G;
  G.ny = p.ny;
  G.width = 2 * p.K + 1;
  G.m = MatrixXcd::Zero(static_cast<Eigen::Index>(rows.size()) * G.width * p.ny, p.nc());
  for (size_t r = 0; r < rows.size(); ++r)
    for (int j = 0; j < p.nphi; ++j) {
      const cd f = (p.is_a[j] ? 1.0 : -1.0) * ipow(p.s(rows[r] - p.k[j]), p.order[j]);
      const Eigen::Index top = (static_cast<Eigen::Index>(r) * G.width + p.K + p.k[j]) * p.ny;
      for (int q = 0; q < p.ny; ++q) G.m(top + q, p.channel[j]) += f * Th(j, q);
    }
  return G;
}

// C_E of one experiment's rows (scalar index ny r + p): rows r and r + o share the lines
// i = l - k = l' - k' when l' - l <= 2K; half bandwidth (2K + 1) ny - 1.
HermitianBand row_covariance(const Prep& x, const Params& p, const BandBlocks& G) {
  const MimoSpectra& d = *x.d;
  const int R = x.R(), ny = p.ny, K = p.K, c = p.nc();
  HermitianBand A;
  A.u = (2 * K + 1) * ny - 1;
  A.ab = MatrixXcd::Zero(A.u + 1, static_cast<Eigen::Index>(R) * ny);
  // H[r, kk] = G(r, kk) C_{l-k} once per row and line (ny x c), then each pair of rows sums
  // H G'^H over the lines they share; explicit loops: the blocks are a few entries each
  const int W = 2 * K + 1;
  MatrixXcd H(static_cast<Eigen::Index>(R) * W * ny, c);
  for (int r = 0; r < R; ++r)
    for (int kk = 0; kk < W; ++kk) {
      const int i = d.rows[r] - (kk - K);
      const Eigen::Index top = (static_cast<Eigen::Index>(r) * W + kk) * ny;
      for (int pp = 0; pp < ny; ++pp)
        for (int b = 0; b < c; ++b) {
          cd v(0.0, 0.0);
          for (int a = 0; a < c; ++a) v += G.m(top + pp, a) * signed_cov(d, c, i, a, b);
          H(top + pp, b) = v;
        }
    }
  std::vector<cd> blk(static_cast<size_t>(ny) * ny);
  for (int r = 0; r < R; ++r)
    for (int o = 0; o <= 2 * K && r + o < R; ++o) {
      const int dl = d.rows[r + o] - d.rows[r];
      std::fill(blk.begin(), blk.end(), cd(0.0, 0.0));
      for (int kk = 0; kk < W; ++kk) {
        const int k2 = kk + dl;
        if (k2 > 2 * K) continue;
        const Eigen::Index h = (static_cast<Eigen::Index>(r) * W + kk) * ny;
        const Eigen::Index g = (static_cast<Eigen::Index>(r + o) * W + k2) * ny;
        for (int pp = 0; pp < ny; ++pp)
          for (int q = 0; q < ny; ++q) {
            cd v(0.0, 0.0);
            for (int b = 0; b < c; ++b) v += H(h + pp, b) * std::conj(G.m(g + q, b));
            blk[pp * ny + q] += v;
          }
      }
      for (int pp = 0; pp < ny; ++pp)
        for (int q = 0; q < ny; ++q) {
          if (o == 0) {
            if (pp >= q) A.ab(pp - q, r * ny + q) = blk[pp * ny + q];
          } else {
            A.ab(o * ny + q - pp, r * ny + pp) = std::conj(blk[pp * ny + q]);  // entry ((r+o) ny + q, r ny + p)
          }
        }
    }
  return A;
}

VectorXcd stacked(const MatrixXcd& E) {  // rows x ny -> index r ny + p
  VectorXcd v(E.size());
  for (Eigen::Index r = 0; r < E.rows(); ++r)
    for (Eigen::Index q = 0; q < E.cols(); ++q) v(r * E.cols() + q) = E(r, q);
  return v;
}

// d e / d xi at the denoised spectra z0_i = z_i - C_i sum_l G_{l,i}^H w_l, free columns only.
MatrixXcd jacobian0(const Prep& x, const Params& p, const BandBlocks& G,
                    const VectorXcd& w, const std::vector<int>& free) {
  const MimoSpectra& d = *x.d;
  const int R = x.R(), ny = p.ny, c = p.nc(), K = p.K;
  const Eigen::Index L1 = d.Y.rows();
  MatrixXcd corr = MatrixXcd::Zero(L1 + K, c);  // signed lines -K..L at i + K
  for (int r = 0; r < R; ++r)
    for (int kk = 0; kk <= 2 * K; ++kk)
      for (int b = 0; b < c; ++b) {
        cd v(0.0, 0.0);
        const Eigen::Index top = (static_cast<Eigen::Index>(r) * (2 * K + 1) + kk) * ny;
        for (int pp = 0; pp < ny; ++pp) v += std::conj(G.m(top + pp, b)) * w(r * ny + pp);
        corr(d.rows[r] - (kk - K) + K, b) += v;
      }
  // a row that reads conj(z_m) (line -m) moves z_m by C_m conj(its correction): the denoised
  // spectrum stays that of a real signal (line 0, its own conjugate, takes 2 Re)
  for (int m = K; m >= 0; --m) {
    const Eigen::RowVectorXcd neg = corr.row(K - m).conjugate();
    if (m > 0) corr.row(K - m).setZero();
    corr.row(K + m) += neg;
  }
  MatrixXcd Y0 = d.Y, U0 = d.U;
  for (Eigen::Index i = 0; i < L1; ++i) {
    const VectorXcd dz = d.C.block(i * c, 0, c, c) * corr.row(i + K).transpose();
    Y0.row(i) -= dz.head(ny).transpose();
    U0.row(i) -= dz.tail(p.nu).transpose();
  }
  const MatrixXcd Psi0 = regressors(p, d.rows, Y0, U0) * p.T;
  MatrixXcd J = MatrixXcd::Zero(R * ny, free.size());
  for (size_t f = 0; f < free.size(); ++f) {
    const int pp = free[f] / p.nrow, i = free[f] % p.nrow;
    for (int r = 0; r < R; ++r) J(r * ny + pp, f) = Psi0(r, i);
  }
  return J;
}

struct Evaluation {
  double cost = 0.0;
  VectorXd grad;
  MatrixXd F;
};

Evaluation evaluate(const std::vector<Prep>& preps, const Params& p, const VectorXd& xi, const std::vector<int>& free,
                    bool derivatives) {
  const MatrixXcd Th = theta_of(p, xi);
  Evaluation ev;
  ev.grad = VectorXd::Zero(free.size());
  ev.F = MatrixXd::Zero(free.size(), free.size());
  for (const Prep& x : preps) {
    const VectorXcd e = stacked(x.Phi * Th);
    const auto G = band_blocks(p, Th, x.d->rows);
    BandChol ch;
    ch.factor(row_covariance(x, p, G));
    const VectorXcd w = ch.solve(e);
    ev.cost += e.dot(w).real();
    if (!derivatives) continue;
    const MatrixXcd J0 = jacobian0(x, p, G, w, free);
    ev.grad += 2.0 * (J0.adjoint() * w).real();
    ev.F += 2.0 * (J0.adjoint() * ch.solve(J0)).real();
  }
  return ev;
}

std::vector<Prep> prepare_all(const std::vector<MimoSpectra>& data, const Params& p) {
  check(data, p);
  std::vector<Prep> out;
  for (const auto& d : data) out.push_back(prepare(d, p));
  return out;
}

Params checked_params(const MimoStructure& s, const VectorXd* xi) {
  Params p = make_params(s);
  if (xi && xi->size() != p.nxi())
    throw std::invalid_argument("xi: must have " + std::to_string(p.nxi()) + " entries, got " +
                                std::to_string(xi->size()));
  if (xi && !xi->allFinite()) throw std::invalid_argument("xi: contains NaN or inf");
  return p;
}

}  // namespace

namespace {

std::vector<int> free_of(const Params& p) {
  std::vector<bool> fixed(p.nxi(), false);
  for (int pp = 0; pp < p.ny; ++pp)
    for (int q = 0; q < p.ny; ++q) fixed[pp * p.nrow + p.fixed_row[q]] = true;
  std::vector<int> out;
  for (int j = 0; j < p.nxi(); ++j)
    if (!fixed[j]) out.push_back(j);
  return out;
}

MimoEstimate wgtls_impl(const std::vector<Prep>& preps, const Params& p, bool noise_free, double tol, int max_iter,
                        bool weighted) {
  MimoEstimate out;
  out.noise_free = noise_free;
  Eigen::Index rows = 0;
  for (const Prep& x : preps) rows += 2 * x.R() * p.ny;
  const int d = p.ny * p.ny;
  auto solve = [&](const std::vector<std::vector<MatrixXcd>>* Ws) {
    MatrixXd J(rows, p.nxi());
    MatrixXd CJ = MatrixXd::Zero(p.nxi(), p.nxi());
    // the Re and Im halves of all experiments: experiment e's rows at its offset in each half
    Eigen::Index at = 0;
    MatrixXd Jpart;
    for (size_t e = 0; e < preps.size(); ++e) {
      const Eigen::Index re = static_cast<Eigen::Index>(preps[e].R()) * p.ny;
      Jpart.resize(2 * re, p.nxi());
      Eigen::Index a = 0;
      whitened(preps[e], p, Ws ? &(*Ws)[e] : nullptr, Jpart, a, CJ);
      J.middleRows(2 * at, 2 * re) = Jpart;
      at += re;
    }
    MatrixXd V;
    subspace(J, out.noise_free ? nullptr : &CJ, d, V, out.singular_values);
    out.xi = normalise(V, p);
  };
  solve(nullptr);
  out.iterations = 0;
  out.converged = true;
  if (!weighted || out.noise_free) return out;
  out.converged = false;
  for (int it = 1; it <= max_iter; ++it) {
    const MatrixXcd Th = theta_of(p, out.xi);
    std::vector<std::vector<MatrixXcd>> Ws;
    for (const Prep& x : preps) Ws.push_back(weights(line_covariances(x, Th)));
    const VectorXd prev = out.xi;
    solve(&Ws);
    out.iterations = it;
    if ((out.xi - prev).norm() <= tol * out.xi.norm()) {
      out.converged = true;
      break;
    }
  }
  return out;
}

MimoEstimate sml_impl(const std::vector<Prep>& preps, const Params& p, const VectorXd& xi0, double tol, int max_iter) {
  const std::vector<int> free = free_of(p);
  const double eps = std::numeric_limits<double>::epsilon();
  MimoEstimate out;
  out.xi = xi0;
  Evaluation ev = evaluate(preps, p, out.xi, free, true);
  double mu = 1e-6;
  int steps = 0;
  bool converged = false;
  while (steps < max_iter) {
    const double dmax = ev.F.diagonal().maxCoeff();
    const VectorXd D = ev.F.diagonal().cwiseMax(eps * dmax);
    MatrixXd A = ev.F;
    A.diagonal() += mu * D;
    Eigen::LLT<MatrixXd> llt(A);
    bool tried = false;
    if (llt.info() == Eigen::Success) {
      const VectorXd step = -llt.solve(ev.grad);
      const double pred = -(ev.grad.dot(step) + 0.5 * step.dot(ev.F * step));
      if (pred <= 8 * eps * std::max(ev.cost, 1.0)) {
        converged = true;
        break;
      }
      VectorXd trial = out.xi;
      for (size_t f = 0; f < free.size(); ++f) trial(free[f]) += step(f);
      const double c_new = evaluate(preps, p, trial, free, false).cost;
      tried = true;
      if (c_new < ev.cost) {
        out.xi = trial;
        ++steps;
        mu = std::max(mu / 10.0, 1e-12);
        ev = evaluate(preps, p, out.xi, free, true);
        double nx = 0.0;
        for (int f : free) nx += out.xi(f) * out.xi(f);
        if (step.norm() <= tol * std::sqrt(nx)) {
          converged = true;
          break;
        }
        continue;
      }
    }
    (void)tried;
    mu *= 10.0;
    if (mu > 1e12) {
      converged = true;  // no step lowers the cost: a minimum to rounding
      break;
    }
  }
  out.cost = ev.cost;
  out.information = ev.F;
  out.iterations = steps;
  out.converged = converged;
  return out;
}

// Re(WJ^H P_E conj(WJ)) with P_E = E{e e^T}, the residues' pseudo-covariance: zero for
// circular noise but between rows l, l' that read a line i and its conjugate -i (l + l' <= 2K),
// where it is G_{l,i} C_i G_{l',-i}^T (E{z_i z_{-i}^T} = E{z_i z_i^H}); line 0 is its own conjugate.
MatrixXd pseudo_term(const Prep& x, const Params& p, const BandBlocks& G, const MatrixXcd& WJ) {
  const MimoSpectra& d = *x.d;
  const int K = p.K, ny = p.ny, c = p.nc(), W = 2 * K + 1;
  std::vector<int> low;
  for (int r = 0; r < x.R(); ++r)
    if (d.rows[r] <= 2 * K - 1) low.push_back(r);
  if (low.empty()) return MatrixXd::Zero(WJ.cols(), WJ.cols());
  const Eigen::Index n = static_cast<Eigen::Index>(low.size()) * ny;
  MatrixXcd PE = MatrixXcd::Zero(n, n), Ci(c, c);
  for (size_t a = 0; a < low.size(); ++a)
    for (size_t b = 0; b < low.size(); ++b) {
      const int r = low[a], r2 = low[b];
      for (int kk = 0; kk < W; ++kk) {
        const int i = d.rows[r] - (kk - K);
        const int k2 = d.rows[r2] + i;  // row r2 reads line -i at harmonic k2
        if (k2 < -K || k2 > K) continue;
        for (int u = 0; u < c; ++u)
          for (int v = 0; v < c; ++v) Ci(u, v) = signed_cov(d, c, i, u, v);
        PE.block(static_cast<Eigen::Index>(a) * ny, static_cast<Eigen::Index>(b) * ny, ny, ny) +=
            G(r, kk) * Ci * G(r2, k2 + K).transpose();
      }
    }
  MatrixXcd sub(n, WJ.cols());
  for (size_t a = 0; a < low.size(); ++a)
    sub.middleRows(static_cast<Eigen::Index>(a) * ny, ny) = WJ.middleRows(static_cast<Eigen::Index>(low[a]) * ny, ny);
  return (sub.adjoint() * PE * sub.conjugate()).real();
}

// Rows l <= K read line 0 and conjugate lines, whose noise is not circular: the circular complex
// likelihood of SML and the Fisher information do not hold for them.
void circular_rows(const std::vector<Prep>& preps, const Params& p, const std::string& what) {
  for (size_t e = 0; e < preps.size(); ++e)
    if (preps[e].R() > 0 && preps[e].d->rows[0] <= p.K)
      throw std::invalid_argument("data[" + std::to_string(e) + "].rows: line " + std::to_string(preps[e].d->rows[0]) +
                                  " reads line 0 and conjugate lines (K = " + std::to_string(p.K) +
                                  "), whose noise is not circular: " + what +
                                  " is the circular complex likelihood's; rows from K + 1");
}

MatrixXd sandwich_impl(const std::vector<Prep>& preps, const Params& p, const VectorXd& xi) {
  const std::vector<int> free = free_of(p);
  const MatrixXcd Th = theta_of(p, xi);
  const Eigen::Index nf = static_cast<Eigen::Index>(free.size());
  MatrixXd H = MatrixXd::Zero(nf, nf), Mt = MatrixXd::Zero(nf, nf);
  for (const Prep& x : preps) {
    const VectorXcd e = stacked(x.Phi * Th);
    const auto G = band_blocks(p, Th, x.d->rows);
    const HermitianBand CE = row_covariance(x, p, G);
    BandChol ch;
    ch.factor(CE);
    const MatrixXcd J = jacobian0(x, p, G, ch.solve(e), free);
    const auto W = weights(line_covariances(x, Th));
    MatrixXcd WJ(J.rows(), nf);
    for (int r = 0; r < x.R(); ++r) WJ.middleRows(r * p.ny, p.ny) = W[r] * J.middleRows(r * p.ny, p.ny);
    H += (J.adjoint() * WJ).real();
    Mt += 0.5 * (WJ.adjoint() * CE.multiply(WJ)).real() + 0.5 * pseudo_term(x, p, G, WJ);
  }
  const MatrixXd Hi = H.inverse();
  return Hi * Mt * Hi;
}

void residues_impl(const Prep& x, const Params& p, const VectorXd& xi, MatrixXcd& e, MatrixXcd& Ce) {
  const MatrixXcd Th = theta_of(p, xi);
  e = x.Phi * Th;
  const auto C = line_covariances(x, Th);
  Ce.resize(static_cast<Eigen::Index>(C.size()) * p.ny, p.ny);
  for (size_t r = 0; r < C.size(); ++r) Ce.middleRows(static_cast<Eigen::Index>(r) * p.ny, p.ny) = C[r];
}

}  // namespace

std::vector<int> mimo_free_indices(const MimoStructure& s) { return free_of(make_params(s)); }

MimoEstimate mimo_wgtls(const std::vector<MimoSpectra>& data, const MimoStructure& s, double tol, int max_iter,
                        bool weighted) {
  const Params p = checked_params(s, nullptr);
  return wgtls_impl(prepare_all(data, p), p, all_zero(data), tol, max_iter, weighted);
}

MimoEstimate mimo_sml(const std::vector<MimoSpectra>& data, const MimoStructure& s, const VectorXd& xi0, double tol,
                      int max_iter) {
  const Params p = checked_params(s, &xi0);
  const std::vector<Prep> preps = prepare_all(data, p);
  circular_rows(preps, p, "SML");
  return sml_impl(preps, p, xi0, tol, max_iter);
}

MatrixXd mimo_fisher(const std::vector<MimoSpectra>& data, const MimoStructure& s, const VectorXd& xi) {
  const Params p = checked_params(s, &xi);
  const std::vector<Prep> preps = prepare_all(data, p);
  circular_rows(preps, p, "the Fisher information");
  return evaluate(preps, p, xi, free_of(p), true).F;
}

MatrixXd mimo_sandwich(const std::vector<MimoSpectra>& data, const MimoStructure& s, const VectorXd& xi) {
  const Params p = checked_params(s, &xi);
  return sandwich_impl(prepare_all(data, p), p, xi);
}

void mimo_residues(const MimoSpectra& d, const MimoStructure& s, const VectorXd& xi, MatrixXcd& e, MatrixXcd& Ce) {
  const Params p = checked_params(s, &xi);
  const std::vector<MimoSpectra> one{d};
  check(one, p);
  residues_impl(prepare(d, p), p, xi, e, Ce);
}

MimoFit mimo_fit(const std::vector<MimoSpectra>& data, const MimoStructure& s, const std::string& method, double tol,
                 int max_iter, bool covariance) {
  if (method != "gtls" && method != "wgtls" && method != "sml")
    throw std::invalid_argument("method: must be 'gtls', 'wgtls' or 'sml', got '" + method + "'");
  const Params p = checked_params(s, nullptr);
  const std::vector<Prep> preps = prepare_all(data, p);
  MimoFit out;
  out.estimate = wgtls_impl(preps, p, all_zero(data), tol, max_iter, method != "gtls");
  const bool noisy = !out.estimate.noise_free;
  if (method == "sml" && noisy) {
    circular_rows(preps, p, "SML");
    out.estimate = sml_impl(preps, p, out.estimate.xi, tol, max_iter);
  }
  if (covariance && noisy) {
    if (method == "sml") {
      Eigen::LLT<MatrixXd> llt(out.estimate.information);
      if (llt.info() != Eigen::Success) throw NumericalError("the Fisher information is not positive definite");
      out.covariance = llt.solve(MatrixXd::Identity(out.estimate.information.rows(), out.estimate.information.cols()));
    } else {
      out.covariance = sandwich_impl(preps, p, out.estimate.xi);
    }
  }
  Eigen::Index rows = 0;
  for (const Prep& x : preps) rows += x.R();
  out.residues.resize(rows, p.ny);
  out.residue_covariance.resize(rows * p.ny, p.ny);
  Eigen::Index at = 0;
  for (const Prep& x : preps) {
    MatrixXcd e, Ce;
    residues_impl(x, p, out.estimate.xi, e, Ce);
    out.residues.middleRows(at, x.R()) = e;
    out.residue_covariance.middleRows(at * p.ny, x.R() * p.ny) = Ce;
    at += x.R();
  }
  return out;
}

}  // namespace lptv
