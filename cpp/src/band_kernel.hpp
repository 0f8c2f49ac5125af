// The small-band LU kernel behind lptv::SmallBandLU (band_lu.hpp): Gaussian elimination with
// partial pivoting of a complex band matrix with K sub- and K super-diagonals, written for
// small K (2K+1 = 3..15 unrolled by a template parameter, one runtime-K instance above).
//
// A streams through a window of K+1 rows. Step k holds rows k..k+K of the row-permuted matrix,
// each as its 2K+1 entries in columns k..k+2K (pivoting fills U up to column k+2K, and only the
// row that enters at step k reaches that far). A row enters the window when it is first
// needed, built by a row source straight into the window: the matrix is never stored, only its
// factors. The right-hand sides of a row (for the FDS: B U and the conditioning check) enter
// with it and are eliminated in the same step, so that the forward substitution is part of the
// factorisation. The pivot search, the row swap and the choice of the first largest
// |Re| + |Im| are those of LAPACK's zgbtf2, so the pivots equal zgbtrf's on the same matrix.
//
// Private to the library (namespace detail); the tests reach it through SmallBandLU.
#pragma once
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <memory>
#include <type_traits>
#include <vector>

#include "lptv/band_lu.hpp"

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace lptv {
namespace detail {

using kcd = std::complex<double>;

// a - l u, and l u, written out: GCC's std::complex product guards against NaN with a library
// call on every product, which keeps the loops below from being unrolled into plain FMAs.
inline kcd cmul(kcd a, kcd b) {
  return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}
inline kcd cmsub(kcd a, kcd l, kcd u) {
  return {a.real() - (l.real() * u.real() - l.imag() * u.imag()),
          a.imag() - (l.real() * u.imag() + l.imag() * u.real())};
}
// 1 / p: conj(p) / |p|^2, one division on the elimination's critical path (each step's
// multipliers wait for it); Smith's method (two divisions) where |p|^2 could overflow or lose
// bits to underflow.
inline kcd crecip(kcd p) {
  const double a = p.real(), b = p.imag();
  const double m = std::max(std::abs(a), std::abs(b));
  if (m > 1e-150 && m < 1e150) {
    const double id = 1.0 / (a * a + b * b);
    return {a * id, -b * id};
  }
  if (std::abs(a) >= std::abs(b)) {
    const double r = b / a, id = 1.0 / (a + b * r);
    return {id, -r * id};
  }
  const double r = a / b, id = 1.0 / (b + a * r);
  return {r * id, -id};
}
inline double cabs1(kcd z) { return std::abs(z.real()) + std::abs(z.imag()); }

// Two complex numbers side by side for the kernels' AVX2 instances (below): GCC's generic
// vectors of four doubles, one AVX register in a function compiled for AVX2. The products are
// those of cmsub and cmul, each rounded once and combined in the same order (x + (-y) is
// x - y; no fused multiply-add: lptv is built with -ffp-contract=off), so the AVX2 instances
// give the same bits as the scalar code (tested). Compiled for SSE2 alone these vectors are
// slower than the scalar code, so only the AVX2 instances use them.
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define LPTV_AVX2_DISPATCH 1
#else
#define LPTV_AVX2_DISPATCH 0
#endif
// The vectors live inside the kernels' AVX2 instances (flatten: all inlined), never across a
// call between differently compiled functions: GCC's note on their ABI does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4i __attribute__((vector_size(32)));
#define LPTV_VINLINE inline __attribute__((always_inline))
LPTV_VINLINE v4d load2(const kcd* p) {
  v4d v;
  std::memcpy(&v, static_cast<const void*>(p), sizeof v);
  return v;
}
LPTV_VINLINE void store2(kcd* p, v4d v) { std::memcpy(static_cast<void*>(p), &v, sizeof v); }
LPTV_VINLINE v4d swap_parts(v4d v) {
#ifdef __clang__
  return __builtin_shufflevector(v, v, 1, 0, 3, 2);
#else
  return __builtin_shuffle(v, v4i{1, 0, 3, 2});
#endif
}
// x - c y for the complex c and two complex y: c y = (cr y_re - ci y_im, cr y_im + ci y_re).
LPTV_VINLINE v4d cmsub2(v4d x, kcd c, v4d y) {
  const v4d cr = {c.real(), c.real(), c.real(), c.real()};
  const v4d ci = {-c.imag(), c.imag(), -c.imag(), c.imag()};
  return x - (cr * y + ci * swap_parts(y));
}
// c y for two complex y, as cmul(y, c).
LPTV_VINLINE v4d cmul2(v4d y, kcd c) {
  const v4d cr = {c.real(), c.real(), c.real(), c.real()};
  const v4d ci = {-c.imag(), c.imag(), -c.imag(), c.imag()};
  return cr * y + ci * swap_parts(y);
}

// Whether the kernels run their AVX2 instances: the processor has AVX2, and neither the
// environment (LPTV_NO_AVX2 set) nor a test (set_avx2_kernels) said otherwise. The same bits
// either way.
inline int& avx2_kernels_setting() {
  static int setting = [] {
#if LPTV_AVX2_DISPATCH
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && !std::getenv("LPTV_NO_AVX2") ? 1 : 0;
#else
    return 0;
#endif
  }();
  return setting;
}
inline bool avx2_kernels() { return avx2_kernels_setting() != 0; }
// For the tests: false runs the scalar instances; true the AVX2 ones where the processor has
// them. Returns the previous setting.
inline bool set_avx2_kernels(bool on) {
  const bool before = avx2_kernels();
#if LPTV_AVX2_DISPATCH
  avx2_kernels_setting() = on && __builtin_cpu_supports("avx2") ? 1 : 0;
#else
  (void)on;
#endif
  return before;
}

// The factors: row k of U as 1/u_kk followed by u_{k,k+1..} / u_kk (the row scaled to a unit
// diagonal, so that the back substitution's step from one unknown to the
// next is one product and one subtraction, x_k = z_k / u_kk - sum_j (u_kj / u_kk) x_j with
// the nearest x_{k+1} last, instead of that and a product by 1/u_kk after it); the multipliers
// of step k (stride K; zero below the last row); piv[k] = p when rows k and k+p were swapped.
// Row k of U has entries in columns k..k+K unless pivoting brought a row reaching further into
// the pivot position (then up to k+2K): U holds entries 0..K of every row (stride K+1), a
// long row has kLongRow set in piv[k] and its entries K+1..2K in Ulong, in the order of k.
// Without pivoting U is then half the bytes of the full width, and the back substitution
// skips the exact zeros it would otherwise subtract (the same result: s - 0 z = s).
// An array of complex numbers left uninitialised on allocation (std::vector would write zeros
// over the factors first: one more pass over the largest array of the FDS).
// Large arrays ask Linux for transparent huge pages: at 10^7 lines the first touches of 4 KiB
// pages (a page fault each) took a fifth of the FDS's time (bench/RESULTS.md).
class RawArray {
 public:
  void resize(size_t count) {
    if (count > cap_) {
      const size_t bytes = 2 * count * sizeof(double);
      void* q = nullptr;
#ifdef __linux__
      constexpr size_t kHuge = size_t(2) << 20;
      if (bytes >= 2 * kHuge) {
        if (posix_memalign(&q, kHuge, (bytes + kHuge - 1) / kHuge * kHuge) != 0) q = nullptr;
        if (q) madvise(q, (bytes + kHuge - 1) / kHuge * kHuge, MADV_HUGEPAGE);
      }
#endif
      if (!q) q = std::malloc(bytes);
      if (!q) throw std::bad_alloc();
      p_.reset(static_cast<double*>(q));
      cap_ = count;
    }
    size_ = count;
  }
  kcd* data() { return reinterpret_cast<kcd*>(p_.get()); }
  const kcd* data() const { return reinterpret_cast<const kcd*>(p_.get()); }
  kcd& operator[](size_t i) { return data()[i]; }
  const kcd& operator[](size_t i) const { return data()[i]; }
  size_t size() const { return size_; }

 private:
  struct Free {
    void operator()(double* q) const { std::free(q); }
  };
  std::unique_ptr<double, Free> p_;
  size_t cap_ = 0, size_ = 0;
};

struct BandFactors {
  static constexpr std::uint8_t kLongRow = 0x80;  // in piv; p <= K <= SmallBandLU::kMaxK < 128
  int n = 0, K = 0;
  RawArray U;
  std::vector<kcd> Ulong;
  RawArray L;  // empty when the factors are used for the right-hand sides given only
  std::vector<std::uint8_t> piv;
  int pivot(int k) const { return piv[k] & ~kLongRow & 0xff; }
};

// Thrown through the kernel as the column of the first exactly zero pivot (the caller names it).
struct ZeroPivot {
  int column;
};

// What a partial factorisation leaves (factor_band with steps < n): the K rows of the window
// at step `steps`, each as its 2K + 1 entries in columns steps..steps+2K (the last one zero),
// and their nz eliminated right-hand sides; rows steps+K.. have not entered.
struct BandTail {
  std::vector<kcd> rows, z;
};

// Factorises the n x n band matrix given by src, eliminating nz right-hand sides on the way.
// Source:  void row(int r, int base, kcd* out): out[j] = A(r, base + j), j = 0..2K (zero
//          outside the band and the matrix);  void rhs(int r, kcd* z): the nz right-hand sides
//          of row r.
// z: (n + 2K) x nz, row-major: rows 0..n-1 receive the forward-eliminated right-hand sides,
// the 2K rows below are set to zero (back_substitute reads past the last row).
// With 0 < steps < n - K and a tail, only the first `steps` columns are eliminated (rows up
// to steps + K - 1 enter): f holds `steps` rows of U, z rows 0..steps-1, the window goes to
// *tail, and z's rows steps..steps+2K-1 are left to the caller (the solution of the rest,
// which back_substitute then reads).
template <int KT, bool V = false, class Source>
void factor_band(Source& src, int n, int Krt, int nz, BandFactors& f, bool keep_L, kcd* z,
                 int steps = -1, BandTail* tail = nullptr) {
  const int K = KT >= 0 ? KT : Krt;
  const int W = 2 * K + 1;
  const bool partial = tail && steps >= 0 && steps < n;
  if (!partial) steps = n;
  f.n = steps;
  f.K = K;
  f.U.resize(static_cast<size_t>(steps) * (K + 1));
  f.Ulong.clear();
  f.piv.resize(steps);
  f.L.resize(keep_L ? static_cast<size_t>(steps) * std::max(K, 1) : 0);
  std::vector<kcd> win(static_cast<size_t>(K + 1) * W), zw(static_cast<size_t>(K + 1) * std::max(nz, 1));
  // Position i of the window at step k lives in slot (k + i) mod (K + 1): the row that leaves
  // frees the slot of the row that enters next. A pivot swap exchanges the two rows' contents
  // (rare in the FDS's diagonally dominant rows), so no slot table sits between the loads.
  auto wrow = [&](int s) { return &win[static_cast<size_t>(s) * W]; };
  auto zrow = [&](int s) { return &zw[static_cast<size_t>(s) * nz]; };
  // Rows 0..K-1 enter against columns 0..2K.
  for (int r = 0; r < std::min(K, n); ++r) {
    src.row(r, 0, wrow(r));
    if (nz) src.rhs(r, zrow(r));
  }
  int s0 = 0;  // slot of position 0 at step k, k mod (K + 1)
  for (int k = 0; k < steps; ++k) {
    auto slot = [&](int i) { return s0 + i <= K ? s0 + i : s0 + i - (K + 1); };
    if (k + K < n) {
      src.row(k + K, k, wrow(slot(K)));
      if (nz) src.rhs(k + K, zrow(slot(K)));
    }
    const int m = std::min(K, n - 1 - k);  // rows below the pivot row in the window
    int p = 0;
    double best = cabs1(wrow(s0)[0]);
    for (int i = 1; i <= m; ++i) {
      const double v = cabs1(wrow(slot(i))[0]);
      if (v > best) best = v, p = i;
    }
    if (best == 0.0) throw ZeroPivot{k};
    if (p) {
      std::swap_ranges(wrow(s0), wrow(s0) + W, wrow(slot(p)));
      std::swap_ranges(zrow(s0), zrow(s0) + nz, zrow(slot(p)));
    }
    const kcd* P = wrow(s0);
    bool long_row = false;
    for (int j = K + 1; j < W; ++j) long_row |= P[j] != kcd(0.0, 0.0);
    f.piv[k] = static_cast<std::uint8_t>(p) | (long_row ? BandFactors::kLongRow : 0);
    kcd* Uk = &f.U[static_cast<size_t>(k) * (K + 1)];
    // 1 / p = conj(p) / |p|^2, and each multiplier r / p as (r conj(p)) / |p|^2: the product
    // r conj(p) does not wait for the division, which shortens the chain from one pivot to the
    // next by a complex product (crecip's Smith's method where |p|^2 could overflow or lose
    // bits to underflow).
    const double pa = P[0].real(), pb = P[0].imag();
    const double pm = std::max(std::abs(pa), std::abs(pb));
    const bool plain = pm > 1e-150 && pm < 1e150;
    const double id = plain ? 1.0 / (pa * pa + pb * pb) : 0.0;
    const kcd inv = plain ? kcd(pa * id, -pb * id) : crecip(P[0]);
    Uk[0] = inv;
    // out[j] = P[from + j] inv, j < count.
    auto scaled = [&](kcd* out, int from, int count) {
      int j = 0;
      if constexpr (V)
        for (; j + 1 < count; j += 2) store2(out + j, cmul2(load2(P + from + j), inv));
      for (; j < count; ++j) out[j] = cmul(P[from + j], inv);
    };
    scaled(Uk + 1, 1, K);
    if (long_row) {
      const size_t at = f.Ulong.size();
      f.Ulong.resize(at + K);
      scaled(&f.Ulong[at], K + 1, K);
    }
    const kcd* zp = zrow(s0);
    kcd* zk = z + static_cast<size_t>(k) * nz;
    for (int c = 0; c < nz; ++c) zk[c] = zp[c];
    for (int i = 1; i <= m; ++i) {
      kcd* R = wrow(slot(i));
      const kcd r = R[0];
      const kcd l = plain ? kcd((r.real() * pa + r.imag() * pb) * id, (r.imag() * pa - r.real() * pb) * id)
                          : cmul(r, inv);
      if (keep_L) f.L[static_cast<size_t>(k) * K + (i - 1)] = l;
      // Eliminate column k and shift the row one column left (the window moves with k). A
      // pivot row that is not long is zero beyond column K: there the row's entries only move
      // (r - l 0 is r).
      kcd* zr = zrow(slot(i));
      const int reach = long_row ? W - 1 : K;  // the pivot row's last nonzero entry
      if constexpr (V) {  // pairs
        int j = 1;
        for (; j + 1 <= reach; j += 2) store2(R + j - 1, cmsub2(load2(R + j), l, load2(P + j)));
        if (j <= reach) R[j - 1] = cmsub(R[j], l, P[j]), ++j;
        for (; j + 1 < W; j += 2) store2(R + j - 1, load2(R + j));
        if (j < W) R[j - 1] = R[j];
        int c = 0;
        for (; c + 1 < nz; c += 2) store2(zr + c, cmsub2(load2(zr + c), l, load2(zp + c)));
        if (c < nz) zr[c] = cmsub(zr[c], l, zp[c]);
      } else {
        for (int j = 1; j <= reach; ++j) R[j - 1] = cmsub(R[j], l, P[j]);
        for (int j = reach + 1; j < W; ++j) R[j - 1] = R[j];
        for (int c = 0; c < nz; ++c) zr[c] = cmsub(zr[c], l, zp[c]);
      }
      R[W - 1] = kcd(0.0, 0.0);
    }
    if (keep_L)  // no rows below the last ones: zero multipliers
      for (int i = m + 1; i <= K; ++i) f.L[static_cast<size_t>(k) * K + (i - 1)] = kcd(0.0, 0.0);
    s0 = s0 == K ? 0 : s0 + 1;
  }
  if (partial) {
    tail->rows.resize(static_cast<size_t>(K) * W);
    tail->z.resize(static_cast<size_t>(K) * nz);
    for (int i = 0; i < K; ++i) {
      const int s = s0 + i <= K ? s0 + i : s0 + i - (K + 1);
      std::copy(wrow(s), wrow(s) + W, &tail->rows[static_cast<size_t>(i) * W]);
      std::copy(zrow(s), zrow(s) + nz, &tail->z[static_cast<size_t>(i) * nz]);
    }
    return;
  }
  std::fill(z + static_cast<size_t>(n) * nz, z + static_cast<size_t>(n + 2 * K) * nz, kcd(0.0, 0.0));
}

// z (rows 0..n-1 forward-eliminated, 2K zero rows below) := U^-1 z, in place.
template <int KT, bool V = false>
void back_substitute(const BandFactors& f, int nz, kcd* z) {
  const int K = KT >= 0 ? KT : f.K;
  size_t next_long = f.Ulong.size();  // long rows are met in the reverse of their order
  for (int k = f.n - 1; k >= 0; --k) {
    const kcd* Uk = &f.U[static_cast<size_t>(k) * (K + 1)];
    const bool long_row = f.piv[k] & BandFactors::kLongRow;
    const kcd* Ul = long_row ? &f.Ulong[next_long -= K] : nullptr;  // entries K+1..2K
    kcd* zk = z + static_cast<size_t>(k) * nz;
    // The farthest term first: z_{k+1}, which the step before has just written, comes last,
    // so one product and one subtraction separate the steps instead of 2K of them.
    int c = 0;
    if constexpr (V) {
      for (; c + 1 < nz; c += 2) {  // two columns at a time, the same operations
        v4d s = cmul2(load2(zk + c), Uk[0]);
        if (long_row)
          for (int j = 2 * K; j > K; --j) s = cmsub2(s, Ul[j - K - 1], load2(zk + static_cast<size_t>(j) * nz + c));
        for (int j = K; j >= 1; --j) s = cmsub2(s, Uk[j], load2(zk + static_cast<size_t>(j) * nz + c));
        store2(zk + c, s);
      }
    }
    for (; c < nz; ++c) {
      kcd s = cmul(zk[c], Uk[0]);
      if (long_row)
        for (int j = 2 * K; j > K; --j) s = cmsub(s, Ul[j - K - 1], zk[static_cast<size_t>(j) * nz + c]);
      for (int j = K; j >= 1; --j) s = cmsub(s, Uk[j], zk[static_cast<size_t>(j) * nz + c]);
      zk[c] = s;
    }
  }
}

// z (n + 2K rows, the last 2K zero) := L^-1 P z, in place, from the stored multipliers.
template <int KT>
void forward_substitute(const BandFactors& f, int nz, kcd* z) {
  const int K = KT >= 0 ? KT : f.K;
  for (int k = 0; k < f.n; ++k) {
    kcd* zk = z + static_cast<size_t>(k) * nz;
    const int p = f.pivot(k);
    if (p) std::swap_ranges(zk, zk + nz, zk + static_cast<size_t>(p) * nz);
    const kcd* Lk = &f.L[static_cast<size_t>(k) * K];
    for (int i = 1; i <= K; ++i) {
      const kcd l = Lk[i - 1];
      kcd* zi = zk + static_cast<size_t>(i) * nz;
      for (int c = 0; c < nz; ++c) zi[c] = cmsub(zi[c], l, zk[c]);
    }
  }
}

// The kernels on the instruction set at hand: the AVX2 instances (the kernel and the row
// source inlined into one function compiled for AVX2) where avx2_kernels(), the scalar ones
// otherwise.
#if LPTV_AVX2_DISPATCH
template <int KT, class Source>
__attribute__((target("avx2"), flatten)) void factor_band_avx2(Source& src, int n, int Krt, int nz,
                                                               BandFactors& f, bool keep_L, kcd* z,
                                                               int steps, BandTail* tail) {
  factor_band<KT, true>(src, n, Krt, nz, f, keep_L, z, steps, tail);
}
template <int KT>
__attribute__((target("avx2"), flatten)) void back_substitute_avx2(const BandFactors& f, int nz, kcd* z) {
  back_substitute<KT, true>(f, nz, z);
}
#endif
template <int KT, class Source>
void factor_band_best(Source& src, int n, int Krt, int nz, BandFactors& f, bool keep_L, kcd* z,
                      int steps = -1, BandTail* tail = nullptr) {
#if LPTV_AVX2_DISPATCH
  if (avx2_kernels()) return factor_band_avx2<KT>(src, n, Krt, nz, f, keep_L, z, steps, tail);
#endif
  factor_band<KT>(src, n, Krt, nz, f, keep_L, z, steps, tail);
}
template <int KT>
void back_substitute_best(const BandFactors& f, int nz, kcd* z) {
#if LPTV_AVX2_DISPATCH
  if (avx2_kernels()) return back_substitute_avx2<KT>(f, nz, z);
#endif
  back_substitute<KT>(f, nz, z);
}

// Calls f(std::integral_constant<int, K>) for K = 0..7, f(std::integral_constant<int, -1>)
// (runtime K) above.
template <class F>
decltype(auto) dispatch_band(int K, F&& f) {
  switch (K) {
    case 0: return f(std::integral_constant<int, 0>());
    case 1: return f(std::integral_constant<int, 1>());
    case 2: return f(std::integral_constant<int, 2>());
    case 3: return f(std::integral_constant<int, 3>());
    case 4: return f(std::integral_constant<int, 4>());
    case 5: return f(std::integral_constant<int, 5>());
    case 6: return f(std::integral_constant<int, 6>());
    case 7: return f(std::integral_constant<int, 7>());
    default: return f(std::integral_constant<int, -1>());
  }
}

#pragma GCC diagnostic pop

}  // namespace detail
}  // namespace lptv
