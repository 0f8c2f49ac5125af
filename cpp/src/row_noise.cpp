// The rows' noise from the realisations of the lines' noise (METHOD.md section 20).
#include <cmath>
#include <stdexcept>

#include "lptv/estimators.hpp"
#include "lptv/jacobian.hpp"
#include "lptv/likelihood.hpp"
#include "rows.hpp"

namespace lptv {

bool has_row_noise(const FrequencyData& d) {
  return d.noiseU.rows() > 0 && d.noise_offset.size() == d.noiseU.rows() && d.noise_last >= d.noise_first;
}

RowNoise row_noise(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows) {
  if (!has_row_noise(d)) throw std::invalid_argument("the data hold no realisations of their noise");
  const Structure& st = p.structure();
  const int K = st.kmax(), Q = static_cast<int>(d.noiseU.rows()), n = p.n_theta();
  RowNoise rn;
  rn.full_rows.assign(rows.size(), 0);
  rn.phi.resize(rows.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    const int l = rows[r];
    if (l - K < d.noise_first || l + K > d.noise_last) continue;
    rn.full_rows[r] = 1;
    Eigen::MatrixXcd& ph = rn.phi[r];
    ph.resize(Q, n);
    for (int q = 0; q < Q; ++q) {
      for (int c = 0; c < n; ++c) {
        const Param& pr = p.params()[c];
        const int i = l - pr.k;
        const double line = double(i) + d.noise_offset[q];
        const double w = st.w0 * line;
        const cd s = st.ts > 0 ? std::polar(1.0, w * st.ts) : cd(0.0, w);
        cd sn = 1.0;
        for (int j = 0; j < pr.order; ++j) sn *= s;
        ph(q, c) = pr.is_a ? sn * d.noiseY(q, i) : -sn * d.noiseU(q, i);
      }
    }
  }
  return rn;
}

Eigen::VectorXd full_residue_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                      const RowNoise& rn, const Eigen::VectorXcd& theta) {
  Eigen::VectorXd v = residue_variance(d, p, rows, theta);
  for (size_t r = 0; r < rows.size(); ++r)
    if (rn.full_rows[r]) v[static_cast<Eigen::Index>(r)] = (rn.phi[r] * theta).squaredNorm();
  return v;
}

Eigen::VectorXd full_residue_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                      const Eigen::VectorXcd& theta) {
  return full_residue_variance(d, p, rows, row_noise(d, p, rows), theta);
}

Eigen::MatrixXd full_real_column_covariance(const FrequencyData& d, const Parametrisation& p,
                                            const std::vector<int>& rows, const RowNoise& rn,
                                            const Eigen::VectorXd& weights) {
  if (weights.size() != static_cast<Eigen::Index>(rows.size()))
    throw std::invalid_argument("weights must have one entry per row");
  Eigen::VectorXd wl = weights;  // eq. 15's rows
  Eigen::MatrixXcd C = Eigen::MatrixXcd::Zero(p.n_theta(), p.n_theta());
  for (size_t r = 0; r < rows.size(); ++r) {
    if (!rn.full_rows[r]) continue;
    wl[static_cast<Eigen::Index>(r)] = 0.0;
    const double w = weights[static_cast<Eigen::Index>(r)];
    if (w == 0.0) continue;
    // E{dJ_l^H dJ_l} = sum_q phi_q^H phi_q (the realisations are scaled to the variance)
    C.noalias() += w * (rn.phi[r].adjoint() * rn.phi[r]);
  }
  if (wl.cwiseAbs().maxCoeff() > 0) C += column_covariance(d, p, rows, wl);
  const Eigen::MatrixXd CJ =
      detail::real_congruence(p, detail::text_entries(p), [&](int a, int b) { return C(a, b); }, false);
  return 0.5 * (CJ + CJ.transpose());
}

Eigen::VectorXd row_noise_scale(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                const RowNoise& rn, const Eigen::VectorXcd& theta) {
  const Eigen::VectorXd line = residue_variance(d, p, rows, theta);
  const Eigen::VectorXd full = full_residue_variance(d, p, rows, rn, theta);
  Eigen::VectorXd s = Eigen::VectorXd::Ones(line.size());
  // pooled over the full rows within +-kRowNoisePool lines: each row's own ratio has the 2 (P - 1)
  // degrees of freedom of one sample variance, the pooled one those of up to 2 kRowNoisePool + 1
  // (the ratio is smooth in frequency where the noise spectra are)
  for (size_t r = 0; r < rows.size(); ++r) {
    if (!rn.full_rows[r]) continue;
    double num = 0, den = 0;
    for (size_t j = 0; j < rows.size(); ++j) {
      if (!rn.full_rows[j] || std::abs(rows[j] - rows[r]) > kRowNoisePool) continue;
      num += full[static_cast<Eigen::Index>(j)];
      den += line[static_cast<Eigen::Index>(j)];
    }
    if (num > 0 && den > 0) s[static_cast<Eigen::Index>(r)] = std::sqrt(num / den);
  }
  return s;
}

Eigen::VectorXd row_noise_scale(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                const Eigen::VectorXcd& theta) {
  return row_noise_scale(d, p, rows, row_noise(d, p, rows), theta);
}

Eigen::VectorXd row_noise_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                   const RowNoise& rn, const Eigen::VectorXcd& theta) {
  const Eigen::VectorXd s = row_noise_scale(d, p, rows, rn, theta);
  return residue_variance(d, p, rows, theta).cwiseProduct(s.cwiseAbs2());
}

Eigen::VectorXd row_noise_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                   const Eigen::VectorXcd& theta) {
  return row_noise_variance(d, p, rows, row_noise(d, p, rows), theta);
}

}  // namespace lptv
