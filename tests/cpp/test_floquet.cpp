#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <utility>

#include "lptv/errors.hpp"
#include "lptv/floquet.hpp"

using lptv::cd;

namespace {

// Coefficient row: harmonics 1..K given, -k the conjugates.
Eigen::RowVectorXcd row(double dc, std::initializer_list<cd> harmonics) {
  const int K = static_cast<int>(harmonics.size());
  Eigen::RowVectorXcd r = Eigen::RowVectorXcd::Zero(2 * K + 1);
  r[K] = dc;
  int k = 1;
  for (cd c : harmonics) {
    r[K + k] = c;
    r[K - k] = std::conj(c);
    ++k;
  }
  return r;
}

// lptv.examples.paper_model(): a_2(t) varies, so F(t) has the harmonics of 1/a_2(t).
lptv::Model paper_model() {
  Eigen::MatrixXcd a(3, 7), b(2, 7);
  a.row(0) = row(1.0, {cd(0.15, 0.09), cd(-0.06, 0.06), cd(0.03, -0.045)});
  a.row(1) = row(1.0, {cd(0.12, -0.06), cd(0.045, 0.03), cd(-0.03, 0.015)});
  a.row(2) = row(1.0, {cd(-0.09, 0.06), cd(0.03, -0.06), cd(0.024, 0.018)});
  b.row(0) = row(1.0, {cd(0.18, 0.06), cd(-0.09, -0.03), cd(0.03, 0.03)});
  b.row(1) = row(1.0, {cd(-0.12, 0.09), cd(0.06, 0.045), cd(-0.03, -0.03)});
  return lptv::Model(a, b, 0.04);
}

// y'' + 2 zeta wn y' + wn^2 (1 + eps cos(w0 t)) y = u.
lptv::Model mathieu(double zeta, double wn, double eps, double w0) {
  Eigen::MatrixXcd a(3, 3), b(1, 1);
  a << 0.5 * eps * wn * wn, wn * wn, 0.5 * eps * wn * wn, 0.0, 2 * zeta * wn, 0.0, 0.0, 1.0, 0.0;
  b << 1.0;
  return lptv::Model(a, b, w0);
}

// max_i |mu_i - nearest eigenvalue of Phi|.
double distance_to_eig(const Eigen::VectorXcd& mu, const Eigen::MatrixXd& Phi) {
  const Eigen::VectorXcd ev = Eigen::EigenSolver<Eigen::MatrixXd>(Phi).eigenvalues();
  double worst = 0.0;
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    worst = std::max(worst, (ev.array() - mu[i]).abs().minCoeff());
  }
  return worst;
}

}  // namespace

TEST_CASE("LTI: the multipliers are exp(p T0) of the poles", "[floquet]") {
  // (s^2 + 0.4 s + 9.04)(s + 1.5): poles -0.2 +- 3j and -1.5; w0 = 0.5, so 3 = 6 w0.
  Eigen::MatrixXcd a(4, 1), b(1, 1);
  a << 13.56, 9.64, 1.9, 1.0;
  b << 1.0;
  const lptv::Model m(a, b, 0.5);
  const auto f = lptv::floquet(m);
  const double T0 = 2 * M_PI / 0.5;
  REQUIRE(f.method == "hill");
  REQUIRE(f.multipliers.size() == 3);
  const cd p[] = {cd(-0.2, 3.0), cd(-0.2, -3.0), cd(-1.5, 0.0)};
  for (cd pi : p) {
    const cd mu = std::exp(pi * T0);
    REQUIRE((f.multipliers.array() - mu).abs().minCoeff() <= 1e-12 * std::abs(mu));
  }
  // The exponents are the poles reduced to the strip |Im| <= w0/2: -0.2 (twice) and -1.5.
  REQUIRE(f.exponents[0].real() == Approx(-0.2).epsilon(1e-13));
  REQUIRE(std::abs(f.exponents[0].imag()) < 1e-12);
  REQUIRE(f.exponents[2].real() == Approx(-1.5).epsilon(1e-13));
  REQUIRE(f.is_stable);
}

TEST_CASE("Hill's method agrees with the product of matrix exponentials", "[floquet]") {
  for (const lptv::Model& m : {paper_model(), mathieu(0.05, 1.3, 0.3, 2.1)}) {
    const auto f = lptv::floquet(m);
    const Eigen::MatrixXd Phi = lptv::monodromy(m, 4000);
    const double rho = f.spectral_radius;
    INFO("spectral radius " << rho << ", truncation " << f.truncation << ", error "
                            << f.error_estimate.maxCoeff());
    REQUIRE(distance_to_eig(f.multipliers, Phi) <= 1e-8 * rho);
    // Liouville: det Phi = prod mu = exp(int_0^T0 trace F) = exp(-int a_{na-1}/a_na dt).
    cd prod = 1.0;
    for (Eigen::Index i = 0; i < f.multipliers.size(); ++i) prod *= f.multipliers[i];
    REQUIRE(std::abs(prod - Phi.determinant()) <= 1e-8 * std::abs(Phi.determinant()));
  }
}

TEST_CASE("the damped Mathieu equation: stable below eps = 4 zeta, unstable above", "[floquet]") {
  // w0 = 2 wn, zeta = 0.02: the first tongue needs eps > about 4 zeta = 0.08 (METHOD.md 12).
  const auto below = lptv::floquet(mathieu(0.02, 1.0, 0.06, 2.0));
  const auto above = lptv::floquet(mathieu(0.02, 1.0, 0.10, 2.0));
  REQUIRE(below.is_stable);
  REQUIRE_FALSE(above.is_stable);
  REQUIRE(above.spectral_radius > 1.0);
  // In the tongue the multipliers are real and negative (period-doubling), their product
  // exp(-2 zeta wn T0) by Liouville.
  for (const auto& f : {below, above}) {
    REQUIRE(f.multipliers[0].imag() == 0.0);
    REQUIRE(f.multipliers[0].real() < 0.0);
    REQUIRE(f.exponents[0].imag() == Approx(1.0));  // w0 / 2
    REQUIRE((f.multipliers[0] * f.multipliers[1]).real() ==
            Approx(std::exp(-2 * 0.02 * 1.0 * M_PI)).epsilon(1e-12));
  }
}

TEST_CASE("discrete time: the product of the one-step companion matrices", "[floquet]") {
  // y[k+1] + a0[k] y[k] = u[k]: mu = prod_k (-a0[k]).
  const int N = 16;
  Eigen::MatrixXcd a(2, 3), b(1, 1);
  a << cd(0.1, 0.05), -0.7, cd(0.1, -0.05), 0.0, 1.0, 0.0;
  b << 1.0;
  const lptv::Model m(a, b, 2 * M_PI / N, 1.0);
  Eigen::VectorXd t(N);
  for (int k = 0; k < N; ++k) t[k] = k;
  const Eigen::VectorXd a0 = m.a_at(t).col(0);
  double mu = 1.0;
  for (int k = 0; k < N; ++k) mu *= -a0[k];
  const auto f = lptv::floquet(m);
  REQUIRE(f.method == "product");
  REQUIRE(f.multipliers.size() == 1);
  REQUIRE(std::abs(f.multipliers[0] - mu) <= 1e-14 * std::abs(mu));
  REQUIRE(f.exponents[0].real() == Approx(std::log(std::abs(mu)) / N).epsilon(1e-13));
  REQUIRE(f.is_stable == (std::abs(mu) < 1));
  REQUIRE(lptv::monodromy(m, 0)(0, 0) == Approx(mu).epsilon(1e-14));
}

TEST_CASE("floquet refuses a vanishing a_na and reports non-convergence", "[floquet]") {
  Eigen::MatrixXcd a(2, 3), b(1, 1);
  a << 0.0, 1.0, 0.0, 0.3, 0.5, 0.3;  // a_1(t) = 0.5 + 0.6 cos(t) changes sign
  b << 1.0;
  const lptv::Model m(a, b, 1.0);
  REQUIRE_THROWS_WITH(lptv::floquet(m), Catch::Contains("vanishes near t = "));
  REQUIRE_THROWS_AS(lptv::monodromy(m, 100), std::invalid_argument);
  // Discrete time only the samples count: a sign change between them is allowed, a zero
  // sample (a_1[4] = 0.5 - 0.5) is not.
  REQUIRE_NOTHROW(lptv::floquet(lptv::Model(a, b, 2 * M_PI / 8, 1.0)));
  a.row(1) << 0.25, 0.5, 0.25;
  REQUIRE_THROWS_WITH(lptv::floquet(lptv::Model(a, b, 2 * M_PI / 8, 1.0)), Catch::Contains("k = 4"));

  lptv::FloquetOptions opt;
  opt.max_truncation = 9;
  Eigen::MatrixXcd a2 = paper_model().a();
  a2.row(2) = row(1.0, {0.0, 0.0, 0.0});  // F(t) then has 3 harmonics; M = 9 is far too few
  try {
    lptv::floquet(lptv::Model(a2, paper_model().b(), 0.04), opt);
    FAIL("expected NumericalError");
  } catch (const lptv::NumericalError& e) {
    REQUIRE_THAT(e.what(), Catch::Contains("M = "));
  }
  opt = lptv::FloquetOptions();
  opt.tol = 0.0;
  REQUIRE_THROWS_AS(lptv::floquet(paper_model(), opt), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::monodromy(paper_model(), 0), std::invalid_argument);
}

TEST_CASE("product_spectral_radius: the radii of monodromy(m, s) for doubling s, until they settle", "[floquet]") {
  // The same sequence by monodromy itself (each s from scratch): the radius reached and the
  // step count agree, and Hill's method agrees with the radius to its own accuracy.
  auto by_monodromy = [](const lptv::Model& m, int first, int max_steps) {
    double prev = std::numeric_limits<double>::quiet_NaN();
    for (int s = first; s <= max_steps; s *= 2) {
      const double rho = Eigen::EigenSolver<Eigen::MatrixXd>(lptv::monodromy(m, s), false)
                             .eigenvalues().cwiseAbs().maxCoeff();
      if (std::isfinite(prev) && std::abs(rho - prev) < 0.1 * std::abs(rho - 1.0)) return std::make_pair(rho, s);
      prev = rho;
    }
    return std::make_pair(std::numeric_limits<double>::quiet_NaN(), 0);
  };
  for (const lptv::Model& m : {paper_model(), mathieu(0.02, 1.0, 0.06, 2.0), mathieu(0.02, 1.0, 0.10, 2.0)}) {
    const lptv::ProductRadius pr = lptv::product_spectral_radius(m, 32, 4096);
    const auto [rho, steps] = by_monodromy(m, 32, 4096);
    REQUIRE(pr.settled);
    REQUIRE(pr.steps == steps);
    REQUIRE(pr.rho == Approx(rho).epsilon(1e-13));
    // (the paper's model: a radius of about 1e-36, where both routes are accurate to about
    // eps times the norm of the monodromy matrix, not relatively)
    const double hill = lptv::floquet(m).spectral_radius;
    CAPTURE(pr.rho, hill);
    REQUIRE(std::abs(pr.rho - hill) <= 1e-8 * hill + 1e-14);
  }
  // Discrete time: the exact product, settled at once.
  Eigen::MatrixXcd a(2, 3), b(1, 1);
  a << cd(0.1, 0.05), -0.7, cd(0.1, -0.05), 0.0, 1.0, 0.0;
  b << 1.0;
  const lptv::Model dt(a, b, 2 * M_PI / 16, 1.0);
  const lptv::ProductRadius pd = lptv::product_spectral_radius(dt, 32, 4096);
  REQUIRE(pd.settled);
  REQUIRE(pd.steps == 0);
  REQUIRE(pd.rho == Approx(std::abs(lptv::monodromy(dt, 0)(0, 0))).epsilon(1e-15));
  REQUIRE_THROWS_AS(lptv::product_spectral_radius(paper_model(), 0, 64), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::product_spectral_radius(paper_model(), 64, 32), std::invalid_argument);
}

TEST_CASE("several outputs: decoupled LTI rows give each row's exp(p T0); rows of different degrees", "[floquet][mimo]") {
  // diag(s^2 + 0.4 s + 9.04, s + 1.5) with a coupling that is zero: the poles -0.2 +- 3j and
  // -1.5; then the same with a first-order second row coupled through A_0 (triangular: the
  // poles stay those of the diagonal).
  const double w0 = 0.5, T0 = 2 * M_PI / w0;
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(3 * 4, 1), b = Eigen::MatrixXcd::Ones(2, 1);
  // row (n ny + p) ny + q
  a(0 * 4 + 0, 0) = 9.04;  // A_0[0, 0]
  a(0 * 4 + 3, 0) = 1.5;   // A_0[1, 1]
  a(1 * 4 + 0, 0) = 0.4;   // A_1[0, 0]
  a(1 * 4 + 3, 0) = 1.0;   // A_1[1, 1]
  a(2 * 4 + 0, 0) = 1.0;   // A_2[0, 0]; A_2[1, 1] = 0: row 1 of degree 1
  a(0 * 4 + 2, 0) = 0.7;   // A_0[1, 0]: triangular coupling
  const lptv::MimoModel m(a, b, 2, 1, w0);
  REQUIRE(lptv::row_degrees(m) == std::vector<int>{2, 1});
  const auto f = lptv::floquet(m);
  REQUIRE(f.multipliers.size() == 3);
  for (cd p : {cd(-0.2, 3.0), cd(-0.2, -3.0), cd(-1.5, 0.0)}) {
    const cd mu = std::exp(p * T0);
    REQUIRE((f.multipliers.array() - mu).abs().minCoeff() <= 1e-12 * std::abs(mu));
  }
  REQUIRE(f.is_stable);
}

TEST_CASE("several outputs: a 1 x 1 model has the SISO multipliers", "[floquet][mimo]") {
  for (const lptv::Model& m : {paper_model(), mathieu(0.05, 1.3, 0.3, 2.1), mathieu(0.02, 1.0, 0.1, 2.0)}) {
    const auto f = lptv::floquet(m);
    const auto g = lptv::floquet(lptv::MimoModel(m));
    REQUIRE(g.is_stable == f.is_stable);
    REQUIRE(g.multipliers.size() == f.multipliers.size());
    for (Eigen::Index i = 0; i < f.multipliers.size(); ++i) {
      const double tol = 2 * (f.error_estimate[i] + g.error_estimate[i]) * std::abs(f.multipliers[i]);
      REQUIRE(std::abs(g.multipliers[i] - f.multipliers[i]) <= tol);
    }
  }
}

TEST_CASE("several outputs: a singular leading row coefficient matrix is refused", "[floquet][mimo]") {
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(2 * 4, 3), b = Eigen::MatrixXcd::Ones(2, 1);
  a(4 + 0, 1) = a(4 + 3, 1) = 1.0;  // A_1 = I + the (0, 0) entry's cos(t)
  a(4 + 0, 0) = a(4 + 0, 2) = 0.5;  // A_1[0, 0](t) = 1 + cos(t): zero at t = pi
  a(0, 1) = a(3, 1) = 0.3;
  REQUIRE_THROWS_AS(lptv::floquet(lptv::MimoModel(a, b, 2, 1, 1.0)), std::invalid_argument);
}

TEST_CASE("several outputs: Hill's multipliers are the eigenvalues of the products", "[floquet][mimo]") {
  // Two masses, M = diag(1, 2), C = 0.02 M, coupling spring 2 (1 + depth cos(w0 t)) pumped at
  // w0 = 2 w_1 = 2.8917: stable at depth 0.05, unstable at 0.4.
  for (double depth : {0.05, 0.4}) {
    Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(3 * 4, 3), b = Eigen::MatrixXcd::Zero(4, 1);
    const double K[2][2] = {{7.0, -2.0}, {-2.0, 5.0}}, S[2][2] = {{1.0, -1.0}, {-1.0, 1.0}};
    for (int p = 0; p < 2; ++p) {
      for (int q = 0; q < 2; ++q) {
        a(p * 2 + q, 1) = K[p][q];
        a(p * 2 + q, 0) = a(p * 2 + q, 2) = depth * S[p][q];
      }
      a(4 + p * 3, 1) = 0.02 * (p + 1);
      a(8 + p * 3, 1) = 1.0 * (p + 1);
      b(p * 3, 0) = 1.0;
    }
    const double w1 = std::sqrt((19.0 - std::sqrt(113.0)) / 4.0);
    const lptv::MimoModel m(a, b, 2, 2, 2 * w1);
    const auto f = lptv::floquet(m);
    const Eigen::MatrixXd Phi = lptv::monodromy(m, 2000);
    REQUIRE(f.multipliers.size() == 4);
    REQUIRE(distance_to_eig(f.multipliers, Phi) <= 1e-10 * Phi.norm());
    REQUIRE(f.is_stable == (depth < 0.1));
  }
}
