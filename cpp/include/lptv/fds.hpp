// The frequency-domain simulator (METHOD.md section 3): the steady-state output
// spectrum Y = A^-1 B U of an LPTV model from one sparse factorisation of the band
// matrix A.
#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "lptv/band_lu.hpp"
#include "lptv/model.hpp"
#include "lptv/sparse_lu.hpp"

namespace lptv {

using SpMat = Eigen::SparseMatrix<cd, Eigen::ColMajor, int>;

// The frequency grid of a model's band system.
//  - continuous time: lines -L..L, matrix index i <-> line i - L;
//  - discrete time: the circular grid of N = samples_per_period() lines, index i <-> line i
//    (line i and i - N are the same).
struct Grid {
  bool circular = false;
  int L = 0;  // continuous time: highest line; discrete time: unused
  int N = 0;  // number of lines in the system (2L+1, or samples per period)
  int line_of(int index) const { return circular ? index : index - L; }
  // The index of line l (wrapped on the circular grid); -1 when outside -L..L.
  int index_of(int line) const;
};

Grid make_grid(const Model& m, int L);

// (j w_l)^n in continuous time, z_l^n = exp(j w_l ts n) in discrete time, for line l.
cd line_power(const Model& m, const Grid& g, int line, int n);

// A_{l,i} = sum_n a_{n,l-i} (j w_i)^n (METHOD.md eq. 5), B likewise with b.
SpMat build_A(const Model& m, const Grid& g);
SpMat build_B(const Model& m, const Grid& g);

// (B U) on the grid without forming B: only the nonzero rows of U cost anything.
Eigen::MatrixXcd apply_B(const Model& m, const Grid& g, const Eigen::MatrixXcd& U);

// One factorisation of A on a fixed grid, reused for any number of inputs.
class Fds {
 public:
  // Continuous time: grid -L..L (L >= 0). Discrete time: L is ignored (the grid is
  // the model's circular one). Throws NumericalError when A is singular, and
  // std::invalid_argument for the band solver on the circular grid.
  Fds(const Model& m, int L, Solver solver = Solver::Auto);
  const Grid& grid() const { return grid_; }
  Solver solver() const { return solver_; }
  // Lower estimate of the componentwise condition number of A with respect to relative
  // changes of the model's coefficients: max_i |(A^-1 b)_i| with |b_i| the sum over row i
  // of |a_{n,k}| |s_j|^n. A value c costs about log10(c) of the 16 digits.
  double condition() const { return condition_; }
  // The line where that maximum is reached.
  int condition_line() const { return condition_line_; }
  // Above this the FDS refuses to solve (NumericalError): fewer than 3 digits would be left.
  static constexpr double kMaxCondition = 1e13;
  // Above this simulate's result carries a warning (SimulateResult::condition; Python warns
  // with lptv.ConditioningWarning): more than half of the 16 digits lost (1 / sqrt(eps) =
  // 6.7e7, rounded up), i.e. a pole within a relative distance of about 1e-8 of the line, so
  // the output there is amplified about that much and is as sensitive to the coefficients
  // (damping 1e-12 on an oscillator's line: condition 2e12, an output of 1e12 times the input
  // that a coefficient change of 1e-12 moves by its own size).
  static constexpr double kWarnCondition = 1e8;
  // Full-grid input spectra (grid.N rows, any number of columns) -> output spectra.
  Eigen::MatrixXcd solve_full(const Eigen::MatrixXcd& U) const;
  // Columns of the harmonic transfer function G = A^-1 B for the given input lines.
  Eigen::MatrixXcd htf_columns(const std::vector<int>& input_lines) const;
  // A^-1 R for any full-grid right-hand sides R (grid.N rows, any number of columns): the one
  // factorisation reused beyond B U (lptv::fit_record's prediction and its Jacobian columns).
  Eigen::MatrixXcd solve_A(const Eigen::MatrixXcd& rhs) const;

 private:
  Model model_;
  Grid grid_;
  Solver solver_;
  std::unique_ptr<SmallBandLU> small_;  // the band solver up to SmallBandLU::kMaxK
  std::unique_ptr<BandLU> band_;        // the band solver above (LAPACK)
  std::unique_ptr<SparseLU> lu_;
  double condition_ = 0.0;
  int condition_line_ = 0;
  Eigen::MatrixXcd solve_factored(const Eigen::MatrixXcd& rhs) const;
};

// One grid, one factorisation, the given inputs only (the factors are not kept): what
// simulate does per grid. Y = A^-1 B U_full for full-grid inputs U_full (grid.N rows, any
// number of columns), with Fds's conditioning check and its NumericalError. With the band
// solver the factorisation, B U, the check and both substitutions are one pass over the grid
// (for a real input, U_full exactly conjugate-symmetric about line 0 as simulate builds it,
// over lines 0..L only: half the work, METHOD.md section 3); the other solvers run Fds and
// Fds::solve_full.
struct GridSolution {
  Grid grid;
  Eigen::MatrixXcd Y;
  double condition = 0.0;  // as Fds::condition()
  int condition_line = 0;  // as Fds::condition_line()
  Solver solver = Solver::Auto;
};
GridSolution solve_grid(const Model& m, int L, const Eigen::MatrixXcd& U_full,
                        Solver solver = Solver::Auto);

struct SimulateOptions {
  Solver solver = Solver::Auto;
  // Continuous time: highest output line wanted (-1: the highest input line).
  int lines_out = -1;
  // Continuous time: fixed guard lines beyond max(highest input line, lines_out)
  // (-1: adaptive, see tol).
  int guard = -1;
  // Adaptive guard: the grid starts at the highest nonzero input line (or lines_out when
  // given) plus a guard, which grows until the wanted lines change by less than tol
  // relative to the largest output line; lines beyond the grid are returned as zero.
  double tol = 1e-13;
  int max_guard = -1;  // -1: max(1024, 4 * band)
};

struct SimulateResult {
  Eigen::MatrixXcd Y;            // one-sided output spectra, lines 0..lines_out
  int guard = 0;                 // guard lines used (continuous time)
  double truncation_error = 0;   // estimated relative error from the truncation
  bool converged = true;         // adaptive guard reached tol
  Solver solver = Solver::Auto;  // backend actually used
  // Fds::condition of the last grid and the line (>= 0) where it peaks. An LTI model's lines do
  // not couple, so there it is the largest sum_n |a_n| |s_l|^n / |a(s_l)| over the lines with
  // input only (a pole next to a line without input leaves the output untouched). Above
  // Fds::kWarnCondition the result has lost more than half of its digits.
  double condition = 0.0;
  int condition_line = 0;
};

// The decay per line the model predicts for its output beyond the excited lines, far from
// line 0: the largest |lambda| < 1 and 1/|lambda| > 1 over the roots of
// sum_k a_{na,k} lambda^-k = 0 (the harmonics of a_na(t)). 0 when a_na is constant (the top
// order does not couple lines), 1 when a root is on the unit circle (no decay). simulate sizes
// its first adaptive grid from it.
double decay_per_line(const Model& m);

// U: one-sided spectra on lines 0..Lu (rows), one column per input; U(0) and, in
// discrete time with even N, U(N/2) must be real. X_l = fft(x)[l] / N.
SimulateResult simulate(const Model& m, const Eigen::MatrixXcd& U,
                        const SimulateOptions& opt = SimulateOptions());

}  // namespace lptv
