#include <catch2/catch.hpp>
#include <random>

#include "lptv/errors.hpp"
#include "lptv/estimators.hpp"
#include "lptv/fds.hpp"
#include "lptv/gsvd.hpp"
#include "lptv/jacobian.hpp"
#include "lptv/multisine.hpp"

using lptv::cd;

namespace {

lptv::Model lptv_model() {
  Eigen::MatrixXcd a(3, 3), b(2, 3);
  a << cd(0.1, 0.05), 1.0, cd(0.1, -0.05), cd(-0.05, 0.02), 0.8, cd(-0.05, -0.02), 0.0, 1.0, 0.0;
  b << cd(0.08, -0.03), 1.0, cd(0.08, 0.03), 0.0, 0.5, 0.0;
  return lptv::Model(a, b, 0.1);
}

// Noise-free data on lines 0..L with every line excited, zero variances.
lptv::FrequencyData noiseless(const lptv::Model& m, int L, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> ph(0, 2 * M_PI);
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(L + 1, 1);
  for (int l = 1; l <= L; ++l) U(l, 0) = std::polar(1.0, ph(gen));
  lptv::SimulateOptions opt;
  lptv::FrequencyData d;
  d.U = U.col(0);
  d.Y = lptv::simulate(m, U, opt).Y.col(0);
  d.varU = d.varY = Eigen::VectorXd::Zero(L + 1);
  d.covYU = Eigen::VectorXcd::Zero(L + 1);
  return d;
}

}  // namespace

TEST_CASE("GSVD pairs satisfy the defining ratio", "[gsvd]") {
  std::mt19937 gen(7);
  std::normal_distribution<double> nd;
  const int n = 6;
  Eigen::MatrixXd A(n, n), B(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = nd(gen), B(i, j) = nd(gen);
  const auto g = lptv::gsvd_pairs(A, B);
  REQUIRE(g.values.size() == n);
  for (int j = 0; j < n; ++j) {
    const Eigen::VectorXd x = g.vectors.col(j);
    REQUIRE((A * x).norm() / (B * x).norm() == Approx(g.values[j]).epsilon(1e-10));
  }
  // The smallest ratio is the smallest generalised eigenvalue of (A^T A, B^T B).
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(A.transpose() * A, B.transpose() * B);
  REQUIRE(g.values[0] * g.values[0] == Approx(es.eigenvalues()[0]).epsilon(1e-8));
}

TEST_CASE("GSVD handles a singular B (infinite pairs)", "[gsvd]") {
  std::mt19937 gen(8);
  std::normal_distribution<double> nd;
  const int n = 5;
  Eigen::MatrixXd A(n, n), B = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = nd(gen);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < n; ++j) B(i, j) = nd(gen);  // rank 3
  const auto g = lptv::gsvd_pairs(A, B);
  REQUIRE(g.infinite == 2);
  REQUIRE(g.values.size() == 3);
}

TEST_CASE("every estimator recovers a noise-free LPTV model", "[estimators]") {
  const lptv::Model m = lptv_model();
  const lptv::FrequencyData d = noiseless(m, 60, 1);
  lptv::Parametrisation p(lptv::Structure::of(m));
  const auto rows = lptv::default_rows(p, d.max_line());
  for (auto method : {lptv::Method::LS, lptv::Method::TLS, lptv::Method::GTLS, lptv::Method::WGTLS}) {
    lptv::EstimateOptions opt;
    opt.method = method;
    const auto r = lptv::estimate(d, p, rows, opt);
    const lptv::Model e = p.to_model(r.theta);
    REQUIRE((e.a() - m.a()).cwiseAbs().maxCoeff() < 1e-9);
    REQUIRE((e.b() - m.b()).cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("the residue of the true model vanishes on noise-free data", "[jacobian]") {
  const lptv::Model m = lptv_model();
  const lptv::FrequencyData d = noiseless(m, 40, 2);
  lptv::Parametrisation p(lptv::Structure::of(m));
  const auto rows = lptv::default_rows(p, d.max_line());
  Eigen::VectorXcd theta(p.n_theta());
  for (int q = 0; q < p.n_theta(); ++q) {
    const auto& pr = p.params()[q];
    theta[q] = pr.is_a ? m.a_coef(pr.order, pr.k) : m.b_coef(pr.order, pr.k);
  }
  const Eigen::VectorXcd e = lptv::residue(d, p, rows, theta);
  REQUIRE(e.cwiseAbs().maxCoeff() < 1e-13 * d.Y.cwiseAbs().maxCoeff());
  const Eigen::VectorXcd e2 = lptv::jacobian(d, p, rows) * theta;
  REQUIRE((e - e2).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("the FDS and the row kernels build bitwise identical band entries", "[jacobian]") {
  const lptv::Model ct = lptv_model();
  Eigen::MatrixXcd a_dt = ct.a();
  a_dt(0, 1) = 0.3, a_dt(1, 1) = -0.5;  // z^2 - 0.5 z + 0.3: poles inside the unit circle
  const lptv::Model dt(a_dt, ct.b(), 2 * M_PI / 64, 1.0);
  for (const lptv::Model& m : {ct, dt}) {
    const lptv::FrequencyData d = noiseless(m, 30, 4);
    lptv::Structure s = lptv::Structure::of(m);
    s.ts = m.ts();
    const lptv::Parametrisation p(s);
    const auto rows = lptv::default_rows(p, d.max_line());
    const Eigen::VectorXcd theta = p.theta_from_model(m);
    const lptv::Grid g = lptv::make_grid(m, d.max_line());
    const lptv::SpMat A = lptv::build_A(m, g), B = lptv::build_B(m, g);
    const Eigen::MatrixXcd J = lptv::jacobian(d, p, rows);
    const Eigen::VectorXcd e = lptv::residue(d, p, rows, theta);
    const int K = m.kmax();
    for (size_t r = 0; r < rows.size(); ++r) {
      const int l = rows[r];
      cd v(0.0, 0.0);  // row l of A Y - B U from the FDS's matrices, in the residue's order
      for (int k = -K; k <= K; ++k) {
        const int i = l - k;
        v += A.coeff(g.index_of(l), g.index_of(i)) * d.Y[i] - B.coeff(g.index_of(l), g.index_of(i)) * d.U[i];
      }
      REQUIRE(e[static_cast<Eigen::Index>(r)] == v);
      for (int q = 0; q < p.n_theta(); ++q) {
        const lptv::Param& pr = p.params()[q];
        const int i = l - pr.k;
        const cd f = lptv::line_power(s, i, pr.order);
        REQUIRE(f == lptv::line_power(m, g, i, pr.order));
        REQUIRE(J(static_cast<Eigen::Index>(r), q) == (pr.is_a ? f * d.Y[i] : -f * d.U[i]));
      }
    }
  }
}

TEST_CASE("rows that need missing lines are refused", "[jacobian]") {
  const lptv::Model m = lptv_model();
  const lptv::FrequencyData d = noiseless(m, 20, 3);
  lptv::Parametrisation p(lptv::Structure::of(m));
  REQUIRE_THROWS_AS(lptv::check_rows(p, {19, 20}, d.max_line()), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::check_rows(p, {0, 2}, d.max_line()), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::check_rows(p, {2, 3}, d.max_line()), std::invalid_argument);  // too few
}

TEST_CASE("noise statistics of periods", "[noise]") {
  std::mt19937 gen(4);
  std::normal_distribution<double> nd;
  Eigen::MatrixXd u(3, 8), y(3, 8);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 8; ++j) u(i, j) = nd(gen), y(i, j) = nd(gen);
  const auto d = lptv::frequency_data_from_periods(u, y);
  REQUIRE(d.U.size() == 5);
  const Eigen::VectorXcd U1 = lptv::spectrum(u.row(1).transpose());
  Eigen::VectorXcd mean = Eigen::VectorXcd::Zero(5);
  for (int p = 0; p < 3; ++p) mean += lptv::spectrum(u.row(p).transpose()) / 3.0;
  REQUIRE((d.U - mean).norm() < 1e-15);
  (void)U1;
  REQUIRE_THROWS_AS(lptv::frequency_data_from_periods(u.topRows(1), y.topRows(1)), std::invalid_argument);
}

TEST_CASE("GTLS: the Cholesky-whitened SVD agrees with the GSVD on a positive definite pair", "[gsvd]") {
  std::mt19937 gen(17);
  std::normal_distribution<double> nd;
  const int n = 9;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, n), G(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (j >= i) R(i, j) = nd(gen) * std::pow(10.0, j % 3);  // uneven column scales
      G(i, j) = nd(gen);
    }
  const Eigen::MatrixXd CJ = G.transpose() * G + 1e-2 * Eigen::MatrixXd::Identity(n, n);
  const lptv::GtlsSolve fast = lptv::gtls_from_r(R, CJ);  // CJ positive definite: Cholesky route
  const Eigen::MatrixXd B = Eigen::LLT<Eigen::MatrixXd>(CJ).matrixU();  // B^T B = CJ
  const lptv::GeneralizedPairs g = lptv::gsvd_pairs(R, B);
  REQUIRE(fast.values.size() == g.values.size());
  for (int i = 0; i < n; ++i) REQUIRE(fast.values[i] == Approx(g.values[i]).epsilon(1e-10));
  const Eigen::VectorXd a = fast.x / fast.x.norm(), b = g.vectors.col(0) / g.vectors.col(0).norm();
  REQUIRE(std::min((a - b).norm(), (a + b).norm()) < 1e-9);
}

TEST_CASE("GTLS: the inverse-iteration route (with a start) agrees with the full SVD", "[gsvd]") {
  for (unsigned seed : {21u, 22u, 23u}) {
    std::mt19937 gen(seed);
    std::normal_distribution<double> nd;
    const int n = 12;
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, n), G(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if (j >= i) R(i, j) = nd(gen) * std::pow(10.0, j % 3);
        G(i, j) = nd(gen);
      }
    const Eigen::MatrixXd CJ = G.transpose() * G + 1e-2 * Eigen::MatrixXd::Identity(n, n);
    const lptv::GtlsSolve full = lptv::gtls_from_r(R, CJ);
    REQUIRE(full.values[1] >= 2.0 * full.values[0]);  // the gap the fast route asks for
    // A start off by a few percent in every direction, as the previous WGTLS solve is.
    Eigen::VectorXd start = full.x;
    for (int i = 0; i < n; ++i) start[i] += 0.05 * full.x.norm() * nd(gen) / std::sqrt(double(n));
    const lptv::GtlsSolve fast = lptv::gtls_from_r(R, CJ, start);
    for (int i = 0; i < n; ++i) REQUIRE(fast.values[i] == Approx(full.values[i]).epsilon(1e-12));
    const Eigen::VectorXd a = fast.x / fast.x.norm(), b = full.x / full.x.norm();
    REQUIRE(std::min((a - b).norm(), (a + b).norm()) < 1e-10);
  }
}

TEST_CASE("WGTLS of estimate equals its iteration written with the row-by-row functions", "[identify]") {
  // estimate() keeps the real Jacobian and the per-row noise terms of a small problem and
  // solves the GTLS problem by inverse iteration from the previous solve; the loop below
  // builds every iteration row by row (residue_variance, weighted_r_factor,
  // real_column_covariance) and solves it by the full SVD.
  const lptv::Model m = lptv_model();
  for (unsigned seed : {3u, 4u, 5u}) {
    const int L = 60, P = 6, N = 2 * L + 8;
    std::mt19937 gen(seed);
    std::normal_distribution<double> nd;
    std::uniform_real_distribution<double> ph(0, 2 * M_PI);
    Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(L + 1, 1);
    for (int l = 1; l <= L; l += 2) U(l, 0) = std::polar(1.0, ph(gen));
    Eigen::VectorXcd Uf = Eigen::VectorXcd::Zero(N / 2 + 1), Yf = Eigen::VectorXcd::Zero(N / 2 + 1);
    Uf.head(L + 1) = U.col(0);
    const Eigen::VectorXcd Ys = lptv::simulate(m, U).Y.col(0);
    const Eigen::Index ny = std::min<Eigen::Index>(Ys.size(), N / 2);
    Yf.head(ny) = Ys.head(ny);
    Yf[0] = Yf[0].real();
    const Eigen::VectorXd u0 = lptv::time_signal(Uf, N), y0 = lptv::time_signal(Yf, N);
    Eigen::MatrixXd u(P, N), y(P, N);
    for (int p = 0; p < P; ++p)
      for (int t = 0; t < N; ++t) u(p, t) = u0[t] + 0.01 * nd(gen), y(p, t) = y0[t] + 0.02 * nd(gen);
    const lptv::FrequencyData d = lptv::frequency_data_from_periods(u, y);
    lptv::Structure s;
    s.na = 2;
    s.nb = 1;
    s.ka = {1, 1, 0};
    s.kb = {1, 0};
    s.w0 = 0.1;
    const lptv::Parametrisation p(s);
    std::vector<int> rows;
    for (int l = 2; l <= L - 1; ++l) rows.push_back(l);
    lptv::EstimateOptions opt;
    opt.tol = 1e-13;
    const lptv::EstimateResult r = lptv::estimate(d, p, rows, opt);
    REQUIRE(r.converged);
    // The same iteration from the public row-by-row functions.
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(rows.size()));
    lptv::GtlsSolve g = lptv::gtls_from_r(lptv::weighted_r_factor(d, p, rows, Eigen::VectorXd()),
                                          lptv::real_column_covariance(d, p, rows, ones));
    Eigen::VectorXcd theta = p.theta_from_xi(g.x);
    for (int it = 0; it < 50; ++it) {
      const Eigen::VectorXd w = lptv::residue_variance(d, p, rows, theta).cwiseInverse();
      g = lptv::gtls_from_r(lptv::weighted_r_factor(d, p, rows, w), lptv::real_column_covariance(d, p, rows, w));
      const Eigen::VectorXcd next = p.theta_from_xi(g.x);
      const double change = (next - theta).norm() / next.norm();
      theta = next;
      if (change < 1e-13) break;
    }
    REQUIRE((r.theta - theta).norm() / theta.norm() < 1e-10);
    REQUIRE(r.singular_values.size() == g.values.size());
    for (Eigen::Index i = 0; i < g.values.size(); ++i) REQUIRE(r.singular_values[i] == Approx(g.values[i]).epsilon(1e-9));
  }
}
