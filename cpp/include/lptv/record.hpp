// One record with its transient (METHOD.md section 17): an LPTV model fitted to a
// single record of L whole parameter periods, started from an unknown state under an arbitrary
// input. On the record's DFT grid (N = L N0 lines, spacing w0 / L) harmonic k of a coefficient
// shifts a spectrum by k L lines, and the record's transient is T(z_l) = sum_{j=1}^{n} c_j z_l^j,
// n = max(na, nb), with real c_j. The fit: the equation-error start (weighted linear least
// squares of E_l(eta) + T(z_l) = 0), the output-error Levenberg-Marquardt on
// Y_hat = A^-1 (B U - T) with the exact Jacobian, the residual noise-level reweighting and the
// covariance (the inverse Fisher information of the output error).
// Continuous time (the structure's ts = 0, RecordData::ts the record's sample time): the grid is
// the signed lines -M..M, M = (N - 1) / 2, of the record's DFT (lines beyond dropped, as the
// FDS does), z_l^n is (j w_l)^n, and the transient is T = sum_{j=0}^{d} c_j (j w_l ts)^j with
// d = n + 1 by default: the Fourier coefficients' term of degree n - 1, the samples' offset of
// the record's jump (degree n) and its first aliasing term (degree n + 1), METHOD.md section 17.
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/structure.hpp"

namespace lptv {

// The record's spectra X_l = (1/N) sum_t x(t) z_l^-t, z_l = exp(j 2 pi l / N), on all N lines
// 0..N-1 (a real record: X_{N-l} = conj(X_l)), and what to fit.
struct RecordData {
  Eigen::VectorXcd U, Y;
  int periods = 1;         // L: whole parameter periods in the record (N = L N0)
  std::vector<int> lines;  // the lines fitted: ascending, distinct, within 1..(N-1)/2
  double ts = 0;           // continuous time: the record's sample time (> 0); discrete time: 0
                           // (the structure's ts is the sample time) or that same ts
};

// Where the output noise variance E|V_l|^2 comes from.
enum class RecordNoise {
  Given,     // RecordOptions::noise_var, one per fitted line
  Residual,  // the fit's own residual, averaged over 2 noise_width + 1 lines, then refitted
};

struct RecordOptions {
  bool transient = true;               // fit T (false: the steady-state model alone)
  // Continuous time: the degree d of T (c_0..c_d), -1 for n + 1; at least n - 1. Discrete time:
  // -1 only (the term z^1..z^n is exact there).
  int transient_degree = -1;
  RecordNoise noise = RecordNoise::Residual;
  Eigen::VectorXd noise_var;           // Given: one positive variance per fitted line
  int noise_width = 10;                // Residual: half width of the average (>= 1)
  int reweightings = 2;                // Residual: fits with the residual's variance after the first
  int max_iterations = 100;            // Levenberg-Marquardt iterations per fit (>= 1)
  // Relative tolerances (as MINPACK's ftol, xtol, gtol): the cost's actual and predicted
  // decrease, the scaled step, the cosine between the residual and the Jacobian's columns.
  double tol = 1e-12;
};

struct RecordFit {
  // xi with xi[norm_index] = 1 (Re a_na,0 = 1, or the known part), and theta = Text xi.
  Eigen::VectorXd eta;
  Eigen::VectorXcd theta;
  // Covariance of eta (n_xi x n_xi; zero row and column at norm_index): the inverse of J^T J,
  // J the whitened Jacobian of the output error at the estimate.
  Eigen::MatrixXd covariance;
  Eigen::VectorXd transient;           // c_1..c_n, or c_0..c_d in continuous time (empty without T)
  Eigen::VectorXd transient_std;
  // The start, [free eta, c], from the weighted equation error (the first fit's weights).
  Eigen::VectorXd start;
  Eigen::VectorXd noise_var;           // per fitted line
  int noise_dof = 0;                   // Residual: 2 noise_width + 1; Given: 0
  Eigen::VectorXcd Y_fit;              // A^-1 (B U - T) on the fitted lines
  double cost = 0;                     // sum over the lines of |Y - Y_fit|^2 / (noise_var / 2)
  int dof = 0;                         // 2 lines - parameters
  bool converged = false;              // the last fit met a tolerance within max_iterations
  int iterations = 0;                  // Levenberg-Marquardt iterations of the last fit
  int evaluations = 0;                 // factorisations of A, all fits
  int fits = 0;                        // output-error fits run (1 + reweightings with Residual)
};

// The whole route. Throws std::invalid_argument naming the argument when the sample time is
// missing (continuous time without RecordData::ts) or differs from the structure's, w0 and ts do not give a whole number N0 of samples per period, U and Y differ
// in length or are not N = periods N0 lines of finite values, the lines are out of range,
// unsorted or too few for the parameters, the options are out of range or the given variances
// not positive and finite; NumericalError when the start or the estimate gives a singular A
// (a pole on a line of the record's grid) or A beyond the FDS's conditioning limit.
RecordFit fit_record(const Parametrisation& p, const RecordData& d, const RecordOptions& opt = RecordOptions());

// The pieces, for the tests.
// The equation error's regression on the fitted lines: E_l = M_l x + e0_l, x = [free eta, c]
// (a unit per line; the fit weights the rows): columns of J Text at the free indices, then
// z_l^1..z_l^n; e0 the column at norm_index.
struct RecordRegression {
  Eigen::MatrixXcd M;
  Eigen::VectorXcd e0;
};
RecordRegression record_regression(const Parametrisation& p, const RecordData& d, bool transient,
                                   int transient_degree = -1);
// Y_hat = A^-1 (B U - T(c)) on all N lines (continuous time: the 2 M + 1 lines -M..M), theta = Text xi (xi[norm_index] = 1), c = c_1..c_n.
Eigen::VectorXcd record_prediction(const Parametrisation& p, const RecordData& d, const Eigen::VectorXd& eta_free,
                                   const Eigen::VectorXd& c, int transient_degree = -1);

}  // namespace lptv
