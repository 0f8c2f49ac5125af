// The exact likelihood (METHOD.md section 10) and lptv::identify, checked by routes that do not
// share its algorithm: finite differences, the dense residue covariance, the diagonal cost for
// LTI models, and a small Monte Carlo of the noise.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "lptv/errors.hpp"
#include "lptv/estimators.hpp"
#include "lptv/fds.hpp"
#include "lptv/jacobian.hpp"
#include "lptv/likelihood.hpp"

using lptv::cd;

namespace {

lptv::Model model(int K) {
  Eigen::MatrixXcd a(3, 2 * K + 1), b(2, 2 * K + 1);
  a.setZero();
  b.setZero();
  a(0, K) = 1.0, a(1, K) = 0.8, a(2, K) = 1.0, b(0, K) = 1.0, b(1, K) = 0.5;
  if (K > 0) {
    a(0, K + 1) = cd(0.1, 0.05), a(0, K - 1) = cd(0.1, -0.05);
    a(1, K + 1) = cd(-0.05, 0.02), a(1, K - 1) = cd(-0.05, -0.02);
    b(0, K + 1) = cd(0.08, -0.03), b(0, K - 1) = cd(0.08, 0.03);
  }
  return lptv::Model(a, b, 0.1);
}

// Steady-state spectra of every line 1..L excited, with circular complex noise of variance
// sigma2 on U and Y (correlated with coefficient rho) and the matching statistics; DC real.
lptv::FrequencyData noisy(const lptv::Model& m, int L, double sigma2, double rho, std::mt19937& gen,
                          bool add_noise = true) {
  std::uniform_real_distribution<double> ph(0, 2 * M_PI);
  std::normal_distribution<double> nd;
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(L + 1, 1);
  for (int l = 1; l <= L; ++l) U(l, 0) = std::polar(1.0, ph(gen));
  lptv::FrequencyData d;
  d.U = U.col(0);
  d.Y = lptv::simulate(m, U, lptv::SimulateOptions()).Y.col(0);
  d.varU = d.varY = Eigen::VectorXd::Constant(L + 1, sigma2);
  d.covYU = Eigen::VectorXcd::Constant(L + 1, cd(rho * sigma2, 0.0));
  if (add_noise) {
    const double s = std::sqrt(sigma2 / 2);
    for (int l = 0; l <= L; ++l) {
      const cd nu(nd(gen), l ? nd(gen) : 0.0), own(nd(gen), l ? nd(gen) : 0.0);
      const double f = l ? s : std::sqrt(sigma2);
      d.U[l] += f * nu;
      d.Y[l] += f * (rho * nu + std::sqrt(1 - rho * rho) * own);
    }
  }
  return d;
}

std::vector<int> rows_from(int first, int last) {
  std::vector<int> r;
  for (int l = first; l <= last; ++l) r.push_back(l);
  return r;
}

}  // namespace

TEST_CASE("exact cost: the gradient matches central differences", "[likelihood]") {
  std::mt19937 gen(3);
  for (int K : {0, 1}) {
    const lptv::Model m = model(K);
    const lptv::FrequencyData d = noisy(m, 40, 1e-3, 0.3, gen);
    const lptv::Parametrisation p(lptv::Structure::of(m));
    // Rows from 1 use the conjugate lines and DC.
    const lptv::ExactLikelihood lik(d, p, rows_from(1, 40 - K));
    Eigen::VectorXd xi = p.xi_from_theta(p.theta_from_model(m));
    xi *= 1.01;  // away from the normalisation, to see every column
    const auto ev = lik.evaluate(p.Text() * xi);
    for (int j = 0; j < p.n_xi(); ++j) {
      const double h = 1e-6 * std::max(1.0, std::abs(xi[j]));
      Eigen::VectorXd xp = xi, xm = xi;
      xp[j] += h;
      xm[j] -= h;
      const double fd = (lik.cost(p.Text() * xp) - lik.cost(p.Text() * xm)) / (2 * h);
      // Central differences: error O(h^2 V''') plus rounding eps V / h ~ 1e-10 V.
      REQUIRE(ev.gradient[j] == Approx(fd).epsilon(1e-5).margin(1e-7 * ev.cost));
    }
  }
}

TEST_CASE("exact cost: for LTI models it is twice the diagonal SML cost", "[likelihood]") {
  std::mt19937 gen(5);
  const lptv::Model m = model(0);
  const lptv::FrequencyData d = noisy(m, 30, 1e-3, -0.4, gen);
  const lptv::Parametrisation p(lptv::Structure::of(m));
  const auto rows = rows_from(1, 30);
  const lptv::ExactLikelihood lik(d, p, rows);
  const Eigen::VectorXcd theta = p.theta_from_model(m) * 1.02;
  const Eigen::VectorXcd e = lptv::residue(d, p, rows, theta);
  const Eigen::VectorXd v = lptv::residue_variance(d, p, rows, theta);
  const double diag = (e.cwiseAbs2().array() / v.array()).sum();
  REQUIRE(lik.cost(theta) == Approx(2 * diag).epsilon(1e-12));
}

TEST_CASE("exact cost: S matches the Monte Carlo covariance of the residue", "[likelihood]") {
  std::mt19937 gen(11);
  const lptv::Model m = model(1);
  const int L = 12;
  const lptv::FrequencyData d0 = noisy(m, L, 1e-2, 0.5, gen, false);
  const lptv::Parametrisation p(lptv::Structure::of(m));
  const auto rows = rows_from(1, L - 1);  // rows 1 and 2 use line 0 and conjugate lines
  const Eigen::VectorXcd theta = p.theta_from_model(m);
  const Eigen::MatrixXd S = lptv::ExactLikelihood(d0, p, rows).residue_covariance(theta);
  const int n = 2 * static_cast<int>(rows.size()), draws = 40000;
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  for (int t = 0; t < draws; ++t) {
    lptv::FrequencyData d = noisy(m, L, 1e-2, 0.5, gen, false);
    lptv::FrequencyData dn = d0;
    std::normal_distribution<double> nd;
    const double s = std::sqrt(0.5e-2);
    for (int l = 0; l <= L; ++l) {
      const cd nu(nd(gen), l ? nd(gen) : 0.0), own(nd(gen), l ? nd(gen) : 0.0);
      const double f = l ? s : std::sqrt(1e-2);
      dn.U[l] += f * nu;
      dn.Y[l] += f * (0.5 * nu + std::sqrt(0.75) * own);
    }
    const Eigen::VectorXcd e = lptv::residue(dn, p, rows, theta);
    Eigen::VectorXd r(n);
    for (int i = 0; i < n / 2; ++i) r[2 * i] = e[i].real(), r[2 * i + 1] = e[i].imag();
    C += r * r.transpose();
  }
  C /= draws;
  // Each entry of a sample covariance has standard error about sqrt((S_ii S_jj + S_ij^2) / draws).
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double se = std::sqrt((S(i, i) * S(j, j) + S(i, j) * S(i, j)) / draws);
      REQUIRE(std::abs(C(i, j) - S(i, j)) <= 5 * se);
    }
}

TEST_CASE("identify: every method through one entry point, sml with its covariance", "[identify]") {
  std::mt19937 gen(7);
  const lptv::Model m = model(1);
  lptv::FrequencyData d = noisy(m, 60, 1e-4, 0.2, gen);
  d.periods = 0;  // known variances: no small-sample correction
  for (auto method : {lptv::Method::LS, lptv::Method::TLS, lptv::Method::GTLS, lptv::Method::WGTLS,
                      lptv::Method::SML}) {
    lptv::IdentifyOptions opt;
    opt.method = method;
    const lptv::Identification r = lptv::identify(d, lptv::Structure::of(m), opt);
    REQUIRE(r.converged);
    REQUIRE(r.eta.size() == static_cast<Eigen::Index>(r.eta_names.size()));
    REQUIRE(r.normalized_residue.size() == static_cast<Eigen::Index>(r.rows.size()));
    const bool has_cov = method == lptv::Method::WGTLS || method == lptv::Method::SML;
    REQUIRE((r.covariance.size() > 0) == has_cov);
    if (method == lptv::Method::SML) {
      // the estimate is within a few standard deviations of the truth
      const lptv::Parametrisation p(lptv::Structure::of(m));
      Eigen::VectorXd truth = p.xi_from_theta(p.theta_from_model(m));
      for (int i = 0; i < r.eta.size(); ++i) {
        const double sd = std::sqrt(r.covariance(i, i));
        if (sd == 0) continue;  // the normalised parameter
        REQUIRE(std::abs(r.eta[i] - truth[i]) < 5 * sd);
      }
    }
  }
}

TEST_CASE("exact cost: rows without noise are a clear numerical error", "[likelihood]") {
  std::mt19937 gen(1);
  const lptv::Model m = model(1);
  lptv::FrequencyData d = noisy(m, 20, 1e-4, 0.0, gen);
  d.varU.setZero();
  d.varY.setZero();
  d.covYU.setZero();
  const lptv::Parametrisation p(lptv::Structure::of(m));
  const lptv::ExactLikelihood lik(d, p, rows_from(2, 19));
  REQUIRE_THROWS_AS(lik.cost(p.theta_from_model(m)), lptv::NumericalError);
}
