// Nonlinear distortion and the best linear time-periodic approximation from M random-phase
// realisations (METHOD.md section 16): per output line j, the least-squares regression of the
// realisations' Y_j on the excited lines c within +-Kh of j (and, near DC, their conjugates -c),
// its residual variance, the noise variance of a period mean and the BLA's branches with their
// total covariance. The F tests on these numbers stay with the caller.
#pragma once
#include <Eigen/Dense>
#include <vector>

namespace lptv {

// M realisations (rows) of the period-mean spectra on lines 0..L (columns) and the noise
// (co)variances of those means (section 4: E{dY conj(dU)} for covYU).
struct DistortionInput {
  Eigen::MatrixXcd U, Y;     // M x (L + 1)
  Eigen::MatrixXd varU, varY;
  Eigen::MatrixXcd covYU;
  std::vector<int> excited;  // ascending, distinct, within 1..L
  int branches = 0;          // Kh: the regressors of line j are the c with |j - c| <= Kh
};

struct DistortionLines {
  std::vector<int> lines;    // output lines 1..L
  std::vector<int> excited;
  int branches = 0;
  int realisations = 0;
  // Per output line (index j - 1):
  Eigen::VectorXd signal;    // mean over the realisations of |Y_j|^2
  Eigen::VectorXd total;     // residual variance sum_m |E_j|^2 / (M - q_j); NaN where M - q_j < 1
  Eigen::VectorXd noise;     // mean over m of var Y_j + sum_c |G_c|^2 var U_c - 2 Re(conj(G_j) cov YU_j);
                             // NaN where M - q_j < 1
  Eigen::VectorXi dof;       // M - q_j (may be <= 0: then nothing was estimated on that line)
  Eigen::VectorXi regressors;  // q_j
  // (2 Kh + 1) x excited: branch k (row Kh + k) of the BLA at excited line c, from output line
  // c + k, and its variance s_j^2 [(X^H X)^-1]_cc; NaN where c + k is not a line 1..L or has no
  // residual degree of freedom.
  Eigen::MatrixXcd bla;
  Eigen::MatrixXd bla_var;
};

// Throws std::invalid_argument naming the field when shapes differ, M < 2, values are not
// finite, variances are negative, the excited lines are empty, unsorted, repeated or outside
// 1..L, or branches is negative or above L. A rank-deficient regression (realisations whose
// excited lines are proportional) gets the minimum-norm solution and the pseudo-inverse, with
// the cut-offs of numpy.linalg.lstsq and numpy.linalg.pinv. Throws NumericalError naming the
// line where the regression overflows (magnitudes near the ends of the double range).
DistortionLines distortion_lines(const DistortionInput& in);

}  // namespace lptv
