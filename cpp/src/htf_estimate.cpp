#include "lptv/htf_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lptv/model.hpp"

namespace lptv {

std::vector<int> excited_lines(const FrequencyData& d, double ratio) {
  d.validate();
  if (!(ratio > 0) || !std::isfinite(ratio)) throw std::invalid_argument("ratio must be finite and > 0");
  const double umax = d.U.cwiseAbs2().maxCoeff();
  std::vector<int> out;
  for (int l = 1; l <= d.max_line(); ++l) {
    const double p = std::norm(d.U[l]);
    const bool above = d.varU[l] > 0 ? p > ratio * d.varU[l] : p > 1e-20 * umax;
    if (above && p > 0) out.push_back(l);
  }
  return out;
}

HtfEstimate htf_estimate(const FrequencyData& d, const std::vector<int>& excited, int branches) {
  d.validate();
  if (branches < 0) throw std::invalid_argument("branches must be >= 0, got " + std::to_string(branches));
  if (excited.empty()) throw std::invalid_argument("excited: no excited lines");
  std::vector<int> lines(excited);
  std::sort(lines.begin(), lines.end());
  const long long Kh = branches;
  for (size_t i = 0; i < lines.size(); ++i) {
    const long long l = lines[i];
    if (l < 1 || l > d.max_line()) {
      throw std::invalid_argument("excited: line " + std::to_string(l) + " is not a line 1.." +
                                  std::to_string(d.max_line()) + " of the data");
    }
    if (i && l == lines[i - 1]) throw std::invalid_argument("excited: line " + std::to_string(l) + " repeats");
    if (i && l - lines[i - 1] <= 2 * Kh) {
      throw std::invalid_argument(
          "excited: lines " + std::to_string(lines[i - 1]) + " and " + std::to_string(l) + " are " +
          std::to_string(l - lines[i - 1]) + " apart; " + std::to_string(branches) +
          " branches on each side need a spacing of more than " + std::to_string(2 * Kh) +
          " (their output lines would overlap): ask for fewer branches or excite sparser lines");
    }
    if (l <= Kh) {
      throw std::invalid_argument("excited: line " + std::to_string(l) + " is within " + std::to_string(branches) +
                                  " lines of DC, where its branches meet those of its conjugate line -" +
                                  std::to_string(l) + ": use fewer branches or excite lines above " +
                                  std::to_string(branches));
    }
    if (l + Kh > d.max_line()) {
      throw std::invalid_argument("excited: line " + std::to_string(l) + " needs output lines up to " +
                                  std::to_string(l + Kh) + " but the data has lines 0.." +
                                  std::to_string(d.max_line()));
    }
    if (d.U[l] == cd(0.0, 0.0)) throw std::invalid_argument("excited: U is zero on line " + std::to_string(l));
  }
  HtfEstimate h;
  h.lines = lines;
  h.branches = branches;
  const int n = static_cast<int>(lines.size()), W = 2 * branches + 1;
  h.G.resize(W, n);
  h.variance.resize(W, n);
  h.branch_statistic = Eigen::VectorXd::Zero(W);
  for (int i = 0; i < n; ++i) {
    const int l = lines[i];
    const cd U = d.U[l];
    const double u2 = std::norm(U);
    for (int k = -branches; k <= branches; ++k) {
      const int m = l + k;
      const cd G = d.Y[m] / U;
      // dG = (dY_m - G dU_l) / U_l; dY_m and dU_l share noise only on the same line (k = 0).
      double v = d.varY[m] + std::norm(G) * d.varU[l];
      if (k == 0) v -= 2.0 * (std::conj(G) * d.covYU[l]).real();
      h.G(branches + k, i) = G;
      h.variance(branches + k, i) = std::max(v, 0.0) / u2;
      const double v0 = d.varY[m] / u2;  // under G_k = 0
      if (v0 > 0) h.branch_statistic[branches + k] += std::norm(G) / v0;
    }
  }
  return h;
}

}  // namespace lptv
