#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <complex>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "lptv/moderation.hpp"

namespace {

// Relative difference, for the comparisons with SciPy's values.
double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

// Values from SciPy 1.17.1 (scipy.special.digamma, scipy.special.polygamma(1, x) and
// polygamma(2, x), scipy.special.betainc, scipy.stats.f.isf), printed with repr.
struct Polygammas { double x, psi0, psi1, psi2; };
const Polygammas kPolygammas[] = {
    {0.001, -1000.5755719318103, 1000001.6425331959, -2000000002.3976321},
    {0.1, -10.423754940411076, 101.43329915079275, -2001.8614573783439},
    {0.5, -1.9635100260214235, 4.93480220054468, -16.828796644234316},
    {1.0, -0.5772156649015329, 1.6449340668482266, -2.404113806319188},
    {2.0, 0.42278433509846713, 0.6449340668482266, -0.4041138063191886},
    {3.0, 0.9227843350984671, 0.39493406684822646, -0.15411380631918856},
    {3.7, 1.1671535393615113, 0.31003785767003833, -0.09539530872855405},
    {7.0, 1.872784335098467, 0.15354517795933756, -0.023530472985855234},
    {15.0, 2.6743466616607936, 0.0689382278476838, -0.004750602716551555},
    {19.5, 2.944554343425595, 0.05261944121365593, -0.0027681678527467016},
    {20.0, 2.970523992242149, 0.051270822935203124, -0.0026281224023146543},
    {31.0, 3.4177714660188583, 0.03278394924662884, -0.0010746911296545256},
    {123.4, 4.8113737751162775, 0.008136651610865263, -6.620473419231093e-05},
    {10000.0, 9.21029037114285, 0.00010000500016666666, -1.0001000050000002e-08},
    {1000000.0, 13.81551005796419, 1.0000005000001667e-06, -1.0000010000005002e-12},
};

struct FQuantile { double p, d1, d2, f; };
const FQuantile kFQuantiles[] = {
    {0.001, 6.0, 6.0, 20.02965472188272},
    {0.001, 6.0, 60.0, 4.372054608726788},
    {0.001, 6.0, 120.0, 4.043746614524752},
    {0.001, 2.0, 2.0, 998.9999999999991},
    {0.001, 62.0, 1240.0, 1.675852799894563},
    {0.001, 14.0, 280.0, 2.6934806558845406},
    {0.05, 3.0, 7.0, 4.346831399907814},
    {0.5, 6.0, 36.0, 0.9082535161815926},
    {0.001, 30.0, 30.0, 3.2170903215322832},
    {1e-06, 6.0, 12.0, 32.26069393206011},
    {0.9, 4.0, 10.0, 0.25511013641558666},
};

struct Beta { double a, b, x, value; };
const Beta kBetas[] = {
    {3.0, 30.0, 0.05, 0.21388552705899083},
    {3.0, 3.0, 0.5, 0.5},
    {0.5, 2.5, 0.9, 0.9988855624584926},
    {31.0, 620.0, 0.06, 0.9238121886679782},
    {10.0, 2.0, 0.999, 0.9999453290118457},
};

}  // namespace

TEST_CASE("Moderation: digamma, trigamma and tetragamma agree with SciPy", "[moderation]") {
  for (const auto& v : kPolygammas) {
    INFO("x = " << v.x);
    CHECK(rel(lptv::digamma(v.x), v.psi0) < 1e-12);
    CHECK(rel(lptv::trigamma(v.x), v.psi1) < 1e-12);
    CHECK(rel(lptv::tetragamma(v.x), v.psi2) < 1e-12);
  }
  CHECK(std::isnan(lptv::digamma(0.0)));
  CHECK(std::isnan(lptv::trigamma(-1.0)));
  CHECK(std::isnan(lptv::tetragamma(std::nan(""))));
}

TEST_CASE("Moderation: the inverse trigamma inverts the trigamma", "[moderation]") {
  // Smyth's iteration stops at a relative step of 1e-10, quadratically convergent, so the
  // result is good to far better than that; over the range the moderation meets.
  for (double y : {1e-3, 0.05, 0.5, 1.0, 3.0, 10.0, 250.0, 4e4, 4e5}) {
    INFO("y = " << y);
    CHECK(rel(lptv::trigamma_inverse(lptv::trigamma(y)), y) < 1e-12);
  }
}

TEST_CASE("Moderation: the incomplete beta function and the F quantile agree with SciPy", "[moderation]") {
  for (const auto& v : kBetas) {
    INFO("a = " << v.a << ", b = " << v.b << ", x = " << v.x);
    CHECK(rel(lptv::incomplete_beta(v.a, v.b, v.x), v.value) < 1e-12);
  }
  for (const auto& v : kFQuantiles) {
    INFO("p = " << v.p << ", d1 = " << v.d1 << ", d2 = " << v.d2);
    CHECK(rel(lptv::f_upper_quantile(v.p, v.d1, v.d2), v.f) < 1e-9);
  }
  // F(2, 2): P(F > f) = 1 / (1 + f), so the upper 1e-3 point is 999 exactly.
  CHECK(rel(lptv::f_upper_quantile(1e-3, 2.0, 2.0), 999.0) < 1e-12);
  CHECK(std::isnan(lptv::f_upper_quantile(0.0, 2.0, 2.0)));
  CHECK(std::isnan(lptv::f_upper_quantile(0.5, 0.0, 2.0)));
}

namespace {

// Lines 0..L of constant variances vu, vy (covariance c) from P periods, spectra zero.
lptv::FrequencyData constant_noise(int L, int P, double vu, double vy, std::complex<double> c) {
  lptv::FrequencyData d;
  d.U = Eigen::VectorXcd::Zero(L + 1);
  d.Y = Eigen::VectorXcd::Zero(L + 1);
  d.varU = Eigen::VectorXd::Constant(L + 1, vu);
  d.varY = Eigen::VectorXd::Constant(L + 1, vy);
  d.covYU = Eigen::VectorXcd::Constant(L + 1, c);
  d.periods = P;
  return d;
}

}  // namespace

// The shape factor (k, v) of inner line i (0-based, m inner lines) for log variances exactly
// constant: the fitted shape is zero and k = n / sum_j exp(-q_j / 2) with q_j the fit's variance
// at x_j from the window's geometry alone (METHOD.md section 7, "the spectrum's shape"); k = 1,
// v = 0 with fewer than 2 W lines within +-2 W (near the first and last lines the window is
// one-sided and the trend extrapolated).
std::pair<double, double> flat_shape(int i, int m, int W, double var_log) {
  const int S = 2 * W;
  if (std::min(i, S) + std::min(m - 1 - i, S) < 2 * W) return {1.0, 0.0};
  double C[5] = {0, 0, 0, 0, 0};
  for (int x = -S; x <= S; ++x) {
    if (x == 0 || i + x < 0 || i + x >= m) continue;
    for (int q = 0; q < 5; ++q) C[q] += std::pow(static_cast<double>(x), q);
  }
  Eigen::Matrix3d A;
  A << C[0], C[1], C[2], C[1], C[2], C[3], C[2], C[3], C[4];
  const Eigen::Matrix2d V = var_log * A.inverse().bottomRightCorner<2, 2>();
  double es = 0, ex = 0, ex2 = 0;
  int n = 0;
  for (int x = -W; x <= W; ++x) {
    if (x == 0 || i + x < 0 || i + x >= m) continue;
    const Eigen::Vector2d X(x, static_cast<double>(x) * x);
    const double e = std::exp(-0.5 * X.dot(V * X));
    es += e;
    ex += e * X[0];
    ex2 += e * X[1];
    ++n;
  }
  const Eigen::Vector2d a(ex / es, ex2 / es);
  return {n / es, a.dot(V * a)};
}

TEST_CASE("Moderation: variances exactly as smooth as their trend", "[moderation]") {
  // No spread of log s^2 about the neighbours' mean: d0 at its cap; every inner line gets
  // w v + (1 - w) (d0 - 2) / d0 k v, w = d / (d + d0), k the shape factor of a flat trend, and
  // dof (d + d0)^2 / (d + d0 + d0^2 (1 / (n d) + v_k / 2)).
  const int L = 100, P = 4, W = 5;
  const double d = 6.0, d0 = lptv::kModerationMaxPriorDof, w = d / (d + d0);
  const auto data = constant_noise(L, P, 0.01, 0.04, {0.01, 0.0});
  const auto mod = lptv::moderated_noise(data, W);
  REQUIRE(mod.moderated);
  CHECK(mod.prior_dof == d0);
  CHECK(mod.outliers.empty());
  CHECK(mod.dof[0] == 3.0);
  CHECK(mod.dof[L] == 3.0);
  CHECK(mod.data.varU[0] == 0.01);
  for (int l : {1, 2, 5, 6, 50, 94, 95, 99}) {
    INFO("line " << l);
    const double n = std::min(l - 1, W) + std::min(L - 1 - l, W);
    const auto [k, vk] = flat_shape(l - 1, L - 1, W, lptv::trigamma(d / 2));
    if (l == 50) CHECK(k > 1.0);                  // the fit's noise taken out of a flat shape
    if (l == 1) CHECK(k > 1.0);                   // the first line too: the trend extrapolated by one line
    const double want = w * 0.04 + (1 - w) * (d0 - 2) / d0 * k * 0.04;
    // The neighbours' sums come from running sums over the lines (L v at most against 2 W v).
    CHECK(std::abs(mod.data.varY[l] - want) <= 1e-13 * want);
    CHECK(std::abs(mod.dof[l] - (d + d0) * (d + d0) / (d + d0 + d0 * d0 * (1.0 / (n * d) + vk / 2.0)))
          <= 1e-12 * mod.dof[l]);
    CHECK(mod.own_weight[l] == w);
    CHECK(mod.neighbour[l]);
    // |covYU|^2 <= varU varY kept: here |c| = sqrt(varU varY) before and after.
    CHECK(std::norm(mod.data.covYU[l]) <= mod.data.varU[l] * mod.data.varY[l]);
  }
  CHECK(!mod.neighbour[0]);
  CHECK(!mod.neighbour[L]);
}

TEST_CASE("Moderation: a line far above its neighbours keeps its own variance", "[moderation]") {
  // Variances alternating between 0.02 and 0.005: log residuals of +-ln(4)/2, a mean square of
  // 0.48 / (1 + 1/20) above trigamma(3) = 0.39, so d0 is finite; and one line at 50 times.
  const int L = 120, P = 4;
  auto data = constant_noise(L, P, 0.01, 0.01, {0.0, 0.0});
  for (int l = 0; l <= L; ++l) data.varU[l] = data.varY[l] = (l % 2) ? 0.02 : 0.005;
  data.varY[60] = 1.0;
  const auto mod = lptv::moderated_noise(data, 10);
  REQUIRE(mod.moderated);
  REQUIRE(mod.outliers == std::vector<int>{60});
  CHECK(mod.data.varY[60] == 1.0);
  CHECK(mod.dof[60] == 6.0);
  CHECK(mod.own_weight[60] == 1.0);
  CHECK(!mod.neighbour[60]);
  CHECK(mod.prior_dof > 0.0);
  CHECK(mod.prior_dof < lptv::kModerationMaxPriorDof);
  CHECK(mod.data.varY[59] < 0.02);   // the outlier is not in its neighbours' mean (about 0.0125)
  // Its sampling errors are its own: weight 1, so 1 / (P - 1) on the diagonal, and it is no
  // neighbour of line 59.
  const Eigen::MatrixXd C = mod.error_covariance({59, 60});
  CHECK(std::abs(C(1, 1) - 1.0 / 3.0) < 1e-15);
  CHECK(C(0, 1) == 0.0);
  CHECK_THROWS_AS(mod.error_covariance({L + 1}), std::invalid_argument);
}

TEST_CASE("Moderation: data that cannot be moderated come back unchanged", "[moderation]") {
  const auto few = lptv::moderated_noise(constant_noise(31, 4, 0.01, 0.01, {}), 10);   // 31 < 32
  CHECK(!few.moderated);
  CHECK(few.prior_dof == 0.0);
  CHECK(few.dof[1] == 6.0);
  CHECK(few.dof[0] == 3.0);
  CHECK(few.own_weight.size() == 0);
  const auto no_periods = lptv::moderated_noise(constant_noise(100, 0, 0.01, 0.01, {}), 10);
  CHECK(!no_periods.moderated);
  CHECK(std::isinf(no_periods.dof[5]));
  CHECK(no_periods.error_covariance({1, 2}).isZero());
  const auto silent = lptv::moderated_noise(constant_noise(100, 4, 0.0, 0.0, {}), 10);
  CHECK(!silent.moderated);
  CHECK_THROWS_AS(lptv::moderated_noise(constant_noise(100, 4, 0.01, 0.01, {}), 0), std::invalid_argument);
  auto bad = constant_noise(100, 4, 0.01, 0.01, {});
  bad.varY[3] = -1.0;
  CHECK_THROWS_AS(lptv::moderated_noise(bad, 10), std::invalid_argument);
}

TEST_CASE("Moderation of several channels: two channels are the single-channel moderation", "[moderation]") {
  // Variances that scatter about a sloping trend (a deterministic pattern, no random numbers),
  // a spike on the output: the matrix [[varY, covYU], [conj covYU, varU]] per line moderates
  // exactly as the pair.
  const int L = 120, P = 4;
  lptv::FrequencyData d = constant_noise(L, P, 0.01, 0.04, {0.002, 0.001});
  for (int l = 0; l <= L; ++l) {
    d.varU[l] *= std::exp(-0.01 * l + 0.4 * std::sin(1.7 * l));
    d.varY[l] *= std::exp(0.02 * l + 0.5 * std::cos(2.3 * l));
  }
  d.varY[60] *= 50.0;
  const auto one = lptv::moderated_noise(d, 8);
  Eigen::MatrixXcd C(2 * (L + 1), 2);
  for (int l = 0; l <= L; ++l) {
    C(2 * l, 0) = d.varY[l];
    C(2 * l, 1) = d.covYU[l];
    C(2 * l + 1, 0) = std::conj(d.covYU[l]);
    C(2 * l + 1, 1) = d.varU[l];
  }
  const auto two = lptv::moderated_covariances(C, 1, P, 8);
  REQUIRE(one.moderated);
  REQUIRE(two.moderated);
  CHECK(two.prior_dof == one.prior_dof);
  CHECK(two.outliers == one.outliers);
  CHECK(std::find(two.outliers.begin(), two.outliers.end(), 60) != two.outliers.end());
  for (int l = 0; l <= L; ++l) {
    INFO("line " << l);
    CHECK(std::abs(two.covariance(2 * l, 0).real() - one.data.varY[l]) <= 1e-14 * one.data.varY[l]);
    CHECK(std::abs(two.covariance(2 * l + 1, 1).real() - one.data.varU[l]) <= 1e-14 * one.data.varU[l]);
    CHECK(std::abs(two.covariance(2 * l, 1) - one.data.covYU[l]) <= 1e-14 * std::sqrt(one.data.varU[l] * one.data.varY[l]));
    CHECK(two.dof[l] == one.dof[l]);
    CHECK(two.own_weight[l] == one.own_weight[l]);
  }
}

TEST_CASE("Moderation of several channels: bad arguments throw, too few lines come back unchanged", "[moderation]") {
  const Eigen::MatrixXcd C = Eigen::MatrixXcd::Identity(3, 3).replicate(41, 1);   // 41 lines, 3 channels
  CHECK_THROWS_AS(lptv::moderated_covariances(C, 0, 4, 10), std::invalid_argument);
  CHECK_THROWS_AS(lptv::moderated_covariances(C, 3, 4, 10), std::invalid_argument);
  CHECK_THROWS_AS(lptv::moderated_covariances(C, 2, -1, 10), std::invalid_argument);
  CHECK_THROWS_AS(lptv::moderated_covariances(C, 2, 4, 0), std::invalid_argument);
  CHECK_THROWS_AS(lptv::moderated_covariances(C.topRows(121), 2, 4, 10), std::invalid_argument);
  Eigen::MatrixXcd bad = C;
  bad(5, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(lptv::moderated_covariances(bad, 2, 4, 10), std::invalid_argument);
  const auto few = lptv::moderated_covariances(C.topRows(3 * 31), 2, 4, 10);   // Lmax = 30 < 32
  CHECK_FALSE(few.moderated);
  CHECK(few.prior_dof == 0.0);
  CHECK(few.covariance == C.topRows(3 * 31));
  const auto flat = lptv::moderated_covariances(C, 2, 4, 10);                   // exactly flat: d0 at its cap
  CHECK(flat.moderated);
  CHECK(flat.prior_dof == lptv::kModerationMaxPriorDof);
}
