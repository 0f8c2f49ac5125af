#include "lptv/band_lu.hpp"

#include <cmath>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "band_kernel.hpp"
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

namespace {

// Rows of a matrix in LAPACK band storage (kl = ku = K, ldab = 3K + 1).
struct StorageSource {
  const std::vector<std::complex<double>>& ab;
  int n, K, ld;
  void row(int r, int base, std::complex<double>* out) const {
    for (int j = 0; j <= 2 * K; ++j) {
      const int c = base + j;
      out[j] = (c < n && c - r <= K && r - c <= K) ? ab[(2 * K + r - c) + static_cast<size_t>(c) * ld]
                                                   : std::complex<double>(0.0, 0.0);
    }
  }
  void rhs(int, std::complex<double>*) const {}
};

std::string zero_pivot_message(const std::string& where) {
  return "A is singular at " + where +
         " (a zero pivot: the system has a pole on that line, or a_na(t) vanishes)";
}

}  // namespace

SmallBandLU::SmallBandLU(int n, int K, const std::vector<cd>& ab,
                         const std::function<std::string(int)>& label)
    : f_(std::make_unique<detail::BandFactors>()) {
  const int ld = BandLU::ldab(K, K);
  if (n < 1 || K < 0 || K > kMaxK || ab.size() != static_cast<size_t>(ld) * n) {
    throw std::invalid_argument("SmallBandLU: band storage has the wrong size");
  }
  StorageSource src{ab, n, K, ld};
  std::vector<cd> z(static_cast<size_t>(2 * K));
  try {
    detail::dispatch_band(K, [&](auto kt) {
      detail::factor_band_best<decltype(kt)::value>(src, n, K, 0, *f_, true, z.data());
    });
  } catch (const detail::ZeroPivot& e) {
    throw NumericalError(zero_pivot_message(label(e.column)));
  }
}

SmallBandLU::SmallBandLU(std::unique_ptr<detail::BandFactors> f) : f_(std::move(f)) {}
SmallBandLU::~SmallBandLU() = default;
SmallBandLU::SmallBandLU(SmallBandLU&&) noexcept = default;
SmallBandLU& SmallBandLU::operator=(SmallBandLU&&) noexcept = default;
int SmallBandLU::n() const { return f_->n; }
int SmallBandLU::K() const { return f_->K; }
int SmallBandLU::pivot(int k) const {
  f_->piv.at(k);  // the range check
  return f_->pivot(k);
}

Eigen::MatrixXcd SmallBandLU::solve(const Eigen::MatrixXcd& rhs) const {
  const int n = f_->n, K = f_->K;
  if (rhs.rows() != n) throw std::invalid_argument("solve: right-hand side has wrong size");
  if (f_->L.size() == 0) throw std::logic_error("SmallBandLU: factors kept for their own right-hand sides only");
  const Eigen::Index ncol = rhs.cols();
  Eigen::MatrixXcd x(n, ncol);
  if (ncol == 0) return x;
  // Columns in blocks: each block is one pass over the factors with its rows side by side
  // (row-major), so that a step touches K + 1 (forward) or 2K + 1 (back) short rows.
  constexpr Eigen::Index kBlock = 16;
  const Eigen::Index nblocks = (ncol + kBlock - 1) / kBlock;
  auto run = [&](Eigen::Index b0, Eigen::Index b1) {
    std::vector<cd> z;
    for (Eigen::Index b = b0; b < b1; ++b) {
      const Eigen::Index c0 = b * kBlock, nz = std::min(kBlock, ncol - c0);
      z.assign(static_cast<size_t>(n + 2 * K) * nz, cd(0.0, 0.0));
      for (Eigen::Index c = 0; c < nz; ++c)
        for (int i = 0; i < n; ++i) z[static_cast<size_t>(i) * nz + c] = rhs(i, c0 + c);
      detail::dispatch_band(K, [&](auto kt) {
        detail::forward_substitute<decltype(kt)::value>(*f_, static_cast<int>(nz), z.data());
        detail::back_substitute_best<decltype(kt)::value>(*f_, static_cast<int>(nz), z.data());
      });
      for (Eigen::Index c = 0; c < nz; ++c)
        for (int i = 0; i < n; ++i) x(i, c0 + c) = z[static_cast<size_t>(i) * nz + c];
    }
  };
  // Two threads when there are at least two blocks and enough work to pay for a thread
  // (bench/HISTORY.md, the many-inputs section).
  if (nblocks >= 2 && static_cast<double>(n) * static_cast<double>(ncol) >= 2e5 &&
      std::thread::hardware_concurrency() >= 2) {
    const Eigen::Index mid = nblocks / 2;
    std::exception_ptr failure;  // an allocation failure on the second thread, rethrown here
    std::thread t([&] {
      try {
        run(0, mid);
      } catch (...) {
        failure = std::current_exception();
      }
    });
    run(mid, nblocks);
    t.join();
    if (failure) std::rethrow_exception(failure);
  } else {
    run(0, nblocks);
  }
  if (!x.allFinite()) throw NumericalError("band solve produced NaN or inf");
  return x;
}

}  // namespace lptv
