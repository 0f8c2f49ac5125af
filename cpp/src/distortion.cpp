#include "lptv/distortion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lptv/errors.hpp"

namespace lptv {

namespace {

using cd = std::complex<double>;

template <class Mat>
void check_matrix(const Mat& x, const char* name, Eigen::Index M, Eigen::Index n) {
  if (x.rows() != M || x.cols() != n) {
    throw std::invalid_argument(std::string(name) + " must be " + std::to_string(M) + " x " + std::to_string(n) +
                                " (realisations x lines 0..L, as U), got " + std::to_string(x.rows()) + " x " +
                                std::to_string(x.cols()));
  }
  if (!x.allFinite()) throw std::invalid_argument(std::string(name) + " contains NaN or inf");
}

void validate(const DistortionInput& in) {
  const Eigen::Index M = in.U.rows(), n = in.U.cols();
  if (M < 2) throw std::invalid_argument("U: at least 2 realisations (rows) are needed, got " + std::to_string(M));
  if (n < 2) throw std::invalid_argument("U: at least lines 0..1 (2 columns) are needed, got " + std::to_string(n));
  check_matrix(in.U, "U", M, n);
  check_matrix(in.Y, "Y", M, n);
  check_matrix(in.varU, "varU", M, n);
  check_matrix(in.varY, "varY", M, n);
  check_matrix(in.covYU, "covYU", M, n);
  if ((in.varU.array() < 0).any()) throw std::invalid_argument("varU must be >= 0 (a variance)");
  if ((in.varY.array() < 0).any()) throw std::invalid_argument("varY must be >= 0 (a variance)");
  const int L = static_cast<int>(n) - 1;
  if (in.excited.empty()) throw std::invalid_argument("excited: no excited lines");
  for (size_t i = 0; i < in.excited.size(); ++i) {
    const int c = in.excited[i];
    if (c < 1 || c > L) {
      throw std::invalid_argument("excited: line " + std::to_string(c) + " is not a line 1.." + std::to_string(L) +
                                  " of the data");
    }
    if (i && c <= in.excited[i - 1]) {
      throw std::invalid_argument("excited: lines must be ascending and distinct, got " +
                                  std::to_string(in.excited[i - 1]) + " before " + std::to_string(c));
    }
  }
  if (in.branches < 0 || in.branches > L) {
    throw std::invalid_argument("branches must be within 0.." + std::to_string(L) + ", got " +
                                std::to_string(in.branches));
  }
}

}  // namespace

DistortionLines distortion_lines(const DistortionInput& in) {
  validate(in);
  const int M = static_cast<int>(in.U.rows()), L = static_cast<int>(in.U.cols()) - 1, Kh = in.branches;
  const std::vector<int>& ex = in.excited;
  const int n_ex = static_cast<int>(ex.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double eps = std::numeric_limits<double>::epsilon();

  DistortionLines out;
  out.excited = ex;
  out.branches = Kh;
  out.realisations = M;
  out.lines.resize(L);
  out.signal.resize(L);
  out.total = Eigen::VectorXd::Constant(L, nan);
  out.noise = Eigen::VectorXd::Constant(L, nan);
  out.dof.resize(L);
  out.regressors.resize(L);
  out.bla = Eigen::MatrixXcd::Constant(2 * Kh + 1, n_ex, cd(nan, nan));
  out.bla_var = Eigen::MatrixXd::Constant(2 * Kh + 1, n_ex, nan);

  // Regressor c > 0 stands for excited line c, c < 0 for the conjugate of line -c; the order
  // (excited lines ascending, then their conjugates) is that of the NumPy route.
  std::vector<int> cs, ci;  // regressor and its excited index
  Eigen::MatrixXcd X;
  for (int j = 1; j <= L; ++j) {
    const int i = j - 1;
    out.lines[i] = j;
    const auto yj = in.Y.col(j);
    out.signal[i] = yj.cwiseAbs2().mean();
    cs.clear();
    ci.clear();
    const int lo = static_cast<int>(std::lower_bound(ex.begin(), ex.end(), j - Kh) - ex.begin());
    for (int e = lo; e < n_ex && ex[e] <= j + Kh; ++e) cs.push_back(ex[e]), ci.push_back(e);
    for (int e = 0; e < n_ex && ex[e] + j <= Kh; ++e) cs.push_back(-ex[e]), ci.push_back(e);
    const int q = static_cast<int>(cs.size());
    out.regressors[i] = q;
    out.dof[i] = M - q;
    if (M - q < 1) continue;

    Eigen::VectorXcd G = Eigen::VectorXcd::Zero(q), r = yj;
    Eigen::MatrixXd Cinv;  // (X^H X)^+ by the singular values of X
    if (q) {
      X.resize(M, q);
      for (int a = 0; a < q; ++a) {
        if (cs[a] > 0)
          X.col(a) = in.U.col(cs[a]);
        else
          X.col(a) = in.U.col(-cs[a]).conjugate();
      }
      // The SVD gives the least-squares solution and (X^H X)^+ = V S^-2 V^H together; small
      // matrices (q < M, a few each), so Jacobi's accuracy costs nothing. Cut-offs as
      // numpy.linalg.lstsq (rcond = eps max(M, q)) and numpy.linalg.pinv of X^H X (1e-15 of
      // its largest eigenvalue).
      Eigen::JacobiSVD<Eigen::MatrixXcd> svd(X, Eigen::ComputeThinU | Eigen::ComputeThinV);
      const Eigen::VectorXd& s = svd.singularValues();
      const double smax = s.size() ? s[0] : 0.0;
      const Eigen::VectorXcd Uty = svd.matrixU().adjoint() * yj;
      Eigen::VectorXcd w = Eigen::VectorXcd::Zero(s.size());
      Eigen::VectorXd s2inv = Eigen::VectorXd::Zero(s.size());
      for (Eigen::Index k = 0; k < s.size(); ++k) {
        if (s[k] > eps * std::max(M, q) * smax) w[k] = Uty[k] / s[k];
        if (s[k] * s[k] > 1e-15 * smax * smax) s2inv[k] = 1.0 / (s[k] * s[k]);
      }
      G = svd.matrixV() * w;
      r = yj - X * G;
      const Eigen::MatrixXcd& V = svd.matrixV();
      Cinv.resize(q, 1);
      for (int a = 0; a < q; ++a) Cinv(a, 0) = (V.row(a).cwiseAbs2().transpose().cwiseProduct(s2inv)).sum();
    }
    const double s2 = r.squaredNorm() / (M - q);
    // Noise of one realisation's period mean: the output's, plus the input noise through G
    // (var U_{|c|}; the output and input noise share a covariance only on the same line).
    double nv = 0.0;
    for (int m = 0; m < M; ++m) {
      double v = in.varY(m, j);
      for (int a = 0; a < q; ++a) {
        const int c = cs[a];
        v += std::norm(G[a]) * in.varU(m, std::abs(c));
        if (c == j) v -= 2.0 * (std::conj(G[a]) * in.covYU(m, j)).real();
      }
      nv += v;
    }
    bool finite = std::isfinite(s2) && std::isfinite(nv) && G.allFinite();
    for (int a = 0; a < q; ++a) finite = finite && std::isfinite(Cinv(a, 0) * s2);
    if (!finite) {
      throw NumericalError("distortion_lines: the regression of line " + std::to_string(j) +
                           " overflowed (the spectra or variances span too many orders of magnitude): "
                           "scale U and Y");
    }
    out.total[i] = s2;
    out.noise[i] = nv / M;
    for (int a = 0; a < q; ++a) {
      if (cs[a] < 0) continue;
      out.bla(Kh + (j - cs[a]), ci[a]) = G[a];
      out.bla_var(Kh + (j - cs[a]), ci[a]) = Cinv(a, 0) * s2;
    }
  }
  return out;
}

}  // namespace lptv
