// lptv::simulate against the arithmetic floor of its band elimination, side by side in one run,
// on the paper-like example (Ka = Kb = 3, na = 2, nb = 1, one input) on the grid -L..L.
//
// simulate (guard 0, lines_out L: the grid -L..L) takes the half-grid route: L + 1 band rows,
// rows L..K of A in the unknowns Y_L..Y_0 eliminated by the small band kernel with their two
// right-hand sides (B U and the conditioning check), a small corner system, one back
// substitution. The floor kernel below performs the floating-point operations of that route's
// rows and nothing else: per band row the powers of one new line, the 2K + 1 entries of the row
// of A, (B U)_l, the check's entry, the pivot's reciprocal, the scaled row of U, the K
// multipliers, the K (K + 2) multiply-subtractions of the elimination (a row of the window
// without pivoting reaches column K of the pivot row: the products with its zeros beyond are
// not arithmetic the result needs), the back substitution of both right-hand sides and the
// check's max |x|. Each operation is the kernel's own (the same products, sums and order, so
// that its solution equals simulate's bit for bit where no pivoting occurs; compared below),
// minus products by an exact 1 and sums with an exact 0. Not in it: the pivot search (no row
// is exchanged here), the window's slots, the row source's bounds and tests, the corner, the
// argument checks and the allocations: bookkeeping. The window lives in local arrays of fixed
// size (registers where the compiler can), the factors and the right-hand sides go to memory
// and are read back by the back substitution, as the two passes need.
//
// Two instances of the floor, like the kernel's: compiled for the baseline instruction set
// (the scalar floor: one complex number per operation, the code as the kernel's scalar
// instance is compiled) and for AVX2 with two complex numbers per register wherever the
// kernel's AVX2 instance pairs them (the vector floor). simulate runs the kernel's AVX2
// instance unless LPTV_NO_AVX2 is set; the ratio that judges an instance is against the floor
// of the same instruction set.
//
// Usage: bench_fds_floor [lines ...]   (default 100001; lines = 2L + 1)
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "band_kernel.hpp"
#include "band_row.hpp"
#include "bench_common.hpp"
#include "fds_fold.hpp"
#include "lptv/fds.hpp"

namespace {

using lptv::detail::kcd;
constexpr int K = 3, NA = 2, NB = 1, NZ = 2, W = 2 * K + 1;  // the paper-like example; nz: input + check

struct FloorData {
  int L = 0;
  double w0 = 0;
  double aj[W][NA + 1][2];  // a_{n,k} j^n by column j of a reversed row (harmonic k = j - K)
  double bj[W][NB + 1][2];
  double mag[NA + 1];       // the check's row magnitude as a polynomial in |l| (lines l >= K)
  kcd step;                 // the check's phase step from line l to l - 1
};

// Floating-point operations per band row of the floor (and of the route): counted from the code
// below, K, NA, NB, NZ as above.
struct Count {
  int mul, add, div;
};
constexpr Count floor_count() {
  Count c{0, 0, 0};
  c.mul += NA;                          // powers of the new line: w = w0 l, w^2 .. w^na
  c.mul += W * 2 * NA, c.add += W * 2 * NA;  // A entries: sum_n (a_{n,k} j^n) w^n, complex times real
  c.mul += W * 2 * NB, c.add += W * 2 * NB;  // B entries
  c.mul += W * 4, c.add += W * 2 + (W - 1) * 2;  // (B U)_l: 2K + 1 complex products, summed
  c.mul += NA + 4 + 2, c.add += NA + 2;  // check: magnitude (Horner), phase recurrence, product
  c.mul += 4, c.add += 1, c.div += 1;    // pivot: |p|^2, 1 / |p|^2, conj(p) / |p|^2
  c.mul += K * 4, c.add += K * 2;        // U's row scaled to a unit diagonal: K complex products
  c.mul += K * 6, c.add += K * 2;        // multipliers (r conj(p)) / |p|^2
  c.mul += K * (K + NZ) * 4, c.add += K * (K + NZ) * 4;  // elimination: complex multiply-subtractions
  c.mul += NZ * (4 + 4 * K), c.add += NZ * (2 + 4 * K);  // back substitution: product, K mult.-sub.
  c.mul += 2, c.add += 1;                // the check's |x|^2 for its max
  return c;
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
using lptv::detail::cmsub;
using lptv::detail::cmul;

// The route's arithmetic on rows L..K (steps L - 2K + 1), the corner's 2K solutions taken from
// `corner` (lines 0..2K-1), then the back substitution into y (lines 0..L). u: lines 0..L + K
// (zero above L). Returns the check's max |x|^2.
template <bool V>
__attribute__((always_inline)) inline double floor_solve_impl(const FloorData& d, const kcd* u,
                                                              const kcd* corner, kcd* Uf, kcd* z, kcd* y) {
  using namespace lptv::detail;
  const int L = d.L, steps = L - 2 * K + 1;
  // Powers of the window's column lines: t[j] for line l + K - j of the row entering.
  double t[W][NA + 1];
  kcd uw[W];
  auto powers = [&](int line, double* tp) {
    const double w = d.w0 * line;
    tp[0] = 1.0, tp[1] = w;
    for (int n = 2; n <= NA; ++n) tp[n] = tp[n - 1] * w;
  };
  // Entry j of a row from its column's powers: c_0 + c_1 w + c_2 w^2 (the first term needs no
  // product: its power is 1).
  auto entry = [](const double (*c)[2], const double* tp, int order) {
    double re = c[0][0], im = c[0][1];
    for (int n = 1; n <= order; ++n) re += c[n][0] * tp[n], im += c[n][1] * tp[n];
    return kcd(re, im);
  };
  kcd win[K + 1][W];
  kcd zw[K + 1][NZ];
  kcd phase = std::polar(1.0, lptv::detail::kCheckPhaseStep * (L + 1));
  // A row (line l) into window position pos, with its right-hand sides; t and uw hold the
  // lines l + K .. l - K. A row below the top enters against the lines l + K .. l - K (its
  // diagonal at column K); the top rows (l = L - pos, pos < K) enter as the kernel's do,
  // against the lines L .. L - 2K (the diagonal at column pos, zero beyond column K + pos: the
  // lines above L are not in the system).
  auto enter = [&](int l, int pos, bool top) {
    if (top) {
      for (int j = 0; j < W; ++j) {
        const int c = j - pos + K;  // the same entry in the row's own frame (line l + K - c = L - j)
        win[pos][j] = c < W ? entry(d.aj[c], t[c], NA) : kcd(0.0, 0.0);
      }
    } else {
      for (int j = 0; j < W; ++j) win[pos][j] = entry(d.aj[j], t[j], NA);
    }
    double re = 0.0, im = 0.0;
    for (int j = W - 1; j >= 0; --j) {  // lines l - K .. l + K, as the route sums them
      const kcd v = entry(d.bj[j], t[j], NB);
      if (j == W - 1) re = v.real() * uw[j].real() - v.imag() * uw[j].imag(),
                      im = v.real() * uw[j].imag() + v.imag() * uw[j].real();
      else re += v.real() * uw[j].real() - v.imag() * uw[j].imag(),
           im += v.real() * uw[j].imag() + v.imag() * uw[j].real();
    }
    zw[pos][0] = kcd(re, im);
    const double x = l;
    double mg = d.mag[NA];
    for (int n = NA - 1; n >= 0; --n) mg = mg * x + d.mag[n];
    phase = cmul(phase, d.step);
    zw[pos][1] = kcd(mg * phase.real(), mg * phase.imag());
  };
  auto slide = [&](int low_line) {  // the window's lines move down by one
    for (int j = 0; j + 1 < W; ++j) {
      for (int n = 0; n <= NA; ++n) t[j][n] = t[j + 1][n];
      uw[j] = uw[j + 1];
    }
    powers(low_line, t[W - 1]);
    uw[W - 1] = u[low_line];
  };
  // Lines L + K .. L - K in the window before the first row (line L) enters.
  for (int j = 0; j < W; ++j) powers(L + K - j, t[j]), uw[j] = u[L + K - j];
  for (int r = 0; r < K; ++r) {
    enter(L - r, r, true);
    slide(L - r - 1 - K);
  }
  for (int k = 0; k < steps; ++k) {
    enter(L - k - K, K, false);
    if (k + 1 < steps) slide(L - k - 2 * K - 1);
    const kcd* P = win[0];
    const double pa = P[0].real(), pb = P[0].imag();
    const double id = 1.0 / (pa * pa + pb * pb);
    const kcd inv(pa * id, -pb * id);
    kcd* Uk = Uf + static_cast<size_t>(k) * (K + 1);
    Uk[0] = inv;
    kcd p[K + 1], zp[NZ];
    for (int j = 1; j <= K; ++j) p[j] = P[j];
    for (int c = 0; c < NZ; ++c) zp[c] = zw[0][c];
    int j0 = 1;
    if constexpr (V)
      for (; j0 + 1 <= K; j0 += 2) store2(Uk + j0, cmul2(load2(p + j0), inv));
    for (; j0 <= K; ++j0) Uk[j0] = cmul(p[j0], inv);
    kcd* zk = z + static_cast<size_t>(k) * NZ;
    for (int c = 0; c < NZ; ++c) zk[c] = zp[c];
    for (int i = 1; i <= K; ++i) {
      const kcd r = win[i][0];
      const kcd l((r.real() * pa + r.imag() * pb) * id, (r.imag() * pa - r.real() * pb) * id);
      kcd* out = win[i - 1];
      const kcd* R = win[i];
      int j = 1;
      if constexpr (V) {
        for (; j + 1 <= K; j += 2) store2(out + j - 1, cmsub2(load2(R + j), l, load2(p + j)));
        store2(zw[i - 1], cmsub2(load2(zw[i]), l, load2(zp)));
      } else {
        for (int c = 0; c < NZ; ++c) zw[i - 1][c] = cmsub(zw[i][c], l, zp[c]);
      }
      for (; j <= K; ++j) out[j - 1] = cmsub(R[j], l, p[j]);
      for (j = K + 1; j <= i + K; ++j) out[j - 1] = R[j];  // beyond the pivot row's reach
    }
  }
  // The corner's solutions (lines 2K-1..0) below the last step, then back substitution.
  for (int i = 0; i < 2 * K; ++i)
    for (int c = 0; c < NZ; ++c) z[static_cast<size_t>(L - i) * NZ + c] = c == 0 ? corner[i] : kcd(0.0, 0.0);
  double best = 0.0;
  for (int k = steps - 1; k >= 0; --k) {
    const kcd* Uk = Uf + static_cast<size_t>(k) * (K + 1);
    kcd* zk = z + static_cast<size_t>(k) * NZ;
    if constexpr (V) {
      v4d s = cmul2(load2(zk), Uk[0]);
      for (int j = K; j >= 1; --j) s = cmsub2(s, Uk[j], load2(zk + static_cast<size_t>(j) * NZ));
      store2(zk, s);
    } else {
      for (int c = 0; c < NZ; ++c) {
        kcd s = cmul(zk[c], Uk[0]);
        for (int j = K; j >= 1; --j) s = cmsub(s, Uk[j], zk[static_cast<size_t>(j) * NZ + c]);
        zk[c] = s;
      }
    }
    y[L - k] = zk[0];
    const double a = std::norm(zk[1]);
    best = a > best ? a : best;
  }
  return best;
}

// no-tree-loop-distribute-patterns: the window's moves stay moves, not calls to memmove.
__attribute__((noinline, optimize("no-tree-loop-distribute-patterns"))) double floor_scalar(const FloorData& d, const kcd* u, const kcd* corner, kcd* Uf,
                                              kcd* z, kcd* y) {
  return floor_solve_impl<false>(d, u, corner, Uf, z, y);
}
__attribute__((noinline, target("avx2"), flatten, optimize("no-tree-loop-distribute-patterns"))) double floor_avx2(const FloorData& d, const kcd* u,
                                                                     const kcd* corner, kcd* Uf, kcd* z, kcd* y) {
  return floor_solve_impl<true>(d, u, corner, Uf, z, y);
}
#pragma GCC diagnostic pop

FloorData floor_data(const lptv::Model& m, int L) {
  FloorData d;
  d.L = L;
  d.w0 = m.w0();
  Eigen::MatrixXcd aj(m.a().rows(), m.a().cols()), bj(m.b().rows(), m.b().cols());
  for (Eigen::Index k = 0; k < aj.cols(); ++k) lptv::detail::times_j_powers(m.a().col(k).data(), NA, aj.col(k).data());
  for (Eigen::Index k = 0; k < bj.cols(); ++k) lptv::detail::times_j_powers(m.b().col(k).data(), NB, bj.col(k).data());
  for (int j = 0; j < W; ++j) {
    for (int n = 0; n <= NA; ++n) d.aj[j][n][0] = aj(n, j).real(), d.aj[j][n][1] = aj(n, j).imag();
    for (int n = 0; n <= NB; ++n) d.bj[j][n][0] = bj(n, j).real(), d.bj[j][n][1] = bj(n, j).imag();
  }
  // The check's polynomial in |l| (lptv::detail::CheckMagnitude::far), read back by evaluation:
  // p(x) at x = 0, 1, 2 gives its three coefficients (na = 2) up to rounding.
  const lptv::detail::CheckMagnitude cm(m.a().cwiseAbs(), m.w0());
  static_assert(NA == 2, "the check's polynomial is recovered for na = 2");
  const double p0 = cm.far(0, NA), p1 = cm.far(1, NA), p2 = cm.far(2, NA);
  d.mag[0] = p0, d.mag[2] = (p2 - 2 * p1 + p0) / 2, d.mag[1] = p1 - p0 - d.mag[2];
  d.step = std::polar(1.0, -lptv::detail::kCheckPhaseStep);
  return d;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int run(int argc, char** argv) {
  std::vector<long> sizes;
  for (int i = 1; i < argc; ++i) {
    char* end = nullptr;
    const long n = std::strtol(argv[i], &end, 10);
    if (end == argv[i] || *end || n < 4 * K + 3 || n > 200000001) {
      std::fprintf(stderr, "bench_fds_floor: lines must be integers from %d to 200000001, got '%s'\n", 4 * K + 3, argv[i]);
      return 2;
    }
    sizes.push_back(n);
  }
  if (sizes.empty()) sizes.push_back(100001);
  const lptv::Model model = bench::paper_model();
  if (model.ka() != K || model.kb() != K || model.na() != NA || model.nb() != NB) {
    std::fprintf(stderr, "bench_fds_floor: the floor is compiled for K = %d, na = %d, nb = %d; bench::paper_model() "
                 "has Ka = %d, Kb = %d, na = %d, nb = %d\n", K, NA, NB, model.ka(), model.kb(), model.na(), model.nb());
    return 1;
  }
  const bool avx2 = lptv::detail::avx2_kernels();
  constexpr Count c = floor_count();
  std::printf("lptv::simulate against the arithmetic floor of its band elimination; paper-like example "
              "(Ka = Kb = %d, na = %d, nb = %d, one input), grid -L..L of n = 2L + 1 lines, guard 0\n", K, NA, NB);
  std::printf("half-grid route: L + 1 band rows, 2 right-hand sides (B U and the check); the floor per band row: "
              "%d complex multiply-subtractions in the elimination (K (K + 2)),\n  %d in the back substitution, "
              "%d complex products (U's row, K; the multipliers, K; back substitution, 2; the check's phase, 1), "
              "%d (B U) complex products,\n  %d real-times-complex multiply-adds in the entries of A and B, 1 division: "
              "%d multiplications + %d additions + %d division = %d flops per band row, %.1f per line\n",
              K * (K + NZ), NZ * K, K + K + NZ + 1, W, W * (NA + NB), c.mul, c.add, c.div, c.mul + c.add + c.div,
              (c.mul + c.add + c.div) / 2.0);
  std::printf("simulate runs the kernel's %s instance; scalar floor: the baseline instruction set; vector floor: "
              "AVX2, two complex numbers per register where the kernel pairs them\n", avx2 ? "AVX2" : "scalar");
  std::printf("ns per grid line (time / n), the fastest of the rounds, the three taking turns\n\n");
  std::printf("%9s %7s %10s %10s %10s %9s %9s %10s %10s\n", "lines", "rounds", "simulate", "floor vec",
              "floor sca", "sim/vec", "sim/sca", "vs sim", "sca/vec");
  bool failed = false;
  for (const long n : sizes) {
    const int L = static_cast<int>((n - 1) / 2);
    std::mt19937_64 gen(7);
    std::normal_distribution<double> nd;
    Eigen::MatrixXcd U(L + 1, 1);
    for (int l = 0; l <= L; ++l) U(l, 0) = kcd(nd(gen), nd(gen));
    U(0, 0) = U(0, 0).real();
    lptv::SimulateOptions so;
    so.guard = 0;
    so.lines_out = L;
    const FloorData d = floor_data(model, L);
    std::vector<kcd> u(L + 1 + K, kcd(0.0, 0.0)), Uf(static_cast<size_t>(L + 1) * (K + 1)),
        z(static_cast<size_t>(L + 1) * NZ), y(L + 1);
    for (int l = 0; l <= L; ++l) u[l] = U(l, 0);
    Eigen::MatrixXcd Ys = lptv::simulate(model, U, so).Y;
    std::vector<kcd> corner(2 * K);
    for (int i = 0; i < 2 * K; ++i) corner[i] = Ys(i, 0);
    double t_sim = 1e300, t_vec = 1e300, t_sca = 1e300;
    const int rounds = std::max(5, std::min(200, static_cast<int>(2e7 / double(n))));
    // max |y_floor - y_simulate| over lines 2K..L; a NaN anywhere makes it NaN (std::max would drop it).
    auto max_diff = [&] {
      double m = 0;
      for (int l = 2 * K; l <= L; ++l) {
        const double e = std::abs(y[l] - Ys(l, 0));
        if (std::isnan(e) || e > m) m = e;
        if (std::isnan(m)) break;
      }
      return m;
    };
    // Each floor returns the check's max |x|^2 over lines 2K..L: finite and positive whenever its
    // work was done on finite numbers, and the same in every round (the same operations on the
    // same data), which the rounds below verify.
    double diff_vec = 0, diff_sca = 0, check_vec = 0, check_sca = 0;
    const double scale = Ys.cwiseAbs().maxCoeff();
    int check_changed = 0;
    for (int r = 0; r < rounds; ++r) {
      auto t0 = std::chrono::steady_clock::now();
      Ys = lptv::simulate(model, U, so).Y;
      t_sim = std::min(t_sim, seconds_since(t0));
      t0 = std::chrono::steady_clock::now();
      const double cv = floor_avx2(d, u.data(), corner.data(), Uf.data(), z.data(), y.data());
      t_vec = std::min(t_vec, seconds_since(t0));
      if (r == 0) diff_vec = max_diff(), check_vec = cv;
      t0 = std::chrono::steady_clock::now();
      const double cs = floor_scalar(d, u.data(), corner.data(), Uf.data(), z.data(), y.data());
      t_sca = std::min(t_sca, seconds_since(t0));
      if (r == 0) diff_sca = max_diff(), check_sca = cs;
      check_changed += cv != check_vec || cs != check_sca;
    }
    const double nn = 2.0 * L + 1;
    const double diff = std::isnan(diff_vec) || diff_vec > diff_sca ? diff_vec : diff_sca;
    std::printf("%9ld %7d %10.2f %10.2f %10.2f %9.2f %9.2f %10.1e %10.2f\n", long(nn), rounds, 1e9 * t_sim / nn,
                1e9 * t_vec / nn, 1e9 * t_sca / nn, t_sim / t_vec, t_sim / t_sca, diff / scale, t_sca / t_vec);
    if (!(std::isfinite(scale) && scale > 0)) {
      std::fprintf(stderr, "bench_fds_floor: simulate's output is %g at its largest at n = %ld (finite and nonzero "
                   "expected)\n", scale, long(nn));
      failed = true;
    }
    if (!(diff <= 1e-12 * scale)) {
      std::fprintf(stderr, "bench_fds_floor: the floor's solution differs from simulate's at n = %ld: %.1e relative "
                   "(vector floor %.1e, scalar floor %.1e; NaN: a floor computed NaNs)\n", long(nn), diff / scale,
                   diff_vec / scale, diff_sca / scale);
      failed = true;
    }
    if (!(std::isfinite(check_vec) && check_vec > 0 && check_vec == check_sca) || check_changed) {
      std::fprintf(stderr, "bench_fds_floor: the floors' conditioning check at n = %ld: max |x|^2 %g (vector), %g "
                   "(scalar), changed in %d of %d rounds (finite, positive, equal and unchanged expected)\n",
                   long(nn), check_vec, check_sca, check_changed, rounds);
      failed = true;
    }
  }
  std::printf("\nvs sim: max |y_floor - y_simulate| / max |y| over lines 2K..L (0: the floor's operations are the "
              "route's, bit for bit)\n");
  return failed ? 1 : 0;
}

int main(int argc, char** argv) {
  return bench::guarded_main("bench_fds_floor", [&] { return run(argc, argv); });
}
