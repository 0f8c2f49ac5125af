#include "lptv/band_lu.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "lptv/errors.hpp"

extern "C" {
// LAPACK; the trailing size_t arguments are the hidden lengths of character arguments.
void zgbtrf_(const int* m, const int* n, const int* kl, const int* ku, std::complex<double>* ab,
             const int* ldab, int* ipiv, int* info);
void zgbtrs_(const char* trans, const int* n, const int* kl, const int* ku, const int* nrhs,
             const std::complex<double>* ab, const int* ldab, const int* ipiv, std::complex<double>* b,
             const int* ldb, int* info, std::size_t);
}

namespace lptv {

BandLU::BandLU(int n, int kl, int ku, std::vector<cd> ab, const std::function<std::string(int)>& label)
    : n_(n), kl_(kl), ku_(ku), ab_(std::move(ab)), ipiv_(n) {
  const int ld = ldab(kl, ku);
  if (n < 1 || ab_.size() != static_cast<size_t>(ld) * n) {
    throw std::invalid_argument("BandLU: band storage has the wrong size");
  }
  int info = 0;
  zgbtrf_(&n_, &n_, &kl_, &ku_, ab_.data(), &ld, ipiv_.data(), &info);
  if (info < 0) throw NumericalError("band LU (zgbtrf): invalid argument " + std::to_string(-info));
  if (info > 0) {
    // Partial pivoting permutes rows only: U(info, info) = 0 belongs to column info - 1.
    std::ostringstream msg;
    msg << "A is singular at " << label(info - 1)
        << " (a zero pivot: the system has a pole on that line, or a_na(t) vanishes)";
    throw NumericalError(msg.str());
  }
}

Eigen::MatrixXcd BandLU::solve(const Eigen::MatrixXcd& rhs) const {
  if (rhs.rows() != n_) throw std::invalid_argument("solve: right-hand side has wrong size");
  Eigen::MatrixXcd x = rhs;
  if (x.cols() == 0) return x;
  const int ld = ldab(kl_, ku_), nrhs = static_cast<int>(x.cols());
  int info = 0;
  zgbtrs_("N", &n_, &kl_, &ku_, &nrhs, ab_.data(), &ld, ipiv_.data(), x.data(), &n_, &info, 1);
  if (info != 0) throw NumericalError("band solve (zgbtrs) failed");
  if (!x.allFinite()) throw NumericalError("band solve produced NaN or inf");
  return x;
}

}  // namespace lptv
