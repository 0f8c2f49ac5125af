// The LPTV model: sum_n a_n(t) d^n y = sum_m b_m(t) d^m u, coefficients as finite
// Fourier series in the parameter fundamental w0 (METHOD.md section 1).
#pragma once
#include <Eigen/Dense>
#include <complex>
#include <vector>

namespace lptv {

using cd = std::complex<double>;

class Model {
 public:
  // a: (na+1) x (2Ka+1), b: (nb+1) x (2Kb+1); column K+k holds harmonic k of the
  // row's coefficient. w0 > 0 is the parameter fundamental (rad/s). ts == 0 means
  // continuous time; ts > 0 means discrete time with sample period ts (forward shift).
  // Throws std::invalid_argument on non-finite values, even column counts, or
  // coefficients that are not conjugate-symmetric (to a relative 1e-12).
  Model(Eigen::MatrixXcd a, Eigen::MatrixXcd b, double w0, double ts = 0.0);

  int na() const { return static_cast<int>(a_.rows()) - 1; }
  int nb() const { return static_cast<int>(b_.rows()) - 1; }
  int ka() const { return static_cast<int>(a_.cols() - 1) / 2; }
  int kb() const { return static_cast<int>(b_.cols() - 1) / 2; }
  int kmax() const { return ka() > kb() ? ka() : kb(); }
  double w0() const { return w0_; }
  double ts() const { return ts_; }
  bool discrete() const { return ts_ > 0.0; }
  const Eigen::MatrixXcd& a() const { return a_; }
  const Eigen::MatrixXcd& b() const { return b_; }

  // Harmonic k of a_n (zero outside -Ka..Ka).
  cd a_coef(int n, int k) const;
  cd b_coef(int m, int k) const;

  // Discrete time: samples per parameter period N = 2 pi / (w0 ts); throws
  // std::invalid_argument when that is not an integer.
  int samples_per_period() const;

  // Coefficient values on a time grid: (len(t)) x (na+1), real parts (the
  // coefficients are real by conjugate symmetry).
  Eigen::MatrixXd a_at(const Eigen::VectorXd& t) const;
  Eigen::MatrixXd b_at(const Eigen::VectorXd& t) const;

 private:
  Eigen::MatrixXcd a_, b_;
  double w0_, ts_;
};

// Evaluates sum_k c_k exp(j k w0 t) for each row of coef (rows x (2K+1)) at times t.
Eigen::MatrixXd evaluate_fourier(const Eigen::MatrixXcd& coef, double w0,
                                 const Eigen::VectorXd& t);

}  // namespace lptv
