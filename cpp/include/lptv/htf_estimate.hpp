// The nonparametric harmonic transfer function from periodic data (METHOD.md section 11): with
// excited lines spaced more than 2 Kh apart, output line l + k carries only the branch G_k of
// excited line l, so G_k(w_l) = Y_{l+k} / U_l, with its variance from the periods.
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/noise.hpp"

namespace lptv {

struct HtfEstimate {
  std::vector<int> lines;   // the excited lines l (ascending)
  int branches = 0;         // Kh: branches k = -Kh..Kh
  // (2 Kh + 1) x lines: row Kh + k holds G_k(w_l) and the variance of that estimate
  // (errors-in-variables: output and input noise, and their covariance on k = 0).
  Eigen::MatrixXcd G;
  Eigen::MatrixXd variance;
  // Per branch: sum over the lines of |G_k|^2 / var G_k under the hypothesis G_k = 0 (the
  // variance then is var Y_{l+k} / |U_l|^2): about 2 x chi2 with 2 lines.size() degrees of
  // freedom / 2 for known variances, larger where the branch stands above the noise.
  Eigen::VectorXd branch_statistic;
};

// Throws std::invalid_argument when a line is not in the data, an excited line is within
// 2 Kh of another (or within Kh of DC, whose conjugate line mirrors it), a branch's output line
// lies beyond the data, or U vanishes on an excited line.
HtfEstimate htf_estimate(const FrequencyData& d, const std::vector<int>& excited, int branches);

// Excited lines: |U_l|^2 above `ratio` times var U_l (noisy input), or above 1e-20 max |U|^2
// where the input carries no noise. DC is never counted.
std::vector<int> excited_lines(const FrequencyData& d, double ratio = 100.0);

}  // namespace lptv
