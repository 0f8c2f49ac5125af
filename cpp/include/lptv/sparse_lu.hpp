// Sparse LU of a complex square matrix through SuiteSparse: KLU directly (it exposes
// the singular column and a pivot-based condition estimate) or UMFPACK through
// Eigen's UmfPackSupport module. One factorisation, many right-hand sides.
#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <complex>
#include <functional>
#include <memory>
#include <string>

namespace lptv {

// Auto: Band on the continuous-time grid (A is banded), KLU on the circular discrete-time
// grid (the band wraps around the corners). Band is continuous time only.
enum class Solver { Auto, KLU, UMFPACK, Band };

// "auto" / "band" / "klu" / "umfpack"; throws std::invalid_argument on anything else.
Solver solver_from_string(const std::string& name);
std::string solver_name(Solver s);
// The backend Auto resolves to on a grid (see bench/RESULTS.md for the measurements).
Solver default_solver(bool circular_grid);

class SparseLU {
 public:
  using SpMat = Eigen::SparseMatrix<std::complex<double>, Eigen::ColMajor, int>;
  // Factorises A. Throws NumericalError when A is exactly singular (naming the column as
  // index_label(col)); how well conditioned A is, the caller judges (Fds does).
  SparseLU(const SpMat& A, Solver solver, const std::function<std::string(int)>& index_label);
  ~SparseLU();
  SparseLU(const SparseLU&) = delete;
  SparseLU& operator=(const SparseLU&) = delete;

  Eigen::MatrixXcd solve(const Eigen::MatrixXcd& rhs) const;
  Solver solver() const { return solver_; }
  // KLU: its crude reciprocal condition estimate min|U_kk| / max|U_kk| of the row-scaled
  // matrix; UMFPACK: 0 (not computed).
  double rcond() const { return rcond_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Solver solver_;
  double rcond_ = 0.0;
};

}  // namespace lptv
