#include "lptv/model.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>
#include <string>

namespace lptv {
namespace {

void check_coefficients(const Eigen::MatrixXcd& c, const char* name) {
  std::ostringstream msg;
  if (c.rows() < 1) {
    msg << name << " must have at least one row (order >= 0), got 0";
    throw std::invalid_argument(msg.str());
  }
  if (c.cols() % 2 != 1) {
    msg << name << " must have an odd number of columns 2K+1 (harmonics -K..K), got "
        << c.cols();
    throw std::invalid_argument(msg.str());
  }
  if (!c.allFinite()) {
    msg << name << " contains NaN or inf";
    throw std::invalid_argument(msg.str());
  }
  const Eigen::Index K = (c.cols() - 1) / 2;
  const double scale = c.cwiseAbs().maxCoeff();
  const double tol = 1e-12 * (scale > 0 ? scale : 1.0);
  for (Eigen::Index n = 0; n < c.rows(); ++n) {
    for (Eigen::Index k = 0; k <= K; ++k) {
      const cd d = c(n, K + k) - std::conj(c(n, K - k));
      if (std::abs(d) > tol && k == 0) {
        msg << name << " is not conjugate-symmetric: row " << n << ", harmonic 0 is " << c(n, K)
            << " but must be real (the mean of a real coefficient)";
        throw std::invalid_argument(msg.str());
      }
      if (std::abs(d) > tol) {
        msg << name << " is not conjugate-symmetric: row " << n << ", harmonic " << k
            << " is " << c(n, K + k) << " but harmonic " << -k << " is " << c(n, K - k)
            << " (a real coefficient needs c[n, K-k] = conj(c[n, K+k]))";
        throw std::invalid_argument(msg.str());
      }
    }
  }
}

}  // namespace

Model::Model(Eigen::MatrixXcd a, Eigen::MatrixXcd b, double w0, double ts)
    : a_(std::move(a)), b_(std::move(b)), w0_(w0), ts_(ts) {
  if (!(std::isfinite(w0_) && w0_ > 0)) {
    throw std::invalid_argument("w0 must be a finite positive angular frequency (rad/s), got " +
                                std::to_string(w0_));
  }
  if (!(std::isfinite(ts_) && ts_ >= 0)) {
    throw std::invalid_argument("ts must be finite and >= 0 (0 for continuous time), got " +
                                std::to_string(ts_));
  }
  check_coefficients(a_, "a");
  check_coefficients(b_, "b");
  // Exact symmetry from here on: imaginary parts of harmonic 0 and rounding
  // differences between k and -k are removed.
  for (Eigen::MatrixXcd* c : {&a_, &b_}) {
    const Eigen::Index K = (c->cols() - 1) / 2;
    for (Eigen::Index n = 0; n < c->rows(); ++n) {
      for (Eigen::Index k = 0; k <= K; ++k) {
        // The midpoint as x + (y - x) / 2: exact when the pair is already symmetric, and no
        // overflow of x + y for entries near the largest double (x + y gave inf).
        const cd x = (*c)(n, K + k);
        const cd v = x + 0.5 * (std::conj((*c)(n, K - k)) - x);
        (*c)(n, K + k) = v;
        (*c)(n, K - k) = std::conj(v);
      }
    }
  }
  if (a_.row(a_.rows() - 1).cwiseAbs().maxCoeff() == 0.0) {
    throw std::invalid_argument("a: the leading coefficient a_na(t) is identically zero; "
                                "lower na or give a nonzero last row");
  }
  if (discrete()) samples_per_period();
}

cd Model::a_coef(int n, int k) const {
  const int K = ka();
  if (n < 0 || n > na() || k < -K || k > K) return cd(0.0, 0.0);
  return a_(n, K + k);
}

cd Model::b_coef(int m, int k) const {
  const int K = kb();
  if (m < 0 || m > nb() || k < -K || k > K) return cd(0.0, 0.0);
  return b_(m, K + k);
}

int Model::samples_per_period() const {
  if (!discrete()) {
    throw std::invalid_argument("samples_per_period: the model is continuous-time (ts == 0)");
  }
  const double N = 2.0 * M_PI / (w0_ * ts_);
  const double Nr = std::round(N);
  if (!(Nr <= 2147483647.0)) {
    std::ostringstream msg;
    msg << "w0 and ts give 2*pi/(w0*ts) = " << N << " samples per parameter period, more than a grid can hold";
    throw std::invalid_argument(msg.str());
  }
  if (Nr < 1 || std::abs(N - Nr) > 1e-9 * Nr) {
    std::ostringstream msg;
    msg << "w0 and ts do not fit a grid: 2*pi/(w0*ts) = " << N
        << " samples per parameter period is not an integer";
    throw std::invalid_argument(msg.str());
  }
  const int n = static_cast<int>(Nr);
  if (2 * kmax() + 1 > n) {
    std::ostringstream msg;
    msg << "harmonic counts do not fit the grid: " << kmax() << " harmonics need at least "
        << 2 * kmax() + 1 << " samples per period, the model has " << n;
    throw std::invalid_argument(msg.str());
  }
  return n;
}

Eigen::MatrixXd evaluate_fourier(const Eigen::MatrixXcd& coef, double w0,
                                 const Eigen::VectorXd& t) {
  const Eigen::Index K = (coef.cols() - 1) / 2;
  Eigen::MatrixXd out(t.size(), coef.rows());
  std::vector<cd> phasor(static_cast<size_t>(K) + 1);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    // e^{jkwt} once per time and harmonic, shared by the coefficients
    for (Eigen::Index k = 1; k <= K; ++k) phasor[static_cast<size_t>(k)] = std::polar(1.0, double(k) * w0 * t[i]);
    for (Eigen::Index n = 0; n < coef.rows(); ++n) {
      double v = coef(n, K).real();
      for (Eigen::Index k = 1; k <= K; ++k) {
        // c_k e^{jkwt} + conj(c_k) e^{-jkwt} = 2 Re(c_k e^{jkwt})
        v += 2.0 * (coef(n, K + k) * phasor[static_cast<size_t>(k)]).real();
      }
      out(i, n) = v;
    }
  }
  return out;
}

Eigen::MatrixXd Model::a_at(const Eigen::VectorXd& t) const {
  if (!t.allFinite()) throw std::invalid_argument("t contains NaN or inf");
  return evaluate_fourier(a_, w0_, t);
}

Eigen::MatrixXd Model::b_at(const Eigen::VectorXd& t) const {
  if (!t.allFinite()) throw std::invalid_argument("t contains NaN or inf");
  return evaluate_fourier(b_, w0_, t);
}

}  // namespace lptv
