#include "lptv/jacobian.hpp"
#include "lptv/errors.hpp"
#include "rows.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lptv {

cd line_power(const Structure& s, int line, int n) {
  return detail::line_power(detail::line_variable(s.w0, s.ts, line), n);
}

Eigen::MatrixXcd jacobian(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows) {
  const detail::Lines X{d};
  Eigen::Matrix<cd, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(rows.size(), p.n_theta());
  detail::RowPowers pw(p.structure());
  for (size_t r = 0; r < rows.size(); ++r) {
    pw.compute(rows[r]);
    detail::jacobian_row(p, X, pw, rows[r], J.row(static_cast<Eigen::Index>(r)).data());
  }
  return J;
}

namespace {

// Calls f(r, pw, A, B) for every row r with the row's powers and band entries, on up to
// two threads (f writes only to row r's outputs).
template <class F>
void for_each_row(const Parametrisation& p, const std::vector<int>& rows, const Eigen::VectorXcd& theta,
                  F&& f) {
  detail::parallel_rows(rows.size(), [&](size_t begin, size_t end, int) {
    const detail::HarmonicCoefficients c = detail::by_harmonic(p, theta);
    detail::RowPowers pw(p.structure());
    std::vector<cd> A, B;
    for (size_t r = begin; r < end; ++r) {
      pw.compute(rows[r]);
      detail::band_row(c, pw, A, B);
      f(r, pw, A, B);
    }
  });
}

}  // namespace

Eigen::VectorXcd residue(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                         const Eigen::VectorXcd& theta) {
  const detail::Lines X{d};
  Eigen::VectorXcd e(rows.size());
  const int K = p.structure().kmax();
  for_each_row(p, rows, theta, [&](size_t r, const detail::RowPowers&, const std::vector<cd>& A,
                                   const std::vector<cd>& B) {
    cd v(0.0, 0.0);
    for (int k = -K; k <= K; ++k) {
      const int i = rows[r] - k;
      v += A[K + k] * X.Y(i) - B[K + k] * X.U(i);
    }
    e[r] = v;
  });
  return e;
}

Eigen::VectorXd residue_variance(const FrequencyData& d, const Parametrisation& p,
                                 const std::vector<int>& rows, const Eigen::VectorXcd& theta) {
  const detail::Lines X{d};
  Eigen::VectorXd v(rows.size());
  const int K = p.structure().kmax();
  for_each_row(p, rows, theta, [&](size_t r, const detail::RowPowers&, const std::vector<cd>& A,
                                   const std::vector<cd>& B) {
    double s = 0;
    for (int k = -K; k <= K; ++k) {
      const int i = rows[r] - k;
      const cd a = A[K + k], b = B[K + k];
      s += std::norm(a) * X.varY(i) + std::norm(b) * X.varU(i) -
           2.0 * (a * std::conj(b) * X.covYU(i)).real();
    }
    v[r] = s;
  });
  return v;
}

Eigen::MatrixXcd residue_variance_gradient(const FrequencyData& d, const Parametrisation& p,
                                           const std::vector<int>& rows, const Eigen::VectorXcd& theta) {
  const detail::Lines X{d};
  Eigen::MatrixXcd G(rows.size(), p.n_theta());
  const int K = p.structure().kmax();
  for_each_row(p, rows, theta, [&](size_t r, const detail::RowPowers& pw, const std::vector<cd>& A,
                                   const std::vector<cd>& B) {
    for (int q = 0; q < p.n_theta(); ++q) {
      const Param& pr = p.params()[q];
      const int i = rows[r] - pr.k;
      // dJ = f dX with f = +s^n (a) or -s^n (b); sum_q f_q theta_q over the harmonic's
      // group is A_li on the Y side and -B_li on the U side.
      const cd SY = A[K + pr.k], SU = -B[K + pr.k];
      const cd f = (pr.is_a ? 1.0 : -1.0) * pw(pr.k, pr.order);
      const cd e = pr.is_a ? X.varY(i) * SY + std::conj(X.covYU(i)) * SU
                           : X.covYU(i) * SY + X.varU(i) * SU;
      G(static_cast<Eigen::Index>(r), q) = std::conj(f) * e;
    }
  });
  return G;
}

Eigen::MatrixXcd column_covariance(const FrequencyData& d, const Parametrisation& p,
                                   const std::vector<int>& rows, const Eigen::VectorXd& weights) {
  if (weights.size() != static_cast<Eigen::Index>(rows.size())) {
    throw std::invalid_argument("weights must have one entry per row");
  }
  const detail::Lines X{d};
  const auto by_k = detail::params_by_harmonic(p);
  Eigen::MatrixXcd parts[2];
  parts[0] = parts[1] = Eigen::MatrixXcd::Zero(p.n_theta(), p.n_theta());
  detail::parallel_rows(rows.size(), [&](size_t begin, size_t end, int part) {
    Eigen::MatrixXcd& C = parts[part];
    detail::RowPowers pw(p.structure());
    std::vector<cd> f;
    for (size_t r = begin; r < end; ++r) {
      const double w = weights[r];
      if (w == 0.0) continue;
      pw.compute(rows[r]);
      detail::noise_block_entries(p, X, pw, rows[r], by_k, f, [&](int a, int b, cd v) { C(a, b) += w * v; });
    }
  });
  return parts[0] + parts[1];
}

}  // namespace lptv
