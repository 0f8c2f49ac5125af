// Stability of the periodic system (METHOD.md section 12): the characteristic multipliers
// mu_i = eig(Phi) of the monodromy matrix Phi of the homogeneous equation over one period,
// and the Floquet exponents lambda_i = ln(mu_i) / T0.
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "lptv/mimo.hpp"
#include "lptv/model.hpp"

namespace lptv {

struct FloquetOptions {
  // Continuous time: the truncation M of Hill's matrix grows until every kept exponent
  // changes by less than tol * (1 + |ln|mu_i||) in ln(mu_i) = lambda_i T0 from one
  // truncation to the next, or by less than the rounding error its condition number allows.
  double tol = 1e-11;
  int min_truncation = 8;    // first M (raised to the number of harmonics of F(t))
  int max_truncation = 256;  // NumericalError when the exponents have not settled by then
};

struct Floquet {
  // na multipliers by decreasing |mu| (conjugate pairs: positive imaginary part first).
  // Continuous time: exp(lambda_i T0), which underflows to 0 for exponents below about
  // -745 / T0; discrete time: the eigenvalues of the product of the N one-step companion
  // matrices (0 when a_0[k] vanishes at a sample).
  Eigen::VectorXcd multipliers;
  // lambda_i = ln(mu_i) / T0 (1/s), T0 = 2 pi / w0 (= N ts in discrete time), on the
  // principal branch: Im lambda in (-w0/2, w0/2]. Defined modulo j w0 only: lambda + j n w0
  // gives the same multiplier. -inf where a discrete-time multiplier is 0.
  Eigen::VectorXcd exponents;
  // Estimated relative error of mu_i. Continuous time: max(change of ln(mu_i) between the
  // last two truncations, eps ||H|| T0 / rcond_i, LAPACK's bound from the eigenvalue's
  // condition number). Discrete time: kappa_i ||E|| / |mu_i|, E the rounding of the product
  // (large for multipliers far below the largest; inf for mu_i = 0).
  Eigen::VectorXd error_estimate;
  double spectral_radius = 0;  // max |mu_i| (0 when na = 0)
  // Every |mu_i| < 1 by more than its estimated error: asymptotically stable. A multiplier
  // within its error of the unit circle (a marginal system) counts as not stable.
  bool is_stable = true;
  int truncation = 0;      // continuous time: M of the last Hill matrix (harmonics -M..M)
  int harmonics = 0;       // continuous time: harmonics of F(t) kept (those above eps)
  double convergence = 0;  // continuous time: max change of ln(mu_i) between the last two M
  std::string method;      // "hill" (continuous time) or "product" (discrete time)
};

// Multipliers and exponents of the model's homogeneous equation sum_n a_n(t) d^n y = 0.
//  - Continuous time: Hill's method on the companion form x' = F(t) x, x = (y, ..., y^(na-1)):
//    eigenvalues of [F_{p-q}] - diag(j p w0 I), p, q = -M..M, keeping per exponent the
//    eigenvalue whose eigenvector is centred nearest harmonic 0; M grows until they settle.
//  - Discrete time (forward shift, sum_n a_n[k] y[k+n] = 0, state (y[k], ..., y[k+na-1])):
//    the eigenvalues of the product of the N = samples_per_period() companion matrices.
// Throws std::invalid_argument when a_na(t) vanishes somewhere over the period (naming
// the time or sample) or an option is out of range, NumericalError when the exponents do not
// converge by opt.max_truncation (naming the M reached) or 1/a_na(t) needs too many harmonics.
Floquet floquet(const Model& m, const FloquetOptions& opt = FloquetOptions());

// First-order sensitivity of the Floquet exponents to the coefficients of a(t) (METHOD.md
// section 22): the eigenvalue's derivative from its left and right eigenvectors,
// d lambda = u^H dH v / (u^H v), H Hill's matrix at the settled truncation (continuous time) or
// the monodromy matrix of the product (discrete time, d lambda = d mu / (mu T0)).
struct FloquetSensitivity {
  Floquet floquet;  // as floquet(m, opt) returns it
  // gradient[i](n, Ka + h) = d lambda_i / d a_{n,h} (n = 0..na, h = -Ka..Ka), for the exponents in
  // floquet.exponents' order, with a_{n,h} and a_{n,-h} taken as independent complex variables
  // (a real perturbation of harmonic h > 0 moves both: Re d a_{n,h} (g_h + g_-h), and so on).
  // b(t) does not enter. Zero for an exponent of -inf (a zero discrete-time multiplier).
  std::vector<Eigen::MatrixXcd> gradient;
  // |u| |v| / |u^H v| of each exponent's eigenvalue: its condition number (inf for a defective
  // or zero one), large where two exponents meet.
  Eigen::VectorXd condition;
};
FloquetSensitivity floquet_sensitivity(const Model& m, const FloquetOptions& opt = FloquetOptions());

// Several outputs (METHOD.md section 19, "Stability of the matrix system"): the multipliers of
// sum_n A_n(t) d^n y = 0 for a row-reduced A(t, s) (row degrees d_p, the leading row coefficient
// matrix L(t), row p from A_{d_p}(t), invertible over the period). The state is the observer
// form of the right-form coefficients, of dimension sum_p d_p, so there are that many
// multipliers; continuous time by Hill's method, discrete time by the product of the N one-step
// matrices, with the options, errors and verdict of floquet(const Model&). A 1 x 1 model has
// the SISO model's multipliers (to their error estimates: the state differs).
// Throws std::invalid_argument naming the time or sample where L is singular, or the row of A
// that is zero.
Floquet floquet(const MimoModel& m, const FloquetOptions& opt = FloquetOptions());

// The row degrees d_p of A(t, s): the highest order with a nonzero coefficient in row p.
std::vector<int> row_degrees(const MimoModel& m);

// The monodromy matrix of that state form by products, for checks (as monodromy(const Model&)):
// continuous time `steps` fourth-order Magnus steps and 2 steps, extrapolated; discrete time the
// product of the N one-step matrices (`steps` ignored). sum_p d_p square.
Eigen::MatrixXd monodromy(const MimoModel& m, int steps);

// The state matrix of that form at time t (continuous time: x' = F(t) x) or the one-step
// matrix of sample t / ts (discrete time: x[k+1] = G[k] x[k]); sum_p d_p square.
Eigen::MatrixXd state_matrix_at(const MimoModel& m, double t);

// The monodromy matrix Phi (na x na) by an independent route, for checks:
//  - continuous time: the product of exp(Omega_k) over `steps` equal sub-intervals of one
//    period, Omega_k the fourth-order Magnus step with F(t) at the two Gauss points (from the
//    coefficients' values, not their harmonics), extrapolated (Richardson) with 2 * steps to
//    sixth order;
//  - discrete time: the product of the N one-step companion matrices (`steps` is ignored).
// Throws std::invalid_argument for steps < 1 (continuous time) or a vanishing a_na(t).
Eigen::MatrixXd monodromy(const Model& m, int steps);

// The spectral radius of the monodromy matrix by products, for a stability check whose cost is
// bounded before it starts: monodromy(m, s) for s = first_steps, 2 first_steps, ... up to
// max_steps (each run of 2 s steps reused for the next s), until two successive radii differ by
// less than a tenth of their distance to 1. `settled` says whether they did; `rho` is the last
// radius then, `steps` the s it was reached with (0 in discrete time, where the one exact
// product settles unless its radius is exactly 1), `reason` the last overflow's message.
// Throws std::invalid_argument for a vanishing a_na(t) or steps out of range.
struct ProductRadius {
  bool settled = false;
  double rho = 0.0;
  int steps = 0;
  std::string reason;
};
ProductRadius product_spectral_radius(const Model& m, int first_steps, int max_steps);

}  // namespace lptv
