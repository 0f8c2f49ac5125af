// Several inputs and outputs (METHOD.md section 19): the matrix model
// sum_n A_n(t) d^n y = sum_m B_m(t) d^m u with A_n(t) (ny x ny) and B_m(t) (ny x nu), each entry
// a finite Fourier series in w0, and its simulator, the block band FDS.
#pragma once
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "lptv/fds.hpp"

namespace lptv {

class MimoModel {
 public:
  // a: (na+1) ny ny rows, row (n ny + p) ny + q the Fourier coefficients of entry (p, q) of
  // A_n(t), 2Ka+1 columns (column Ka + k holds harmonic k); b: (nb+1) ny nu rows, row
  // (m ny + p) nu + r the entry (p, r) of B_m(t), 2Kb+1 columns. An entry with fewer harmonics
  // or a lower order holds zeros. ny = nu = 1 is the SISO layout of lptv::Model.
  // Throws std::invalid_argument on non-finite values, even column counts, row counts that are
  // not multiples of ny ny (ny nu), coefficients that are not conjugate-symmetric (to a relative
  // 1e-12), or a leading matrix A_na(t) that is identically zero.
  MimoModel(Eigen::MatrixXcd a, Eigen::MatrixXcd b, int n_outputs, int n_inputs, double w0,
            double ts = 0.0);
  // The SISO model as a 1 x 1 MIMO model.
  explicit MimoModel(const Model& m);

  int n_outputs() const { return ny_; }
  int n_inputs() const { return nu_; }
  int na() const { return static_cast<int>(a_.rows()) / (ny_ * ny_) - 1; }
  int nb() const { return static_cast<int>(b_.rows()) / (ny_ * nu_) - 1; }
  int ka() const { return static_cast<int>(a_.cols() - 1) / 2; }
  int kb() const { return static_cast<int>(b_.cols() - 1) / 2; }
  int kmax() const { return ka() > kb() ? ka() : kb(); }
  double w0() const { return w0_; }
  double ts() const { return ts_; }
  bool discrete() const { return ts_ > 0.0; }
  const Eigen::MatrixXcd& a() const { return a_; }
  const Eigen::MatrixXcd& b() const { return b_; }

  // Harmonic k of entry (p, q) of A_n, (p, r) of B_m (zero outside the stored range).
  cd a_coef(int n, int p, int q, int k) const;
  cd b_coef(int m, int p, int r, int k) const;

  // Discrete time: N = 2 pi / (w0 ts), with the checks of Model::samples_per_period.
  int samples_per_period() const;

  // The entries' values on a time grid: (len(t)) x (rows of a), (len(t)) x (rows of b), real.
  Eigen::MatrixXd a_at(const Eigen::VectorXd& t) const;
  Eigen::MatrixXd b_at(const Eigen::VectorXd& t) const;

 private:
  Eigen::MatrixXcd a_, b_;
  int ny_, nu_;
  double w0_, ts_;
};

// The grid of the block band system: continuous time lines -L..L, discrete time the circular
// grid of N lines. Scalar unknown ny * index + p is channel p of the grid's line index (channel
// fastest: METHOD.md eq. 19.4 is then a band matrix of ny (Ka + 1) - 1 sub- and super-diagonals).
Grid make_grid(const MimoModel& m, int L);

// AA (grid.N ny square) and BB (grid.N ny x grid.N nu) of METHOD.md eq. 19.4.
SpMat build_mimo_A(const MimoModel& m, const Grid& g);
SpMat build_mimo_B(const MimoModel& m, const Grid& g);

// One factorisation of AA on a fixed grid, reused for any number of right-hand sides.
class MimoFds {
 public:
  // Continuous time: grid -L..L; discrete time: L ignored. Solver::Auto is the band LU in
  // continuous time (the core's kernel up to 64 sub-diagonals, LAPACK above) and KLU in
  // discrete time. Throws NumericalError when AA is singular or its componentwise condition
  // (as Fds::condition) is above Fds::kMaxCondition.
  MimoFds(const MimoModel& m, int L, Solver solver = Solver::Auto);
  ~MimoFds();
  const Grid& grid() const { return grid_; }
  Solver solver() const { return solver_; }
  double condition() const { return condition_; }
  int condition_line() const { return condition_line_; }
  // Full-grid inputs (grid.N nu rows, channel fastest; any number of columns) -> outputs
  // (grid.N ny rows).
  Eigen::MatrixXcd solve_full(const Eigen::MatrixXcd& U) const;
  // AA^-1 R for full-grid right-hand sides (grid.N ny rows).
  Eigen::MatrixXcd solve_A(const Eigen::MatrixXcd& rhs) const;
  // Columns of the HTF matrix GG = AA^-1 BB for the given input lines: column j nu + r is
  // input channel r of input_lines[j] (grid.N ny rows).
  Eigen::MatrixXcd htf_columns(const std::vector<int>& input_lines) const;

 private:
  MimoModel model_;
  Grid grid_;
  Solver solver_;
  std::unique_ptr<SmallBandLU> small_;
  std::unique_ptr<BandLU> band_;
  std::unique_ptr<SparseLU> lu_;
  double condition_ = 0.0;
  int condition_line_ = 0;
};

struct MimoSimulateResult {
  // One-sided output spectra on lines 0..lines_out; column e ny + p is output p of
  // experiment e.
  Eigen::MatrixXcd Y;
  int guard = 0;
  double truncation_error = 0;
  bool converged = true;
  Solver solver = Solver::Auto;
  double condition = 0.0;
  int condition_line = 0;
};

// U: one-sided input spectra on lines 0..Lu (rows); column e nu + r is input r of experiment e
// (a multiple of nu columns). Lines 0 and, in discrete time with even N, N/2 must be real.
// The options are simulate's (SimulateOptions): the adaptive guard of METHOD.md section 19.
MimoSimulateResult simulate_mimo(const MimoModel& m, const Eigen::MatrixXcd& U,
                                 const SimulateOptions& opt = SimulateOptions());

}  // namespace lptv
