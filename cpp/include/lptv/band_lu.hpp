// Band LU of the continuous-time FDS matrix: A has 2K+1 diagonals by construction (METHOD.md
// eq. 5), so a band factorisation needs no ordering analysis and O(N K^2) work. SmallBandLU is
// the FDS's own kernel (partial pivoting, the pivots of LAPACK's zgbtrf); BandLU calls LAPACK
// (zgbtrf/zgbtrs), the fallback for wide bands and the kernel's test oracle.
#pragma once
#include <Eigen/Dense>
#include <complex>
#include <cstdint>
#include <functional>
#include <memory>
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

namespace detail {
struct BandFactors;
}

// LU with partial pivoting of a complex band matrix with K sub- and K super-diagonals, for
// small K: the loops are unrolled for 2K+1 = 1..15 diagonals (one runtime-K instance above),
// with no call to the BLAS. The factors take (3K+1) complex numbers and a byte per row. The
// FDS builds A row by row straight into the factorisation (lptv::Fds, lptv::solve_grid); this
// constructor takes a matrix already in LAPACK band storage.
class SmallBandLU {
 public:
  using cd = std::complex<double>;
  // Widest band the kernel takes; wider ones go to LAPACK (BandLU).
  static constexpr int kMaxK = 64;
  // ab as BandLU takes it (kl = ku = K, ldab = 3K + 1; the first K rows are not read). Throws
  // NumericalError naming index_label(column) at the first exactly zero pivot.
  SmallBandLU(int n, int K, const std::vector<cd>& ab,
              const std::function<std::string(int)>& index_label);
  explicit SmallBandLU(std::unique_ptr<detail::BandFactors> f);
  ~SmallBandLU();
  SmallBandLU(SmallBandLU&&) noexcept;
  SmallBandLU& operator=(SmallBandLU&&) noexcept;

  int n() const;
  int K() const;
  // inv(A) rhs for any number of columns: the columns go through the factors together, in
  // blocks (one pass over the factors per block), on two threads when there are enough.
  Eigen::MatrixXcd solve(const Eigen::MatrixXcd& rhs) const;
  // Row k of the permuted factorisation: piv(k) = p when step k swapped rows k and k + p.
  int pivot(int k) const;

 private:
  std::unique_ptr<detail::BandFactors> f_;
};

}  // namespace lptv
