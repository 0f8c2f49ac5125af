#include <catch2/catch.hpp>

#include "lptv/fds.hpp"
#include "lptv/htf_estimate.hpp"

using lptv::cd;

TEST_CASE("HTF estimate: exact branches of a modulated input through an LTI filter", "[htf]") {
  // y = 1/(s+1) [(1 + 0.5 cos(w0 t)) u]: G_k(w_l) = b_k / (j w_{l+k} + 1), b_{+-1} = 0.25, b_0 = 1.
  Eigen::MatrixXcd a(2, 1), b(1, 3);
  a << 1.0, 1.0;
  b << 0.25, 1.0, 0.25;
  const double w0 = 0.1;
  const lptv::Model m(a, b, w0);
  const int L = 100;
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(L + 1, 1);
  const std::vector<int> lines = {10, 20, 30, 40};
  for (int l : lines) U(l, 0) = std::polar(1.0, 0.3 * l);
  lptv::FrequencyData d;
  d.U = U.col(0);
  d.Y = lptv::simulate(m, U).Y.col(0);
  d.varU = d.varY = Eigen::VectorXd::Constant(L + 1, 1e-6);
  d.covYU = Eigen::VectorXcd::Zero(L + 1);
  REQUIRE(lptv::excited_lines(d) == lines);
  const lptv::HtfEstimate h = lptv::htf_estimate(d, lines, 2);
  for (size_t i = 0; i < lines.size(); ++i)
    for (int k = -2; k <= 2; ++k) {
      const cd bk = std::abs(k) == 1 ? 0.25 : k == 0 ? 1.0 : 0.0;
      const cd expected = bk / cd(1.0, w0 * (lines[i] + k));
      REQUIRE(std::abs(h.G(2 + k, i) - expected) < 1e-13);
      REQUIRE(h.variance(2 + k, i) > 0);
    }
  REQUIRE_THROWS_AS(lptv::htf_estimate(d, {10, 13}, 2), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::htf_estimate(d, {2}, 2), std::invalid_argument);
}
