// lptv::MimoModel and the block band FDS (METHOD.md section 19) in C++ without Python: the
// 1 x 1 model against the SISO FDS, the solvers against each other, a block-diagonal model
// against its outputs simulated one by one, and the validation.
#include <catch2/catch.hpp>

#include "lptv/errors.hpp"
#include "lptv/mimo.hpp"

using lptv::cd;

namespace {

// Continuous time: a_0(t) = 2 + 0.4 cos(w0 t) (harmonics +-1: 0.2), a_1 = 0.5, a_2 = 1.
// Discrete time: a_0[t] = 0.1 + 0.1 cos(w0 t), a_1 = -0.3, a_2 = 1 (poles well inside the circle).
// b_0 = 1, b_1 = 0.2.
lptv::Model siso(double w0, double ts = 0.0) {
  Eigen::MatrixXcd a(3, 3), b(2, 1);
  if (ts > 0) {
    a << 0.05, 0.1, 0.05, 0.0, -0.3, 0.0, 0.0, 1.0, 0.0;
  } else {
    a << 0.2, 2.0, 0.2, 0.0, 0.5, 0.0, 0.0, 1.0, 0.0;
  }
  b << 1.0, 0.2;
  return lptv::Model(a, b, w0, ts);
}

Eigen::MatrixXcd input(int lines, int cols, unsigned seed) {
  Eigen::MatrixXcd U(lines + 1, cols);
  for (int l = 0; l <= lines; ++l)
    for (int c = 0; c < cols; ++c)
      U(l, c) = cd(std::cos(1.3 * l + 0.7 * c + seed), l ? std::sin(2.1 * l - c + seed) : 0.0);
  return U;
}

double max_abs(const Eigen::MatrixXcd& x) { return x.cwiseAbs().maxCoeff(); }

}  // namespace

TEST_CASE("a 1 x 1 MIMO model simulates as the SISO model", "[mimo]") {
  for (double ts : {0.0, 1.0}) {
    const lptv::Model s = siso(ts > 0 ? 2 * M_PI / 32 : 0.3, ts);
    const lptv::MimoModel m(s);
    REQUIRE(m.n_outputs() == 1);
    REQUIRE(m.n_inputs() == 1);
    REQUIRE(m.na() == 2);
    REQUIRE(m.ka() == 1);
    const Eigen::MatrixXcd U = input(ts > 0 ? 15 : 20, 2, 1);  // below the Nyquist line of N = 32
    lptv::SimulateOptions opt;
    opt.guard = ts > 0 ? -1 : 30;
    const Eigen::MatrixXcd Ys = lptv::simulate(s, U, opt).Y;
    const Eigen::MatrixXcd Ym = lptv::simulate_mimo(m, U, opt).Y;  // two experiments of one input
    REQUIRE(max_abs(Ym - Ys) <= 1e-12 * max_abs(Ys));
  }
}

TEST_CASE("solvers agree on the block band system", "[mimo]") {
  // two outputs: the SISO coefficients on the diagonal, a periodic coupling off it
  const lptv::Model s = siso(0.4);
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(3 * 4, 3), b = Eigen::MatrixXcd::Zero(2 * 2 * 3, 1);
  for (int n = 0; n < 3; ++n) {
    a.row(n * 4 + 0) = s.a().row(n);
    a.row(n * 4 + 3) = s.a().row(n);
  }
  a.row(1) << cd(0.1, 0.05), -0.3, cd(0.1, -0.05);  // A_0 entry (0, 1)
  a.row(2) << 0.0, -0.2, 0.0;                       // A_0 entry (1, 0)
  b << 1.0, 0.5, 0.0, 1.0, 0.2, 0.0, 0.0, 0.2, 0.0, 0.0, 0.0, 0.0;
  const lptv::MimoModel m(a, b, 2, 3, 0.4);
  REQUIRE(m.nb() == 1);
  const Eigen::MatrixXcd U = input(25, 3, 2);
  lptv::SimulateOptions opt;
  opt.guard = 20;
  const Eigen::MatrixXcd Y = lptv::simulate_mimo(m, U, opt).Y;
  REQUIRE(Y.cols() == 2);
  for (lptv::Solver solver : {lptv::Solver::KLU, lptv::Solver::UMFPACK}) {
    opt.solver = solver;
    REQUIRE(max_abs(lptv::simulate_mimo(m, U, opt).Y - Y) <= 1e-13 * max_abs(Y));
  }
  const lptv::MimoSimulateResult r = lptv::simulate_mimo(m, U);
  REQUIRE(r.converged);
  REQUIRE(r.solver == lptv::Solver::Band);
  REQUIRE(max_abs(r.Y - Y) <= 1e-12 * max_abs(Y));
}

TEST_CASE("uncoupled outputs simulate one by one", "[mimo]") {
  const lptv::Model s = siso(0.5);
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(3 * 4, 3), b = Eigen::MatrixXcd::Zero(2 * 2, 1);
  for (int n = 0; n < 3; ++n) a.row(n * 4) = a.row(n * 4 + 3) = s.a().row(n);
  b << 1.0, 0.0, 0.0, 0.0;  // B_0 = [[1, 0], [0, 0]], B_1 = [[0, 0], [0, 1]]
  b.conservativeResize(8, 1);
  b.bottomRows(4) << 0.0, 0.0, 0.0, 1.0;
  const lptv::MimoModel m(a, b, 2, 2, 0.5);
  const Eigen::MatrixXcd U = input(15, 2, 3);
  lptv::SimulateOptions opt;
  opt.guard = 25;
  const Eigen::MatrixXcd Y = lptv::simulate_mimo(m, U, opt).Y;
  Eigen::MatrixXcd b0(1, 1), b1(2, 1);
  b0 << 1.0;
  b1 << 0.0, 1.0;
  const Eigen::MatrixXcd Y0 = lptv::simulate(lptv::Model(s.a(), b0, 0.5), U.col(0), opt).Y;
  const Eigen::MatrixXcd Y1 = lptv::simulate(lptv::Model(s.a(), b1, 0.5), U.col(1), opt).Y;
  REQUIRE(max_abs(Y.col(0) - Y0) <= 1e-12 * max_abs(Y0));
  REQUIRE(max_abs(Y.col(1) - Y1) <= 1e-12 * max_abs(Y1));
}

TEST_CASE("MIMO models and inputs are validated", "[mimo]") {
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Identity(8, 1), b = Eigen::MatrixXcd::Ones(2, 1);
  a.setZero();
  a(0, 0) = a(3, 0) = 2.0;
  a(4, 0) = a(7, 0) = 1.0;
  REQUIRE_NOTHROW(lptv::MimoModel(a, b, 2, 1, 1.0));
  REQUIRE_THROWS_AS(lptv::MimoModel(a.topRows(6), b, 2, 1, 1.0), std::invalid_argument);  // rows
  REQUIRE_THROWS_AS(lptv::MimoModel(a, b, 2, 2, 1.0), std::invalid_argument);             // b rows
  Eigen::MatrixXcd lead = a;
  lead.bottomRows(4).setZero();
  REQUIRE_THROWS_AS(lptv::MimoModel(lead, b, 2, 1, 1.0), std::invalid_argument);
  Eigen::MatrixXcd asym = Eigen::MatrixXcd::Zero(8, 3);
  asym.col(1) = a.col(0);
  asym(1, 0) = cd(0.1, 0.1);
  REQUIRE_THROWS_AS(lptv::MimoModel(asym, b, 2, 1, 1.0), std::invalid_argument);
  const lptv::MimoModel m(a, b, 2, 1, 1.0);
  REQUIRE_THROWS_AS(lptv::simulate_mimo(m, Eigen::MatrixXcd::Ones(3, 1) * cd(0, 1)), std::invalid_argument);
  // y'' + y = u per output with w0 = 1: an undamped resonance on line 1, AA exactly singular
  Eigen::MatrixXcd res = Eigen::MatrixXcd::Zero(12, 1);
  res(0, 0) = res(3, 0) = 1.0;    // A_0 = I
  res(8, 0) = res(11, 0) = 1.0;   // A_2 = I
  lptv::SimulateOptions opt;
  opt.solver = lptv::Solver::KLU;
  REQUIRE_THROWS_AS(lptv::simulate_mimo(lptv::MimoModel(res, b, 2, 1, 1.0), input(3, 1, 0), opt),
                    lptv::NumericalError);
}
