// The exact likelihood's diagonal route for K = 0 (LTI structures: S block diagonal, factored
// row by row) against its band route on the same data: the route claims the band route's
// operations on the same numbers (the band's entries between rows are exact zeros), so every
// output must be the same bits. Several seeds, continuous and discrete time, complex
// input/output noise correlation, a known coefficient.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <string>

#include "lptv/errors.hpp"
#include "lptv/estimators.hpp"
#include "lptv/fds.hpp"
#include "lptv/likelihood.hpp"
#include "rows.hpp"  // detail::set_diagonal_likelihood (private: the tests' include path)

using lptv::cd;

namespace {

// Restores the diagonal route when a check fails half-way.
struct DiagonalRoute {
  explicit DiagonalRoute(bool on) : before(lptv::detail::set_diagonal_likelihood(on)) {}
  ~DiagonalRoute() { lptv::detail::set_diagonal_likelihood(before); }
  bool before;
};

// An LTI model of orders 3 / 1 (stable in either time domain) and data on lines 0..L: the
// steady state, plus circular noise whose variances and complex input/output covariance vary
// from line to line.
lptv::FrequencyData lti_data(const lptv::Model& m, int L, std::mt19937& gen) {
  std::uniform_real_distribution<double> ph(0, 2 * M_PI), var(0.5e-4, 2e-4), corr(-0.6, 0.6);
  std::normal_distribution<double> nd;
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(L + 1, 1);
  for (int l = 1; l <= L; ++l) U(l, 0) = std::polar(1.0, ph(gen));
  lptv::FrequencyData d;
  d.U = U.col(0);
  d.Y = lptv::simulate(m, U, lptv::SimulateOptions()).Y.col(0);
  d.varU.resize(L + 1);
  d.varY.resize(L + 1);
  d.covYU.resize(L + 1);
  for (int l = 0; l <= L; ++l) {
    d.varU[l] = var(gen);
    d.varY[l] = var(gen);
    const double rho = corr(gen), phase = l ? ph(gen) : 0.0;
    d.covYU[l] = std::polar(rho * std::sqrt(d.varU[l] * d.varY[l]), phase);
    if (l) {
      d.U[l] += std::sqrt(d.varU[l] / 2) * cd(nd(gen), nd(gen));
      d.Y[l] += std::sqrt(d.varY[l] / 2) * cd(nd(gen), nd(gen));
    }
  }
  return d;
}

lptv::Model lti_model(bool discrete) {
  Eigen::MatrixXcd a(4, 1), b(2, 1);
  if (discrete) {  // poles at 0.5 and 0.6 +- 0.3j
    a << -0.225, 0.96, -1.7, 1.0;
    b << 0.3, 0.2;
    return lptv::Model(a, b, 2 * M_PI / 256, 1.0);
  }
  a << 2.0, 3.0, 2.5, 1.0;  // (s + 1)(s^2 + 1.5 s + 2)
  b << 1.0, 0.4;
  return lptv::Model(a, b, 0.02);
}

lptv::Structure structure_of(const lptv::Model& m, bool known_b1) {
  lptv::Structure s = lptv::Structure::of(m);
  if (known_b1) s.known.push_back({false, 1, m.b().row(1).transpose()});
  return s;
}

}  // namespace

TEST_CASE("exact likelihood, K = 0: the diagonal route gives the band route's bits", "[likelihood]") {
  for (const bool discrete : {false, true}) {
    for (const bool known : {false, true}) {
      for (unsigned seed = 1; seed <= 4; ++seed) {
        CAPTURE(discrete, known, seed);
        std::mt19937 gen(seed);
        const lptv::Model m = lti_model(discrete);
        const lptv::FrequencyData d = lti_data(m, 120, gen);
        const lptv::Parametrisation p(structure_of(m, known));
        std::vector<int> rows;
        for (int l = 3; l <= 110; l += (l % 7 == 0 ? 2 : 1)) rows.push_back(l);
        std::shuffle(rows.begin(), rows.end(), gen);  // unsorted rows: the routes sort them alike
        const lptv::ExactLikelihood lik(d, p, rows);
        REQUIRE(lik.half_bandwidth() == 1);
        // theta near the truth, off it by a random perturbation, so that residues are not noise only
        Eigen::VectorXcd theta = p.theta_from_model(m);
        std::normal_distribution<double> nd;
        for (Eigen::Index q = 0; q < theta.size(); ++q) theta[q] *= 1.0 + 0.01 * nd(gen);
        const std::vector<double> w_rows = [&] {
          std::vector<double> w;
          std::uniform_real_distribution<double> u(0.5, 2.0);
          for (size_t r = 0; r < rows.size(); ++r) w.push_back(u(gen) * 1e4);
          return w;
        }();
        const Eigen::VectorXd weights = Eigen::Map<const Eigen::VectorXd>(w_rows.data(), static_cast<Eigen::Index>(w_rows.size()));

        auto run = [&](bool diagonal) {
          DiagonalRoute route(diagonal);
          struct Out {
            double cost;
            lptv::ExactLikelihood::Evaluation ev;
            Eigen::MatrixXd fisher, sandwich, S;
            lptv::EstimateResult sml;
          } o;
          o.cost = lik.cost(theta);
          o.ev = lik.evaluate(theta);
          o.fisher = lik.fisher_information(theta);
          o.sandwich = lik.sandwich_covariance(theta, weights);
          o.S = lik.residue_covariance(theta);
          lptv::EstimateOptions opt;
          opt.method = lptv::Method::SML;
          opt.tol = 1e-12;
          o.sml = lptv::estimate(d, p, rows, opt);
          return o;
        };
        const auto band = run(false);
        const auto diag = run(true);
        CHECK(diag.cost == band.cost);
        CHECK(diag.ev.cost == band.ev.cost);
        CHECK(diag.ev.whitened == band.ev.whitened);
        CHECK(diag.ev.gradient == band.ev.gradient);
        CHECK(diag.ev.jacobian == band.ev.jacobian);
        CHECK(diag.ev.denoised.Y == band.ev.denoised.Y);
        CHECK(diag.ev.denoised.U == band.ev.denoised.U);
        CHECK(diag.fisher == band.fisher);
        CHECK(diag.sandwich == band.sandwich);
        CHECK(diag.S == band.S);
        CHECK(diag.sml.theta == band.sml.theta);
        CHECK(diag.sml.iterations == band.sml.iterations);
        CHECK(diag.sml.cost == band.sml.cost);
        CHECK(diag.sml.information == band.sml.information);
        // and the comparison is not empty: the likelihood moved the estimate off its start
        CHECK(band.ev.cost > 0);
        CHECK(band.sml.iterations >= 1);
      }
    }
  }
}

TEST_CASE("exact likelihood, K = 0: a row without noise is refused alike by both routes", "[likelihood]") {
  std::mt19937 gen(7);
  const lptv::Model m = lti_model(false);
  lptv::FrequencyData d = lti_data(m, 60, gen);
  d.varU[20] = d.varY[20] = 0.0;
  d.covYU[20] = 0.0;
  const lptv::Parametrisation p(lptv::Structure::of(m));
  std::vector<int> rows;
  for (int l = 1; l <= 50; ++l) rows.push_back(l);
  const lptv::ExactLikelihood lik(d, p, rows);
  const Eigen::VectorXcd theta = p.theta_from_model(m);
  std::string messages[2];
  for (const bool diagonal : {false, true}) {
    DiagonalRoute route(diagonal);
    try {
      lik.cost(theta);
    } catch (const lptv::NumericalError& e) {
      messages[diagonal] = e.what();
    }
  }
  CHECK(messages[0].find("row (line) 20") != std::string::npos);
  CHECK(messages[1] == messages[0]);
}
