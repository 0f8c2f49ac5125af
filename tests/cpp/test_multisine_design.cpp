#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "lptv/multisine.hpp"

TEST_CASE("Schroeder's phases for a flat spectrum are -pi k (k - 1) / F", "[design]") {
  const int F = 50;
  const Eigen::VectorXd phi = lptv::schroeder_phases(Eigen::VectorXd::Ones(F));
  for (int k = 1; k <= F; ++k) {
    const double d = std::remainder(phi[k - 1] + M_PI * k * (k - 1) / F, 2 * M_PI);
    REQUIRE(std::abs(d) <= 1e-12);
  }
}

TEST_CASE("crest factor of 50 flat lines: Schroeder about 1.72, minimised <= 1.5", "[design]") {
  const int F = 50, N = 1024;
  std::vector<int> lines(F);
  for (int i = 0; i < F; ++i) lines[i] = i + 1;
  const Eigen::VectorXd A = Eigen::VectorXd::Ones(F);
  const Eigen::VectorXd phi0 = lptv::schroeder_phases(A);
  const auto r = lptv::minimize_crest_factor(lines, A, phi0, N);
  REQUIRE(r.oversample == 1);
  REQUIRE(r.initial_crest_factor > 1.65);
  REQUIRE(r.crest_factor <= 1.5);
  // the reported crest factor is that of the signal built from the returned phases
  const Eigen::VectorXd x = lptv::time_signal(lptv::multisine_spectrum(lines, A, r.phases, N), N);
  REQUIRE(std::abs(lptv::crest_factor(x) - r.crest_factor) <= 1e-12);
  for (size_t i = 1; i < r.best_per_p.size(); ++i) REQUIRE(r.best_per_p[i] <= r.best_per_p[i - 1]);
}

TEST_CASE("the L_p objective's gradient against central differences", "[design]") {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> ud(0.0, 2 * M_PI);
  const std::vector<int> lines{0, 2, 3, 5, 8, 13, 21, 32};
  Eigen::VectorXd A = Eigen::VectorXd::Ones(8), phi(8);
  for (int i = 0; i < 8; ++i) phi[i] = ud(gen);
  Eigen::VectorXd g;
  lptv::lp_norm_log(lines, A, phi, 64, 2, 8, &g);
  REQUIRE(g[0] == 0.0);  // DC keeps its phase
  REQUIRE(g[7] == 0.0);  // and so does line 32, the Nyquist line of N = 64
  for (int i = 1; i < 7; ++i) {
    const double h = 1e-5;
    Eigen::VectorXd p = phi, m = phi;
    p[i] += h;
    m[i] -= h;
    const double fd = (lptv::lp_norm_log(lines, A, p, 64, 2, 8) - lptv::lp_norm_log(lines, A, m, 64, 2, 8)) / (2 * h);
    REQUIRE(std::abs(fd - g[i]) <= 1e-7 * (g.cwiseAbs().maxCoeff() + 1e-3));
  }
}

TEST_CASE("crest design refuses bad input", "[design]") {
  const Eigen::VectorXd A = Eigen::VectorXd::Ones(2), phi = Eigen::VectorXd::Zero(2);
  REQUIRE_THROWS_AS(lptv::minimize_crest_factor({1, 1}, A, phi, 16), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::minimize_crest_factor({1, 9}, A, phi, 16), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::minimize_crest_factor({1, 2}, Eigen::VectorXd::Zero(2), phi, 16), std::invalid_argument);
  lptv::CrestOptions opt;
  opt.max_p = 24;
  REQUIRE_THROWS_AS(lptv::minimize_crest_factor({1, 2}, A, phi, 16, opt), std::invalid_argument);
}
