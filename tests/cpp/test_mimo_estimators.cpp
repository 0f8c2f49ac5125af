// The MIMO estimators (METHOD.md section 19) in C++ without Python: noise-free spectra from the
// block band FDS give the normalised coefficients (TLS), noisy spectra give SML no worse than
// WGTLS and estimates within a few standard deviations of the truth, the Fisher information and
// the sandwich are symmetric positive definite, and bad input throws. The comparison with the
// dense reference is tests/python/test_mimo_fit.py's.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "lptv/errors.hpp"
#include "lptv/mimo.hpp"
#include "lptv/mimo_estimators.hpp"

using lptv::cd;

namespace {

// Two masses, M = I (so A_2,0 = I already), C = 0.3 I, K(t) = K0 + 0.4 cos(t) S, B = [[1, 0.5], [0, 1]].
lptv::MimoModel two_by_two() {
  const int ny = 2, nu = 2;
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(3 * ny * ny, 3), b = Eigen::MatrixXcd::Zero(ny * nu, 3);
  const double K0[2][2] = {{7.0, -2.0}, {-2.0, 5.0}}, S[2][2] = {{1.0, -1.0}, {-1.0, 1.0}};
  for (int p = 0; p < ny; ++p)
    for (int q = 0; q < ny; ++q) {
      a((0 * ny + p) * ny + q, 1) = K0[p][q];
      a((0 * ny + p) * ny + q, 0) = a((0 * ny + p) * ny + q, 2) = 0.2 * S[p][q];
      a((1 * ny + p) * ny + q, 1) = p == q ? 0.3 : 0.0;
      a((2 * ny + p) * ny + q, 1) = p == q ? 1.0 : 0.0;
    }
  b(0, 1) = 1.0;
  b(1, 1) = 0.5;
  b(3, 1) = 1.0;
  return lptv::MimoModel(a, b, ny, nu, 1.0);
}

lptv::MimoStructure structure() {
  lptv::MimoStructure s;
  s.ny = 2;
  s.nu = 2;
  s.ka = Eigen::MatrixXi::Zero(3, 2);
  s.ka.row(0).setConstant(1);
  s.kb = Eigen::MatrixXi::Zero(1, 2);
  s.w0 = 1.0;
  return s;
}

// xi of the model in the structure's layout (row p: a_0 q=0,1 with re0 re1 im1; a_1, a_2 re0; b_0 re0).
Eigen::VectorXd truth(const lptv::MimoModel& m) {
  Eigen::VectorXd xi(2 * (2 * 3 + 2 + 2 + 2));
  int j = 0;
  for (int p = 0; p < 2; ++p) {
    for (int q = 0; q < 2; ++q) {
      const cd c0 = m.a_coef(0, p, q, 0), c1 = m.a_coef(0, p, q, 1);
      xi(j++) = c0.real();
      xi(j++) = c1.real();
      xi(j++) = c1.imag();
    }
    for (int n = 1; n <= 2; ++n)
      for (int q = 0; q < 2; ++q) xi(j++) = m.a_coef(n, p, q, 0).real();
    for (int r = 0; r < 2; ++r) xi(j++) = m.b_coef(0, p, r, 0).real();
  }
  return xi;
}

// Two experiments (orthogonal: input 2 flips sign), lines 2..24 excited, spectra up to L = 40;
// noise of standard deviation sigma on every line and channel, the covariance of the means
// that of P periods.
std::vector<lptv::MimoSpectra> experiments(const lptv::MimoModel& m, double sigma, unsigned seed) {
  const int L = 40, P = 8, c = 4;
  std::mt19937 gen(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> ph(0.0, 2 * M_PI);
  Eigen::MatrixXcd U0 = Eigen::MatrixXcd::Zero(L + 1, 2);
  for (int l = 2; l <= 24; ++l)
    for (int r = 0; r < 2; ++r) U0(l, r) = std::polar(1.0, ph(gen));
  std::vector<lptv::MimoSpectra> out;
  for (int e = 0; e < 2; ++e) {
    Eigen::MatrixXcd U = U0;
    if (e == 1) U.col(1) *= -1.0;
    lptv::SimulateOptions opt;
    opt.lines_out = L;
    const Eigen::MatrixXcd Y = lptv::simulate_mimo(m, U, opt).Y;
    lptv::MimoSpectra d;
    d.Y = Y;
    d.U = U;
    d.C = Eigen::MatrixXcd::Zero((L + 1) * c, c);
    for (int l = 0; l <= L; ++l) {
      Eigen::MatrixXcd Z(P, c);
      for (int k = 0; k < P; ++k)
        for (int ch = 0; ch < c; ++ch) Z(k, ch) = sigma * cd(nd(gen), nd(gen)) / std::sqrt(2.0);
      const Eigen::RowVectorXcd mean = Z.colwise().mean();
      if (sigma > 0) {
        d.Y.row(l) += mean.head(2);
        d.U.row(l) += mean.tail(2);
        const Eigen::MatrixXcd dz = Z.rowwise() - mean;
        d.C.block(l * c, 0, c, c) = (dz.transpose() * dz.conjugate()) / double(P * (P - 1));
      }
    }
    for (int l = 2; l <= L - 1; ++l) d.rows.push_back(l);
    out.push_back(d);
  }
  return out;
}

}  // namespace

TEST_CASE("noise-free spectra give the coefficients", "[mimo_estimators]") {
  const lptv::MimoModel m = two_by_two();
  const auto data = experiments(m, 0.0, 1);
  const lptv::MimoEstimate est = lptv::mimo_wgtls(data, structure(), 1e-12, 50);
  REQUIRE(est.noise_free);
  const Eigen::VectorXd xi = truth(m);
  // the FDS's spectra are exact to about 1e-15 of the largest line; the TLS problem's condition
  // (largest over the 5th smallest singular value) amplifies that
  const double cond = est.singular_values(est.singular_values.size() - 1) / est.singular_values(4);
  REQUIRE(cond < 1e4);
  REQUIRE((est.xi - xi).cwiseAbs().maxCoeff() <= 1e-12 * cond * xi.cwiseAbs().maxCoeff());
}

TEST_CASE("SML from WGTLS on noisy spectra", "[mimo_estimators]") {
  const lptv::MimoModel m = two_by_two();
  const Eigen::VectorXd xi = truth(m);
  const std::vector<int> free = lptv::mimo_free_indices(structure());
  REQUIRE(static_cast<Eigen::Index>(free.size()) == xi.size() - 4);
  for (unsigned seed : {2u, 3u}) {
    const auto data = experiments(m, 0.02, seed);
    const lptv::MimoEstimate w = lptv::mimo_wgtls(data, structure(), 1e-10, 50);
    REQUIRE(w.converged);
    const lptv::MimoEstimate s = lptv::mimo_sml(data, structure(), w.xi, 1e-10, 50);
    REQUIRE(s.converged);
    // SML minimises the cost WGTLS only approximates
    const double c_w = lptv::mimo_sml(data, structure(), w.xi, 1e-10, 0).cost;
    REQUIRE(s.cost <= c_w);
    const Eigen::MatrixXd F = lptv::mimo_fisher(data, structure(), s.xi);
    REQUIRE((F - s.information).cwiseAbs().maxCoeff() <= 1e-10 * F.cwiseAbs().maxCoeff());
    REQUIRE((F - F.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * F.cwiseAbs().maxCoeff());
    Eigen::LLT<Eigen::MatrixXd> llt(F);
    REQUIRE(llt.info() == Eigen::Success);
    const Eigen::MatrixXd cov = llt.solve(Eigen::MatrixXd::Identity(F.rows(), F.cols()));
    for (size_t f = 0; f < free.size(); ++f)  // 5 standard deviations: 6e-7 for one of 36 normal draws
      REQUIRE(std::abs(s.xi(free[f]) - xi(free[f])) <= 5 * std::sqrt(cov(f, f)));
    const Eigen::MatrixXd sw = lptv::mimo_sandwich(data, structure(), w.xi);
    Eigen::LLT<Eigen::MatrixXd> l2(0.5 * (sw + sw.transpose()));
    REQUIRE(l2.info() == Eigen::Success);
  }
}

TEST_CASE("MIMO estimators refuse bad input", "[mimo_estimators]") {
  const lptv::MimoModel m = two_by_two();
  auto data = experiments(m, 0.01, 4);
  lptv::MimoStructure s = structure();
  auto bad = data;
  bad[0].rows = {0, 1, 2};  // line 0 is not a row (rows are lines 1..L - K)
  REQUIRE_THROWS_AS(lptv::mimo_wgtls(bad, s, 1e-10, 10), std::invalid_argument);
  bad[0].rows = {1, 2, 3};  // row 1 reads line 0: WGTLS takes it, the circular likelihood does not
  const lptv::MimoEstimate low = lptv::mimo_wgtls(bad, s, 1e-10, 10);
  REQUIRE(low.xi.allFinite());
  REQUIRE_THROWS_AS(lptv::mimo_sml(bad, s, low.xi, 1e-10, 10), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::mimo_fisher(bad, s, low.xi), std::invalid_argument);
  bad = data;
  bad[1].C.conservativeResize(bad[1].C.rows() - 1, Eigen::NoChange);
  REQUIRE_THROWS_AS(lptv::mimo_wgtls(bad, s, 1e-10, 10), std::invalid_argument);
  s.ka = Eigen::MatrixXi::Zero(3, 3);
  REQUIRE_THROWS_AS(lptv::mimo_wgtls(data, s, 1e-10, 10), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::mimo_sml(data, structure(), Eigen::VectorXd::Zero(3), 1e-10, 10), std::invalid_argument);
}

TEST_CASE("mimo_fit is WGTLS, SML and their covariances in one call", "[mimo_estimators]") {
  const lptv::MimoModel m = two_by_two();
  const auto data = experiments(m, 0.02, 5);
  const lptv::MimoEstimate w = lptv::mimo_wgtls(data, structure(), 1e-10, 50);
  const lptv::MimoEstimate s = lptv::mimo_sml(data, structure(), w.xi, 1e-10, 50);
  const lptv::MimoFit fw = lptv::mimo_fit(data, structure(), "wgtls", 1e-10, 50, true);
  const lptv::MimoFit fs = lptv::mimo_fit(data, structure(), "sml", 1e-10, 50, true);
  REQUIRE(fw.estimate.xi == w.xi);  // the same operations on the same numbers
  REQUIRE(fs.estimate.xi == s.xi);
  const Eigen::MatrixXd sw = lptv::mimo_sandwich(data, structure(), w.xi);
  REQUIRE((fw.covariance - sw).cwiseAbs().maxCoeff() <= 1e-12 * sw.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd I = fs.covariance * s.information;
  REQUIRE((I - Eigen::MatrixXd::Identity(I.rows(), I.cols())).cwiseAbs().maxCoeff() <= 1e-8);
  Eigen::MatrixXcd e, Ce;
  lptv::mimo_residues(data[1], structure(), s.xi, e, Ce);
  const Eigen::Index r0 = static_cast<Eigen::Index>(data[0].rows.size());
  REQUIRE(fs.residues.rows() == r0 + e.rows());
  REQUIRE((fs.residues.bottomRows(e.rows()) - e).cwiseAbs().maxCoeff() == 0.0);
  REQUIRE((fs.residue_covariance.bottomRows(Ce.rows()) - Ce).cwiseAbs().maxCoeff() == 0.0);
  REQUIRE_THROWS_AS(lptv::mimo_fit(data, structure(), "ls", 1e-10, 50, true), std::invalid_argument);
}

TEST_CASE("an absent entry of B (kb = -1) is the structure without it", "[mimo_estimators]") {
  // nb = 1 with every B_1 entry absent has exactly the parameters and rows of nb = 0: the same
  // estimates, SML costs and covariances to rounding
  const lptv::MimoModel m = two_by_two();
  const auto data = experiments(m, 0.02, 5);
  lptv::MimoStructure s0 = structure(), s1 = structure();
  s1.kb = Eigen::MatrixXi::Zero(2, 2);
  s1.kb.row(1).setConstant(-1);
  REQUIRE(lptv::mimo_free_indices(s1) == lptv::mimo_free_indices(s0));
  for (const std::string method : {"wgtls", "sml"}) {
    const lptv::MimoFit f0 = lptv::mimo_fit(data, s0, method, 1e-10, 50, true);
    const lptv::MimoFit f1 = lptv::mimo_fit(data, s1, method, 1e-10, 50, true);
    REQUIRE((f0.estimate.xi - f1.estimate.xi).cwiseAbs().maxCoeff() <= 1e-12 * f0.estimate.xi.cwiseAbs().maxCoeff());
    REQUIRE((f0.covariance - f1.covariance).cwiseAbs().maxCoeff() <= 1e-10 * f0.covariance.cwiseAbs().maxCoeff());
  }
  // one column's B_1 present, the other's absent: one real parameter more per output row
  s1.kb(1, 0) = 0;
  REQUIRE(lptv::mimo_free_indices(s1).size() == lptv::mimo_free_indices(s0).size() + 2);
  s1.kb(1, 0) = -2;
  REQUIRE_THROWS_AS(lptv::mimo_wgtls(data, s1, 1e-10, 10), std::invalid_argument);
}
