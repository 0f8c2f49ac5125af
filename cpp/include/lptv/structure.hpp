// The structure of an LPTV model to estimate (orders, harmonic counts, known coefficients, time
// domain) and its real parametrisation theta = T eta + d (METHOD.md section 5).
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "lptv/model.hpp"

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
  // The structure of a model's own orders and harmonic counts (every a_n with Ka, every b_m
  // with Kb), nothing known, its w0 and ts.
  static Structure of(const Model& m);
  // Complex parameters (every harmonic of every coefficient, known ones included) and the free
  // real unknowns after the normalisation, in 64-bit arithmetic (no allocation).
  long long n_complex_parameters() const;
  long long n_unknowns() const;
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
  // The inverse maps: theta (conjugate-symmetric where the structure is) -> xi with
  // xi[norm_index] as theta has it (1 for the known column), read off entry by entry.
  Eigen::VectorXd xi_from_theta(const Eigen::VectorXcd& theta) const;
  // theta of a model whose orders and harmonic counts fit in the structure (harmonics the
  // structure does not have must be zero in the model); throws std::invalid_argument otherwise.
  Eigen::VectorXcd theta_from_model(const Model& m) const;
  // theta -> a model (harmonic counts padded to the largest of each side).
  Model to_model(const Eigen::VectorXcd& theta) const;
  // Names of the entries of eta: "a0.re0", "a0.re1", "a0.im1", ..., "b1.im3".
  std::vector<std::string> eta_names() const;
  // The indices of xi other than norm_index: the free real parameters.
  std::vector<int> free_indices() const;

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
// The per-row part of check_rows (lines >= 1, within the data for K harmonics, no repeats),
// from the structure alone: no parametrisation is built.
void check_row_lines(const Structure& s, const std::vector<int>& rows, int max_line);

}  // namespace lptv
