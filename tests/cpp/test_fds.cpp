#include <catch2/catch.hpp>
#include <random>

#include "lptv/errors.hpp"
#include "lptv/fds.hpp"
#include "lptv/multisine.hpp"

using lptv::cd;

TEST_CASE("LTI FDS equals B(jw)/A(jw) U", "[fds]") {
  Eigen::MatrixXcd a(3, 1), b(2, 1);
  a << 1.0, 1.0, 1.0;
  b << 1.0, 1.0;
  lptv::Model m(a, b, 0.5);
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(21, 1);
  for (int l = 1; l <= 20; ++l) U(l, 0) = std::polar(1.0, 0.3 * l);
  for (auto solver : {lptv::Solver::KLU, lptv::Solver::UMFPACK}) {
    lptv::SimulateOptions opt;
    opt.solver = solver;
    const auto r = lptv::simulate(m, U, opt);
    for (int l = 0; l <= 20; ++l) {
      const cd s(0.0, 0.5 * l);
      const cd G = (1.0 + s) / (1.0 + s + s * s);
      REQUIRE(std::abs(r.Y(l, 0) - G * U(l, 0)) <= 1e-14 * std::abs(U(l, 0)) + 1e-300);
    }
  }
}

TEST_CASE("discrete-time LPTV FDS equals the time recursion", "[fds]") {
  // y[t+1] = -a0[t]/a1 y[t] + b0 u[t]:  a_0(t) y[t] + y[t+1] = u[t]
  const int N = 32;
  Eigen::MatrixXcd a(2, 3), b(1, 1);
  a << cd(0.1, 0.05), -0.5, cd(0.1, -0.05), 0.0, 1.0, 0.0;
  b << 1.0;
  lptv::Model m(a, b, 2 * M_PI / N, 1.0);
  std::mt19937 gen(3);
  std::normal_distribution<double> nd;
  Eigen::VectorXd u(N);
  for (int t = 0; t < N; ++t) u[t] = nd(gen);
  Eigen::VectorXd tt(N);
  for (int t = 0; t < N; ++t) tt[t] = t;
  const Eigen::VectorXd a0 = m.a_at(tt).col(0);
  // Periodic steady state by running many periods (|a0| < 1 contracts).
  double y = 0;
  Eigen::VectorXd ys(N);
  for (int p = 0; p < 200; ++p) {
    for (int t = 0; t < N; ++t) {
      ys[t] = y;
      y = -a0[t] * y + u[t];
    }
  }
  const Eigen::VectorXcd Yt = lptv::spectrum(ys);
  const auto r = lptv::simulate(m, lptv::spectrum(u));
  REQUIRE((r.Y.col(0) - Yt).cwiseAbs().maxCoeff() <= 1e-12 * Yt.cwiseAbs().maxCoeff());
}

TEST_CASE("a pole on a grid line is reported by line", "[fds]") {
  Eigen::MatrixXcd a(3, 1), b(1, 1);
  a << 4.0, 0.0, 1.0;  // s^2 + 4: poles at +-2j, i.e. line +-2 for w0 = 1
  b << 1.0;
  lptv::Model m(a, b, 1.0);
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Ones(4, 1);
  try {
    lptv::simulate(m, U);
    FAIL("expected NumericalError");
  } catch (const lptv::NumericalError& e) {
    REQUIRE_THAT(e.what(), Catch::Contains("line -2") || Catch::Contains("line 2"));
  }
}

TEST_CASE("multisine spectrum and time signal round-trip", "[multisine]") {
  std::vector<int> lines{1, 5, 7, 16};
  Eigen::VectorXd amp(4), ph(4);
  amp << 1.0, 0.5, 2.0, 1.5;
  ph << 0.1, 2.0, 4.0, 1.0;
  const int N = 32;
  const Eigen::VectorXcd X = lptv::multisine_spectrum(lines, amp, ph, N);
  const Eigen::VectorXd x = lptv::time_signal(X, N);
  for (int t = 0; t < N; ++t) {
    double v = 0;
    for (int i = 0; i < 4; ++i) v += amp[i] * std::cos(2 * M_PI * lines[i] * t / N + ph[i]);
    REQUIRE(x[t] == Approx(v).margin(1e-12));
  }
  REQUIRE((lptv::spectrum(x) - X).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("band and sparse backends agree on an LPTV model", "[fds]") {
  Eigen::MatrixXcd a(3, 5), b(2, 3);
  a << cd(0.02, 0.01), cd(0.1, 0.05), 1.0, cd(0.1, -0.05), cd(0.02, -0.01),
      0.0, cd(-0.05, 0.02), 0.8, cd(-0.05, -0.02), 0.0,
      0.0, 0.0, 1.0, 0.0, 0.0;
  b << cd(0.08, -0.03), 1.0, cd(0.08, 0.03), 0.0, 0.5, 0.0;
  lptv::Model m(a, b, 0.2);
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(41, 2);
  for (int l = 1; l <= 30; l += 3) U(l, 0) = std::polar(1.0, 0.7 * l), U(l, 1) = std::polar(0.5, -0.2 * l);
  lptv::SimulateOptions opt;
  opt.guard = 40;
  opt.solver = lptv::Solver::Band;
  const auto band = lptv::simulate(m, U, opt);
  opt.solver = lptv::Solver::KLU;
  const auto klu = lptv::simulate(m, U, opt);
  REQUIRE(band.solver == lptv::Solver::Band);
  REQUIRE((band.Y - klu.Y).cwiseAbs().maxCoeff() <= 1e-13 * klu.Y.cwiseAbs().maxCoeff());
}

TEST_CASE("simulate reports the condition of the lines with input, and where", "[fds]") {
  // s^2 + d s + wn^2 with wn = 1 on line 1 (w0 = 1): the line's condition is (2 + d) / d
  const double d = 1e-12;
  Eigen::MatrixXcd a(3, 1), b(1, 1);
  a << 1.0, d, 1.0;
  b << 1.0;
  const lptv::Model m(a, b, 1.0);
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(4, 1);
  U(1, 0) = 0.5;
  const auto r = lptv::simulate(m, U);
  REQUIRE(r.condition > lptv::Fds::kWarnCondition);
  REQUIRE(std::abs(r.condition - (2 + d) / d) <= 1e-12 * r.condition);
  REQUIRE(r.condition_line == 1);
  // input on line 3 only: LTI lines do not couple, line 1 loses nothing
  U(1, 0) = 0.0;
  U(3, 0) = 0.5;
  const auto q = lptv::simulate(m, U);
  REQUIRE(q.condition < lptv::Fds::kWarnCondition);
  REQUIRE(q.condition_line == 3);
  // an LPTV model (b(t) time-varying) reports the grid's maximum, on line 1
  Eigen::MatrixXcd bt(1, 3);
  bt << 0.2, 1.0, 0.2;
  U(3, 0) = 0.0;
  U(2, 0) = 0.5;
  const auto p = lptv::simulate(lptv::Model(a, bt, 1.0), U);
  REQUIRE(p.condition > lptv::Fds::kWarnCondition);
  REQUIRE(p.condition_line == 1);
}

TEST_CASE("sizes near INT_MAX are refused before anything is allocated", "[fds][limits]") {
  Eigen::MatrixXcd a(2, 3), b(1, 1);
  a << cd(0.1, 0.0), 2.0, cd(0.1, 0.0), 0.0, 1.0, 0.0;
  b << 1.0;
  const lptv::Model ct(a, b, 0.1);
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Ones(10, 1);
  // A fixed guard near INT_MAX: highest line + guard overflowed an int (negative L).
  lptv::SimulateOptions opt;
  opt.guard = 2147483647;
  REQUIRE_THROWS_WITH(lptv::simulate(ct, U, opt),
                      Catch::Contains("-2147483656..2147483656 is too large") && Catch::Contains("GB"));
  // A discrete-time grid of 2^31 - 1 lines was allocated (std::bad_alloc).
  Eigen::MatrixXcd ad(2, 1), bd(1, 1);
  ad << 0.3, 1.0;
  bd << 1.0;
  const lptv::Model dt(ad, bd, 2 * M_PI / 2147483647.0, 1.0);
  REQUIRE(dt.samples_per_period() == 2147483647);
  REQUIRE_THROWS_WITH(lptv::make_grid(dt, 0), Catch::Contains("2147483647 samples per period is too large"));
  REQUIRE_THROWS_WITH(lptv::simulate(dt, Eigen::MatrixXcd::Ones(3, 1)),
                      Catch::Contains("2147483647 samples per period is too large"));
  // The largest grid still passes the check: 2^27 + 1 samples per period (no simulation here).
  const lptv::Model dt_max(ad, bd, 2 * M_PI / 134217729.0, 1.0);
  REQUIRE(lptv::make_grid(dt_max, 0).N == 134217729);
  // A multisine period of 2^31 - 1 samples: the same bound (it was allocated, std::bad_alloc).
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  REQUIRE_THROWS_WITH(lptv::multisine_spectrum({1}, one, one, 2147483647),
                      Catch::Contains("n_samples = 2147483647 is too large (at most 134217729"));
  REQUIRE_THROWS_WITH(lptv::time_signal(Eigen::VectorXcd::Ones(1), 134217730),
                      Catch::Contains("n_samples = 134217730 is too large"));
}
