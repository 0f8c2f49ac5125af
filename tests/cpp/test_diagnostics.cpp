// lptv::identify's data diagnostics: degenerate data refused with the argument and the cause.
#include <catch2/catch.hpp>
#include <random>
#include <stdexcept>
#include <string>

#include "lptv/diagnostics.hpp"
#include "lptv/estimators.hpp"
#include "lptv/fds.hpp"

using lptv::cd;

namespace {

lptv::Model lti_model() {
  Eigen::MatrixXcd a(3, 1), b(2, 1);
  a << 2.0, 0.6, 1.0;
  b << 1.0, 0.5;
  return lptv::Model(a, b, 0.1);
}

// Data on lines 0..L: the input excited on `lines` (unit amplitude, random phases), complex
// Gaussian noise of variance var (per line, on the mean) added to U and Y, variances known.
lptv::FrequencyData data(const lptv::Model& m, int L, const std::vector<int>& lines, double var,
                         unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> ph(0, 2 * M_PI);
  std::normal_distribution<double> nd(0.0, std::sqrt(var / 2));
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(L + 1, 1);
  for (int l : lines) U(l, 0) = std::polar(1.0, ph(gen));
  lptv::FrequencyData d;
  d.U = U.col(0);
  d.Y = lptv::simulate(m, U).Y.col(0);
  for (int l = 1; l <= L; ++l) {
    d.U[l] += cd(nd(gen), nd(gen));
    d.Y[l] += cd(nd(gen), nd(gen));
  }
  d.varU = d.varY = Eigen::VectorXd::Constant(L + 1, var);
  d.varU[0] = d.varY[0] = 0.0;
  d.covYU = Eigen::VectorXcd::Zero(L + 1);
  return d;
}

std::vector<int> range(int lo, int hi) {
  std::vector<int> r;
  for (int l = lo; l <= hi; ++l) r.push_back(l);
  return r;
}

std::string refusal(const lptv::FrequencyData& d, const lptv::Structure& s, lptv::IdentifyOptions opt = {}) {
  try {
    lptv::identify(d, s, opt);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("identify names a dead input", "[diagnostics]") {
  const auto m = lti_model();
  const auto s = lptv::Structure::of(m);
  for (unsigned seed : {1u, 2u, 3u}) {
    auto d = data(m, 60, range(1, 50), 1e-6, seed);
    d.U.setZero();
    d.varU.setZero();
    for (auto method : {lptv::Method::LS, lptv::Method::TLS, lptv::Method::WGTLS}) {
      lptv::IdentifyOptions opt;
      opt.method = method;
      REQUIRE_THAT(refusal(d, s, opt), Catch::StartsWith("u: the input spectrum is zero on the fitted lines"));
    }
    // only noise on the input: at the level of its noise
    auto n = data(m, 60, {}, 1e-6, seed);
    n.Y = data(m, 60, range(1, 50), 1e-6, seed).Y;
    REQUIRE_THAT(refusal(n, s), Catch::StartsWith("u: the input spectrum on the fitted lines") &&
                                    Catch::Contains("is at the level of its noise"));
  }
}

TEST_CASE("identify names a constant output and one of noise only", "[diagnostics]") {
  const auto m = lti_model();
  const auto s = lptv::Structure::of(m);
  for (unsigned seed : {1u, 2u, 3u}) {
    auto d = data(m, 60, range(1, 50), 1e-6, seed);
    auto c = d;
    c.Y.setZero();
    c.Y[0] = 3.0;
    c.varY.setZero();
    REQUIRE_THAT(refusal(c, s), Catch::StartsWith("y: the output is constant"));
    auto n = d;
    n.Y = data(m, 60, {}, 1e-6, seed + 10).Y;
    REQUIRE_THAT(refusal(n, s), Catch::StartsWith("y: the output shows no variation above its noise"));
  }
}

TEST_CASE("identify names the excited lines when the fit misses them", "[diagnostics]") {
  const auto m = lti_model();
  const auto d = data(m, 100, range(10, 20), 1e-6, 4);
  lptv::IdentifyOptions opt;
  opt.rows = range(60, 90);
  const std::string e = refusal(d, lptv::Structure::of(m), opt);
  REQUIRE_THAT(e, Catch::StartsWith("u: the input is not excited on the fitted lines") &&
                      Catch::Contains("excited on lines 10, 11, 12, 13, ..., 20 (11 lines)"));
}

TEST_CASE("identify counts the rows that carry signal", "[diagnostics]") {
  const auto m = lti_model();
  const auto d = data(m, 40, {10, 11}, 1e-6, 5);
  lptv::IdentifyOptions opt;
  opt.rows = range(5, 30);
  REQUIRE_THAT(refusal(d, lptv::Structure::of(m), opt),
               Catch::StartsWith("lines: only 2 of the 26 fitted lines carry signal"));
  // the same data suffice for a first-order model (2 free parameters)
  lptv::Structure first;
  first.na = 1;
  first.nb = 0;
  first.ka = {0, 0};
  first.kb = {0};
  first.w0 = m.w0();
  const auto diag = lptv::diagnose_data(d, first, range(1, 40));
  REQUIRE(diag.informative_rows == 2);
  REQUIRE(diag.excited == std::vector<int>{10, 11});
}

TEST_CASE("identify names known coefficients that cannot fix the scale", "[diagnostics]") {
  const auto m = lti_model();
  const auto d = data(m, 60, range(1, 50), 1e-6, 6);
  auto s = lptv::Structure::of(m);
  s.known.push_back({true, 1, Eigen::VectorXcd::Zero(1)});
  REQUIRE_THAT(refusal(d, s), Catch::StartsWith("known: a1 = 0 cannot fix the scale"));
  auto t = lptv::Structure::of(m);
  t.known.push_back({true, 2, Eigen::VectorXcd::Zero(1)});
  t.known.push_back({false, 0, Eigen::VectorXcd::Ones(1)});
  REQUIRE_THAT(refusal(d, t), Catch::StartsWith("known: a2 = 0 makes the highest-order coefficient"));
  // a nonzero known value fixes the scale: accepted, and the estimate is the system's
  auto k = lptv::Structure::of(m);
  k.known.push_back({false, 0, Eigen::VectorXcd::Ones(1)});
  const auto r = lptv::identify(d, k);
  REQUIRE(std::abs(r.model.a()(0, 0) - cd(2.0, 0.0)) < 1e-2);
}

TEST_CASE("sound data pass the diagnostics", "[diagnostics]") {
  const auto m = lti_model();
  for (unsigned seed : {7u, 8u, 9u, 10u}) {
    const auto d = data(m, 60, range(1, 50), 1e-2, seed);
    const auto diag = lptv::diagnose_data(d, lptv::Structure::of(m), range(1, 60));
    REQUIRE(diag.input.present);
    REQUIRE(diag.output.present);
    REQUIRE(diag.warnings.empty());
    REQUIRE_NOTHROW(lptv::identify(d, lptv::Structure::of(m)));
  }
}

TEST_CASE("format_lines abbreviates", "[diagnostics]") {
  REQUIRE(lptv::format_lines({3}) == "3 (1 line)");
  REQUIRE(lptv::format_lines({1, 2, 3, 4, 5}) == "1, 2, 3, 4, 5 (5 lines)");
  REQUIRE(lptv::format_lines({1, 2, 3, 4, 5, 9}) == "1, 2, 3, 4, ..., 9 (6 lines)");
}
