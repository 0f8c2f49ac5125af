// lptv::identify: one entry point for every method, with the covariance of the iterative
// methods, the residue diagnostics of METHOD.md section 7 and warnings that name a cause.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "lptv/diagnostics.hpp"
#include "lptv/errors.hpp"
#include "lptv/estimators.hpp"
#include "lptv/likelihood.hpp"

namespace lptv {

ExpectedFraction expected_fraction_above_0db(int n_rows, int n_free, int periods) {
  if (n_rows < 1) throw std::invalid_argument("n_rows must be >= 1, got " + std::to_string(n_rows));
  if (n_free < 0) throw std::invalid_argument("n_free must be >= 0, got " + std::to_string(n_free));
  if (periods < 0 || periods == 1) {
    throw std::invalid_argument("periods must be 0 (known variances) or >= 2, got " + std::to_string(periods));
  }
  // |e|^2 / var e ~ F(2, 2(P-1)) with variances from P periods, Exp(1) with known ones; fitting
  // n parameters to 2|R| real equations shrinks |e|^2 by c = 1 - n / (2|R|).
  const double c = std::max(1.0 - n_free / (2.0 * n_rows), 1e-6);
  double p;
  if (periods >= 2) {
    const double q = periods - 1;
    p = std::pow(1.0 + 1.0 / (c * q), -q);
  } else {
    p = std::exp(-1.0 / c);
  }
  const double s = 3.0 * std::sqrt(p * (1 - p) / n_rows);
  return {p, std::max(0.0, p - s), std::min(1.0, p + s)};
}

// The first-order covariance (inverse Fisher information, or the WGTLS sandwich) evaluated
// with noise (co)variances from P periods is too small on two counts:
// - the sample variances of the mean have 2(P-1) real degrees of freedom, so the Fisher
//   information built from them is too large on average by E{1 / (chi2_{2(P-1)} / (2(P-1)))}
//   = (P-1)/(P-2);
// - the estimate itself, weighted by those sample variances, has a variance (P-2)/(P-3) times
//   that with known variances (Pintelon, Schoukens, Guillaume, "Sample maximum likelihood", 1997).
// Together (P-1)/(P-3), finite from P = 4; the Monte Carlo in bench/ checks the coverage.
double covariance_correction(int periods) {
  if (periods == 0) return 1.0;
  if (periods < 4) return std::numeric_limits<double>::infinity();
  return (periods - 1.0) / (periods - 3.0);
}

namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

}  // namespace

Identification identify(const FrequencyData& d, const Structure& s, const IdentifyOptions& opt) {
  d.validate();
  s.validate();
  if (!opt.rows.empty()) check_row_lines(s, opt.rows, d.max_line());
  {
    // Equations against unknowns before anything is allocated for the structure.
    const long long K = s.kmax();
    const long long n_rows = opt.rows.empty() ? std::max(0LL, d.max_line() - 2 * K)
                                              : static_cast<long long>(opt.rows.size());
    if (2 * n_rows <= s.n_unknowns()) {
      throw std::invalid_argument(
          "the orders and harmonic counts leave " + std::to_string(s.n_unknowns()) + " free parameters for " +
          std::to_string(2 * n_rows) + " real equations (" + std::to_string(n_rows) +
          " lines): use more lines or fewer harmonics / lower orders");
    }
  }
  const Parametrisation p(s);
  const std::vector<int> rows = opt.rows.empty() ? default_rows(p, d.max_line()) : opt.rows;
  check_rows(p, rows, d.max_line());
  // Degenerate data (no input power, a constant output, too few rows with signal, known
  // coefficients that cannot fix the scale) are refused here with their cause, before they
  // surface as a rank-deficient decomposition.
  const DataDiagnosis diagnosis = diagnose_data(d, s, rows);

  EstimateOptions eo;
  eo.method = opt.method;
  eo.tol = opt.tol;
  eo.max_iter = opt.max_iter;
  const EstimateResult er = estimate(d, p, rows, eo);

  Identification res(p.to_model(er.theta));
  res.method = opt.method;
  res.rows = rows;
  res.theta = er.theta;
  res.eta = er.eta;
  res.eta_names = p.eta_names();
  res.n_free = p.n_xi() - 1;
  res.iterations = er.iterations;
  res.converged = er.converged;
  res.cost = er.cost;
  res.cost_history = er.cost_history;
  res.singular_values = er.singular_values;
  res.noise_free = er.noise_free;

  res.residue = residue(d, p, rows, er.theta);
  res.residue_variance = residue_variance(d, p, rows, er.theta);
  const Eigen::Index R = static_cast<Eigen::Index>(rows.size());
  res.normalized_residue.resize(R);
  int positive = 0, above = 0;
  for (Eigen::Index r = 0; r < R; ++r) {
    const double v = res.residue_variance[r];
    if (v > 0) {
      res.normalized_residue[r] = std::abs(res.residue[r]) / std::sqrt(v);
      ++positive;
      above += res.normalized_residue[r] > 1.0;
    } else {
      res.normalized_residue[r] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  res.fraction_above_0db = positive ? double(above) / positive : std::numeric_limits<double>::quiet_NaN();
  res.fraction_expected = expected_fraction_above_0db(static_cast<int>(R), res.n_free, d.periods >= 2 ? d.periods : 0);
  res.residue_ok = res.fraction_above_0db >= res.fraction_expected.lo &&
                   res.fraction_above_0db <= res.fraction_expected.hi;

  res.warnings = diagnosis.warnings;
  const bool weighted = opt.method == Method::GTLS || opt.method == Method::WGTLS || opt.method == Method::SML;
  // LS and TLS do not weigh the noise, so their own singular values say nothing about what the
  // noise leaves determined: the test below reads those of the GTLS problem on the same rows
  // (one more solve), so that an estimate the data do not determine is flagged whatever the
  // method.
  Eigen::VectorXd sv_noise;
  if (!weighted && !er.noise_free) {
    EstimateOptions go;
    go.method = Method::GTLS;
    try {
      const EstimateResult g = estimate(d, p, rows, go);
      if (!g.noise_free) sv_noise = g.singular_values;
    } catch (const NumericalError&) {
      // a rank-deficient GTLS pair: nothing to compare; the estimate stands as computed
    }
  }
  const auto& sv = weighted ? er.singular_values : sv_noise;
  // Close smallest generalised singular values mean a second direction explains the data
  // almost as well. That points to too many harmonics or orders only when the residues are not
  // too large: an under-modelled fit has close values too, for a different reason, and puts
  // more residues above 0 dB than the band allows (the residue test says so). Over-fitting puts
  // fewer, so a fraction below the band does not silence the warning.
  // "Close": in a noise-only subspace of dimension d the generalised eigenvalues sv^2 behave
  // like those of a d x d Wishart matrix with m = 2|R| - n_free degrees of freedom over m,
  // within (1 -+ sqrt(d/m))^2 (Marchenko-Pastur); d = 4 covers one harmonic too many (a common
  // periodic factor: cos, sin and the true direction) with margin. On the paper's example
  // (bench/python/bench_identifiability.py) the bound is 1.46; one harmonic too many gives
  // sv1^2/sv0^2 = 1.01-1.35, the correct model 1.51-3.6 at P = 4 and 3.7-7.2 at P = 8 (a fixed
  // bound of 2 fired on ~10 % of correct P = 4 fits and missed over-fitted small problems).
  const double m_dof = std::max(1.0, 2.0 * static_cast<double>(R) - res.n_free);
  const double c = std::min(0.5, std::sqrt(4.0 / m_dof));
  const double close = std::pow((1 + c) / (1 - c), 2);
  if (!er.noise_free && sv.size() >= 2 && sv[1] * sv[1] < close * sv[0] * sv[0]) {
    // (LS, TLS: their residues are not those of the tested GTLS problem, so the gate does not
    // apply to them.)
    if (!weighted || res.fraction_above_0db <= res.fraction_expected.hi) {
      res.nearly_unidentifiable = true;
      res.warnings.push_back(format(
          "the two smallest generalised singular values are close (%.3g, %.3g): the model is nearly "
          "unidentifiable; too many harmonics (a common periodic factor of numerator and denominator), "
          "too high orders or too little signal above the noise are the likely causes", sv[0], sv[1]) +
          (weighted ? "" : " (values of the noise-weighted GTLS problem on the same lines)"));
    }
  }
  if ((opt.method == Method::WGTLS || opt.method == Method::SML) && !er.converged) {
    res.warnings.push_back(std::string(opt.method == Method::SML ? "SML" : "WGTLS") + " did not converge in " +
                           std::to_string(opt.max_iter) + " iterations" + format(" (tol %g)", opt.tol));
  }
  if (er.noise_free) {
    res.warnings.push_back("the data carry no noise (zero variances): the noise-weighted estimate reduces to TLS");
  }
  if (positive < R) {
    res.warnings.push_back("the residue variance is zero on " + std::to_string(R - positive) + " of " +
                           std::to_string(R) + " rows (no noise there): their normalised residues are NaN "
                           "and the 0 dB fraction is taken over the other rows");
  }

  if (opt.covariance && !er.noise_free && (opt.method == Method::WGTLS || opt.method == Method::SML)) {
    const int P = d.periods;
    const double factor = covariance_correction(P);
    try {
      const ExactLikelihood lik(d, p, rows);
      Eigen::MatrixXd cov_free;
      if (opt.method == Method::SML) {
        Eigen::MatrixXd F = lik.fisher_information(er.theta);
        Eigen::LDLT<Eigen::MatrixXd> ldlt(F);
        if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0))
          throw NumericalError("the Fisher information is singular");
        cov_free = ldlt.solve(Eigen::MatrixXd::Identity(F.rows(), F.cols()));
        cov_free = 0.5 * (cov_free + cov_free.transpose()).eval();
      } else {
        // The final WGTLS weights: 1 / var e_l, floored as the iteration floors them.
        const double vmax = res.residue_variance.maxCoeff();
        const Eigen::VectorXd w = res.residue_variance.cwiseMax(vmax * 1e-14).cwiseInverse();
        cov_free = lik.sandwich_covariance(er.theta, w);
      }
      if (std::isfinite(factor)) {
        res.covariance = eta_covariance(p, cov_free * factor);
      } else {
        res.covariance = eta_covariance(p, cov_free);
        res.warnings.push_back(
            "the covariance is first-order only: with noise variances from " + std::to_string(P) +
            " periods the estimate's variance is not finite in theory (4 periods or more are needed "
            "for calibrated intervals)");
      }
    } catch (const NumericalError& e) {
      res.warnings.push_back(std::string("no covariance: ") + e.what());
    }
  }
  return res;
}

}  // namespace lptv
