#include "lptv/fds.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "band_row.hpp"
#include "lptv/errors.hpp"

namespace lptv {

int Grid::index_of(int line) const {
  if (circular) {
    int i = line % N;
    return i < 0 ? i + N : i;
  }
  return (line < -L || line > L) ? -1 : line + L;
}

Grid make_grid(const Model& m, int L) {
  Grid g;
  if (m.discrete()) {
    g.circular = true;
    g.N = m.samples_per_period();
    g.L = g.N / 2;
  } else {
    if (L < 0) throw std::invalid_argument("L must be >= 0, got " + std::to_string(L));
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

// Entries sum_n c_{n,l-i} s_i^n for |l-i| <= K; on the circular grid the band wraps.
SpMat build_band(const Model& m, const Grid& g, const Eigen::MatrixXcd& c) {
  const int order = static_cast<int>(c.rows()) - 1;
  const int K = static_cast<int>(c.cols() - 1) / 2;
  std::vector<Eigen::Triplet<cd, int>> trip;
  trip.reserve(static_cast<size_t>(g.N) * (2 * K + 1));
  std::vector<cd> pw(order + 1);
  for (int col = 0; col < g.N; ++col) {
    const int i = g.line_of(col);
    detail::line_powers(detail::line_variable(m.w0(), m.ts(), i), order, pw.data());
    for (int k = -K; k <= K; ++k) {
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

Fds::Fds(const Model& m, int L, Solver solver) : model_(m), grid_(make_grid(m, L)) {
  solver_ = solver == Solver::Auto ? default_solver(grid_.circular) : solver;
  const Grid g = grid_;
  auto label = [g](int col) { return "line " + std::to_string(g.line_of(col)); };
  if (solver_ == Solver::Band) {
    if (grid_.circular) {
      throw std::invalid_argument("solver: the band solver needs the continuous-time grid; the "
                                  "discrete-time grid wraps around (use 'klu' or 'umfpack')");
    }
    band_ = std::make_unique<BandLU>(grid_.N, m.ka(), m.ka(), detail::band_storage_A(m, grid_), label);
  } else {
    lu_ = std::make_unique<SparseLU>(build_A(m, grid_), solver_, label);
  }
  // Conditioning with respect to the coefficients: a right-hand side of unit phases scaled by
  // the magnitude of the terms in each row. An entry that cancels to rounding level (a pole
  // on a grid line up to rounding) makes the solution huge exactly there; a large but
  // accurately computed entry (high frequencies, high orders) does not.
  const int K = m.ka(), na = m.na();
  const Eigen::MatrixXd absa = m.a().cwiseAbs();  // |a_{n,k}|, once
  Eigen::VectorXd mag = Eigen::VectorXd::Zero(grid_.N);
  std::vector<double> wn(na + 1);
  for (int j = 0; j < grid_.N; ++j) {
    const int i = grid_.line_of(j);
    detail::line_powers(std::abs(detail::line_variable(m.w0(), m.ts(), i)), na, wn.data());
    for (int k = -K; k <= K; ++k) {
      const int row = grid_.index_of(i + k);
      if (row >= 0) mag[row] += detail::band_entry(absa.col(K + k).data(), wn.data(), na);
    }
  }
  Eigen::VectorXcd b(grid_.N);
  for (int i = 0; i < grid_.N; ++i) b[i] = mag[i] * std::polar(1.0, 2.399963229728653 * i);  // golden angle
  const Eigen::VectorXcd x = solve_A(b);
  Eigen::Index where = 0;
  condition_ = x.cwiseAbs().maxCoeff(&where);
  if (!(condition_ < kMaxCondition)) {
    std::ostringstream msg;
    msg << "A is numerically singular near " << label(static_cast<int>(where))
        << " (condition number with respect to the coefficients above " << condition_
        << "): a pole on or next to that line, or a_na(t) nearly vanishes";
    throw NumericalError(msg.str());
  }
}

Eigen::MatrixXcd Fds::solve_A(const Eigen::MatrixXcd& rhs) const {
  return band_ ? band_->solve(rhs) : lu_->solve(rhs);
}

Eigen::MatrixXcd Fds::solve_full(const Eigen::MatrixXcd& U) const {
  if (U.rows() != grid_.N) {
    throw std::invalid_argument("U must have " + std::to_string(grid_.N) +
                                " rows (the grid), got " + std::to_string(U.rows()));
  }
  return solve_A(apply_B(model_, grid_, U));
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

void check_input(const Eigen::MatrixXcd& U) {
  if (U.rows() < 1 || U.cols() < 1) throw std::invalid_argument("U must not be empty");
  if (!U.allFinite()) throw std::invalid_argument("U contains NaN or inf");
  const double scale = std::max(U.cwiseAbs().maxCoeff(), 1e-300);
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

// The highest line with a nonzero input (0 for an all-zero input).
int last_nonzero_line(const Eigen::MatrixXcd& U) {
  for (Eigen::Index l = U.rows() - 1; l > 0; --l) {
    if (!U.row(l).isZero(0.0)) return static_cast<int>(l);
  }
  return 0;
}

}  // namespace

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
      const double scale = std::max(U.cwiseAbs().maxCoeff(), 1e-300);
      if (U.row(Lu).imag().cwiseAbs().maxCoeff() > 1e-12 * scale) {
        throw std::invalid_argument("U: the Nyquist line N/2 must be real for a real input signal");
      }
    }
    int lines_out = opt.lines_out < 0 ? Lu : opt.lines_out;
    if (lines_out > g.N / 2) {
      throw std::invalid_argument("lines_out must be <= N/2 = " + std::to_string(g.N / 2));
    }
    Fds fds(m, 0, opt.solver);
    res.Y = to_onesided(g, fds.solve_full(to_full(g, U)), lines_out);
    res.solver = fds.solver();
    return res;
  }

  const int lines_out = opt.lines_out < 0 ? Lu : opt.lines_out;
  // The output beyond the last excited line only decays, so the grid starts there (or at
  // the lines asked for explicitly); trailing zero lines of U cost nothing.
  const int band = std::max(last_nonzero_line(U), opt.lines_out < 0 ? 0 : opt.lines_out);
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
  auto run = [&](int band_lines, int guard) {
    Fds fds(m, band_lines + guard, opt.solver);
    res.solver = fds.solver();
    const Eigen::MatrixXcd full = fds.solve_full(to_full(fds.grid(), U));
    const double peak = std::max(full.cwiseAbs().maxCoeff(), 1e-300);
    const int L = fds.grid().L;
    double edge = 0;
    for (int l = std::max(0, L - K + 1); l <= L; ++l) {
      edge = std::max(edge, full.row(fds.grid().index_of(l)).cwiseAbs().maxCoeff());
    }
    const double cond = std::max(1.0, fds.condition());
    return Run{to_onesided(fds.grid(), full, lines_out), 10.0 * cond * edge / peak, edge / peak, cond};
  };
  if (m.kmax() == 0) {
    // LTI: A is diagonal, lines do not couple, no truncation error.
    res.Y = run(band, 0).Y;
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
  // A start that is small next to the band costs little and, for the fast decay of most
  // systems, is already enough: one factorisation.
  int guard = std::max({16, 4 * K, band / 256});
  Run prev = run(band, guard);
  res.Y = prev.Y;
  res.guard = guard;
  res.truncation_error = prev.bound;
  if (prev.bound <= opt.tol) {
    res.converged = true;
    return res;
  }
  const int excited = last_nonzero_line(U);
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
    const double peak = std::max(cur.Y.cwiseAbs().maxCoeff(), 1e-300);
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
