#include <catch2/catch.hpp>

#include "lptv/model.hpp"

using lptv::cd;

TEST_CASE("model validates its coefficients", "[model]") {
  Eigen::MatrixXcd a(2, 3), b(1, 1);
  a << cd(0.1, 0.2), 1.0, cd(0.1, -0.2), 0.0, 1.0, 0.0;
  b << 1.0;
  REQUIRE_NOTHROW(lptv::Model(a, b, 1.0));
  Eigen::MatrixXcd bad = a;
  bad(0, 0) = cd(0.1, 0.3);
  REQUIRE_THROWS_AS(lptv::Model(bad, b, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::Model(a, b, -1.0), std::invalid_argument);
  Eigen::MatrixXcd even(2, 2);
  even.setOnes();
  REQUIRE_THROWS_AS(lptv::Model(even, b, 1.0), std::invalid_argument);
  bad = a;
  bad(1, 1) = NAN;
  REQUIRE_THROWS_AS(lptv::Model(bad, b, 1.0), std::invalid_argument);
}

TEST_CASE("coefficients evaluate as real Fourier series", "[model]") {
  Eigen::MatrixXcd a(1, 3), b(1, 1);
  a << cd(0.1, 0.2), 2.0, cd(0.1, -0.2);
  b << 1.0;
  lptv::Model m(a, b, 2.0);
  Eigen::VectorXd t(3);
  t << 0.0, 0.3, 1.7;
  const Eigen::MatrixXd v = m.a_at(t);
  for (int i = 0; i < 3; ++i) {
    // 2 + 2 Re((0.1 - 0.2j) e^{j 2 t})
    const double expect = 2.0 + 2.0 * (cd(0.1, -0.2) * std::polar(1.0, 2.0 * t[i])).real();
    REQUIRE(v(i, 0) == Approx(expect).epsilon(1e-14));
  }
}

TEST_CASE("discrete-time grid must be whole", "[model]") {
  Eigen::MatrixXcd a(2, 1), b(1, 1);
  a << 0.5, 1.0;
  b << 1.0;
  REQUIRE(lptv::Model(a, b, 2 * M_PI / 64, 1.0).samples_per_period() == 64);
  REQUIRE_THROWS_AS(lptv::Model(a, b, 1.0, 1.0), std::invalid_argument);
}
