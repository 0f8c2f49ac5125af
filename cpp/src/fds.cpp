#include "lptv/fds.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "band_kernel.hpp"
#include "band_row.hpp"
#include "fds_fold.hpp"
#include "lptv/errors.hpp"

namespace lptv {

int Grid::index_of(int line) const {
  if (circular) {
    int i = line % N;
    return i < 0 ? i + N : i;
  }
  return (line < -L || line > L) ? -1 : line + L;
}

// The grid -L..L in 64-bit arithmetic: 2 L + 1 and the guard grown on top of it must stay ints,
// and the factors must fit in memory; refuse before anything is allocated.
static void check_grid_size(long long L, int K) {
  constexpr long long kMaxLines = 1LL << 26;  // 2 (L + guard) + 1 stays far below INT_MAX
  if (L > kMaxLines) {
    const double gb = (2.0 * static_cast<double>(L) + 1) * 16.0 * (3.0 * K + 4) / 1e9;
    throw std::invalid_argument("the grid of lines -" + std::to_string(L) + ".." + std::to_string(L) +
                                " is too large (at most " + std::to_string(kMaxLines) +
                                " lines each side): its band factors alone would take about " +
                                std::to_string(static_cast<long long>(gb + 0.5)) + " GB");
  }
}

Grid make_grid(const Model& m, int L) {
  Grid g;
  if (m.discrete()) {
    g.circular = true;
    g.N = m.samples_per_period();
    // The circular grid holds all N lines: the same bound as the continuous grid -L..L.
    constexpr int kMaxSamples = 2 * (1 << 26) + 1;
    if (g.N > kMaxSamples) {
      const double gb = static_cast<double>(g.N) * 16.0 * (3.0 * m.kmax() + 4) / 1e9;
      throw std::invalid_argument("the grid of the model's " + std::to_string(g.N) +
                                  " samples per period is too large (at most " +
                                  std::to_string(kMaxSamples) +
                                  " lines): its band factors alone would take about " +
                                  std::to_string(static_cast<long long>(gb + 0.5)) + " GB");
    }
    g.L = g.N / 2;
  } else {
    if (L < 0) throw std::invalid_argument("L must be >= 0, got " + std::to_string(L));
    check_grid_size(L, m.kmax());
    g.L = L;
    g.N = 2 * L + 1;
  }
  return g;
}

cd line_power(const Model& m, const Grid& g, int line, int n) {
  (void)g;
  return detail::line_power(detail::line_variable(m.w0(), m.ts(), line), n);
}

namespace {

// The harmonics k whose column of c (K + k) holds a nonzero coefficient. A zero column adds
// exact zeros to the band sums, so leaving it out changes no bit; it matters for models whose
// harmonics are sparse, such as a record's (lptv::fit_record: only the multiples of L, 2K + 1
// of 2 K L + 1 columns).
std::vector<int> nonzero_harmonics(const Eigen::MatrixXcd& c) {
  const int K = static_cast<int>(c.cols() - 1) / 2;
  std::vector<int> ks;
  for (int k = -K; k <= K; ++k)
    if (!c.col(K + k).isZero(0.0)) ks.push_back(k);
  return ks;
}

// Entries sum_n c_{n,l-i} s_i^n for |l-i| <= K; on the circular grid the band wraps.
SpMat build_band(const Model& m, const Grid& g, const Eigen::MatrixXcd& c) {
  const int order = static_cast<int>(c.rows()) - 1;
  const int K = static_cast<int>(c.cols() - 1) / 2;
  const std::vector<int> ks = nonzero_harmonics(c);
  std::vector<Eigen::Triplet<cd, int>> trip;
  trip.reserve(static_cast<size_t>(g.N) * ks.size());
  std::vector<cd> pw(order + 1);
  for (int col = 0; col < g.N; ++col) {
    const int i = g.line_of(col);
    detail::line_powers(detail::line_variable(m.w0(), m.ts(), i), order, pw.data());
    for (const int k : ks) {
      const int row = g.index_of(i + k);
      if (row < 0) continue;
      const cd v = detail::band_entry(c.col(K + k).data(), pw.data(), order);
      if (v != cd(0.0, 0.0)) trip.emplace_back(row, col, v);
    }
  }
  SpMat M(g.N, g.N);
  M.setFromTriplets(trip.begin(), trip.end());  // sums duplicates: none when 2K+1 <= N
  M.makeCompressed();
  return M;
}

}  // namespace

SpMat build_A(const Model& m, const Grid& g) { return build_band(m, g, m.a()); }
SpMat build_B(const Model& m, const Grid& g) { return build_band(m, g, m.b()); }

namespace detail {

std::vector<cd> band_storage_A(const Model& m, const Grid& g) {
  const int K = m.ka(), na = m.na(), ld = BandLU::ldab(K, K);
  std::vector<cd> ab(static_cast<size_t>(ld) * g.N, cd(0.0, 0.0));
  std::vector<cd> pw(na + 1);
  for (int j = 0; j < g.N; ++j) {
    line_powers(line_variable(m.w0(), m.ts(), g.line_of(j)), na, pw.data());
    for (int k = std::max(-K, -j); k <= std::min(K, g.N - 1 - j); ++k) {
      ab[(2 * K + k) + static_cast<size_t>(j) * ld] = band_entry(m.a().col(K + k).data(), pw.data(), na);
    }
  }
  return ab;
}

}  // namespace detail

Eigen::MatrixXcd apply_B(const Model& m, const Grid& g, const Eigen::MatrixXcd& U) {
  const int K = m.kb(), nb = m.nb();
  Eigen::MatrixXcd out = Eigen::MatrixXcd::Zero(g.N, U.cols());
  std::vector<cd> pw(nb + 1);
  for (int j = 0; j < g.N; ++j) {
    if (U.row(j).isZero(0.0)) continue;
    const int i = g.line_of(j);
    detail::line_powers(detail::line_variable(m.w0(), m.ts(), i), nb, pw.data());
    for (int k = -K; k <= K; ++k) {
      const int row = g.index_of(i + k);
      if (row < 0) continue;
      const cd v = detail::band_entry(m.b().col(K + k).data(), pw.data(), nb);
      if (v != cd(0.0, 0.0)) out.row(row) += v * U.row(j);
    }
  }
  return out;
}

namespace {

constexpr double kGoldenAngle = detail::kCheckPhaseStep;

// The conditioning check's right-hand side (see Fds::condition): row i's magnitude of terms,
// sum over its entries of sum_n |a_{n,k}| |s_j|^n, times the unit phase exp(j g i) of the
// golden angle g. This is the route of the sparse solvers and of LAPACK's band LU; the small
// band kernel forms the same vector row by row (ModelRows below).
Eigen::VectorXcd check_rhs(const Model& m, const Grid& grid) {
  const int K = m.ka(), na = m.na();
  const Eigen::MatrixXd absa = m.a().cwiseAbs();  // |a_{n,k}|, once
  const std::vector<int> ks = nonzero_harmonics(m.a());
  Eigen::VectorXd mag = Eigen::VectorXd::Zero(grid.N);
  std::vector<double> wn(na + 1);
  for (int j = 0; j < grid.N; ++j) {
    const int i = grid.line_of(j);
    detail::line_powers(std::abs(detail::line_variable(m.w0(), m.ts(), i)), na, wn.data());
    for (const int k : ks) {
      const int row = grid.index_of(i + k);
      if (row >= 0) mag[row] += detail::band_entry(absa.col(K + k).data(), wn.data(), na);
    }
  }
  Eigen::VectorXcd b(grid.N);
  for (int i = 0; i < grid.N; ++i) b[i] = mag[i] * std::polar(1.0, kGoldenAngle * i);
  return b;
}

// The refusal of Fds::Fds: fewer than 3 digits left.
void check_condition(double condition, int where, const std::function<std::string(int)>& label) {
  if (!(condition < Fds::kMaxCondition)) {
    std::ostringstream msg;
    msg << "A is numerically singular near " << label(where)
        << " (condition number with respect to the coefficients above " << condition
        << "): a pole on or next to that line, or a_na(t) nearly vanishes";
    throw NumericalError(msg.str());
  }
}

// The rows of A of a continuous-time model on the grid -L..L for the small band kernel, built
// from the band-row kernel (band_entry_ct: the same numbers as build_A's and band_storage_A's
// band_entry), and the right-hand sides of each row: (B U)_r for the columns of U (when given), then the conditioning check's entry (check_rhs, the phase by a
// recurrence re-anchored every 256 rows).
template <int NA>  // the order na as a constant (with nb <= na), or -1: any orders
class ModelRows {
 public:
  ModelRows(const Model& m, const Grid& g, const Eigen::MatrixXcd* U)
      : m_(m), g_(g), U_(U), K_(m.ka()), Kb_(m.kb()), na_(m.na()), nb_(m.nb()),
        P_(std::max(na_, nb_) + 1), mag_(m.a().cwiseAbs(), m.w0()), aj_(m.a().rows(), m.a().cols()),
        bj_(m.b().rows(), m.b().cols()) {
    for (Eigen::Index k = 0; k < aj_.cols(); ++k) detail::times_j_powers(m.a().col(k).data(), na_, aj_.col(k).data());
    for (Eigen::Index k = 0; k < bj_.cols(); ++k) detail::times_j_powers(m.b().col(k).data(), nb_, bj_.col(k).data());
    int R = 1;
    while (R < 2 * std::max(K_, Kb_) + 1) R *= 2;
    mask_ = R - 1;
    t_.resize(static_cast<size_t>(R) * P());
    nrhs_ = U ? static_cast<int>(U->cols()) : 0;
    if (U) {
      nonzero_.resize(g.N);
      for (int i = 0; i < g.N; ++i) nonzero_[i] = !U->row(i).isZero(0.0);
    }
    step_ = std::polar(1.0, kGoldenAngle);
  }
  int columns() const { return nrhs_ + 1; }
  int na() const { return NA >= 0 ? NA : na_; }
  int P() const { return NA >= 0 ? NA + 1 : P_; }

  __attribute__((always_inline)) void row(int r, int base, cd* out) {
    ensure(std::min(g_.N - 1, r + std::max(K_, Kb_)));
    const cd* a = aj_.data();
    const int n = na();
    if (base == r - K_ && r + K_ <= g_.N - 1) {
      // Rows whose band lies inside the grid: no bounds to test, entry j in column r - K + j.
      for (int j = 0; j <= 2 * K_; ++j)
        out[j] = detail::band_entry_ct(a + static_cast<size_t>(2 * K_ - j) * (n + 1), t(base + j), n);
      return;
    }
    const int lo = std::max(0, r - K_ - base), hi = std::min({2 * K_, r + K_ - base, g_.N - 1 - base});
    for (int j = 0; j < lo; ++j) out[j] = cd(0.0, 0.0);
    for (int j = lo; j <= hi; ++j) {
      const int c = base + j;
      out[j] = detail::band_entry_ct(a + static_cast<size_t>(K_ + r - c) * (n + 1), t(c), n);
    }
    for (int j = hi + 1; j <= 2 * K_; ++j) out[j] = cd(0.0, 0.0);
  }

  __attribute__((always_inline)) void rhs(int r, cd* z) {
    ensure(std::min(g_.N - 1, r + std::max(K_, Kb_)));
    const cd* b = bj_.data();
    const int lo = std::max(0, r - Kb_), hi = std::min(g_.N - 1, r + Kb_);
    for (int q = 0; q < nrhs_; ++q) {
      const cd* u = U_->data() + static_cast<size_t>(q) * g_.N;
      double re = 0.0, im = 0.0;
      for (int c = lo; c <= hi; ++c) {
        if (!nonzero_[c]) continue;  // B U costs nothing on lines without input
        const cd v = detail::band_entry_ct(b + static_cast<size_t>(Kb_ + r - c) * (nb_ + 1), t(c), nb_);
        re += v.real() * u[c].real() - v.imag() * u[c].imag();
        im += v.real() * u[c].imag() + v.imag() * u[c].real();
      }
      z[q] = cd(re, im);
    }
    const double mag = magnitude(r);
    phase_ = (r & 255) == 0 ? std::polar(1.0, kGoldenAngle * r) : detail::cmul(phase_, step_);
    z[nrhs_] = cd(mag * phase_.real(), mag * phase_.imag());
  }

 private:
  // Row r's sum over its entries of sum_n |a_{n,k}| |s_c|^n.
  double magnitude(int r) const {
    const int i = g_.line_of(r);
    if (r - K_ >= 0 && r + K_ <= g_.N - 1 && (i >= K_ || i <= -K_)) return mag_.far(i, na());
    return mag_.direct(r, std::max(0, r - K_), std::min(g_.N - 1, r + K_), na(), [this](int c) { return t(c); });
  }
  const double* t(int c) const { return &t_[static_cast<size_t>(c & mask_) * P()]; }
  // Powers of the lines of the columns up to c (columns arrive in increasing order).
  void ensure(int c) {
    for (; next_ <= c; ++next_)  // s = j w, w = w0 l as line_variable forms it
      detail::real_powers(m_.w0() * g_.line_of(next_), P() - 1, &t_[static_cast<size_t>(next_ & mask_) * P()]);
  }
  const Model& m_;
  const Grid& g_;
  const Eigen::MatrixXcd* U_;
  int K_, Kb_, na_, nb_, P_, mask_ = 0, nrhs_ = 0, next_ = 0;
  detail::CheckMagnitude mag_;
  Eigen::MatrixXcd aj_, bj_;  // the coefficients times j^n (detail::times_j_powers)
  std::vector<double> t_;
  std::vector<char> nonzero_;
  cd phase_{1.0, 0.0}, step_;
};

[[noreturn]] void zero_pivot(int column, const std::function<std::string(int)>& label) {
  std::ostringstream msg;
  msg << "A is singular at " << label(column)
      << " (a zero pivot: the system has a pole on that line, or a_na(t) vanishes)";
  throw NumericalError(msg.str());
}

// The small band kernel on the model's grid: factorises A with the right-hand sides of
// ModelRows eliminated on the way, back-substitutes them, and returns the solutions of the U
// columns (n x U.cols()) and the check's max |x_i| and where it is.
struct FusedSolve {
  Eigen::MatrixXcd Y;
  double condition = 0.0;
  int where = 0;
};

template <int NA>
FusedSolve fused_band_solve_as(const Model& m, const Grid& g, const Eigen::MatrixXcd* U,
                            detail::BandFactors& f, bool keep_L,
                            const std::function<std::string(int)>& label) {
  ModelRows<NA> src(m, g, U);
  const int n = g.N, K = m.ka(), nz = src.columns();
  detail::RawArray z;
  z.resize(static_cast<size_t>(n + 2 * K) * nz);
  try {
    detail::dispatch_band(K, [&](auto kt) {
      detail::factor_band_best<decltype(kt)::value>(src, n, K, nz, f, keep_L, z.data());
      detail::back_substitute_best<decltype(kt)::value>(f, nz, z.data());
    });
  } catch (const detail::ZeroPivot& e) {
    zero_pivot(e.column, label);
  }
  FusedSolve out;
  const int nu = nz - 1;
  out.Y.resize(n, nu);
  for (int i = 0; i < n; ++i) {
    const cd* zi = &z[static_cast<size_t>(i) * nz];
    for (int q = 0; q < nu; ++q) out.Y(i, q) = zi[q];
    const double a = std::norm(zi[nu]);
    if (a > out.condition || !(a == a)) out.condition = a, out.where = i;
  }
  out.condition = std::abs(z[static_cast<size_t>(out.where) * nz + nu]);
  if (!out.Y.allFinite()) throw NumericalError("band solve produced NaN or inf");
  return out;
}

FusedSolve fused_band_solve(const Model& m, const Grid& g, const Eigen::MatrixXcd* U,
                            detail::BandFactors& f, bool keep_L,
                            const std::function<std::string(int)>& label) {
  // The orders as constants for the common models, so that the sums unroll (the same sums).
  if (m.nb() <= m.na()) {
    switch (m.na()) {
      case 1: return fused_band_solve_as<1>(m, g, U, f, keep_L, label);
      case 2: return fused_band_solve_as<2>(m, g, U, f, keep_L, label);
      case 3: return fused_band_solve_as<3>(m, g, U, f, keep_L, label);
      default: break;
    }
  }
  return fused_band_solve_as<-1>(m, g, U, f, keep_L, label);
}

bool use_small_band(const Model& m) { return m.ka() <= SmallBandLU::kMaxK; }

std::function<std::string(int)> line_label(const Grid& g) {
  return [g](int col) { return "line " + std::to_string(g.line_of(col)); };
}

// The half-grid route (fds_fold.hpp) for a real input given by its lines 0.., with the
// refusals of the full-grid one.
detail::FoldedSolution solve_half(const Model& m, const Grid& g, const detail::HalfInput& U,
                                  Eigen::MatrixXcd* full = nullptr) {
  const auto label = line_label(g);
  detail::FoldedSolution r;
  try {
    r = detail::solve_folded(m, g, U, full);
  } catch (const detail::ZeroPivot& e) {
    zero_pivot(e.column, label);
  }
  // A finite peak2 is a finite solution; otherwise look (a square may overflow a finite Y).
  if (!std::isfinite(r.peak2) && !(full ? full->allFinite() : r.Y.allFinite()))
    throw NumericalError("band solve produced NaN or inf");
  check_condition(r.condition, r.where, label);
  return r;
}

}  // namespace

Fds::Fds(const Model& m, int L, Solver solver) : model_(m), grid_(make_grid(m, L)) {
  solver_ = solver == Solver::Auto ? default_solver(grid_.circular) : solver;
  const auto label = line_label(grid_);
  if (solver_ == Solver::Band) {
    if (grid_.circular) {
      throw std::invalid_argument("solver: the band solver needs the continuous-time grid; the "
                                  "discrete-time grid wraps around (use 'klu' or 'umfpack')");
    }
    if (use_small_band(m)) {
      // One pass: A built into the factorisation, the check's right-hand side eliminated and
      // back-substituted with it.
      auto f = std::make_unique<detail::BandFactors>();
      const FusedSolve r = fused_band_solve(m, grid_, nullptr, *f, true, label);
      small_ = std::make_unique<SmallBandLU>(std::move(f));
      condition_ = r.condition;
      condition_line_ = grid_.line_of(r.where);
      check_condition(condition_, r.where, label);
      return;
    }
    band_ = std::make_unique<BandLU>(grid_.N, m.ka(), m.ka(), detail::band_storage_A(m, grid_), label);
  } else {
    lu_ = std::make_unique<SparseLU>(build_A(m, grid_), solver_, label);
  }
  // Conditioning with respect to the coefficients: a right-hand side of unit phases scaled by
  // the magnitude of the terms in each row. An entry that cancels to rounding level (a pole
  // on a grid line up to rounding) makes the solution huge exactly there; a large but
  // accurately computed entry (high frequencies, high orders) does not.
  const Eigen::VectorXcd x = solve_factored(check_rhs(m, grid_));
  Eigen::Index where = 0;
  condition_ = x.cwiseAbs().maxCoeff(&where);
  condition_line_ = grid_.line_of(static_cast<int>(where));
  check_condition(condition_, static_cast<int>(where), label);
}

GridSolution solve_grid(const Model& m, int L, const Eigen::MatrixXcd& U_full, Solver solver) {
  GridSolution out;
  out.grid = make_grid(m, L);
  out.solver = solver == Solver::Auto ? default_solver(out.grid.circular) : solver;
  if (U_full.rows() != out.grid.N) {
    throw std::invalid_argument("U must have " + std::to_string(out.grid.N) +
                                " rows (the grid), got " + std::to_string(U_full.rows()));
  }
  if (out.solver == Solver::Band && !out.grid.circular && use_small_band(m)) {
    const auto label = line_label(out.grid);
    const int L = out.grid.L;
    if (detail::can_fold(m, out.grid) && detail::real_input(out.grid, U_full)) {
      // A real input: half the grid (fds_fold.hpp).
      out.Y.resize(out.grid.N, U_full.cols());
      const detail::FoldedSolution r = solve_half(m, out.grid, U_full.middleRows(L, L + 1), &out.Y);
      out.condition = r.condition;
      out.condition_line = out.grid.line_of(r.where);  // a line >= 0 (|x| is symmetric)
      return out;
    }
    detail::BandFactors f;
    FusedSolve r = fused_band_solve(m, out.grid, &U_full, f, false, label);
    check_condition(r.condition, r.where, label);
    out.Y = std::move(r.Y);
    out.condition = r.condition;
    out.condition_line = out.grid.line_of(r.where);
    return out;
  }
  const Fds fds(m, L, solver);
  out.Y = fds.solve_full(U_full);
  out.condition = fds.condition();
  out.condition_line = fds.condition_line();
  out.solver = fds.solver();
  return out;
}

Eigen::MatrixXcd Fds::solve_factored(const Eigen::MatrixXcd& rhs) const {
  if (small_) return small_->solve(rhs);
  return band_ ? band_->solve(rhs) : lu_->solve(rhs);
}

Eigen::MatrixXcd Fds::solve_A(const Eigen::MatrixXcd& rhs) const {
  if (rhs.rows() != grid_.N) {
    throw std::invalid_argument("rhs must have " + std::to_string(grid_.N) + " rows (the grid), got " +
                                std::to_string(rhs.rows()));
  }
  return solve_factored(rhs);
}

Eigen::MatrixXcd Fds::solve_full(const Eigen::MatrixXcd& U) const {
  if (U.rows() != grid_.N) {
    throw std::invalid_argument("U must have " + std::to_string(grid_.N) +
                                " rows (the grid), got " + std::to_string(U.rows()));
  }
  return solve_factored(apply_B(model_, grid_, U));
}

Eigen::MatrixXcd Fds::htf_columns(const std::vector<int>& input_lines) const {
  Eigen::MatrixXcd rhs = Eigen::MatrixXcd::Zero(grid_.N, static_cast<Eigen::Index>(input_lines.size()));
  for (size_t j = 0; j < input_lines.size(); ++j) {
    const int idx = grid_.index_of(input_lines[j]);
    if (idx < 0) {
      throw std::invalid_argument("lines: input line " + std::to_string(input_lines[j]) +
                                  " is outside the grid -" + std::to_string(grid_.L) + ".." +
                                  std::to_string(grid_.L));
    }
    rhs(idx, static_cast<Eigen::Index>(j)) = 1.0;
  }
  return solve_full(rhs);
}

namespace {

// max |x_ij| without a hypot per entry (the square root of the largest |x|^2; cwiseAbs where
// the squares overflow).
double max_abs(const Eigen::MatrixXcd& x) {
  if (x.size() == 0) return 0.0;
  const double m2 = x.cwiseAbs2().maxCoeff();
  return std::isfinite(m2) ? std::sqrt(m2) : x.cwiseAbs().maxCoeff();
}

void check_input(const Eigen::MatrixXcd& U) {
  if (U.rows() < 1 || U.cols() < 1) throw std::invalid_argument("U must not be empty");
  if (!U.allFinite()) throw std::invalid_argument("U contains NaN or inf");
  if (U.row(0).imag().isZero(0.0)) return;  // the usual real DC line: no scale needed
  const double scale = std::max(max_abs(U), 1e-300);
  for (Eigen::Index j = 0; j < U.cols(); ++j) {
    if (std::abs(U(0, j).imag()) > 1e-12 * scale) {
      throw std::invalid_argument(
          "U: line 0 (DC) must be real for a real input signal, column " + std::to_string(j) +
          " has imaginary part " + std::to_string(U(0, j).imag()));
    }
  }
}

// One-sided spectra on lines 0..Lu -> full grid (conjugate lines filled in). Lines beyond
// a continuous-time grid must be zero (the caller sizes the grid to the last nonzero one).
Eigen::MatrixXcd to_full(const Grid& g, const Eigen::MatrixXcd& U) {
  Eigen::MatrixXcd F = Eigen::MatrixXcd::Zero(g.N, U.cols());
  const Eigen::Index rows = g.circular ? U.rows() : std::min<Eigen::Index>(U.rows(), g.L + 1);
  for (Eigen::Index l = 0; l < rows; ++l) {
    F.row(g.index_of(static_cast<int>(l))) = U.row(l);
    if (l > 0) F.row(g.index_of(-static_cast<int>(l))) += U.row(l).conjugate();
  }
  if (g.circular && g.N % 2 == 0 && U.rows() > g.N / 2) {
    // Line N/2 is its own conjugate: the two contributions above add to 2 Re U.
    F.row(g.N / 2) = U.row(g.N / 2).real().cast<cd>();
  }
  if (g.circular && U.rows() > 0) F.row(0) = U.row(0).real().cast<cd>();
  return F;
}

// Lines 0..lines_out of a full-grid solution; lines beyond a continuous-time grid are zero
// (the truncation the guard controls).
Eigen::MatrixXcd to_onesided(const Grid& g, const Eigen::MatrixXcd& Y, int lines_out) {
  Eigen::MatrixXcd out = Eigen::MatrixXcd::Zero(lines_out + 1, Y.cols());
  const int top = g.circular ? lines_out : std::min(lines_out, g.L);
  for (int l = 0; l <= top; ++l) out.row(l) = Y.row(g.index_of(l));
  return out;
}

// An LTI model's lines do not couple: the condition that matters for the output is that of
// the lines with input, sum_n |a_n| |s_l|^n / |a(s_l)| (A's diagonal), the largest of them.
void lti_condition_on_input_lines(const Model& m, const Eigen::MatrixXcd& U, SimulateResult& res) {
  const int na = m.na();
  std::vector<cd> pw(na + 1);
  std::vector<double> wn(na + 1);
  const Eigen::VectorXd absa = m.a().col(0).cwiseAbs();
  res.condition = 0.0;
  res.condition_line = 0;
  for (Eigen::Index l = 0; l < U.rows(); ++l) {
    if (U.row(l).isZero(0.0)) continue;
    const cd s = detail::line_variable(m.w0(), m.ts(), static_cast<int>(l));
    detail::line_powers(s, na, pw.data());
    detail::line_powers(std::abs(s), na, wn.data());
    const double c = detail::band_entry(absa.data(), wn.data(), na) /
                     std::abs(detail::band_entry(m.a().col(0).data(), pw.data(), na));
    if (c > res.condition) res.condition = c, res.condition_line = static_cast<int>(l);
  }
}

// The highest line with a nonzero input (0 for an all-zero input).
int last_nonzero_line(const Eigen::MatrixXcd& U) {
  for (Eigen::Index l = U.rows() - 1; l > 0; --l) {
    if (!U.row(l).isZero(0.0)) return static_cast<int>(l);
  }
  return 0;
}

}  // namespace

namespace {

// The factor 10 cond of the truncation bound, taken before the factorisation gives cond
// (Fds::condition): 10 x 30. A larger condition number costs a second grid, not accuracy.
constexpr double kAssumedCondition = 300.0;

}  // namespace

double decay_per_line(const Model& m) {
  // Far from line 0 row l of A is (j w0 l)^na sum_k a_{na,k} Y_{l-k} up to O(1/l), so beyond
  // the excited lines Y_l behaves like a sum of lambda^l over the roots of
  // sum_k a_{na,k} lambda^(kmax-k) (the harmonics of a_na(t), kmin..kmax those that are
  // nonzero): roots inside the unit circle decay towards +inf, those outside towards -inf.
  // The slowest of either side is the prediction. A root on the circle (a_na(t) has a real
  // zero) decays not at all: 1.
  const int K = m.ka(), na = m.na();
  int lo = -K, hi = K;
  while (lo <= hi && m.a()(na, K + lo) == cd(0.0, 0.0)) ++lo;
  while (hi >= lo && m.a()(na, K + hi) == cd(0.0, 0.0)) --hi;
  if (hi <= lo) return 0.0;  // a_na constant (or a single harmonic): no coupling at the top order
  const int deg = hi - lo;
  // Companion matrix of the monic polynomial lambda^deg + sum c_i lambda^i.
  Eigen::MatrixXcd C = Eigen::MatrixXcd::Zero(deg, deg);
  const cd lead = m.a()(na, K + lo);  // coefficient of lambda^(hi - lo)
  for (int i = 0; i < deg; ++i) {
    // lambda^i has the coefficient a_{na, hi - i}.
    C(0, deg - 1 - i) = -m.a()(na, K + hi - i) / lead;
    if (i + 1 < deg) C(i + 1, i) = 1.0;
  }
  const Eigen::VectorXcd roots = Eigen::ComplexEigenSolver<Eigen::MatrixXcd>(C, false).eigenvalues();
  double q = 0;
  for (Eigen::Index i = 0; i < roots.size(); ++i) {
    const double r = std::abs(roots[i]);
    q = std::max(q, r < 1 ? r : 1 / r);
  }
  return q;
}

SimulateResult simulate(const Model& m, const Eigen::MatrixXcd& U, const SimulateOptions& opt) {
  check_input(U);
  SimulateResult res;
  const int Lu = static_cast<int>(U.rows()) - 1;
  if (m.discrete()) {
    const Grid g = make_grid(m, 0);
    if (Lu > g.N / 2) {
      throw std::invalid_argument("U has lines 0.." + std::to_string(Lu) +
                                  " but the discrete-time grid of " + std::to_string(g.N) +
                                  " samples per period has one-sided lines 0.." +
                                  std::to_string(g.N / 2));
    }
    if (g.N % 2 == 0 && Lu == g.N / 2) {
      const double scale = std::max(max_abs(U), 1e-300);
      if (U.row(Lu).imag().cwiseAbs().maxCoeff() > 1e-12 * scale) {
        throw std::invalid_argument("U: the Nyquist line N/2 must be real for a real input signal");
      }
    }
    int lines_out = opt.lines_out < 0 ? Lu : opt.lines_out;
    if (lines_out > g.N / 2) {
      throw std::invalid_argument("lines_out must be <= N/2 = " + std::to_string(g.N / 2));
    }
    const GridSolution s = solve_grid(m, 0, to_full(g, U), opt.solver);
    res.Y = to_onesided(g, s.Y, lines_out);
    res.solver = s.solver;
    res.condition = s.condition;
    res.condition_line = std::min(s.condition_line, g.N - s.condition_line);
    if (m.kmax() == 0) lti_condition_on_input_lines(m, U, res);
    return res;
  }

  const int lines_out = opt.lines_out < 0 ? Lu : opt.lines_out;
  // The output beyond the last excited line only decays, so the grid starts there (or at
  // the lines asked for explicitly); trailing zero lines of U cost nothing.
  const int band = std::max(last_nonzero_line(U), opt.lines_out < 0 ? 0 : opt.lines_out);
  check_grid_size(band, m.kmax());
  const int K = std::max(1, m.kmax());
  // One grid: the wanted lines and a bound on their truncation error. Dropping the lines
  // beyond the grid drops coupling terms no larger than the outermost K computed lines times
  // the row magnitudes; A^-1 amplifies that by about its componentwise condition number
  // (Fds::condition, a lower estimate: hence the factor 10).
  struct Run {
    Eigen::MatrixXcd Y;
    double bound;
    double edge;  // outermost K lines relative to the peak
    double cond;
  };
  // A real input (U_0 exactly real) on the band solver's grids: half the grid, from the
  // one-sided U as it is (fds_fold.hpp).
  const bool half = (opt.solver == Solver::Auto || opt.solver == Solver::Band) &&
                    use_small_band(m) && U.row(0).imag().isZero(0.0);
  auto run = [&](int band_lines, int guard) {
    // A guard given by the caller can be anything up to INT_MAX: add in 64 bits.
    const long long L = static_cast<long long>(band_lines) + guard;
    check_grid_size(L, m.kmax());
    const Grid g = make_grid(m, static_cast<int>(L));
    if (half && detail::can_fold(m, g)) {
      detail::FoldedSolution s = solve_half(m, g, U.topRows(std::min<Eigen::Index>(U.rows(), g.L + 1)));
      res.solver = Solver::Band;
      // max_abs(s.Y): the square root of the largest |y|^2, here from the solve's own pass.
      const double peak = std::max(std::isfinite(s.peak2) ? std::sqrt(s.peak2) : max_abs(s.Y), 1e-300);
      double edge = 0;
      for (int l = std::max(0, g.L - K + 1); l <= g.L; ++l) edge = std::max(edge, s.Y.row(l).cwiseAbs().maxCoeff());
      const double cond = std::max(1.0, s.condition);
      res.condition = s.condition;
      res.condition_line = g.line_of(s.where);
      const double bound = 10.0 * cond * edge / peak;
      if (s.Y.rows() == lines_out + 1) return Run{std::move(s.Y), bound, edge / peak, cond};
      Eigen::MatrixXcd out = Eigen::MatrixXcd::Zero(lines_out + 1, s.Y.cols());
      const int top = std::min(lines_out, g.L);
      out.topRows(top + 1) = s.Y.topRows(top + 1);
      return Run{std::move(out), bound, edge / peak, cond};
    }
    const GridSolution s = solve_grid(m, g.L, to_full(g, U), opt.solver);
    res.solver = s.solver;
    const Eigen::MatrixXcd& full = s.Y;
    const double peak = std::max(max_abs(full), 1e-300);
    double edge = 0;
    for (int l = std::max(0, g.L - K + 1); l <= g.L; ++l) {
      edge = std::max(edge, full.row(g.index_of(l)).cwiseAbs().maxCoeff());
    }
    const double cond = std::max(1.0, s.condition);
    res.condition = s.condition;
    res.condition_line = std::abs(s.condition_line);
    return Run{to_onesided(g, full, lines_out), 10.0 * cond * edge / peak, edge / peak, cond};
  };
  if (m.kmax() == 0) {
    // LTI: A is diagonal, lines do not couple, no truncation error.
    res.Y = run(band, 0).Y;
    lti_condition_on_input_lines(m, U, res);
    return res;
  }
  if (opt.guard >= 0) {
    // Fixed guard on the documented grid: max(highest input line, lines_out) + guard.
    Run r = run(std::max(Lu, lines_out), opt.guard);
    res.Y = std::move(r.Y);
    res.guard = opt.guard;
    res.truncation_error = r.bound;
    res.converged = r.bound <= opt.tol;
    return res;
  }
  // Adaptive guard: accept a grid when its bound is below tol (one factorisation for a
  // well-conditioned, fast-decaying system); otherwise double the guard until two grids agree
  // to tol, or the bound of the larger one is below tol.
  const int max_guard = opt.max_guard >= 0 ? opt.max_guard : std::max(1024, 4 * band);
  const int excited = last_nonzero_line(U);
  // The first grid is sized from the decay the model predicts beyond the excited lines
  // (decay_per_line): normally it meets the bound, one factorisation. Without a prediction
  // (a_na(t) vanishing somewhere), a start that is small next to the band.
  int guard = std::max({16, 4 * K, band / 256});
  const double q = decay_per_line(m);
  if (q > 0 && q < 1) {
    const double D = 1.25 * std::log(opt.tol / kAssumedCondition) / std::log(q) + 2 * K;
    guard = std::max(4 * K, static_cast<int>(std::ceil(std::min(D, 1e9))) - (band - excited));
  }
  guard = std::min(guard, max_guard);
  Run prev = run(band, guard);
  res.Y = prev.Y;
  res.guard = guard;
  res.truncation_error = prev.bound;
  if (prev.bound <= opt.tol) {
    res.converged = true;
    return res;
  }
  if (guard >= max_guard) {
    res.converged = false;
    return res;
  }
  while (true) {
    // The output decays about geometrically beyond the last excited line: from the edge
    // value at distance D, the distance where the bound meets tol, with a margin.
    int next = 2 * guard;
    const int D = band + guard - excited;
    if (prev.edge > 0 && prev.edge < 1 && D > 0) {
      const double need = D * std::log(opt.tol / (10.0 * prev.cond)) / std::log(prev.edge);
      if (std::isfinite(need)) {
        next = std::max(next, static_cast<int>(std::min(1.25 * need, 1e9)) - (band - excited));
      }
    }
    next = std::min(next, std::max(max_guard, 2 * guard));
    Run cur = run(band, next);
    const double peak = std::max(max_abs(cur.Y), 1e-300);
    const double diff = (cur.Y - prev.Y).cwiseAbs().maxCoeff() / peak;
    res.Y = cur.Y;
    res.guard = next;
    res.truncation_error = std::min(diff, cur.bound);
    if (res.truncation_error <= opt.tol) {
      res.converged = true;
      return res;
    }
    if (next >= max_guard) {
      res.converged = false;
      return res;
    }
    prev = std::move(cur);
    guard = next;
  }
}

}  // namespace lptv
