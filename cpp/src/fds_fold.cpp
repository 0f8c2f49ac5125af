#include "fds_fold.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "band_kernel.hpp"
#include "band_row.hpp"
#include "lptv/band_lu.hpp"

namespace lptv {
namespace detail {

namespace {

// Rows L, L-1, ..., 0 of A in the unknowns Y_L, Y_L-1, ..., Y_0 (row r and column c of the
// reversed matrix are lines L - r and L - c), each built from the band-row kernel's
// band_entry_ct: the same numbers as build_A's band_entry.
// Right-hand sides of a row: (B U)_l for each column of U, summed in the full grid's order
// (U_{-l} = conj(U_l)), then the check's entry m_l exp(j g l).
// NA, NB: the orders na and nb as constants (or -1: any); KT: K = Ka as a constant (or -1), so
// that the sums over orders and the entries of a row unroll (the same sums).
template <int NA, int NB, int KT>
class FoldedRows {
 public:
  FoldedRows(const Model& m, const Grid& g, const HalfInput& U)
      : m_(m), U_(U), R_(static_cast<int>(std::min<Eigen::Index>(U.rows(), g.L + 1))), L_(g.L),
        K_(m.ka()), Kb_(m.kb()), Km_(std::max(K_, Kb_)), na_(m.na()), nb_(m.nb()),
        P_(std::max(na_, nb_) + 1), nrhs_(static_cast<int>(U.cols())),
        mag_(m.a().cwiseAbs(), m.w0()), aj_(m.a().rows(), m.a().cols()), bj_(m.b().rows(), m.b().cols()),
        next_(g.L) {
    for (Eigen::Index k = 0; k < aj_.cols(); ++k) times_j_powers(m.a().col(k).data(), na_, aj_.col(k).data());
    for (Eigen::Index k = 0; k < bj_.cols(); ++k) times_j_powers(m.b().col(k).data(), nb_, bj_.col(k).data());
    int R = 1;
    while (R < 2 * Km_ + 1) R *= 2;
    mask_ = R - 1;
    t_.resize(static_cast<size_t>(R) * P());
    nonzero_.assign(g.L + 1, 0);  // by |line|
    for (int i = 0; i < R_; ++i) nonzero_[i] = !U.row(i).isZero(0.0);
    step_ = std::polar(1.0, -kCheckPhaseStep);  // from line l to line l - 1
  }
  int columns() const { return nrhs_ + 1; }
  int na() const { return NA >= 0 ? NA : na_; }
  int nb() const { return NB >= 0 ? NB : nb_; }
  int K() const { return KT >= 0 ? KT : K_; }
  int P() const { return NA >= 0 ? NA + 1 : P_; }  // nb <= na when NA >= 0

  // A(l, i) for the line l of reversed row r and the lines i of reversed columns base..base+2K.
  __attribute__((always_inline)) void row(int r, int base, cd* out) {
    const int l = L_ - r;
    ensure(l - Km_);
    const cd* a = aj_.data();
    const int n = na(), K = this->K();
    if (l + K <= L_ && base == L_ - l - K) {
      // Rows whose band lies inside the grid (all but the top K): no bounds to test, the
      // entry j in column line l + K - j.
      for (int j = 0; j <= 2 * K; ++j)
        out[j] = band_entry_ct(a + static_cast<size_t>(j) * (n + 1), t(l + K - j), n);
      return;
    }
    for (int j = 0; j <= 2 * K; ++j) {
      const int i = L_ - base - j;
      out[j] = (i < 0 || i > L_ || std::abs(l - i) > K)
                   ? cd(0.0, 0.0)
                   : band_entry_ct(a + static_cast<size_t>(K + l - i) * (n + 1), t(i), n);
    }
  }
  // A(l, i) for |l - i| <= K, any line i of the grid (negative lines too).
  cd entry(const cd* a, int l, int i) const {
    return band_entry_ct(a + static_cast<size_t>(K_ + l - i) * (na() + 1), t(i), na());
  }
  const cd* a() const { return aj_.data(); }

  __attribute__((always_inline)) void rhs(int r, cd* z) {
    const int l = L_ - r;
    ensure(l - Km_);
    const cd* b = bj_.data();
    const int nb = this->nb();
    const int lo = std::max(-L_, l - Kb_), hi = std::min(L_, l + Kb_);
    for (int q = 0; q < nrhs_; ++q) {
      const cd* u = U_.col(q).data();  // line i >= 0; conj(u[-i]) for i < 0
      double re = 0.0, im = 0.0;
      if (lo >= 0) {  // no conjugate lines in this row
        for (int c = lo; c <= hi; ++c) {
          if (!nonzero_[c]) continue;
          const cd v = band_entry_ct(b + static_cast<size_t>(Kb_ + l - c) * (nb + 1), t(c), nb);
          re += v.real() * u[c].real() - v.imag() * u[c].imag();
          im += v.real() * u[c].imag() + v.imag() * u[c].real();
        }
        z[q] = cd(re, im);
        continue;
      }
      for (int c = lo; c <= hi; ++c) {
        const int a = c < 0 ? -c : c;
        if (!nonzero_[a]) continue;
        const cd uc = c < 0 ? std::conj(u[a]) : u[a];
        const cd v = band_entry_ct(b + static_cast<size_t>(Kb_ + l - c) * (nb + 1), t(c), nb);
        re += v.real() * uc.real() - v.imag() * uc.imag();
        im += v.real() * uc.imag() + v.imag() * uc.real();
      }
      z[q] = cd(re, im);
    }
    const double mag = magnitude(l);
    // exp(j g l) by a recurrence down the lines, re-anchored every 256 lines and at line 0
    // (exactly 1 there: the real part of row 0 is all the corner takes).
    phase_ = (first_ || (l & 255) == 255 || l == 0) ? std::polar(1.0, kCheckPhaseStep * l) : cmul(phase_, step_);
    first_ = false;
    z[nrhs_] = cd(mag * phase_.real(), mag * phase_.imag());
  }

 private:
  // The check's row magnitude: the sum over row l's entries of sum_n |a_{n,k}| |s_c|^n.
  double magnitude(int l) const {
    if (l >= K_ && l + K_ <= L_) return mag_.far(l, na());  // columns l - K..l + K in 0..L
    return mag_.direct(l, std::max(-L_, l - K_), std::min(L_, l + K_), na(), [this](int c) { return t(c); });
  }
  const double* t(int c) const { return &t_[static_cast<size_t>(c & mask_) * P()]; }
  // Powers of the lines down to c (rows arrive by decreasing line).
  void ensure(int c) {
    for (; next_ >= c; --next_)  // s = j w, w = w0 l as line_variable forms it
      real_powers(m_.w0() * next_, P() - 1, &t_[static_cast<size_t>(next_ & mask_) * P()]);
  }
  const Model& m_;
  const HalfInput& U_;
  int R_, L_, K_, Kb_, Km_, na_, nb_, P_, nrhs_, mask_ = 0;
  CheckMagnitude mag_;
  Eigen::MatrixXcd aj_, bj_;  // the coefficients times j^n (times_j_powers)
  int next_;  // the highest line whose powers are not yet computed
  std::vector<double> t_;
  std::vector<char> nonzero_;
  cd phase_{1.0, 0.0}, step_;
  bool first_ = true;
};

// The real system of the last 2K rows in Y_0..Y_2K-1: unknown 0 is Re Y_0 (Y_0 is real),
// 2i - 1 and 2i are Re and Im of Y_i; row 0 of A gives one equation (its real part: the
// imaginary part vanishes for a real Y_0), the others two.
class CornerSystem {
 public:
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  CornerSystem(int K, int nz) : n_(4 * K - 1), nz_(nz), M_(Rows::Zero(n_, n_)), b_(n_, nz) {}
  // Adds the complex equation sum_i d_i Y_i + sum_i c_i conj(Y_i) = z to the next rows;
  // real_only: its real part alone.
  void begin(const cd* z, bool real_only) {
    re_ = next_;
    im_ = real_only ? -1 : next_ + 1;
    next_ += real_only ? 1 : 2;
    for (int q = 0; q < nz_; ++q) {
      b_(re_, q) = z[q].real();
      if (im_ >= 0) b_(im_, q) = z[q].imag();
    }
  }
  void direct(int i, cd d) {  // d Y_i
    if (i == 0) {
      add(re_, 0, d.real());
      add(im_, 0, d.imag());
      return;
    }
    add(re_, 2 * i - 1, d.real()), add(re_, 2 * i, -d.imag());
    add(im_, 2 * i - 1, d.imag()), add(im_, 2 * i, d.real());
  }
  void conjugate(int i, cd c) {  // c conj(Y_i), i >= 1
    add(re_, 2 * i - 1, c.real()), add(re_, 2 * i, c.imag());
    add(im_, 2 * i - 1, c.imag()), add(im_, 2 * i, -c.real());
  }
  // Y_i for column q; throws ZeroPivot with the line (the caller maps it) of an exactly
  // singular system. Gaussian elimination with partial pivoting (the largest |entry| of the
  // column, the first of equals) written out for these few unknowns (4K - 1): a general dense
  // LU costs more in its set-up than in its arithmetic here.
  const Rows& solve() {
    Rows& M = M_;
    Rows& b = b_;
    std::vector<double> inv(n_);
    for (int c = 0; c < n_; ++c) {
      int p = c;
      double best = std::abs(M(c, c));
      for (int r = c + 1; r < n_; ++r)
        if (std::abs(M(r, c)) > best) best = std::abs(M(r, c)), p = r;
      if (best == 0.0) throw ZeroPivot{(c + 1) / 2};
      if (p != c) {
        M.row(p).swap(M.row(c));
        b.row(p).swap(b.row(c));
      }
      inv[c] = 1.0 / M(c, c);
      for (int r = c + 1; r < n_; ++r) {
        const double l = M(r, c) * inv[c];
        if (l == 0.0) continue;
        for (int j = c + 1; j < n_; ++j) M(r, j) -= l * M(c, j);
        for (int q = 0; q < nz_; ++q) b(r, q) -= l * b(c, q);
      }
    }
    for (int c = n_ - 1; c >= 0; --c) {
      for (int q = 0; q < nz_; ++q) {
        double v = b(c, q);
        for (int j = c + 1; j < n_; ++j) v -= M(c, j) * b(j, q);
        b(c, q) = v * inv[c];
      }
    }
    return b;
  }

 private:
  void add(int row, int col, double v) {
    if (row >= 0) M_(row, col) += v;
  }
  int n_, nz_, next_ = 0, re_ = 0, im_ = 0;
  Rows M_, b_;
};

}  // namespace

bool can_fold(const Model& m, const Grid& g) {
  const int K = m.ka();
  return !g.circular && !m.discrete() && K >= 1 && K <= SmallBandLU::kMaxK && g.L >= 2 * K + 1;
}

bool real_input(const Grid& g, const Eigen::MatrixXcd& U_full) {
  const int L = g.L;
  if (g.circular || U_full.rows() != g.N) return false;
  for (Eigen::Index q = 0; q < U_full.cols(); ++q) {
    const cd* u = U_full.col(q).data() + L;
    if (u[0].imag() != 0.0) return false;
    for (int l = 1; l <= L; ++l)
      if (u[-l] != std::conj(u[l])) return false;
  }
  return true;
}

namespace {

template <int NA, int NB, int KT>
FoldedSolution solve_folded_as(const Model& m, const Grid& g, const HalfInput& U, Eigen::MatrixXcd* full) {
  const int L = g.L, K = m.ka(), W = 2 * K + 1;
  FoldedRows<NA, NB, KT> src(m, g, U);
  const int nz = src.columns(), nu = nz - 1;
  // Columns Y_L..Y_2K by the band kernel: rows L..K enter.
  const int steps = L - 2 * K + 1;
  BandFactors f;
  BandTail tail;
  RawArray z;
  z.resize(static_cast<size_t>(L + 1) * nz);  // rows steps..L: Y_2K-1..Y_0 from the corner
  try {
    factor_band_best<KT>(src, L + 1, K, nz, f, false, z.data(), steps, &tail);
  } catch (const ZeroPivot& e) {
    throw ZeroPivot{L + (L - e.column)};
  }
  // The corner: the window's K rows (entry j: Y_{2K-1-j}) and rows K-1..0, not yet entered.
  CornerSystem cs(K, nz);
  for (int i = 0; i < K; ++i) {
    cs.begin(&tail.z[static_cast<size_t>(i) * nz], false);
    for (int j = 0; j < 2 * K; ++j) cs.direct(2 * K - 1 - j, tail.rows[static_cast<size_t>(i) * W + j]);
  }
  std::vector<cd> zr(nz);
  for (int l = K - 1; l >= 0; --l) {
    src.rhs(L - l, zr.data());  // also the powers of the lines down to l - max(Ka, Kb)
    cs.begin(zr.data(), l == 0);
    for (int i = l - K; i <= l + K; ++i) {
      const cd v = src.entry(src.a(), l, i);
      if (i >= 0) cs.direct(i, v);
      else cs.conjugate(-i, v);
    }
  }
  CornerSystem::Rows y;
  try {
    y = cs.solve();
  } catch (const ZeroPivot& e) {
    throw ZeroPivot{L + e.column};
  }
  for (int i = 0; i < 2 * K; ++i) {
    cd* zi = &z[static_cast<size_t>(L - i) * nz];
    for (int q = 0; q < nz; ++q)
      zi[q] = i == 0 ? cd(y(0, q), 0.0) : cd(y(2 * i - 1, q), y(2 * i, q));
  }
  back_substitute_best<KT>(f, nz, z.data());

  FoldedSolution out;
  if (!full) out.Y.resize(L + 1, nu);
  double best = -1.0, peak2 = 0.0;
  int at = 0;
  for (int l = 0; l <= L; ++l) {
    const cd* zl = &z[static_cast<size_t>(L - l) * nz];
    if (full) {
      for (int q = 0; q < nu; ++q) (*full)(L - l, q) = std::conj(zl[q]), (*full)(L + l, q) = zl[q];
    } else {
      for (int q = 0; q < nu; ++q) out.Y(l, q) = zl[q];
    }
    for (int q = 0; q < nu; ++q) {
      const double y2 = zl[q].real() * zl[q].real() + zl[q].imag() * zl[q].imag();
      peak2 = (y2 > peak2 || !(y2 == y2)) && peak2 == peak2 ? y2 : peak2;  // a NaN stays
    }
    const double a = std::norm(zl[nu]);
    if (a > best || !(a == a)) best = a, at = l;
  }
  out.peak2 = peak2;
  out.where = L + at;
  out.condition = std::abs(z[static_cast<size_t>(L - at) * nz + nu]);
  return out;
}

template <int NA, int NB>
FoldedSolution solve_folded_orders(const Model& m, const Grid& g, const HalfInput& U, Eigen::MatrixXcd* full) {
  return dispatch_band(m.ka(), [&](auto kt) {
    constexpr int KT = decltype(kt)::value;  // K >= 1 here (can_fold): no instance for K = 0
    return solve_folded_as<NA, NB, KT == 0 ? -1 : KT>(m, g, U, full);
  });
}

}  // namespace

FoldedSolution solve_folded(const Model& m, const Grid& g, const HalfInput& U, Eigen::MatrixXcd* full) {
  // The orders and K as constants for the common models, so that the sums and the rows unroll
  // (the same sums): na = 1..3 with nb = na - 1 or na; na alone for a smaller nb.
  const int na = m.na(), nb = m.nb();
  if (nb <= na && na >= 1 && na <= 3) {
    switch (4 * na + nb) {
      case 4: return solve_folded_orders<1, 0>(m, g, U, full);
      case 5: return solve_folded_orders<1, 1>(m, g, U, full);
      case 9: return solve_folded_orders<2, 1>(m, g, U, full);
      case 10: return solve_folded_orders<2, 2>(m, g, U, full);
      case 14: return solve_folded_orders<3, 2>(m, g, U, full);
      case 15: return solve_folded_orders<3, 3>(m, g, U, full);
      default: break;
    }
    switch (na) {
      case 2: return solve_folded_orders<2, -1>(m, g, U, full);
      default: return solve_folded_orders<3, -1>(m, g, U, full);
    }
  }
  return solve_folded_orders<-1, -1>(m, g, U, full);
}

}  // namespace detail
}  // namespace lptv
