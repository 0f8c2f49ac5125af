#include <catch2/catch.hpp>

#include <cmath>

#include "lptv/distortion.hpp"
#include "lptv/errors.hpp"

using cd = std::complex<double>;

namespace {

lptv::DistortionInput zeros(int M, int L) {
  lptv::DistortionInput in;
  in.U = Eigen::MatrixXcd::Zero(M, L + 1);
  in.Y = Eigen::MatrixXcd::Zero(M, L + 1);
  in.varU = Eigen::MatrixXd::Zero(M, L + 1);
  in.varY = Eigen::MatrixXd::Zero(M, L + 1);
  in.covYU = Eigen::MatrixXcd::Zero(M, L + 1);
  return in;
}

}  // namespace

TEST_CASE("Distortion: an exactly linear system is recovered, conjugate regressor included", "[distortion]") {
  // Lines 1 and 4 excited, Kh = 2. Line 1 regresses on U_1 and conj(U_1) (|1 - (-1)| = 2), and
  // Y_1 = a U_1 + b conj(U_1); line 4 is an LTI gain, Y_4 = h U_4; lines 2, 3, 5, 6 see
  // regressors but carry no output; nothing else is on the lines. Random phases per realisation.
  const int M = 5, L = 6;
  lptv::DistortionInput in = zeros(M, L);
  in.excited = {1, 4};
  in.branches = 2;
  const cd a(0.7, -0.2), b(0.1, 0.3), h(-1.5, 0.5);
  for (int m = 0; m < M; ++m) {
    in.U(m, 1) = std::polar(1.0, 1.3 * m + 0.2);
    in.U(m, 4) = std::polar(2.0, 2.9 * m * m + 0.5);
    in.Y(m, 1) = a * in.U(m, 1) + b * std::conj(in.U(m, 1));
    in.Y(m, 4) = h * in.U(m, 4);
  }
  const double vy = 1e-4, vu = 2e-5;
  const cd cov(3e-6, -1e-6);
  in.varY.setConstant(vy);
  in.varU.setConstant(vu);
  in.covYU.setConstant(cov);
  const lptv::DistortionLines d = lptv::distortion_lines(in);
  REQUIRE(d.lines == std::vector<int>{1, 2, 3, 4, 5, 6});
  // regressors: line 1: 1, -1; 2: 1, 4; 3: 1, 4; 4: 4; 5: 4; 6: 4
  REQUIRE(d.regressors == (Eigen::VectorXi(6) << 2, 2, 2, 1, 1, 1).finished());
  REQUIRE(d.dof == (Eigen::VectorXi(6) << 3, 3, 3, 4, 4, 4).finished());
  const double tol = 1e-14;
  REQUIRE(std::abs(d.bla(2, 0) - a) < tol);  // branch 0 of line 1
  REQUIRE(std::abs(d.bla(2, 1) - h) < tol);  // branch 0 of line 4
  for (int k : {1, 2}) REQUIRE(std::abs(d.bla(2 + k, 0)) < tol);  // lines 2, 3 from line 1
  for (int k : {-2, -1, 1, 2}) REQUIRE(std::abs(d.bla(2 + k, 1)) < tol);
  REQUIRE(std::isnan(d.bla(0, 0).real()));  // output lines -1, 0 are not lines
  REQUIRE(std::isnan(d.bla_var(1, 0)));
  for (int i = 0; i < L; ++i) REQUIRE(d.total[i] < 1e-28);  // no residual
  // Noise of a period mean: var Y + sum |G|^2 var U - 2 Re(conj(G_0) cov), G_0 the same line's.
  REQUIRE(d.noise[0] == Approx(vy + (std::norm(a) + std::norm(b)) * vu - 2 * (std::conj(a) * cov).real()).epsilon(1e-13));
  REQUIRE(d.noise[3] == Approx(vy + std::norm(h) * vu - 2 * (std::conj(h) * cov).real()).epsilon(1e-13));
  REQUIRE(d.noise[1] == Approx(vy).epsilon(1e-10));  // G ~ 0 there
  REQUIRE(d.signal[3] == Approx(std::norm(h) * 4.0).epsilon(1e-14));
  REQUIRE(d.signal[1] == 0.0);
  // no residual: no BLA variance either
  REQUIRE(d.bla_var(2, 1) < 1e-28);
}

TEST_CASE("Distortion: a known residual", "[distortion]") {
  // One excited line 1, Kh = 0, U_1 = 1 in all three realisations, Y_1 = 1, 2, 3:
  // G = 2, residuals -1, 0, 1, s^2 = 2 / (3 - 1) = 1, var G = s^2 / (X^H X) = 1/3.
  // Line 2 has no regressor: its total is the mean power (9 + 16 + 0) / 3.
  lptv::DistortionInput in = zeros(3, 2);
  in.excited = {1};
  in.U.col(1).setConstant(1.0);
  in.Y.col(1) << 1.0, 2.0, 3.0;
  in.Y.col(2) << 3.0, cd(0, 4), 0.0;
  in.varY.col(2) << 0.1, 0.2, 0.3;
  const lptv::DistortionLines d = lptv::distortion_lines(in);
  REQUIRE(d.dof == (Eigen::VectorXi(2) << 2, 3).finished());
  REQUIRE(std::abs(d.bla(0, 0) - 2.0) < 1e-15);
  REQUIRE(d.bla_var(0, 0) == Approx(1.0 / 3.0).epsilon(1e-15));
  REQUIRE(d.total[0] == Approx(1.0).epsilon(1e-15));
  REQUIRE(d.noise[0] == 0.0);
  REQUIRE(d.total[1] == Approx(25.0 / 3.0).epsilon(1e-15));
  REQUIRE(d.signal[1] == Approx(25.0 / 3.0).epsilon(1e-15));
  REQUIRE(d.noise[1] == Approx(0.2).epsilon(1e-15));
  REQUIRE(d.signal[0] == Approx(14.0 / 3.0).epsilon(1e-15));
}

TEST_CASE("Distortion: no residual degree of freedom, rank deficiency", "[distortion]") {
  // Two realisations, Kh = 2, excited 1, 2: line 1 has 1, 2, -1 as regressors (q = 3 > M):
  // nothing estimated. Line 4 has only 2 (q = 1, one dof left).
  lptv::DistortionInput in = zeros(2, 4);
  in.excited = {1, 2};
  in.branches = 2;
  in.U.col(1) << 1.0, 2.0;
  in.U.col(2) << 1.0, cd(0, 1);
  in.Y.col(4) << 2.0, cd(0, 2);
  lptv::DistortionLines d = lptv::distortion_lines(in);
  REQUIRE(d.dof[0] == -1);
  REQUIRE(std::isnan(d.total[0]));
  REQUIRE(std::isnan(d.noise[0]));
  REQUIRE(std::abs(d.bla(2 + 2, 1) - 2.0) < 1e-15);
  REQUIRE(d.total[3] < 1e-28);  // rounding: |r| ~ eps |y|
  // Real, equal U_1 in both realisations: U_1 and conj(U_1) are one column twice. With one
  // excited line and Kh = 2, line 1 regresses on U_1 and conj(U_1), rank 1: the minimum-norm
  // solution splits the gain x^H y / x^H x = 2 + 0.5i evenly (numpy.linalg.lstsq's answer);
  // residuals -i, -i, 2i over M - q = 1 (q counts both columns, as the NumPy route does): s^2 = 6;
  // the pseudo-inverse of X^H X = 12 [1 1; 1 1] has 1/48 on its diagonal.
  lptv::DistortionInput r = zeros(3, 3);
  r.excited = {1};
  r.branches = 2;
  r.U.col(1).setConstant(2.0);
  r.Y.col(1) << 4.0, 4.0, cd(4.0, 3.0);
  d = lptv::distortion_lines(r);
  REQUIRE(std::abs(d.bla(2, 0) - cd(1.0, 0.25)) < 1e-14);
  REQUIRE(d.total[0] == Approx(6.0).epsilon(1e-13));
  REQUIRE(d.bla_var(2, 0) == Approx(6.0 / 48.0).epsilon(1e-13));
}

TEST_CASE("Distortion: bad input names the argument", "[distortion]") {
  lptv::DistortionInput in = zeros(3, 4);
  in.excited = {1, 3};
  REQUIRE_NOTHROW(lptv::distortion_lines(in));
  auto fails = [](lptv::DistortionInput x, const char* what) {
    REQUIRE_THROWS_WITH(lptv::distortion_lines(x), Catch::Contains(what));
  };
  lptv::DistortionInput x = in;
  x.U = Eigen::MatrixXcd::Zero(1, 5);
  fails(x, "at least 2 realisations");
  x = in;
  x.Y = Eigen::MatrixXcd::Zero(3, 4);
  fails(x, "Y must be 3 x 5");
  x = in;
  x.covYU = Eigen::MatrixXcd::Zero(2, 5);
  fails(x, "covYU must be");
  x = in;
  x.varY(1, 2) = -1.0;
  fails(x, "varY must be >= 0");
  x = in;
  x.varU(0, 0) = std::nan("");
  fails(x, "varU contains NaN");
  x = in;
  x.excited = {};
  fails(x, "excited: no excited lines");
  x = in;
  x.excited = {3, 1};
  fails(x, "ascending and distinct");
  x = in;
  x.excited = {0, 2};
  fails(x, "line 0 is not a line 1..4");
  x = in;
  x.excited = {5};
  fails(x, "line 5 is not");
  x = in;
  x.branches = -1;
  fails(x, "branches must be within 0..4");
  x = in;
  x.branches = 5;
  fails(x, "branches must be within 0..4");
}

TEST_CASE("Distortion: overflow is a NumericalError naming the line", "[distortion]") {
  // U_1 = 1e-300, Y_1 = 1e100: G = 1e400 is not a double.
  lptv::DistortionInput in = zeros(3, 2);
  in.excited = {1};
  in.U.col(1) << 1e-300, 2e-300, 1e-300;
  in.Y.col(1) << 1e100, -1e100, 3e100;
  REQUIRE_THROWS_WITH(lptv::distortion_lines(in), Catch::Contains("regression of line 1 overflowed"));
  REQUIRE_THROWS_AS(lptv::distortion_lines(in), lptv::NumericalError);
}
