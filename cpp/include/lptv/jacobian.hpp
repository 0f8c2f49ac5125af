// Residue e(theta) = A(theta) Y - B(theta) U on a set of rows, its Jacobian, the real
// parametrisation theta = T eta + d, the residue variance and the column covariance
// of the Jacobian's noise (METHOD.md sections 5 and 6).
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/model.hpp"
#include "lptv/noise.hpp"

namespace lptv {

// Which coefficients are free, and how many harmonics each has.
struct Structure {
  int na = 0, nb = 0;
  std::vector<int> ka;  // harmonic count of a_0 .. a_na (size na+1)
  std::vector<int> kb;  // harmonic count of b_0 .. b_nb (size nb+1)
  // A coefficient known exactly: its Fourier row (2K+1 values, harmonic k in
  // column K+k, K = its own harmonic count in ka/kb). It leaves the unknowns,
  // and then fixes the scale: no normalisation is needed.
  struct Known {
    bool is_a = true;
    int order = 0;
    Eigen::VectorXcd coef;
  };
  std::vector<Known> known;
  double w0 = 1.0;
  double ts = 0.0;  // 0: continuous time

  int kmax() const;
  // Throws std::invalid_argument naming what is wrong.
  void validate() const;
};

// One complex parameter theta_p: harmonic k of a_order (is_a) or b_order.
struct Param {
  bool is_a;
  int order;
  int k;
};

class Parametrisation {
 public:
  explicit Parametrisation(const Structure& s);

  const Structure& structure() const { return s_; }
  const std::vector<Param>& params() const { return params_; }
  int n_theta() const { return static_cast<int>(params_.size()); }
  int n_eta() const { return static_cast<int>(T_.cols()); }
  // Columns of the homogeneous real problem: eta, plus one for the known part.
  int n_xi() const { return n_eta() + (has_known() ? 1 : 0); }
  bool has_known() const { return has_known_; }
  // theta = T eta + d. Real unknowns per coefficient with K harmonics:
  // Re c_0, Re c_1, Im c_1, ..., Re c_K, Im c_K (known coefficients excluded).
  const Eigen::MatrixXcd& T() const { return T_; }
  const Eigen::VectorXcd& d() const { return d_; }
  // [T, d] when some coefficient is known, else T: theta = Text xi.
  const Eigen::MatrixXcd& Text() const { return Text_; }
  // Index in xi that is set to 1 at the end: the known column, or Re a_{na,0}.
  int norm_index() const { return norm_index_; }
  // Index of harmonic k of a_order / b_order in theta (-1: not a parameter).
  int theta_index(bool is_a, int order, int k) const;
  // xi (normalised or not) -> theta; normalises so that xi[norm_index] = 1.
  Eigen::VectorXcd theta_from_xi(const Eigen::VectorXd& xi) const;
  Eigen::VectorXd eta_from_xi(const Eigen::VectorXd& xi) const;
  // theta -> a model (harmonic counts padded to the largest of each side).
  Model to_model(const Eigen::VectorXcd& theta) const;

 private:
  Structure s_;
  std::vector<Param> params_;
  std::vector<int> offset_a_, offset_b_;  // first theta index of each coefficient
  Eigen::MatrixXcd T_, Text_;
  Eigen::VectorXcd d_;
  bool has_known_ = false;
  int norm_index_ = -1;
};

// Rows (lines) the data supports by default: K+1 .. Lmax-K (METHOD.md section 5).
std::vector<int> default_rows(const Parametrisation& p, int max_line);
// Throws std::invalid_argument when rows are not >= 1, repeat, or need lines
// beyond the data (|l +- K| > Lmax), or leave fewer equations than unknowns.
void check_rows(const Parametrisation& p, const std::vector<int>& rows, int max_line);

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

// Value of s^n for line l: (j l w0)^n or exp(j l w0 ts)^n.
cd line_power(const Structure& s, int line, int n);

}  // namespace lptv
