// The matrix LPTV model (METHOD.md section 19): validation and evaluation.
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "lptv/mimo.hpp"

namespace lptv {
namespace {

// Entry label of row `row` of a coefficient matrix: "a[n, p, q]".
std::string entry_label(const char* name, Eigen::Index row, int rows_per_order, int cols) {
  std::ostringstream s;
  s << name << "[" << row / rows_per_order << ", " << (row % rows_per_order) / cols << ", "
    << row % cols << "]";
  return s.str();
}

void check_side(const Eigen::MatrixXcd& c, const char* name, int ny, int ncols) {
  std::ostringstream msg;
  const int per_order = ny * ncols;
  if (c.rows() < per_order || c.rows() % per_order != 0) {
    msg << name << " must have (order+1) * " << ny << " * " << ncols << " rows (one per order and entry), got "
        << c.rows();
    throw std::invalid_argument(msg.str());
  }
  if (c.cols() % 2 != 1) {
    msg << name << " must have an odd number of columns 2K+1 (harmonics -K..K), got " << c.cols();
    throw std::invalid_argument(msg.str());
  }
  if (!c.allFinite()) {
    msg << name << " contains NaN or inf";
    throw std::invalid_argument(msg.str());
  }
  const Eigen::Index K = (c.cols() - 1) / 2;
  const double scale = c.cwiseAbs().maxCoeff();
  const double tol = 1e-12 * (scale > 0 ? scale : 1.0);
  for (Eigen::Index r = 0; r < c.rows(); ++r) {
    for (Eigen::Index k = 0; k <= K; ++k) {
      if (std::abs(c(r, K + k) - std::conj(c(r, K - k))) <= tol) continue;
      msg << name << " is not conjugate-symmetric: entry " << entry_label(name, r, per_order, ncols);
      if (k == 0) {
        msg << ", harmonic 0 is " << c(r, K) << " but must be real (the mean of a real coefficient)";
      } else {
        msg << ", harmonic " << k << " is " << c(r, K + k) << " but harmonic " << -k << " is "
            << c(r, K - k) << " (a real coefficient needs harmonic -k = conj(harmonic k))";
      }
      throw std::invalid_argument(msg.str());
    }
  }
}

void symmetrise(Eigen::MatrixXcd& c) {
  const Eigen::Index K = (c.cols() - 1) / 2;
  for (Eigen::Index r = 0; r < c.rows(); ++r) {
    for (Eigen::Index k = 0; k <= K; ++k) {
      // as lptv::Model: the midpoint x + (y - x) / 2, exact for a symmetric pair
      const cd x = c(r, K + k);
      const cd v = x + 0.5 * (std::conj(c(r, K - k)) - x);
      c(r, K + k) = v;
      c(r, K - k) = std::conj(v);
    }
  }
}

}  // namespace

MimoModel::MimoModel(Eigen::MatrixXcd a, Eigen::MatrixXcd b, int n_outputs, int n_inputs, double w0,
                     double ts)
    : a_(std::move(a)), b_(std::move(b)), ny_(n_outputs), nu_(n_inputs), w0_(w0), ts_(ts) {
  if (ny_ < 1 || nu_ < 1 || ny_ > 4096 || nu_ > 4096) {
    throw std::invalid_argument("n_outputs and n_inputs must lie in 1..4096, got " + std::to_string(ny_) +
                                " and " + std::to_string(nu_));
  }
  if (!(std::isfinite(w0_) && w0_ > 0)) {
    throw std::invalid_argument("w0 must be a finite positive angular frequency (rad/s), got " +
                                std::to_string(w0_));
  }
  if (!(std::isfinite(ts_) && ts_ >= 0)) {
    throw std::invalid_argument("ts must be finite and >= 0 (0 for continuous time), got " +
                                std::to_string(ts_));
  }
  check_side(a_, "a", ny_, ny_);
  check_side(b_, "b", ny_, nu_);
  symmetrise(a_);
  symmetrise(b_);
  const Eigen::Index lead = static_cast<Eigen::Index>(na()) * ny_ * ny_;
  if (a_.bottomRows(a_.rows() - lead).cwiseAbs().maxCoeff() == 0.0) {
    throw std::invalid_argument("a: the leading matrix A_na(t) is identically zero; lower na or give "
                                "a nonzero last order");
  }
  if (discrete()) samples_per_period();
}

MimoModel::MimoModel(const Model& m) : MimoModel(m.a(), m.b(), 1, 1, m.w0(), m.ts()) {}

cd MimoModel::a_coef(int n, int p, int q, int k) const {
  const int K = ka();
  if (n < 0 || n > na() || p < 0 || p >= ny_ || q < 0 || q >= ny_ || k < -K || k > K) return cd(0.0, 0.0);
  return a_((static_cast<Eigen::Index>(n) * ny_ + p) * ny_ + q, K + k);
}

cd MimoModel::b_coef(int m, int p, int r, int k) const {
  const int K = kb();
  if (m < 0 || m > nb() || p < 0 || p >= ny_ || r < 0 || r >= nu_ || k < -K || k > K) return cd(0.0, 0.0);
  return b_((static_cast<Eigen::Index>(m) * ny_ + p) * nu_ + r, K + k);
}

int MimoModel::samples_per_period() const {
  if (!discrete()) {
    throw std::invalid_argument("samples_per_period: the model is continuous-time (ts == 0)");
  }
  const double N = 2.0 * M_PI / (w0_ * ts_);
  const double Nr = std::round(N);
  if (!(Nr <= 2147483647.0) || Nr < 1 || std::abs(N - Nr) > 1e-9 * Nr) {
    std::ostringstream msg;
    msg << "w0 and ts do not fit a grid: 2*pi/(w0*ts) = " << N
        << " samples per parameter period is not an integer that a grid can hold";
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

Eigen::MatrixXd MimoModel::a_at(const Eigen::VectorXd& t) const {
  if (!t.allFinite()) throw std::invalid_argument("t contains NaN or inf");
  return evaluate_fourier(a_, w0_, t);
}

Eigen::MatrixXd MimoModel::b_at(const Eigen::VectorXd& t) const {
  if (!t.allFinite()) throw std::invalid_argument("t contains NaN or inf");
  return evaluate_fourier(b_, w0_, t);
}

}  // namespace lptv
