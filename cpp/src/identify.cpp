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

namespace {

// Every variance of a covariance finite and not negative, or a NumericalError: a negative
// variance is rounding that swamped the result, never a reportable interval.
void check_variances(const Eigen::MatrixXd& cov) {
  for (Eigen::Index i = 0; i < cov.rows(); ++i) {
    if (!std::isfinite(cov(i, i)) || cov(i, i) < 0) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.3g", cov(i, i));
      throw NumericalError(std::string("the covariance has a variance of ") + buf + " (entry " +
                           std::to_string(i) + "): rounding swamped it (the information matrix is nearly "
                           "singular at this estimate)");
    }
  }
}

// The fraction of normalised residues above 0 dB expected over experiments with different P:
// each row's probability from its own experiment's P (the fitted-parameter shrinkage over all
// rows), the band +-3 standard deviations of the count of independent Bernoulli rows.
ExpectedFraction mixed_expected_fraction(const std::vector<int>& n_rows, const std::vector<int>& periods,
                                         int n_free) {
  long long total = 0;
  for (int n : n_rows) total += n;
  double p = 0, var = 0;
  for (size_t e = 0; e < n_rows.size(); ++e) {
    const int P = periods[e] >= 2 ? periods[e] : 0;
    const double pe = expected_fraction_above_0db(static_cast<int>(total), n_free, P).p;
    p += n_rows[e] * pe;
    var += n_rows[e] * pe * (1 - pe);
  }
  p /= double(total);
  const double s = 3.0 * std::sqrt(var) / double(total);
  return {p, std::max(0.0, p - s), std::min(1.0, p + s)};
}

Identification identify_experiments(const std::vector<const FrequencyData*>& ds,
                                    const std::vector<std::vector<int>>& rows, const Parametrisation& p,
                                    const IdentifyOptions& opt) {
  const size_t E = ds.size();
  EstimateOptions eo;
  eo.method = opt.method;
  eo.tol = opt.tol;
  eo.max_iter = opt.max_iter;
  eo.full_rows = opt.full_rows;
  EstimateResult er;
  if (E == 1) {
    er = estimate(*ds[0], p, rows[0], eo);
  } else {
    std::vector<FrequencyData> copies;
    for (const FrequencyData* d : ds) copies.push_back(*d);
    er = estimate(copies, p, rows, eo);
  }

  Identification res(p.to_model(er.theta));
  res.method = opt.method;
  res.n_experiments = static_cast<int>(E);
  for (size_t e = 0; e < E; ++e) {
    res.rows.insert(res.rows.end(), rows[e].begin(), rows[e].end());
    res.experiment.insert(res.experiment.end(), rows[e].size(), static_cast<int>(e));
  }
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

  const Eigen::Index R = static_cast<Eigen::Index>(res.rows.size());
  // the rows' noise from the realisations (METHOD.md section 20) where the fit took it
  auto full = [&](size_t e) { return opt.full_rows && has_row_noise(*ds[e]); };
  auto variance = [&](size_t e) {
    return full(e) ? row_noise_variance(*ds[e], p, rows[e], er.theta) : residue_variance(*ds[e], p, rows[e], er.theta);
  };
  if (E == 1) {
    res.residue = residue(*ds[0], p, rows[0], er.theta);
    res.residue_variance = variance(0);
  } else {
    res.residue.resize(R);
    res.residue_variance.resize(R);
    Eigen::Index at = 0;
    for (size_t e = 0; e < E; ++e) {
      const Eigen::Index n = static_cast<Eigen::Index>(rows[e].size());
      res.residue.segment(at, n) = residue(*ds[e], p, rows[e], er.theta);
      res.residue_variance.segment(at, n) = variance(e);
      at += n;
    }
  }
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
  std::vector<int> periods, n_rows;
  bool same_periods = true;
  for (size_t e = 0; e < E; ++e) {
    periods.push_back(ds[e]->periods);
    n_rows.push_back(static_cast<int>(rows[e].size()));
    same_periods = same_periods && periods[e] == periods[0];
  }
  const int P0 = ds[0]->periods;
  res.fraction_expected = same_periods
                              ? expected_fraction_above_0db(static_cast<int>(R), res.n_free, P0 >= 2 ? P0 : 0)
                              : mixed_expected_fraction(n_rows, periods, res.n_free);
  res.residue_ok = res.fraction_above_0db >= res.fraction_expected.lo &&
                   res.fraction_above_0db <= res.fraction_expected.hi;

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
      EstimateResult g;
      if (E == 1) {
        g = estimate(*ds[0], p, rows[0], go);
      } else {
        std::vector<FrequencyData> copies;
        for (const FrequencyData* d : ds) copies.push_back(*d);
        g = estimate(copies, p, rows, go);
      }
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
      // (format() holds 256 characters: the numbers only)
      res.warnings.push_back(
          format("the two smallest generalised singular values are close (%.3g, %.3g): ", sv[0], sv[1]) +
          "the model is nearly unidentifiable; too many harmonics (a common periodic factor of numerator "
          "and denominator), too high orders or too little signal above the noise are the likely causes" +
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
    try {
      // The final WGTLS weights: 1 / var e_l, floored as the iteration floors them.
      const double vmax = res.residue_variance.maxCoeff();
      const Eigen::VectorXd w = res.residue_variance.cwiseMax(vmax * 1e-14).cwiseInverse();
      if (same_periods) {
        const int P = P0;
        const double factor = covariance_correction(P);
        Eigen::MatrixXd cov_free;
        if (E == 1) {
          ExactLikelihood lik(*ds[0], p, rows[0]);
          if (full(0)) lik.set_row_scale(row_noise_scale(*ds[0], p, rows[0], er.theta));
          if (opt.method == Method::SML) {
            // The information the fit's last step computed at this very theta (the same sum).
            Eigen::MatrixXd F = er.information.size() && !full(0) ? er.information : lik.fisher_information(er.theta);
            cov_free = symmetric_inverse(F, "the Fisher information");
          } else {
            // The sandwich with the estimating equation's second-order noise in its meat.
            const auto t = lik.sandwich_terms(er.theta, w);
            cov_free = sandwich_from_terms(
                t.bread, t.meat + second_order_meat(lik.second_order_terms(er.theta, w), p, er.theta));
          }
        } else {
          // Independent experiments: informations (and both sandwich terms) add.
          Eigen::MatrixXd bread, meat;
          ExactLikelihood::SecondOrderTerms second;
          Eigen::Index at = 0;
          for (size_t e = 0; e < E; ++e) {
            const Eigen::Index n = static_cast<Eigen::Index>(rows[e].size());
            if (opt.method == Method::SML && er.information.size() && !full(e)) {  // the fit's, summed already
              bread = er.information;
              break;
            }
            ExactLikelihood lik(*ds[e], p, rows[e], ExactLikelihood::PartOfSeveral{});
            if (full(e)) lik.set_row_scale(row_noise_scale(*ds[e], p, rows[e], er.theta));
            if (opt.method == Method::SML) {
              const Eigen::MatrixXd F = lik.fisher_information(er.theta);
              if (e == 0) bread = F; else bread += F;
            } else {
              const auto t = lik.sandwich_terms(er.theta, w.segment(at, n));
              const auto so = lik.second_order_terms(er.theta, w.segment(at, n));
              if (e == 0) {
                bread = t.bread; meat = t.meat; second = so;
              } else {
                bread += t.bread; meat += t.meat; second += so;
              }
            }
            at += n;
          }
          // One lambda for all experiments: the second-order terms add before they combine.
          if (opt.method != Method::SML) meat += second_order_meat(second, p, er.theta);
          if (opt.method == Method::SML) {
            cov_free = symmetric_inverse(bread, "the Fisher information");
          } else {
            cov_free = sandwich_from_terms(bread, meat);
          }
        }
        if (std::isfinite(factor)) {
          res.covariance = eta_covariance(p, cov_free * factor);
        } else {
          res.covariance = eta_covariance(p, cov_free);
          res.warnings.push_back(
              "the covariance has no small-sample correction: with noise variances from " + std::to_string(P) +
              " periods the estimate's variance is not finite in theory (4 periods or more are needed "
              "for calibrated intervals)");
        }
      } else {
        // Different P: the estimate weights each experiment by its sample information, so the
        // bread is the plain sum and each experiment's meat (for SML its information) carries
        // its own covariance_correction(P_e) (METHOD.md section 14).
        Eigen::MatrixXd bread, meat;
        ExactLikelihood::SecondOrderTerms second;
        Eigen::Index at = 0;
        std::vector<int> first_order;
        for (size_t e = 0; e < E; ++e) {
          ExactLikelihood lik(*ds[e], p, rows[e], ExactLikelihood::PartOfSeveral{});
          if (full(e)) lik.set_row_scale(row_noise_scale(*ds[e], p, rows[e], er.theta));
          const Eigen::Index n = static_cast<Eigen::Index>(rows[e].size());
          double c = covariance_correction(periods[e]);
          if (!std::isfinite(c)) {
            first_order.push_back(static_cast<int>(e));
            c = 1.0;
          }
          Eigen::MatrixXd Be, Me;
          if (opt.method == Method::SML) {
            Be = lik.fisher_information(er.theta);
            Me = c * Be;
          } else {
            auto t = lik.sandwich_terms(er.theta, w.segment(at, n));
            Be = std::move(t.bread);
            Me = c * t.meat;
            // Its second-order terms with the experiment's factor (CJ_W, which only gives
            // lambda's direction, as it is).
            auto so = lik.second_order_terms(er.theta, w.segment(at, n));
            so.qq *= c;
            so.qr *= c;
            so.rr *= c;
            if (e == 0) second = std::move(so); else second += so;
          }
          if (e == 0) { bread = Be; meat = Me; } else { bread += Be; meat += Me; }
          at += n;
        }
        if (opt.method != Method::SML) meat += second_order_meat(second, p, er.theta);
        res.covariance = eta_covariance(p, sandwich_from_terms(bread, meat));
        if (!first_order.empty()) {
          std::string which;
          for (int e : first_order) which += (which.empty() ? "" : ", ") + std::to_string(e);
          res.warnings.push_back(
              "the covariance has no small-sample correction for experiment(s) " + which +
              ": with noise variances from fewer than 4 periods the estimate's variance is not finite in "
              "theory (4 periods or more are needed for calibrated intervals)");
        }
      }
      check_variances(res.covariance);
    } catch (const NumericalError& e) {
      res.covariance.resize(0, 0);
      res.warnings.push_back(std::string("no covariance: ") + e.what());
    }
  }
  return res;
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
  std::vector<std::vector<int>> rows{opt.rows.empty() ? default_rows(p, d.max_line()) : opt.rows};
  check_rows(p, rows[0], d.max_line());
  // Degenerate data (no input power, a constant output, too few rows with signal, known
  // coefficients that cannot fix the scale) are refused here with their cause, before they
  // surface as a rank-deficient decomposition.
  const DataDiagnosis diagnosis = diagnose_data(d, s, rows[0]);
  Identification res = identify_experiments({&d}, rows, p, opt);
  res.warnings.insert(res.warnings.begin(), diagnosis.warnings.begin(), diagnosis.warnings.end());
  return res;
}

Identification identify(const std::vector<FrequencyData>& experiments, const Structure& s,
                        const IdentifyOptions& opt) {
  const size_t E = experiments.size();
  if (E == 0) throw std::invalid_argument("experiments: the list is empty (give one or more data sets)");
  if (E == 1 && opt.experiment_rows.empty()) return identify(experiments[0], s, opt);
  if (!opt.experiment_rows.empty() && opt.experiment_rows.size() != E) {
    throw std::invalid_argument("experiment_rows must give one list of rows per experiment (" +
                                std::to_string(E) + "), got " + std::to_string(opt.experiment_rows.size()));
  }
  if (!opt.rows.empty() && (E > 1 || !opt.experiment_rows.empty())) {
    throw std::invalid_argument("rows: with several experiments give the rows of each in experiment_rows");
  }
  for (size_t e = 0; e < E; ++e) {
    try {
      experiments[e].validate();
    } catch (const std::invalid_argument& err) {
      throw std::invalid_argument("experiment " + std::to_string(e) + ": " + err.what());
    }
  }
  s.validate();
  const long long K = s.kmax();
  long long n_rows = 0;
  for (size_t e = 0; e < E; ++e) {
    const bool given = !opt.experiment_rows.empty() && !opt.experiment_rows[e].empty();
    if (given) {
      try {
        check_row_lines(s, opt.experiment_rows[e], experiments[e].max_line());
      } catch (const std::invalid_argument& err) {
        throw std::invalid_argument("experiment " + std::to_string(e) + ": " + err.what());
      }
    } else if (experiments[e].max_line() - 2 * K < 1) {
      throw std::invalid_argument("experiment " + std::to_string(e) + ": its lines 0.." +
                                  std::to_string(experiments[e].max_line()) + " leave no default row for K = " +
                                  std::to_string(K) + " harmonics");
    }
    n_rows += given ? static_cast<long long>(opt.experiment_rows[e].size()) : experiments[e].max_line() - 2 * K;
  }
  if (2 * n_rows <= s.n_unknowns()) {
    throw std::invalid_argument(
        "the orders and harmonic counts leave " + std::to_string(s.n_unknowns()) + " free parameters for " +
        std::to_string(2 * n_rows) + " real equations over all experiments (" + std::to_string(n_rows) +
        " lines): use more lines or fewer harmonics / lower orders");
  }
  const Parametrisation p(s);
  std::vector<std::vector<int>> rows(E);
  std::vector<const FrequencyData*> ds;
  for (size_t e = 0; e < E; ++e) {
    const bool given = !opt.experiment_rows.empty() && !opt.experiment_rows[e].empty();
    rows[e] = given ? opt.experiment_rows[e] : default_rows(p, experiments[e].max_line());
    ds.push_back(&experiments[e]);
  }
  // The diagnostics per experiment (a dead channel in one record is named with it); the rows
  // carrying signal are counted over all of them, since records complete each other.
  std::vector<std::string> warnings;
  long long informative = 0;
  bool clear = false;
  for (size_t e = 0; e < E; ++e) {
    DataDiagnosis dd;
    try {
      dd = diagnose_data(experiments[e], s, rows[e], false);
    } catch (const std::invalid_argument& err) {
      throw std::invalid_argument("experiment " + std::to_string(e) + ": " + err.what());
    }
    informative += dd.informative_rows;
    clear = clear || dd.input.clear;
    for (const auto& w : dd.warnings) warnings.push_back("experiment " + std::to_string(e) + ": " + w);
  }
  if (clear && 2 * informative <= s.n_unknowns()) {
    throw std::invalid_argument(
        "lines: only " + std::to_string(informative) + " of the fitted lines of all experiments carry "
        "signal: " + std::to_string(2 * informative) + " real equations for " +
        std::to_string(s.n_unknowns()) + " free parameters; fit lines next to the excited ones, "
        "excite more lines, or use fewer harmonics / lower orders");
  }
  Identification res = identify_experiments(ds, rows, p, opt);
  res.warnings.insert(res.warnings.begin(), warnings.begin(), warnings.end());
  return res;
}

}  // namespace lptv
