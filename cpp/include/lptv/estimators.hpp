// The estimators of METHOD.md sections 6 and 10: LS, TLS, GTLS and the paper's weighted GTLS
// (eq. 14), all on the real, constrained Jacobian from its R factor, and the sample maximum
// likelihood on the exact cost (eq. 17). lptv::identify is the one entry point: estimate,
// covariance, residue diagnostics and warnings.
#pragma once
#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include "lptv/jacobian.hpp"
#include "lptv/noise.hpp"

namespace lptv {

enum class Method { LS, TLS, GTLS, WGTLS, SML };
Method method_from_string(const std::string& name);
std::string method_name(Method m);

struct EstimateOptions {
  Method method = Method::WGTLS;
  double tol = 1e-10;   // WGTLS, SML: relative change of the parameters that ends the iteration
  int max_iter = 50;    // WGTLS: cap on the weighted solves; SML: on the Levenberg-Marquardt steps
  // The rows' noise from the data's realisations (METHOD.md section 20, has_row_noise): WGTLS's
  // weights and CJ_W from them, SML's residue covariance with those variances on its diagonal
  // (row_noise_scale); data without realisations keep eq. 15.
  bool full_rows = false;
};

struct EstimateResult {
  Eigen::VectorXcd theta;            // all complex parameters (Parametrisation order)
  Eigen::VectorXd eta;               // free real parameters
  int iterations = 0;                // WGTLS: weighted solves after the GTLS start; SML: LM steps
  int start_iterations = 0;          // SML: the weighted solves of its WGTLS start
  bool converged = true;
  // The method's objective at the estimate; SML: V / (2 |R|), the mean of |e_l|^2 / var e_l
  // for uncorrelated rows.
  double cost = 0;
  std::vector<double> cost_history;  // WGTLS, SML: cost per iteration
  // Generalised (GTLS, WGTLS) or ordinary (TLS) singular values of the final problem,
  // ascending (empty for LS). Two close smallest ones mean a near-unidentifiable model.
  Eigen::VectorXd singular_values;
  bool noise_free = false;           // the data carry no noise: GTLS/WGTLS fell back to TLS
  // SML: the Fisher information of the free parameters at the estimate (J^T J of the whitened
  // Jacobian, summed over the experiments), which the last step computed; empty otherwise.
  Eigen::MatrixXd information;
};

// The R factor (n_xi x n_xi) of the real Jacobian [Re(J Text); Im(J Text)] with row l
// scaled by sqrt(weights[l]) (empty weights: all 1), by a QR over blocks of rows:
// O(rows n^2) time, O(block n) memory; the Jacobian is never formed whole.
Eigen::MatrixXd weighted_r_factor(const FrequencyData& d, const Parametrisation& p,
                                  const std::vector<int>& rows, const Eigen::VectorXd& weights);

// CJ_W = Re(Text^H C Text), C = column_covariance(d, p, rows, weights).
Eigen::MatrixXd real_column_covariance(const FrequencyData& d, const Parametrisation& p,
                                       const std::vector<int>& rows, const Eigen::VectorXd& weights);

// min ||R x||^2 / (x^T CJ x) over x; returns the minimising x (unnormalised) and the
// generalised singular values (ascending). GTLS is invariant to column scaling, so
// columns are scaled to unit norm before the GSVD.
struct GtlsSolve {
  Eigen::VectorXd x;
  Eigen::VectorXd values;
};
// start (optional): a guess of x (the previous WGTLS solve's); with it and a gap between the
// two smallest values the vector comes by inverse iteration instead of a full SVD.
GtlsSolve gtls_from_r(const Eigen::MatrixXd& R, const Eigen::MatrixXd& CJ,
                      const Eigen::VectorXd& start = Eigen::VectorXd());

EstimateResult estimate(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                        const EstimateOptions& opt = EstimateOptions());
// Several independent experiments on the same system (same w0 and time domain), each with its
// own rows (METHOD.md section 14): rows stacked, column covariances summed, WGTLS weights per
// row from its own experiment, the exact likelihood's S block diagonal over experiments.
// One experiment gives exactly the single-experiment estimate.
EstimateResult estimate(const std::vector<FrequencyData>& experiments, const Parametrisation& p,
                        const std::vector<std::vector<int>>& rows,
                        const EstimateOptions& opt = EstimateOptions());

// Fraction of normalised residues above 0 dB expected for a correct model, and a band of
// +-3 binomial standard deviations over the rows (METHOD.md section 7).
struct ExpectedFraction {
  double p, lo, hi;
};
ExpectedFraction expected_fraction_above_0db(int n_rows, int n_free, int periods);

// Factor applied to the first-order covariance of the SML and WGTLS estimates when the noise
// (co)variances come from P periods (P = 0: known, factor 1); see identify.cpp.
double covariance_correction(int periods);

struct IdentifyOptions {
  Method method = Method::WGTLS;
  double tol = 1e-10;
  int max_iter = 50;
  std::vector<int> rows;    // lines of the fit; empty: default_rows
  // Several experiments: the rows of each (empty, or an empty entry: that experiment's
  // default_rows). With one experiment, `rows` may be used instead.
  std::vector<std::vector<int>> experiment_rows;
  bool covariance = true;   // WGTLS, SML: compute the covariance of eta
  bool full_rows = false;   // the rows' noise from the data's realisations (EstimateOptions)
};

struct Identification {
  explicit Identification(Model m) : model(std::move(m)) {}
  Model model;                        // normalised: a_{na,0} = 1 (or scaled by known coefficients)
  Method method = Method::WGTLS;
  std::vector<int> rows;              // the rows of every experiment, one after the other
  std::vector<int> experiment;        // per row: the index of its experiment (all 0 for one)
  int n_experiments = 1;
  Eigen::VectorXcd theta;
  Eigen::VectorXd eta;
  std::vector<std::string> eta_names;
  int n_free = 0;
  int iterations = 0;
  bool converged = true;
  double cost = 0;
  std::vector<double> cost_history;
  Eigen::VectorXd singular_values;
  Eigen::VectorXcd residue;           // e_l on the rows
  Eigen::VectorXd residue_variance;   // var e_l (eq. 15)
  Eigen::VectorXd normalized_residue; // |e_l| / sqrt(var e_l); NaN where var e_l = 0 (warned)
  double fraction_above_0db = 0;      // over the rows with var e_l > 0
  ExpectedFraction fraction_expected{0, 0, 0};
  bool residue_ok = false;            // fraction_above_0db inside the expected band
  bool nearly_unidentifiable = false; // the two smallest generalised singular values are close
                                      // (LS, TLS: those of the GTLS problem on the same rows)
  bool noise_free = false;
  // WGTLS (sandwich) and SML (inverse Fisher information), times covariance_correction(P):
  // n_eta x n_eta, zero row and column for the normalised parameter; empty otherwise. With
  // experiments of different P, each experiment's term of the sandwich carries its own factor
  // (METHOD.md section 14).
  Eigen::MatrixXd covariance;
  std::vector<std::string> warnings;
};

// Estimate, covariance and residue diagnostics of every method on the data (METHOD.md 5-7, 10).
Identification identify(const FrequencyData& d, const Structure& s, const IdentifyOptions& opt = IdentifyOptions());
// Several experiments of the same system (same w0, same time domain: the caller's structure)
// fitted together into one model (METHOD.md section 14); rows per experiment from
// opt.experiment_rows. The result's rows, residues and `experiment` run over all experiments.
Identification identify(const std::vector<FrequencyData>& experiments, const Structure& s,
                        const IdentifyOptions& opt = IdentifyOptions());

}  // namespace lptv
