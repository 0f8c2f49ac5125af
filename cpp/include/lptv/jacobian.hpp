// Residue e(theta) = A(theta) Y - B(theta) U on a set of rows, its Jacobian, the real
// parametrisation theta = T eta + d, the residue variance and the column covariance
// of the Jacobian's noise (METHOD.md sections 5 and 6).
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/model.hpp"
#include "lptv/noise.hpp"
#include "lptv/structure.hpp"

namespace lptv {

// J[r, p] = +-(s_{l-k})^n X_{l-k}, l = rows[r]; s = j w (continuous) or z (discrete);
// X = Y for a-parameters (+), U for b-parameters (-). Lines < 0 are conjugates.
Eigen::MatrixXcd jacobian(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows);

// e = J theta, computed row by row without forming J.
Eigen::VectorXcd residue(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                         const Eigen::VectorXcd& theta);

// var e_l = sum_i |A_li|^2 varY_i + |B_li|^2 varU_i - 2 Re(A_li conj(B_li) covYU_i) (eq. 15).
Eigen::VectorXd residue_variance(const FrequencyData& d, const Parametrisation& p,
                                 const std::vector<int>& rows, const Eigen::VectorXcd& theta);

// G[r, p] = (C_l theta)_p with C_l = E{dJ_l^H dJ_l}, so that var e_l = theta^H C_l theta and,
// for theta = T eta + d with real eta, d var e_l / d eta = 2 Re(conj(G_l) T). O(rows x n).
Eigen::MatrixXcd residue_variance_gradient(const FrequencyData& d, const Parametrisation& p,
                                           const std::vector<int>& rows, const Eigen::VectorXcd& theta);

// C = sum_l w_l E{dJ_l^H dJ_l} (n_theta x n_theta, complex Hermitian); only entries of
// parameters with the same harmonic are nonzero: O(rows x n x (na+nb+2)).
Eigen::MatrixXcd column_covariance(const FrequencyData& d, const Parametrisation& p,
                                   const std::vector<int>& rows, const Eigen::VectorXd& weights);

// The rows' noise from the realisations of the lines' noise (METHOD.md section 20), when the
// data hold them (frequency_data_from_record_spectra): each row read on every realisation q at
// its own frequencies, the lines (l - k) + offset_q, so that var e_l(theta) = sum_q |e_{l,q}|^2
// holds the terms between a row's lines and between input and output that eq. 15 drops. A row
// that reads a line outside noise_first..noise_last keeps eq. 15 (full_rows[r] false).
struct RowNoise {
  std::vector<char> full_rows;     // per row: read on the realisations
  std::vector<Eigen::MatrixXcd> phi;  // per full row: Q x n_theta, row q the regressor on realisation q
};
bool has_row_noise(const FrequencyData& d);
RowNoise row_noise(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows);
// var e_l of the rows: sum_q |phi_q theta|^2 on the full rows, eq. 15 on the others.
Eigen::VectorXd full_residue_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                      const RowNoise& rn, const Eigen::VectorXcd& theta);
Eigen::VectorXd full_residue_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                      const Eigen::VectorXcd& theta);
// D of ExactLikelihood::set_row_scale: d_r = sqrt(sum full / sum eq. 15) over the full rows
// within +-kRowNoisePool lines of row r (1 on the rows that keep eq. 15), and the rows' variances
// d_r^2 times eq. 15 that the fits weigh by (METHOD.md section 20).
constexpr int kRowNoisePool = 3;
Eigen::VectorXd row_noise_scale(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                const RowNoise& rn, const Eigen::VectorXcd& theta);
Eigen::VectorXd row_noise_scale(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                const Eigen::VectorXcd& theta);
Eigen::VectorXd row_noise_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                   const RowNoise& rn, const Eigen::VectorXcd& theta);
Eigen::VectorXd row_noise_variance(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                                   const Eigen::VectorXcd& theta);
// CJ_W = Re(Text^H C Text), C = sum_l w_l C_l with C_l = phi_l^H phi_l on the full rows and
// E{dJ_l^H dJ_l} of eq. 15's noise on the others.
Eigen::MatrixXd full_real_column_covariance(const FrequencyData& d, const Parametrisation& p,
                                            const std::vector<int>& rows, const RowNoise& rn,
                                            const Eigen::VectorXd& weights);

// Value of s^n for line l: (j l w0)^n or exp(j l w0 ts)^n.
cd line_power(const Structure& s, int line, int n);

}  // namespace lptv
