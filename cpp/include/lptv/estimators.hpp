// The estimators of METHOD.md section 6: LS, TLS, GTLS and the paper's weighted GTLS
// (eq. 14), all on the real, constrained Jacobian, all from its R factor.
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "lptv/jacobian.hpp"
#include "lptv/noise.hpp"

namespace lptv {

enum class Method { LS, TLS, GTLS, WGTLS };
Method method_from_string(const std::string& name);
std::string method_name(Method m);

struct EstimateOptions {
  Method method = Method::WGTLS;
  double tol = 1e-10;   // WGTLS: relative change of theta that ends the iteration
  int max_iter = 50;    // WGTLS: cap on the weighted solves
};

struct EstimateResult {
  Eigen::VectorXcd theta;            // all complex parameters (Parametrisation order)
  Eigen::VectorXd eta;               // free real parameters
  int iterations = 0;                // WGTLS: weighted solves after the GTLS start
  bool converged = true;
  double cost = 0;                   // the method's objective at the estimate
  std::vector<double> cost_history;  // WGTLS: cost per iteration
  // Generalised (GTLS, WGTLS) or ordinary (TLS) singular values of the final problem,
  // ascending (empty for LS). Two close smallest ones mean a near-unidentifiable model.
  Eigen::VectorXd singular_values;
  bool noise_free = false;           // the data carry no noise: GTLS/WGTLS fell back to TLS
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
GtlsSolve gtls_from_r(const Eigen::MatrixXd& R, const Eigen::MatrixXd& CJ);

EstimateResult estimate(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                        const EstimateOptions& opt = EstimateOptions());

}  // namespace lptv
