// The small-band LU kernel (lptv::SmallBandLU, and the FDS's fused route through it) against
// LAPACK's zgbtrf/zgbtrs (lptv::BandLU) and against KLU, for every bandwidth the kernel unrolls
// (K = 0..7) and the runtime-K code above; random bands that need pivoting.
#include <catch2/catch.hpp>
#include <random>

#include "lptv/band_lu.hpp"
#include "lptv/errors.hpp"
#include "lptv/fds.hpp"
#include "band_kernel.hpp"  // detail::set_avx2_kernels (private: the tests' include path)

using lptv::cd;

namespace {

// Both routes are backward stable with the same pivots (the kernel's pivot search is
// zgbtf2's), so on these well-conditioned bands they differ by a few rounding errors of the
// solution's largest entry; the brief's 1e-13 leaves a factor ~100 over what was measured.
constexpr double kTol = 1e-13;

double rel_diff(const Eigen::MatrixXcd& x, const Eigen::MatrixXcd& ref) {
  return (x - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff();
}

// A random band in LAPACK band storage (kl = ku = K, ldab = 3K + 1): entries with unit normal
// parts; on every third row the diagonal is scaled by 1e-3, so the pivot comes from below.
std::vector<cd> random_band(int n, int K, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> nd;
  const int ld = lptv::BandLU::ldab(K, K);
  std::vector<cd> ab(static_cast<size_t>(ld) * n, cd(0.0, 0.0));
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - K); i <= std::min(n - 1, j + K); ++i) {
      cd v(nd(gen), nd(gen));
      if (i == j) v = (i % 3 == 0) ? 1e-3 * v : v + cd(2.0 * K, 0.0) * (v / std::abs(v));
      ab[(2 * K + i - j) + static_cast<size_t>(j) * ld] = v;
    }
  return ab;
}

Eigen::MatrixXcd random_rhs(int n, int ncol, unsigned seed) {
  std::mt19937_64 gen(seed + 1000);
  std::normal_distribution<double> nd;
  Eigen::MatrixXcd b(n, ncol);
  for (int j = 0; j < ncol; ++j)
    for (int i = 0; i < n; ++i) b(i, j) = cd(nd(gen), nd(gen));
  return b;
}

std::string col_label(int c) { return "column " + std::to_string(c); }

// A continuous-time LPTV model with Ka = Kb = K: DC terms of a stable second-order system,
// harmonics of total weight depth relative to the DC term of a_0, 0.3 on the other
// coefficients (so a_2(t) stays away from zero; a large depth makes the low lines pivot).
lptv::Model random_model(int K, unsigned seed, double depth) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> nd;
  const double dc_a[3] = {1.0, 0.6, 1.0}, dc_b[2] = {1.0, 0.5};
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(3, 2 * K + 1), b = Eigen::MatrixXcd::Zero(2, 2 * K + 1);
  auto fill = [&](Eigen::MatrixXcd& c, const double* dc) {
    for (int n = 0; n < c.rows(); ++n) {
      c(n, K) = dc[n];
      if (K == 0) continue;
      std::vector<cd> h(K);
      double sum = 0;
      for (int k = 0; k < K; ++k) h[k] = cd(nd(gen), nd(gen)), sum += std::abs(h[k]);
      for (int k = 1; k <= K; ++k) {
        const double d = (&c == &a && n == 0) ? depth : 0.3;
        c(n, K + k) = h[k - 1] * (d * dc[n] / (2 * sum));
        c(n, K - k) = std::conj(c(n, K + k));
      }
    }
  };
  fill(a, dc_a);
  fill(b, dc_b);
  return lptv::Model(a, b, 0.3);
}

// A of the model in LAPACK band storage, from the public sparse builder.
std::vector<cd> band_storage(const lptv::SpMat& A, int K) {
  const int ld = lptv::BandLU::ldab(K, K);
  std::vector<cd> ab(static_cast<size_t>(ld) * A.cols(), cd(0.0, 0.0));
  for (int j = 0; j < A.outerSize(); ++j)
    for (lptv::SpMat::InnerIterator it(A, j); it; ++it)
      ab[static_cast<size_t>(j) * ld + 2 * K + it.row() - j] = it.value();
  return ab;
}

}  // namespace

TEST_CASE("small band LU equals zgbtrf/zgbtrs on random bands that need pivoting", "[band]") {
  for (int K : {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 16}) {
    for (int n : {1, 2, K + 1, 2 * K + 3, 157}) {
      for (unsigned seed = 0; seed < 3; ++seed) {
        CAPTURE(K, n, seed);
        const std::vector<cd> ab = random_band(n, K, 100 * K + seed);
        const Eigen::MatrixXcd b = random_rhs(n, 5, seed);
        const lptv::SmallBandLU lu(n, K, ab, col_label);
        const lptv::BandLU ref(n, K, K, ab, col_label);
        REQUIRE(rel_diff(lu.solve(b), ref.solve(b)) <= kTol);
        // The residual of the kernel's solution on the dense matrix.
        Eigen::MatrixXcd A = Eigen::MatrixXcd::Zero(n, n);
        const int ld = lptv::BandLU::ldab(K, K);
        for (int j = 0; j < n; ++j)
          for (int i = std::max(0, j - K); i <= std::min(n - 1, j + K); ++i)
            A(i, j) = ab[(2 * K + i - j) + static_cast<size_t>(j) * ld];
        const Eigen::MatrixXcd x = lu.solve(b);
        const double res = (A * x - b).cwiseAbs().maxCoeff() /
                           (A.cwiseAbs().maxCoeff() * x.cwiseAbs().maxCoeff() * (2 * K + 1));
        REQUIRE(res <= 1e-15);
        if (K > 0 && n == 157) {
          int swaps = 0;
          for (int k = 0; k < n; ++k) swaps += lu.pivot(k) != 0;
          REQUIRE(swaps > n / 4);  // the premise: these bands need pivoting
        }
      }
    }
  }
}

TEST_CASE("small band LU solves many right-hand sides in blocks and on two threads", "[band]") {
  const int n = 20001, K = 3;
  const std::vector<cd> ab = random_band(n, K, 5);
  const lptv::SmallBandLU lu(n, K, ab, col_label);
  const lptv::BandLU ref(n, K, K, ab, col_label);
  for (int ncol : {1, 15, 16, 17, 40}) {
    CAPTURE(ncol);
    const Eigen::MatrixXcd b = random_rhs(n, ncol, 9);
    const Eigen::MatrixXcd x = lu.solve(b);
    REQUIRE(rel_diff(x, ref.solve(b)) <= kTol);
    // Column by column gives the same bits as the block.
    for (int j = 0; j < ncol; j += 7) REQUIRE(lu.solve(b.col(j)) == x.col(j));
  }
}

TEST_CASE("small band LU names the first zero pivot", "[band]") {
  const int n = 12, K = 2, ld = lptv::BandLU::ldab(K, K);
  std::vector<cd> ab(static_cast<size_t>(ld) * n, cd(0.0, 0.0));
  for (int j = 0; j < n; ++j) ab[2 * K + static_cast<size_t>(j) * ld] = cd(1.0, 0.5);
  ab[2 * K + 5 * static_cast<size_t>(ld)] = 0.0;  // A(5, 5) = 0 and nothing below it
  REQUIRE_THROWS_WITH(lptv::SmallBandLU(n, K, ab, col_label), Catch::Contains("column 5"));
  REQUIRE_THROWS_WITH(lptv::BandLU(n, K, K, ab, col_label), Catch::Contains("column 5"));
}

TEST_CASE("FDS band kernel equals LAPACK's band LU and KLU for every bandwidth", "[band][fds]") {
  // depth 0.3: diagonally dominant rows (no pivoting); depth 3 on a model with a light
  // damping: the low lines need pivots from below.
  for (int K : {0, 1, 2, 3, 4, 5, 6, 7, 8, 10}) {
    for (double depth : {0.3, 3.0}) {
      CAPTURE(K, depth);
      const lptv::Model m = random_model(K, 17 + K, depth);
      const int L = 60;
      const lptv::Grid g = lptv::make_grid(m, L);
      const Eigen::MatrixXcd U = random_rhs(g.N, 3, K);
      const lptv::Fds fds(m, L, lptv::Solver::Band);
      const lptv::BandLU lapack(g.N, K, K, band_storage(lptv::build_A(m, g), K), col_label);
      const Eigen::MatrixXcd ref = lapack.solve(lptv::apply_B(m, g, U));
      REQUIRE(rel_diff(fds.solve_full(U), ref) <= kTol);
      // The fused route (factorisation, B U, check and substitutions in one pass).
      const lptv::GridSolution s = lptv::solve_grid(m, L, U, lptv::Solver::Band);
      REQUIRE(s.solver == lptv::Solver::Band);
      REQUIRE(rel_diff(s.Y, ref) <= kTol);
      REQUIRE(s.condition == Approx(fds.condition()).epsilon(1e-12));
      REQUIRE(fds.condition() < 1e3);
      // The conditioning check agrees with KLU's route (the same right-hand side, solved
      // apart).
      const lptv::Fds klu(m, L, lptv::Solver::KLU);
      REQUIRE(fds.condition() == Approx(klu.condition()).epsilon(1e-10));
      REQUIRE(rel_diff(klu.solve_full(U), ref) <= kTol);
      if (K > 0 && depth > 1) {
        const lptv::SmallBandLU lu(g.N, K, band_storage(lptv::build_A(m, g), K), col_label);
        int swaps = 0;
        for (int k = 0; k < g.N; ++k) swaps += lu.pivot(k) != 0;
        REQUIRE(swaps > 0);  // the premise: this model needs pivoting
      }
    }
  }
}

namespace {

// Full-grid columns of a real input: U_{-l} = conj(U_l), U_0 real (as simulate builds them).
Eigen::MatrixXcd real_input(int L, int ncol, unsigned seed) {
  const Eigen::MatrixXcd h = random_rhs(L + 1, ncol, seed);
  Eigen::MatrixXcd U(2 * L + 1, ncol);
  for (int q = 0; q < ncol; ++q) {
    U(L, q) = h(0, q).real();
    for (int l = 1; l <= L; ++l) U(L + l, q) = h(l, q), U(L - l, q) = std::conj(h(l, q));
  }
  return U;
}

// The full-grid A with rows and columns in reverse line order, in LAPACK band storage: its
// first L - 2K + 1 elimination steps are those of the half-grid route (rows L..K in the
// unknowns Y_L..Y_0).
std::vector<cd> reversed_band(const lptv::SpMat& A, int K) {
  const int n = static_cast<int>(A.rows()), ld = lptv::BandLU::ldab(K, K);
  std::vector<cd> ab(static_cast<size_t>(ld) * n, cd(0.0, 0.0));
  for (int j = 0; j < A.outerSize(); ++j)
    for (lptv::SpMat::InnerIterator it(A, j); it; ++it) {
      const int r = n - 1 - static_cast<int>(it.row()), c = n - 1 - j;
      ab[static_cast<size_t>(c) * ld + 2 * K + r - c] = it.value();
    }
  return ab;
}

}  // namespace

TEST_CASE("the half-grid route for a real input equals LAPACK's band LU on the full grid",
          "[band][fds]") {
  // Every unrolled bandwidth and the runtime-K code; the smallest grids the route takes
  // (L = 2K + 1: one band step, the rest in the corner) and larger ones; depth 3 makes both
  // the band steps and the corner pivot.
  int pivoting_models = 0;
  for (int K : {1, 2, 3, 4, 5, 6, 7, 8, 10}) {
    for (double depth : {0.3, 3.0}) {
      for (unsigned seed = 0; seed < 3; ++seed) {
        const lptv::Model m = random_model(K, 31 * K + seed, depth);
        for (int L : {2 * K + 1, 2 * K + 2, 3 * K + 5, 60}) {
          CAPTURE(K, depth, seed, L);
          const lptv::Grid g = lptv::make_grid(m, L);
          const Eigen::MatrixXcd U = real_input(L, 2, seed + 7);
          const lptv::SpMat A = lptv::build_A(m, g);
          const lptv::BandLU lapack(g.N, K, K, band_storage(A, K), col_label);
          const Eigen::MatrixXcd ref = lapack.solve(lptv::apply_B(m, g, U));
          const lptv::GridSolution s = lptv::solve_grid(m, L, U, lptv::Solver::Band);
          REQUIRE(s.solver == lptv::Solver::Band);
          REQUIRE(rel_diff(s.Y, ref) <= kTol);
          // The solution is conjugate-symmetric by construction.
          for (int l = 0; l <= L; ++l) REQUIRE(s.Y.row(L - l) == s.Y.row(L + l).conjugate());
          // The check: the same magnitudes as the full grid's (the phases differ by a constant).
          const lptv::Fds fds(m, L, lptv::Solver::Band);
          REQUIRE(s.condition == Approx(fds.condition()).epsilon(1e-12));
          // The same solution as the full-grid route on the same input made slightly
          // non-symmetric (an imaginary part of 1e-300 in U_0: the route cannot fold it).
          Eigen::MatrixXcd Ua = U;
          Ua(L, 0) += cd(0.0, 1e-300);
          const lptv::GridSolution full = lptv::solve_grid(m, L, Ua, lptv::Solver::Band);
          REQUIRE(rel_diff(s.Y, full.Y) <= kTol);
          if (L == 60) {
            const lptv::SmallBandLU rev(g.N, K, reversed_band(A, K), col_label);
            for (int k = 0; k < L - 2 * K + 1; ++k)
              if (rev.pivot(k) != 0) {
                ++pivoting_models;
                break;
              }
          }
        }
      }
    }
  }
  REQUIRE(pivoting_models > 0);  // the premise: the band steps pivot for some deep models
}

TEST_CASE("the one-pass route builds build_A's entries, bit for bit", "[band][fds]") {
  // The route builds A's rows with band_entry_ct (half the products of band_entry, the same
  // numbers); with the same entries and right-hand sides the kernel's fused elimination does
  // the operations of SmallBandLU's factorisation and two substitutions in the same order, so
  // the solutions agree in every bit. A general (not conjugate-symmetric) input takes the
  // full-grid route.
  for (int K : {1, 3, 7, 9}) {
    for (double depth : {0.3, 3.0}) {
      const lptv::Model m = random_model(K, 5 * K + 1, depth);
      const int L = 40;
      const lptv::Grid g = lptv::make_grid(m, L);
      const Eigen::MatrixXcd U = random_rhs(g.N, 2, K + 11);
      const lptv::SmallBandLU lu(g.N, K, band_storage(lptv::build_A(m, g), K), col_label);
      CAPTURE(K, depth);
      REQUIRE(lptv::solve_grid(m, L, U, lptv::Solver::Band).Y == lu.solve(lptv::apply_B(m, g, U)));
    }
  }
}

TEST_CASE("the kernels' AVX2 and scalar instances give the same bits", "[band][fds]") {
  // The AVX2 instances pair complex numbers in vector registers with the scalar code's
  // products and sums in the same order (band_kernel.hpp): every result must be identical.
  // Routes: the half-grid route (real input, one and three inputs: nz = 2 and 4 with the
  // check), the full-grid route (general input, nz = 3), SmallBandLU (1, 2, 3 and 17 columns,
  // pivoting bands), for every unrolled bandwidth and the runtime-K code.
  lptv::detail::set_avx2_kernels(true);
  if (!lptv::detail::avx2_kernels()) {
    WARN("this processor has no AVX2: only the scalar instances run here");
    return;
  }
  struct Restore {
    ~Restore() { lptv::detail::set_avx2_kernels(true); }
  } restore;
  auto both = [](const auto& run) {
    lptv::detail::set_avx2_kernels(false);
    const auto scalar = run();
    lptv::detail::set_avx2_kernels(true);
    const auto avx2 = run();
    return std::make_pair(scalar, avx2);
  };
  for (int K : {1, 2, 3, 4, 5, 6, 7, 8, 10}) {
    for (double depth : {0.3, 3.0}) {
      CAPTURE(K, depth);
      const lptv::Model m = random_model(K, 17 * K + 3, depth);
      const int L = 50;
      const lptv::Grid g = lptv::make_grid(m, L);
      for (int ncol : {1, 3}) {
        const Eigen::MatrixXcd U = real_input(L, ncol, K + 5);
        const auto half = both([&] { return lptv::solve_grid(m, L, U, lptv::Solver::Band); });
        REQUIRE(half.first.Y == half.second.Y);
        REQUIRE(half.first.condition == half.second.condition);
      }
      const Eigen::MatrixXcd Ug = random_rhs(g.N, 2, K + 9);
      const auto full = both([&] { return lptv::solve_grid(m, L, Ug, lptv::Solver::Band); });
      REQUIRE(full.first.Y == full.second.Y);
      REQUIRE(full.first.condition == full.second.condition);
      const std::vector<cd> ab = random_band(90, K, 41 * K + 1);
      for (int ncol : {1, 2, 3, 17}) {
        const Eigen::MatrixXcd b = random_rhs(90, ncol, K + ncol);
        const auto lu = both([&] { return lptv::SmallBandLU(90, K, ab, col_label).solve(b); });
        REQUIRE(lu.first == lu.second);
      }
    }
  }
}

TEST_CASE("the half-grid route names the line of an exactly singular A", "[fds]") {
  // s^2 + 4 with zero harmonics (Ka = 1): a pole on line 2 / w0. With w0 = 1 the zero pivot is
  // in the band steps (line 2 >= 2K), with w0 = 2 in the corner (line 1 < 2K).
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(3, 3), b = Eigen::MatrixXcd::Zero(1, 3);
  a(0, 1) = 4.0, a(2, 1) = 1.0, b(0, 1) = 1.0;
  for (double w0 : {1.0, 2.0}) {
    const lptv::Model m(a, b, w0);
    const int L = 8;
    const Eigen::MatrixXcd U = real_input(L, 1, 3);
    const std::string line = w0 == 1.0 ? "line 2 " : "line 1 ";
    REQUIRE_THROWS_WITH(lptv::solve_grid(m, L, U, lptv::Solver::Band),
                        Catch::StartsWith("A is singular at " + line));
  }
}

TEST_CASE("the predicted decay beyond the band is the root of a_na's harmonics", "[fds]") {
  // a_1(t) = 1 + 2 rho cos(w0 t + phi): rho e^{-j phi} + lambda + rho e^{j phi} lambda^2 = 0
  // has |lambda| = (1 - sqrt(1 - 4 rho^2)) / (2 rho) and its reciprocal.
  for (double rho : {0.1, 0.3, 0.49}) {
    const cd h = std::polar(rho, 0.7);
    Eigen::MatrixXcd a(2, 3), b(1, 1);
    a << 0.2, 0.5, 0.2, std::conj(h), 1.0, h;
    b << 1.0;
    const double expected = (1 - std::sqrt(1 - 4 * rho * rho)) / (2 * rho);
    REQUIRE(lptv::decay_per_line(lptv::Model(a, b, 0.3)) == Approx(expected).epsilon(1e-12));
  }
  // A constant top coefficient: no coupling at the top order, no prediction.
  Eigen::MatrixXcd a(2, 3), b(1, 1);
  a << 0.1, 1.0, 0.1, 0.0, 1.0, 0.0;
  b << 1.0;
  REQUIRE(lptv::decay_per_line(lptv::Model(a, b, 0.3)) == 0.0);
}
