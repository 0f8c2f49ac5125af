// Private helpers of the row-wise kernels (jacobian.cpp, estimators.cpp, likelihood.cpp); the
// band entries and line powers of a row come from band_row.hpp.
#pragma once
#include <dlfcn.h>

#include <algorithm>
#include <thread>
#include <vector>

#include "band_row.hpp"
#include "lptv/jacobian.hpp"

namespace lptv {
namespace detail {

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

// Row l of the Jacobian, J[l, q] = +s_{l-k}^n Y_{l-k} (a-parameters), -s_{l-k}^n U_{l-k}
// (b-parameters), from the row's powers (pw.compute(l) done).
inline void jacobian_row(const Parametrisation& p, const Lines& X, const RowPowers& pw, int l, cd* out) {
  for (int q = 0; q < p.n_theta(); ++q) {
    const Param& pr = p.params()[q];
    const int i = l - pr.k;
    const cd f = pw(pr.k, pr.order);
    out[q] = pr.is_a ? f * X.Y(i) : -f * X.U(i);
  }
}

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
