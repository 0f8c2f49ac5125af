// The continuous-time FDS's band LU without lptv's conditioning check, for the benchmarks'
// comparison (not part of lptv): A from the builder lptv::Fds uses for its band solver,
// LAPACK's zgbtrf and zgbtrs, nothing else - the floor under what the FDS can cost with these
// routines.
#pragma once
#include <lapacke.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "band_row.hpp"  // lptv's private band builders (cpp/src)
#include "lptv/band_lu.hpp"
#include "lptv/fds.hpp"

namespace bench {

// A in LAPACK band storage (kl = ku = Ka, kl rows of pivoting workspace): the array lptv::Fds
// hands its band solver, from the same (private) builder.
inline std::vector<lptv::cd> band_storage(const lptv::Model& m, const lptv::Grid& g) {
  return lptv::detail::band_storage_A(m, g);
}

class BareBandLU {
 public:
  BareBandLU(int n, int K, std::vector<lptv::cd> ab)
      : n_(n), K_(K), ld_(lptv::BandLU::ldab(K, K)), ab_(std::move(ab)), ipiv_(n) {
    const lapack_int info = LAPACKE_zgbtrf(LAPACK_COL_MAJOR, n, n, K, K, z(ab_.data()), ld_,
                                           ipiv_.data());
    if (info != 0) throw std::runtime_error("zgbtrf failed, info " + std::to_string(info));
  }
  // b (n x nrhs, column-major) := inv(A) b.
  void solve(lptv::cd* b, int nrhs) const {
    const lapack_int info = LAPACKE_zgbtrs(LAPACK_COL_MAJOR, 'N', n_, K_, K_, nrhs,
                                           z(ab_.data()), ld_, ipiv_.data(), z(b), n_);
    if (info != 0) throw std::runtime_error("zgbtrs failed");
  }

 private:
  static lapack_complex_double* z(lptv::cd* p) { return reinterpret_cast<lapack_complex_double*>(p); }
  static const lapack_complex_double* z(const lptv::cd* p) {
    return reinterpret_cast<const lapack_complex_double*>(p);
  }
  lapack_int n_, K_, ld_;
  std::vector<lptv::cd> ab_;
  std::vector<lapack_int> ipiv_;
};

}  // namespace bench
