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

// a b by the textbook formula, without the NaN recovery of std::complex's operator* (a test
// of every product's result and, on NaN, a library call); the same bits where the product is
// finite (no contraction: -ffp-contract=off). What the per-row inner loops multiply with.
inline cd mul(cd a, cd b) {
  return cd(a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real());
}

// Row l of the Jacobian, J[l, q] = +s_{l-k}^n Y_{l-k} (a-parameters), -s_{l-k}^n U_{l-k}
// (b-parameters), from the row's powers (pw.compute(l) done).
inline void jacobian_row(const Parametrisation& p, const Lines& X, const RowPowers& pw, int l, cd* out) {
  for (int q = 0; q < p.n_theta(); ++q) {
    const Param& pr = p.params()[q];
    const int i = l - pr.k;
    const cd f = pw(pr.k, pr.order);
    out[q] = pr.is_a ? mul(f, X.Y(i)) : mul(-f, X.U(i));
  }
}

// Nonzeros of Text (theta = Text xi): theta_p contributes v to xi column c. One or two per row.
struct TextEntry {
  int p, c;
  cd v;
};

inline std::vector<TextEntry> text_entries(const Parametrisation& p) {
  std::vector<TextEntry> out;
  const Eigen::MatrixXcd& T = p.Text();
  for (int c = 0; c < T.cols(); ++c)
    for (int q = 0; q < T.rows(); ++q)
      if (T(q, c) != cd(0.0, 0.0)) out.push_back({q, c, T(q, c)});
  return out;
}

// Re(Text^H M Text) (conj_right false) or Re(Text^H M conj(Text)) (true), n_xi x n_xi, from
// Text's nonzeros (text_entries, grouped by column): O(n_xi^2) products where the dense
// triple product takes O(n_theta^3). M is given by its entries m(p, q) over theta's indices.
template <class M>
inline Eigen::MatrixXd real_congruence(const Parametrisation& p, const std::vector<TextEntry>& text, M&& m,
                                       bool conj_right) {
  const int nx = p.n_xi();
  std::vector<int> start(static_cast<size_t>(nx) + 1, 0);
  for (const TextEntry& e : text) ++start[static_cast<size_t>(e.c) + 1];
  for (int c = 0; c < nx; ++c) start[static_cast<size_t>(c) + 1] += start[static_cast<size_t>(c)];
  Eigen::MatrixXd out(nx, nx);
  for (int b = 0; b < nx; ++b)
    for (int a = 0; a < nx; ++a) {
      double v = 0.0;
      for (int i = start[static_cast<size_t>(a)]; i < start[static_cast<size_t>(a) + 1]; ++i) {
        const TextEntry& ea = text[static_cast<size_t>(i)];
        for (int j = start[static_cast<size_t>(b)]; j < start[static_cast<size_t>(b) + 1]; ++j) {
          const TextEntry& eb = text[static_cast<size_t>(j)];
          v += mul(mul(std::conj(ea.v), m(ea.p, eb.p)), conj_right ? std::conj(eb.v) : eb.v).real();
        }
      }
      out(a, b) = v;
    }
  return out;
}

// Row l of J Text (n_xi complex entries) into xrow, through Text's nonzeros; jrow is scratch
// of n_theta entries (pw.compute(l) done).
inline void jacobian_text_row(const Parametrisation& p, const Lines& X, const RowPowers& pw, int l,
                              const std::vector<TextEntry>& text, std::vector<cd>& jrow, cd* xrow) {
  jrow.resize(static_cast<size_t>(p.n_theta()));
  jacobian_row(p, X, pw, l, jrow.data());
  std::fill(xrow, xrow + p.n_xi(), cd(0.0, 0.0));
  for (const TextEntry& e : text) xrow[e.c] += mul(jrow[static_cast<size_t>(e.p)], e.v);
}

// The entries of C_l = E{dJ_l^H dJ_l} that can be nonzero: for each harmonic k (group[K + k],
// the parameters of harmonic k), f(a, b, value) for every pair (a, b) of the group, in that
// order (pw.compute(l) done). dJ[l, q] = f_q dX_{l-k} with f = +s^n (a) or -s^n (b), and
// E{conj(dX_a) dX_b} is var Y, var U or the cross-covariance of line l - k.
template <class F>
inline void noise_block_entries(const Parametrisation& p, const Lines& X, const RowPowers& pw, int l,
                                const std::vector<std::vector<int>>& group, std::vector<cd>& f, F&& out) {
  const int K = static_cast<int>(group.size() / 2);
  for (int k = -K; k <= K; ++k) {
    const auto& g = group[static_cast<size_t>(K + k)];
    const int i = l - k;
    const double vy = X.varY(i), vu = X.varU(i);
    const cd cyu = X.covYU(i);
    f.resize(g.size());
    for (size_t a = 0; a < g.size(); ++a) {
      const Param& pr = p.params()[static_cast<size_t>(g[a])];
      f[a] = (pr.is_a ? 1.0 : -1.0) * pw(k, pr.order);
    }
    for (size_t a = 0; a < g.size(); ++a) {
      const bool ya = p.params()[static_cast<size_t>(g[a])].is_a;
      const cd fa = std::conj(f[a]);
      for (size_t b = 0; b < g.size(); ++b) {
        const bool yb = p.params()[static_cast<size_t>(g[b])].is_a;
        const cd e = ya ? (yb ? cd(vy, 0.0) : std::conj(cyu)) : (yb ? cyu : cd(vu, 0.0));
        out(g[a], g[b], mul(mul(fa, f[b]), e));
      }
    }
  }
}

// The parameters grouped by harmonic k (index K + k): only those share a noisy line in a row.
inline std::vector<std::vector<int>> params_by_harmonic(const Parametrisation& p) {
  const int K = p.structure().kmax();
  std::vector<std::vector<int>> by_k(static_cast<size_t>(2 * K + 1));
  for (int q = 0; q < p.n_theta(); ++q) by_k[static_cast<size_t>(K + p.params()[static_cast<size_t>(q)].k)].push_back(q);
  return by_k;
}

// Whether the exact likelihood takes its diagonal route for K = 0 (an LTI structure: S is
// block diagonal, one 2 x 2 block per row; likelihood.cpp). The same bits as the band route;
// the tests turn it off to compare the two. Returns the previous setting.
inline bool& diagonal_likelihood_setting() {
  static bool on = true;
  return on;
}
inline bool set_diagonal_likelihood(bool on) {
  const bool before = diagonal_likelihood_setting();
  diagonal_likelihood_setting() = on;
  return before;
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
    const OpenBlas& ob = openblas();
    if (!ob.set || !ob.get) return;
    set_ = ob.set;
    saved_ = ob.get();
    if (saved_ != 1) set_(1);
  }
  ~SingleThreadedBlas() {
    if (set_ && saved_ != 1) set_(saved_);
  }
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

 private:
  struct OpenBlas {
    void (*set)(int) = nullptr;
    int (*get)() = nullptr;
  };
  // OpenBLAS's thread controls, found once. In a program linked against it they are global
  // symbols; in a Python extension module the library is loaded with RTLD_LOCAL and
  // dlsym(RTLD_DEFAULT) does not see them, so the already loaded library is also looked up by
  // name (RTLD_NOLOAD: never loads anything new).
  static const OpenBlas& openblas() {
    static const OpenBlas ob = [] {
      OpenBlas o;
      auto find = [&](void* h) {
        o.set = reinterpret_cast<void (*)(int)>(dlsym(h, "openblas_set_num_threads"));
        o.get = reinterpret_cast<int (*)()>(dlsym(h, "openblas_get_num_threads"));
        return o.set && o.get;
      };
      if (find(RTLD_DEFAULT)) return o;
      for (const char* name : {"libopenblas.so.0", "libopenblas.so", "libblas.so.3"}) {
        if (void* h = dlopen(name, RTLD_LAZY | RTLD_NOLOAD)) {
          if (find(h)) return o;  // the handle stays open: the library is in use anyway
          dlclose(h);
        }
      }
      o = OpenBlas();
      return o;
    }();
    return ob;
  }
  void (*set_)(int) = nullptr;
  int saved_ = 1;
};

}  // namespace detail
}  // namespace lptv
