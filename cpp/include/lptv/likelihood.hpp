// The exact errors-in-variables likelihood of the residue for LPTV rows (METHOD.md
// section 10): the banded residue covariance S = M Cov(n) M^T (eq. 16), the cost
// V = r^T S^{-1} r (eq. 17), its exact gradient, the Fisher information and the
// Cramer-Rao bound.
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/noise.hpp"
#include "lptv/structure.hpp"

namespace lptv {

// The likelihood of one data set on one set of rows. Rows are taken in ascending order
// (rows l and l' share noisy lines only when |l - l'| <= 2K, so S is banded in that order);
// every per-row output below is in the caller's order.
//
// Real residue r = [Re e_l, Im e_l] per row; real noise n = [Re dY_m, Im dY_m, Re dU_m,
// Im dU_m] per measured line m >= 0 (DC: real parts only). r = M(theta) x with x the
// measured spectra in the layout of n, so dV/dxi_j = 2 q^T M_j x0 with q = S^{-1} r and
// x0 = x - Cov(n) M^T q, the data nearest to x that the model explains exactly (the
// noiseless spectra the likelihood eliminates). The whitened Jacobian L^{-1} M_j x0 thus
// gives the exact gradient and the Gauss-Newton (Fisher) approximation of the Hessian.
struct ExactFit;

class ExactLikelihood {
 public:
  ExactLikelihood(const FrequencyData& d, const Parametrisation& p, std::vector<int> rows);
  // One experiment of several fitted together (METHOD.md section 14): the rows are checked
  // line by line only, since the equations are counted over all experiments.
  struct PartOfSeveral {};
  ExactLikelihood(const FrequencyData& d, const Parametrisation& p, std::vector<int> rows, PartOfSeveral);

  struct Evaluation {
    double cost = 0;             // V = r^T S^{-1} r
    Eigen::VectorXd whitened;    // w = L^{-1} r (S = L L^T), sorted-row order; V = |w|^2
    Eigen::VectorXd gradient;    // dV/dxi over all n_xi entries of xi (theta = Text xi)
    Eigen::MatrixXd jacobian;    // L^{-1} dr/dxi at x0 (sorted-row order), all n_xi columns
    FrequencyData denoised;      // x0 as spectra (lines the rows do not use: as measured)
  };

  // The cost alone (one banded Cholesky).
  double cost(const Eigen::VectorXcd& theta) const;
  // Cost, gradient and whitened Jacobian. Throws NumericalError when S is not positive
  // definite (rows whose lines carry no noise), naming the row.
  Evaluation evaluate(const Eigen::VectorXcd& theta) const;

  // F = J^T S^{-1} J over the free entries of xi (Parametrisation::free_indices), J = dr/dxi
  // at x0 (at the data themselves when they are noiseless: then F^{-1} is the Cramer-Rao bound).
  Eigen::MatrixXd fisher_information(const Eigen::VectorXcd& theta) const;

  // Sandwich covariance of the free entries of xi for an estimator whose estimating equation
  // is J^T W (M x) = 0 with the real row weights W = diag(w_l, w_l): H^{-1} J^T W S W J H^{-1},
  // H = J^T W J, J = dr/dxi at x0 (the weighted GTLS of eq. 14 to first order in the noise).
  Eigen::MatrixXd sandwich_covariance(const Eigen::VectorXcd& theta, const Eigen::VectorXd& weights) const;
  // Its two terms, H = J^T W J (bread) and J^T W S W J (meat): experiments are independent, so
  // both add over the experiments of a joint fit.
  struct SandwichTerms {
    Eigen::MatrixXd bread, meat;
  };
  SandwichTerms sandwich_terms(const Eigen::VectorXcd& theta, const Eigen::VectorXd& weights) const;

  // The second-order part of WGTLS's estimating equation (METHOD.md section 10): at the
  // estimate, with dJ the noise of the Jacobian and r0 = dJ xi that of the residue, the
  // equation's noise is q - lambda CJ_W xi, q = dJ^T W r0 (second order in the noise, zero
  // mean after the bias correction), lambda = R / (xi^T CJ_W xi), R = r0^T W r0. Its pieces
  // for one experiment, in xi coordinates (all n_xi entries), for Gaussian noise circular on
  // every line (a DC line read by a row is taken as circular too):
  struct SecondOrderTerms {
    Eigen::MatrixXd qq;  // Cov(q)
    Eigen::VectorXd qr;  // Cov(q, R)
    double rr = 0;       // Var(R)
    Eigen::MatrixXd cj;  // CJ_W = E{dJ^T W dJ}
    SecondOrderTerms& operator+=(const SecondOrderTerms& o);
  };
  SecondOrderTerms second_order_terms(const Eigen::VectorXcd& theta, const Eigen::VectorXd& weights) const;

  // The rows' noise scaled (METHOD.md section 20): S = D S_line D with D = diag(scale), one
  // entry per row in the caller's order (empty: none), held fixed; the cost, its exact
  // gradient for that D (the Jacobian (1 - d_r) J_r(x) + d_r J_r(x0) of row r), the Fisher
  // information, the sandwich and the residue covariance all take it.
  void set_row_scale(const Eigen::VectorXd& scale);

  // S in dense form, sorted-row order (for tests and small problems).
  Eigen::MatrixXd residue_covariance(const Eigen::VectorXcd& theta) const;

  const std::vector<int>& sorted_rows() const { return sorted_; }
  // order()[i]: position in the caller's rows of sorted row i.
  const std::vector<int>& order() const { return order_; }
  int half_bandwidth() const { return kd_; }

 private:
  struct Factor;  // the banded Cholesky factor of S and the per-entry blocks
  // The fit's trial steps need the cost only and its accepted steps the rest from the same
  // factor: it reaches both through the private factor() and evaluate(Factor).
  friend ExactFit minimise_exact_cost(const ExactLikelihood& lik, const Parametrisation& p,
                                      const Eigen::VectorXcd& theta0, double tol, int max_iter);
  friend ExactFit minimise_exact_cost(const std::vector<ExactLikelihood>& liks, const Parametrisation& p,
                                      const Eigen::VectorXcd& theta0, double tol, int max_iter);
  void init(const std::vector<int>& rows);  // sorted rows and bandwidth, after the checks
  Factor factor(const Eigen::VectorXcd& theta) const;
  // K = 0: S block diagonal, factored row by row (the same bits as the band route).
  bool diagonal() const;
  void factor_diagonal(Factor& f) const;
  // With whiten = false: cost, w and x0, and the Jacobian at x0 not whitened (no gradient).
  Evaluation evaluate(const Factor& f, bool whiten) const;
  Eigen::MatrixXd real_jacobian(const FrequencyData& x) const;  // dr/dxi, sorted-row order
  Eigen::MatrixXd scaled_jacobian(const FrequencyData& x0) const;  // with the row scale, if any

  FrequencyData d_;
  Parametrisation p_;
  std::vector<int> sorted_, order_;
  Eigen::VectorXd scale_;  // sorted-row order; empty: none
  int K_ = 0, kd_ = 0;
};

// Levenberg-Marquardt on V over the free entries of xi from theta0 (normalised first), with
// the exact gradient and the Gauss-Newton Hessian of the whitened residue. Converged: the
// relative step fell below tol, or no step lowers V any more (a minimum to rounding).
struct ExactFit {
  Eigen::VectorXcd theta;
  Eigen::VectorXd xi;
  double cost = 0;                   // V at the estimate
  std::vector<double> cost_history;  // V after each accepted step
  int iterations = 0;
  bool converged = false;
  Eigen::MatrixXd information;       // J^T S^{-1} J over the free entries at the estimate
};
ExactFit minimise_exact_cost(const ExactLikelihood& lik, const Parametrisation& p,
                             const Eigen::VectorXcd& theta0, double tol, int max_iter);
// Several independent experiments (METHOD.md section 14): S is block diagonal over them, so V,
// its gradient and the Gauss-Newton information are the sums of the experiments' own.
ExactFit minimise_exact_cost(const std::vector<ExactLikelihood>& liks, const Parametrisation& p,
                             const Eigen::VectorXcd& theta0, double tol, int max_iter);

// Cov(q - lambda CJ_W xi) over the free entries of xi (free_indices order) from the terms of
// one experiment or their sum over independent experiments (one lambda for all):
// Cov(q) - c v^T - v c^T + Var(R) v v^T, c = Cov(q, R), v = CJ_W xi / (xi^T CJ_W xi).
// Added to the sandwich's meat it gives WGTLS's covariance to second order in the noise.
Eigen::MatrixXd second_order_meat(const ExactLikelihood::SecondOrderTerms& t, const Parametrisation& p,
                                  const Eigen::VectorXcd& theta);

// H^{-1} meat H^{-1} (symmetrised); NumericalError when H is singular.
Eigen::MatrixXd sandwich_from_terms(const Eigen::MatrixXd& bread, const Eigen::MatrixXd& meat);

// The inverse of a symmetric information matrix ``what``: NumericalError when a pivot of its
// LDL^T is not positive, or when its reciprocal condition is at or below one rounding unit (the
// inverse then has no correct digit; METHOD.md section 15).
Eigen::MatrixXd symmetric_inverse(const Eigen::MatrixXd& F, const char* what);

// The Cramer-Rao bound of eta for a design: `noiseless` holds the true spectra U, Y and the
// true (co)variances of the noise on them; theta the true parameters. n_eta x n_eta, zero row
// and column for the normalised parameter.
Eigen::MatrixXd cramer_rao_bound(const FrequencyData& noiseless, const Parametrisation& p,
                                 const std::vector<int>& rows, const Eigen::VectorXcd& theta);
// The bound of several independent experiments: their Fisher informations add.
Eigen::MatrixXd cramer_rao_bound(const std::vector<FrequencyData>& noiseless, const Parametrisation& p,
                                 const std::vector<std::vector<int>>& rows, const Eigen::VectorXcd& theta);

// A covariance of the free entries of xi (free_indices order) placed into eta coordinates:
// n_eta x n_eta, zero row and column for the normalised parameter.
Eigen::MatrixXd eta_covariance(const Parametrisation& p, const Eigen::MatrixXd& cov_free);

}  // namespace lptv
