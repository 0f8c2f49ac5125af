// The continuous-time FDS's band LU without lptv's conditioning check, for the benchmarks'
// comparison (not part of lptv): A built the way lptv::Fds builds it for its band solver,
// LAPACK's zgbtrf and zgbtrs, nothing else - the floor under what the FDS can cost with these
// routines.
#pragma once
#include <lapacke.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "lptv/band_lu.hpp"
#include "lptv/fds.hpp"

namespace bench {

// A in LAPACK band storage (kl = ku = Ka, kl rows of pivoting workspace), built from the model
// column by column the way lptv::Fds builds it for its band solver (that builder is internal to
// fds.cpp).
inline std::vector<lptv::cd> band_storage(const lptv::Model& m, const lptv::Grid& g) {
  const int K = m.ka(), na = m.na(), ld = lptv::BandLU::ldab(K, K);
  std::vector<lptv::cd> ab(static_cast<size_t>(ld) * g.N, lptv::cd(0.0, 0.0));
  std::vector<lptv::cd> pw(na + 1);
  for (int j = 0; j < g.N; ++j) {
    for (int n = 0; n <= na; ++n) pw[n] = lptv::line_power(m, g, g.line_of(j), n);
    for (int k = -K; k <= K; ++k) {
      if (j + k < 0 || j + k >= g.N) continue;
      lptv::cd v(0.0, 0.0);
      for (int n = 0; n <= na; ++n) v += m.a()(n, K + k) * pw[n];
      ab[(2 * K + k) + static_cast<size_t>(j) * ld] = v;
    }
  }
  return ab;
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
