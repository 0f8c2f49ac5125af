// Private helpers of the row-wise kernels (jacobian.cpp, estimators.cpp).
#pragma once
#include <dlfcn.h>

#include <algorithm>
#include <thread>
#include <vector>

#include "lptv/jacobian.hpp"

namespace lptv {
namespace detail {

// s_i^n for the 2K+1 lines i = l - k (k = -K..K) a row l uses, n = 0..order;
// s = j i w0 (continuous time) or exp(j i w0 ts) (discrete time).
class RowPowers {
 public:
  RowPowers(const Structure& s) : s_(s), K_(s.kmax()), order_(std::max(s.na, s.nb)) {
    pw_.resize((2 * K_ + 1) * (order_ + 1));
  }
  void compute(int l) {
    for (int k = -K_; k <= K_; ++k) {
      const int i = l - k;
      const double w = s_.w0 * i;
      const cd z = s_.ts > 0 ? std::polar(1.0, w * s_.ts) : cd(0.0, w);
      cd* p = &pw_[(K_ + k) * (order_ + 1)];
      p[0] = 1.0;
      for (int n = 1; n <= order_; ++n) p[n] = p[n - 1] * z;
    }
  }
  cd operator()(int k, int n) const { return pw_[(K_ + k) * (order_ + 1) + n]; }
  int K() const { return K_; }

 private:
  const Structure& s_;
  int K_, order_;
  std::vector<cd> pw_;
};

// A_{l,i} and B_{l,i} for i = l - k, k = -K..K (index K + k), from the row's powers.
inline void band_row(const Parametrisation& p, const Eigen::VectorXcd& theta, const detail::RowPowers& pw,
              std::vector<cd>& A, std::vector<cd>& B) {
  const int K = pw.K();
  A.assign(2 * K + 1, cd(0.0, 0.0));
  B.assign(2 * K + 1, cd(0.0, 0.0));
  for (int q = 0; q < p.n_theta(); ++q) {
    const Param& pr = p.params()[q];
    (pr.is_a ? A : B)[K + pr.k] += theta[q] * pw(pr.k, pr.order);
  }
}

// Line values with X_{-l} = conj(X_l); the statistics of a conjugate line follow.
struct Lines {
  const FrequencyData& d;
  cd Y(int l) const { return l >= 0 ? d.Y[l] : std::conj(d.Y[-l]); }
  cd U(int l) const { return l >= 0 ? d.U[l] : std::conj(d.U[-l]); }
  double varY(int l) const { return d.varY[l >= 0 ? l : -l]; }
  double varU(int l) const { return d.varU[l >= 0 ? l : -l]; }
  // E{dY_l conj(dU_l)}; on a conjugate line it is the conjugate.
  cd covYU(int l) const { return l >= 0 ? d.covYU[l] : std::conj(d.covYU[-l]); }
};

// Runs f(begin, end, part) over [0, n) in up to two parts on two threads when n is large
// enough to pay for a thread (the machines this targets have few cores; the kernels are
// memory-light and scale).
template <class F>
int parallel_rows(size_t n, F&& f, size_t min_rows = 20000) {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  if (hw < 2 || n < min_rows) {
    f(size_t(0), n, 0);
    return 1;
  }
  const size_t mid = n / 2;
  std::thread t([&] { f(size_t(0), mid, 0); });
  f(mid, n, 1);
  t.join();
  return 2;
}

// While alive, asks OpenBLAS (when it is the BLAS this process uses) for one thread, and
// restores its setting afterwards. Other BLAS libraries are left alone.
class SingleThreadedBlas {
 public:
  explicit SingleThreadedBlas(bool active) {
    if (!active) return;
    set_ = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    auto get = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
    if (!set_ || !get) {
      set_ = nullptr;
      return;
    }
    saved_ = get();
    set_(1);
  }
  ~SingleThreadedBlas() {
    if (set_) set_(saved_);
  }
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

 private:
  void (*set_)(int) = nullptr;
  int saved_ = 1;
};

}  // namespace detail
}  // namespace lptv
