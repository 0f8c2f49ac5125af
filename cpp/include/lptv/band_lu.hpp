// Band LU of the continuous-time FDS matrix through LAPACK (zgbtrf/zgbtrs/zgbcon): A has
// 2K+1 diagonals by construction (METHOD.md eq. 5), so a band factorisation needs no
// ordering analysis and O(N K^2) work.
#pragma once
#include <Eigen/Dense>
#include <complex>
#include <functional>
#include <string>
#include <vector>

namespace lptv {

class BandLU {
 public:
  using cd = std::complex<double>;
  // A (n x n) in LAPACK band storage with kl sub- and ku super-diagonals:
  // ab[(kl + ku + i - j) + j * ldab] = A(i, j), ldab = 2 kl + ku + 1 (the first kl rows are
  // workspace for the pivoting). Throws NumericalError when A is exactly singular (naming
  // index_label(column)); how well conditioned A is, the caller judges (Fds does).
  BandLU(int n, int kl, int ku, std::vector<cd> ab, const std::function<std::string(int)>& index_label);
  static int ldab(int kl, int ku) { return 2 * kl + ku + 1; }

  Eigen::MatrixXcd solve(const Eigen::MatrixXcd& rhs) const;

 private:
  int n_, kl_, ku_;
  std::vector<cd> ab_;
  std::vector<int> ipiv_;
};

}  // namespace lptv
