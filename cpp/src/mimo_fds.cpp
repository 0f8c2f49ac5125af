// The block band FDS of a matrix LPTV model (METHOD.md section 19, eqs. 19.3-19.5): AA Y = BB U on
// the grid's lines, channel fastest, so AA is a scalar band matrix with ny (Ka + 1) - 1 sub- and
// super-diagonals (continuous time) or a band wrapping around the corners (discrete time).
#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "lptv/errors.hpp"
#include "lptv/mimo.hpp"

namespace lptv {
namespace {

// The golden angle: the conditioning check's phase step, as the SISO FDS takes it.
const double kGolden = M_PI * (3.0 - std::sqrt(5.0));

cd line_variable(const MimoModel& m, int line) {
  if (m.discrete()) return std::polar(1.0, m.w0() * m.ts() * line);
  return cd(0.0, m.w0() * line);
}

// Calls f(scalar row, scalar column, value) for every nonzero scalar entry of AA (a_side) or BB:
// block (row line index ri, column line index ci = ri - k) entry (p, q) is
// sum_n c_{n,pq,k} s_ci^n. With magnitude, |c| and |s| instead (the conditioning check's terms).
template <class F>
void for_each_entry(const MimoModel& m, const Grid& g, bool a_side, bool magnitude, F&& f) {
  const Eigen::MatrixXcd& c = a_side ? m.a() : m.b();
  const int ny = m.n_outputs(), nc = a_side ? ny : m.n_inputs();
  const int order = a_side ? m.na() : m.nb();
  const int K = static_cast<int>(c.cols() - 1) / 2;
  std::vector<cd> pw(static_cast<size_t>(order) + 1);
  for (int ci = 0; ci < g.N; ++ci) {
    cd s = line_variable(m, g.line_of(ci));
    if (magnitude) s = cd(std::abs(s), 0.0);
    pw[0] = cd(1.0, 0.0);
    for (int n = 1; n <= order; ++n) pw[static_cast<size_t>(n)] = pw[static_cast<size_t>(n) - 1] * s;
    for (int k = -K; k <= K; ++k) {
      int ri = ci + k;
      if (g.circular) {
        ri = ((ri % g.N) + g.N) % g.N;
      } else if (ri < 0 || ri >= g.N) {
        continue;
      }
      for (int p = 0; p < ny; ++p) {
        for (int q = 0; q < nc; ++q) {
          cd v(0.0, 0.0);
          for (int n = 0; n <= order; ++n) {
            const cd a = c((static_cast<Eigen::Index>(n) * ny + p) * nc + q, K + k);
            v += (magnitude ? cd(std::abs(a), 0.0) : a) * pw[static_cast<size_t>(n)];
          }
          if (v != cd(0.0, 0.0)) f(ri * ny + p, ci * nc + q, v);
        }
      }
    }
  }
}

SpMat build(const MimoModel& m, const Grid& g, bool a_side) {
  const int ny = m.n_outputs(), nc = a_side ? ny : m.n_inputs();
  std::vector<Eigen::Triplet<cd, int>> t;
  t.reserve(static_cast<size_t>(g.N) * ny * nc * (2 * (a_side ? m.ka() : m.kb()) + 1));
  for_each_entry(m, g, a_side, false, [&](int r, int c, cd v) { t.emplace_back(r, c, v); });
  SpMat M(g.N * ny, g.N * nc);
  M.setFromTriplets(t.begin(), t.end());  // sums coinciding entries (none on a valid grid)
  return M;
}

std::function<std::string(int)> channel_label(const Grid& g, int ny) {
  return [g, ny](int col) {
    return "line " + std::to_string(g.line_of(col / ny)) + ", output " + std::to_string(col % ny);
  };
}

void check_condition(double condition, int where, const std::function<std::string(int)>& label) {
  if (!(condition < Fds::kMaxCondition)) {
    std::ostringstream msg;
    msg << "AA is numerically singular near " << label(where)
        << " (condition number with respect to the coefficients above " << condition
        << "): a pole on or next to that line, or the leading matrix A_na(t) nearly singular";
    throw NumericalError(msg.str());
  }
}

void check_grid(long long L, const MimoModel& m) {
  const long long width = std::max(m.n_outputs(), m.n_inputs());
  if (L > (1LL << 26) || (2 * L + 1) * width > INT_MAX / 4) {
    throw std::invalid_argument("the grid of lines -" + std::to_string(L) + ".." + std::to_string(L) +
                                " is too large for the block band system");
  }
}

double max_abs(const Eigen::MatrixXcd& x) { return x.size() ? x.cwiseAbs().maxCoeff() : 0.0; }

// One-sided spectra (rows: lines 0..Lu; column e nc + r) -> full-grid columns (grid.N nc rows
// per experiment e), the conjugate lines filled in.
Eigen::MatrixXcd to_full(const Grid& g, const Eigen::MatrixXcd& U, int nc) {
  const int E = static_cast<int>(U.cols()) / nc;
  Eigen::MatrixXcd F = Eigen::MatrixXcd::Zero(static_cast<Eigen::Index>(g.N) * nc, E);
  const int rows = g.circular ? static_cast<int>(U.rows()) : std::min(static_cast<int>(U.rows()), g.L + 1);
  for (int l = 0; l < rows; ++l) {
    const int i = g.index_of(l), ic = g.index_of(-l);
    const bool self = g.circular && (l == 0 || 2 * l == g.N);  // DC and Nyquist: their own conjugate
    for (int e = 0; e < E; ++e) {
      for (int r = 0; r < nc; ++r) {
        const cd v = U(l, e * nc + r);
        if (self) {
          F(static_cast<Eigen::Index>(i) * nc + r, e) = cd(v.real(), 0.0);
          continue;
        }
        F(static_cast<Eigen::Index>(i) * nc + r, e) = v;
        if (l > 0) F(static_cast<Eigen::Index>(ic) * nc + r, e) += std::conj(v);
      }
    }
  }
  return F;
}

Eigen::MatrixXcd to_onesided(const Grid& g, const Eigen::MatrixXcd& Y, int ny, int lines_out) {
  const int E = static_cast<int>(Y.cols());
  Eigen::MatrixXcd out = Eigen::MatrixXcd::Zero(lines_out + 1, static_cast<Eigen::Index>(E) * ny);
  const int top = g.circular ? lines_out : std::min(lines_out, g.L);
  for (int l = 0; l <= top; ++l) {
    const Eigen::Index i = g.index_of(l);
    for (int e = 0; e < E; ++e)
      for (int p = 0; p < ny; ++p) out(l, e * ny + p) = Y(i * ny + p, e);
  }
  return out;
}

int last_nonzero_line(const Eigen::MatrixXcd& U) {
  for (Eigen::Index l = U.rows() - 1; l > 0; --l)
    if (!U.row(l).isZero(0.0)) return static_cast<int>(l);
  return 0;
}

}  // namespace

Grid make_grid(const MimoModel& m, int L) {
  Grid g;
  if (m.discrete()) {
    g.circular = true;
    g.N = m.samples_per_period();
    return g;
  }
  if (L < 0) throw std::invalid_argument("L must be >= 0, got " + std::to_string(L));
  check_grid(L, m);
  g.L = L;
  g.N = 2 * L + 1;
  return g;
}

SpMat build_mimo_A(const MimoModel& m, const Grid& g) { return build(m, g, true); }
SpMat build_mimo_B(const MimoModel& m, const Grid& g) { return build(m, g, false); }

MimoFds::MimoFds(const MimoModel& m, int L, Solver solver) : model_(m), grid_(make_grid(m, L)) {
  solver_ = solver == Solver::Auto ? default_solver(grid_.circular) : solver;
  const int ny = m.n_outputs();
  const int n = grid_.N * ny;
  const auto label = channel_label(grid_, ny);
  if (solver_ == Solver::Band) {
    if (grid_.circular) {
      throw std::invalid_argument("solver: the band solver needs the continuous-time grid; the "
                                  "discrete-time grid wraps around (use 'klu' or 'umfpack')");
    }
    const int K = ny * (m.ka() + 1) - 1;
    const int ld = BandLU::ldab(K, K);
    std::vector<cd> ab(static_cast<size_t>(ld) * n, cd(0.0, 0.0));
    for_each_entry(m, grid_, true, false, [&](int r, int c, cd v) {
      ab[static_cast<size_t>(2 * K + r - c) + static_cast<size_t>(c) * ld] += v;
    });
    if (K <= SmallBandLU::kMaxK) {
      small_ = std::make_unique<SmallBandLU>(n, K, ab, label);
    } else {
      band_ = std::make_unique<BandLU>(n, K, K, std::move(ab), label);
    }
  } else {
    lu_ = std::make_unique<SparseLU>(build_mimo_A(m, grid_), solver_, label);
  }
  // The conditioning check of METHOD.md section 19: the terms' magnitudes of each scalar row
  // with unit phases stepping by the golden angle.
  Eigen::VectorXd mag = Eigen::VectorXd::Zero(n);
  for_each_entry(m, grid_, true, true, [&](int r, int, cd v) { mag[r] += v.real(); });
  Eigen::MatrixXcd b(n, 1);
  for (int r = 0; r < n; ++r) b(r, 0) = mag[r] * std::polar(1.0, kGolden * r);
  const Eigen::MatrixXcd x = solve_A(b);
  Eigen::Index where = 0;
  condition_ = x.col(0).cwiseAbs().maxCoeff(&where);
  if (!std::isfinite(condition_)) condition_ = INFINITY;
  condition_line_ = grid_.line_of(static_cast<int>(where) / ny);
  check_condition(condition_, static_cast<int>(where), label);
}

MimoFds::~MimoFds() = default;

Eigen::MatrixXcd MimoFds::solve_A(const Eigen::MatrixXcd& rhs) const {
  if (rhs.rows() != static_cast<Eigen::Index>(grid_.N) * model_.n_outputs()) {
    throw std::invalid_argument("right-hand sides must have grid.N * n_outputs = " +
                                std::to_string(grid_.N * model_.n_outputs()) + " rows, got " +
                                std::to_string(rhs.rows()));
  }
  if (small_) return small_->solve(rhs);
  if (band_) return band_->solve(rhs);
  return lu_->solve(rhs);
}

Eigen::MatrixXcd MimoFds::solve_full(const Eigen::MatrixXcd& U) const {
  if (U.rows() != static_cast<Eigen::Index>(grid_.N) * model_.n_inputs()) {
    throw std::invalid_argument("full-grid inputs must have grid.N * n_inputs = " +
                                std::to_string(grid_.N * model_.n_inputs()) + " rows, got " +
                                std::to_string(U.rows()));
  }
  const SpMat B = build_mimo_B(model_, grid_);
  return solve_A(Eigen::MatrixXcd(B * U));
}

Eigen::MatrixXcd MimoFds::htf_columns(const std::vector<int>& input_lines) const {
  const int nu = model_.n_inputs();
  Eigen::MatrixXcd E = Eigen::MatrixXcd::Zero(static_cast<Eigen::Index>(grid_.N) * nu,
                                              static_cast<Eigen::Index>(input_lines.size()) * nu);
  for (size_t j = 0; j < input_lines.size(); ++j) {
    const int i = grid_.index_of(input_lines[j]);
    if (i < 0) {
      throw std::invalid_argument("input line " + std::to_string(input_lines[j]) + " is outside the grid -" +
                                  std::to_string(grid_.L) + ".." + std::to_string(grid_.L));
    }
    for (int r = 0; r < nu; ++r) E(static_cast<Eigen::Index>(i) * nu + r, static_cast<Eigen::Index>(j) * nu + r) = 1.0;
  }
  return solve_full(E);
}

MimoSimulateResult simulate_mimo(const MimoModel& m, const Eigen::MatrixXcd& U, const SimulateOptions& opt) {
  const int ny = m.n_outputs(), nu = m.n_inputs();
  if (U.rows() < 1 || U.cols() < 1) throw std::invalid_argument("U must not be empty");
  if (U.cols() % nu != 0) {
    throw std::invalid_argument("U must have a multiple of n_inputs = " + std::to_string(nu) +
                                " columns (experiment e, input r in column e * n_inputs + r), got " +
                                std::to_string(U.cols()));
  }
  if (!U.allFinite()) throw std::invalid_argument("U contains NaN or inf");
  const double scale = std::max(max_abs(U), 1e-300);
  for (Eigen::Index j = 0; j < U.cols(); ++j) {
    if (std::abs(U(0, j).imag()) > 1e-12 * scale) {
      throw std::invalid_argument("U: line 0 (DC) must be real for a real input signal, column " +
                                  std::to_string(j) + " has imaginary part " + std::to_string(U(0, j).imag()));
    }
  }
  MimoSimulateResult res;
  const int Lu = static_cast<int>(U.rows()) - 1;
  const int lines_out = opt.lines_out < 0 ? Lu : opt.lines_out;
  if (m.discrete()) {
    const Grid g = make_grid(m, 0);
    if (Lu > g.N / 2) {
      throw std::invalid_argument("U has lines 0.." + std::to_string(Lu) + " but the discrete-time grid of " +
                                  std::to_string(g.N) + " samples per period has one-sided lines 0.." +
                                  std::to_string(g.N / 2));
    }
    if (g.N % 2 == 0 && Lu == g.N / 2 && U.row(Lu).imag().cwiseAbs().maxCoeff() > 1e-12 * scale) {
      throw std::invalid_argument("U: the Nyquist line N/2 must be real for a real input signal");
    }
    if (lines_out > g.N / 2) throw std::invalid_argument("lines_out must be <= N/2 = " + std::to_string(g.N / 2));
    const MimoFds f(m, 0, opt.solver);
    res.Y = to_onesided(g, f.solve_full(to_full(g, U, nu)), ny, lines_out);
    res.solver = f.solver();
    res.condition = f.condition();
    res.condition_line = std::min(f.condition_line(), g.N - f.condition_line());
    return res;
  }
  const int band = std::max(last_nonzero_line(U), opt.lines_out < 0 ? 0 : opt.lines_out);
  check_grid(band, m);
  const int K = std::max(1, m.kmax());
  struct Run {
    Eigen::MatrixXcd Y;
    double bound, edge, cond;
  };
  // One grid: the wanted lines and the bound on their truncation error (METHOD.md section 3):
  // the outermost K lines relative to the peak, amplified by the condition.
  auto run = [&](int band_lines, int guard) {
    const long long L = static_cast<long long>(band_lines) + guard;
    check_grid(L, m);
    const MimoFds f(m, static_cast<int>(L), opt.solver);
    const Grid& g = f.grid();
    const Eigen::MatrixXcd Y = f.solve_full(to_full(g, U, nu));
    const double peak = std::max(max_abs(Y), 1e-300);
    double edge = 0;
    for (int l = std::max(0, g.L - K + 1); l <= g.L; ++l) {
      for (int side : {l, -l}) {
        const Eigen::Index i = g.index_of(side);
        edge = std::max(edge, Y.middleRows(i * ny, ny).cwiseAbs().maxCoeff());
      }
    }
    res.solver = f.solver();
    res.condition = f.condition();
    res.condition_line = std::abs(f.condition_line());
    const double cond = std::max(1.0, f.condition());
    return Run{to_onesided(g, Y, ny, lines_out), 10.0 * cond * edge / peak, edge / peak, cond};
  };
  if (m.kmax() == 0) {
    // LTI: AA is block diagonal, the lines do not couple, no truncation error.
    res.Y = run(std::max(band, 0), 0).Y;
    return res;
  }
  if (opt.guard >= 0) {
    Run r = run(std::max(Lu, lines_out), opt.guard);
    res.Y = std::move(r.Y);
    res.guard = opt.guard;
    res.truncation_error = r.bound;
    res.converged = r.bound <= opt.tol;
    return res;
  }
  const int max_guard = opt.max_guard >= 0 ? opt.max_guard : std::max(1024, 4 * band);
  const int excited = last_nonzero_line(U);
  int guard = std::min(std::max({16, 4 * K, band / 256}), max_guard);
  Run prev = run(band, guard);
  res.Y = prev.Y;
  res.guard = guard;
  res.truncation_error = prev.bound;
  if (prev.bound <= opt.tol) return res;
  if (guard >= max_guard) {
    res.converged = false;
    return res;
  }
  while (true) {
    // Geometric decay beyond the last excited line: the distance where the bound meets tol.
    int next = 2 * guard;
    const int D = band + guard - excited;
    if (prev.edge > 0 && prev.edge < 1 && D > 0) {
      const double need = D * std::log(opt.tol / (10.0 * prev.cond)) / std::log(prev.edge);
      if (std::isfinite(need)) next = std::max(next, static_cast<int>(std::min(1.25 * need, 1e9)) - (band - excited));
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
