#include "lptv/record.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "lptv/errors.hpp"
#include "lptv/fds.hpp"
#include "rows.hpp"

namespace lptv {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Levenberg-Marquardt: damping raised at most this often per iteration (nu doubles each time,
// so the damping grows by 2^(k (k + 1) / 2): far beyond any useful value).
constexpr int kMaxTrials = 30;
// The first damping, relative to the squared column norms of J: next to nothing, so that from
// the equation-error start (close to the minimum) the steps are Gauss-Newton's and converge
// in a few iterations. A damping of 1e-3 (the usual start) held back the directions whose
// singular values lie below 0.03 of their column's norm: 13-15 iterations instead of 3-6 on
// the discrete-time example.
constexpr double kLambdaStart = 1e-9;

std::string str(long long v) { return std::to_string(v); }

// The record's grid (N = L N0 lines, z_i = exp(j 2 pi i / N)), the parametrisation's
// bookkeeping and the record's spectra: what every row of the fit reads.
class RecordProblem {
 public:
  RecordProblem(const Parametrisation& p, const RecordData& d, bool transient, int transient_degree)
      : p_(p), d_(d) {
    const Structure& s = p.structure();
    ct_ = !(s.ts > 0);
    if (ct_) {
      if (!(d.ts > 0 && std::isfinite(d.ts))) {
        throw std::invalid_argument("ts: a continuous-time record needs its sample time (> 0), got " +
                                    std::to_string(d.ts));
      }
      ts_ = d.ts;
    } else {
      if (d.ts != 0 && d.ts != s.ts) {
        throw std::invalid_argument("ts: the record's sample time " + std::to_string(d.ts) +
                                    " differs from the discrete-time structure's " + std::to_string(s.ts));
      }
      ts_ = s.ts;
    }
    const double n0 = 2.0 * M_PI / (s.w0 * ts_);
    const double n0r = std::round(n0);
    if (!(n0r >= 2 && n0r <= 2147483647.0) || std::abs(n0 - n0r) > 1e-9 * n0r) {
      throw std::invalid_argument("w0 and ts must give a whole number of samples per period, 2 pi / (w0 ts) = " +
                                  std::to_string(n0));
    }
    N0_ = static_cast<int>(n0r);
    if (d.periods < 1) throw std::invalid_argument("periods must be >= 1, got " + str(d.periods));
    if (d.U.size() != d.Y.size()) {
      throw std::invalid_argument("U and Y must have the same length, got " + str(d.U.size()) + " and " +
                                  str(d.Y.size()));
    }
    if (static_cast<long long>(d.periods) * N0_ != d.U.size()) {
      throw std::invalid_argument("U must hold the record's N = periods N0 = " + str(d.periods) + " x " + str(N0_) +
                                  " lines, got " + str(d.U.size()));
    }
    if (!d.U.allFinite()) throw std::invalid_argument("U must be finite");
    if (!d.Y.allFinite()) throw std::invalid_argument("Y must be finite");
    if (2 * s.kmax() + 1 > N0_) {
      throw std::invalid_argument("ka, kb: " + str(2 * s.kmax() + 1) + " harmonics do not fit in a period of " +
                                  str(N0_) + " samples");
    }
    N_ = static_cast<int>(d.U.size());
    L_ = d.periods;
    order_ = std::max(s.na, s.nb);
    if (!ct_ && transient_degree != -1) {
      throw std::invalid_argument("transient_degree: discrete time takes only -1 (the term z^1..z^n is exact), got " +
                                  str(transient_degree));
    }
    if (ct_ && transient_degree != -1 && (transient_degree < order_ - 1 || transient_degree > order_ + 20)) {
      throw std::invalid_argument("transient_degree must lie in " + str(order_ - 1) + ".." + str(order_ + 20) +
                                  " (n - 1 .. n + 20) or be -1, got " + str(transient_degree));
    }
    // Discrete time: T = sum_{j=1}^{n} c_j z^j. Continuous time: T = sum_{j=0}^{d} c_j (j w ts)^j.
    t0_ = ct_ ? 0 : 1;
    const int tdeg = ct_ ? (transient_degree == -1 ? order_ + 1 : transient_degree) : order_;
    nT_ = transient ? tdeg - t0_ + 1 : 0;
    free_ = p.free_indices();
    nf_ = static_cast<int>(free_.size());
    norm_ = p.norm_index();
    text_ = detail::text_entries(p);
    Ka_ = *std::max_element(s.ka.begin(), s.ka.end());
    // The record model's fundamental: the same double that its Fds builds A from, so the rows
    // here and the FDS's entries use the same z_i.
    w0_rec_ = s.w0 / L_;
    // The work grid: discrete time the circular N lines (index = DFT index); continuous time
    // the lines -M..M at index l + M (the DFT's index l mod N), M = (N - 1) / 2.
    M_ = (N_ - 1) / 2;
    G_ = ct_ ? 2 * M_ + 1 : N_;
    U_.resize(G_);
    Y_.resize(G_);
    for (int g = 0; g < G_; ++g) {
      const int i = ct_ ? ((g - M_) % N_ + N_) % N_ : g;
      U_[g] = d.U[i];
      Y_[g] = d.Y[i];
    }
    zp_.resize(static_cast<size_t>(G_) * (order_ + 1));
    tp_.resize(static_cast<size_t>(G_) * (nT_ + 1));
    for (int g = 0; g < G_; ++g) {
      const int line = ct_ ? g - M_ : g;
      detail::line_powers(detail::line_variable(w0_rec_, ct_ ? 0.0 : s.ts, line), order_,
                          &zp_[static_cast<size_t>(g) * (order_ + 1)]);
      // the transient's basis: z^t0 .. z^(t0 + nT - 1), (j w ts)^j in continuous time
      const cd v = ct_ ? cd(0.0, 2.0 * M_PI * line / N_) : zp_[static_cast<size_t>(g) * (order_ + 1) + 1];
      cd pw(1.0, 0.0);
      for (int j = 0; j < t0_; ++j) pw *= v;
      for (int j = 0; j < nT_; ++j, pw *= v) tp_[static_cast<size_t>(g) * (nT_ + 1) + j] = pw;
    }
  }

  // The fitted lines: ascending, distinct, within 1..(N-1)/2, more real equations than parameters.
  void check_lines() const {
    const std::vector<int>& lines = d_.lines;
    const int n_lines = static_cast<int>(lines.size());
    if (n_lines == 0) throw std::invalid_argument("lines must not be empty");
    for (int i = 0; i < n_lines; ++i) {
      const int l = lines[static_cast<size_t>(i)];
      if (l < 1 || 2LL * l > N_ - 1) {
        throw std::invalid_argument("lines must lie in 1.." + str((N_ - 1) / 2) + " (the record's grid), got " + str(l));
      }
      if (i > 0 && l <= lines[static_cast<size_t>(i) - 1]) {
        throw std::invalid_argument("lines must be ascending and distinct, got " + str(lines[i - 1]) + " before " +
                                    str(l));
      }
    }
    if (2 * n_lines <= n_par()) {
      throw std::invalid_argument("lines: " + str(n_lines) + " lines give " + str(2 * n_lines) +
                                  " real equations for " + str(n_par()) + " parameters");
    }
  }

  int N() const { return G_; }  // lines of the work grid
  bool continuous() const { return ct_; }
  // Work-grid index of a (positive) fitted line.
  int index(int l) const { return ct_ ? l + M_ : l; }
  const Eigen::VectorXcd& U() const { return U_; }
  const Eigen::VectorXcd& Y() const { return Y_; }
  // The transient's basis at work-grid index g: nT entries.
  const cd* t(int g) const { return &tp_[static_cast<size_t>(g) * (nT_ + 1)]; }
  int n_free() const { return nf_; }
  int n_transient() const { return nT_; }
  int n_par() const { return nf_ + nT_; }
  int norm() const { return norm_; }
  const Parametrisation& par() const { return p_; }
  const std::vector<int>& free() const { return free_; }
  const RecordData& data() const { return d_; }
  // z_i^0 .. z_i^order.
  const cd* z(int i) const { return &zp_[static_cast<size_t>(i) * (order_ + 1)]; }
  // The line a harmonic k brings to line l: l - k L on the circular grid; continuous time
  // (work-grid indices) -1 beyond -M..M, where the FDS takes the spectra as zero.
  int source(int l, int k) const {
    if (ct_) {
      const int i = l - k * L_;
      return i < 0 || i >= G_ ? -1 : i;
    }
    const int i = (l - k * L_) % N_;
    return i < 0 ? i + N_ : i;
  }

  // Row l of J(X) Text into xrow (n_xi entries): J[l, q] = +z_i^n X_i (a-parameters),
  // -z_i^n U_i (b-parameters), i = l - k L; jrow is scratch of n_theta entries.
  void xi_row(const Eigen::VectorXcd& X, int l, cd* jrow, cd* xrow) const {
    for (int q = 0; q < p_.n_theta(); ++q) {
      const Param& pr = p_.params()[static_cast<size_t>(q)];
      const int i = source(l, pr.k);
      if (i < 0) {
        jrow[q] = cd(0.0, 0.0);
        continue;
      }
      const cd f = z(i)[pr.order];
      jrow[q] = pr.is_a ? f * X[i] : -f * U_[i];
    }
    std::fill(xrow, xrow + p_.n_xi(), cd(0.0, 0.0));
    for (const detail::TextEntry& e : text_) xrow[e.c] += jrow[e.p] * e.v;
  }

  // xi of x = [free eta, c]: xi[norm_index] = 1.
  Eigen::VectorXd xi_of(const Eigen::VectorXd& x) const {
    Eigen::VectorXd xi = Eigen::VectorXd::Zero(p_.n_xi());
    for (int c = 0; c < nf_; ++c) xi[free_[static_cast<size_t>(c)]] = x[c];
    xi[norm_] = 1.0;
    return xi;
  }
  Eigen::VectorXcd theta_of(const Eigen::VectorXd& x) const { return p_.Text() * xi_of(x); }

  // The model whose FDS solves A Y = R on the record's grid: fundamental w0 / L, harmonic k of
  // a_n at k L, B the identity.
  Model record_model(const Eigen::VectorXcd& theta) const {
    const Structure& s = p_.structure();
    Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(s.na + 1, 2 * Ka_ * L_ + 1);
    for (int q = 0; q < p_.n_theta(); ++q) {
      const Param& pr = p_.params()[static_cast<size_t>(q)];
      if (pr.is_a) a(pr.order, (Ka_ + pr.k) * L_) = theta[q];
    }
    return Model(std::move(a), Eigen::MatrixXcd::Constant(1, 1, cd(1.0, 0.0)), w0_rec_, ct_ ? 0.0 : s.ts);
  }
  // Its FDS: the circular grid, or continuous time the lines -M..M.
  std::unique_ptr<Fds> fds(const Eigen::VectorXcd& theta) const {
    return std::make_unique<Fds>(record_model(theta), ct_ ? M_ : 0, Solver::KLU);
  }

  // B(theta) U - T(c) on the work grid.
  Eigen::VectorXcd forcing(const Eigen::VectorXcd& theta, const Eigen::VectorXd& x) const {
    Eigen::VectorXcd r(G_);
    for (int l = 0; l < G_; ++l) {
      cd v(0.0, 0.0);
      for (int q = 0; q < p_.n_theta(); ++q) {
        const Param& pr = p_.params()[static_cast<size_t>(q)];
        if (pr.is_a) continue;
        const int i = source(l, pr.k);
        if (i >= 0) v += theta[q] * z(i)[pr.order] * U_[i];
      }
      for (int j = 0; j < nT_; ++j) v -= x[nf_ + j] * t(l)[j];
      r[l] = v;
    }
    return r;
  }

 private:
  const Parametrisation& p_;
  const RecordData& d_;
  bool ct_ = false;
  int N0_ = 0, N_ = 0, L_ = 1, order_ = 0, nT_ = 0, t0_ = 1, nf_ = 0, norm_ = 0, Ka_ = 0, M_ = 0, G_ = 0;
  double w0_rec_ = 0, ts_ = 0;
  std::vector<int> free_;
  std::vector<detail::TextEntry> text_;
  std::vector<cd> zp_, tp_;
  Eigen::VectorXcd U_, Y_;
};

// x = V S^+ U^T b and V S^+2 V^T for a tall A (rows >= cols): a QR of A, then the SVD of its R;
// singular values below max(rows, cols) eps s_max count as zero (numpy.linalg.lstsq's and
// pinv's cut-off), so a rank-deficient problem gets the minimum-norm answer.
struct TallSvd {
  Eigen::VectorXd s;
  Eigen::MatrixXd U, V;  // of R: A = Q U S V^T
  Eigen::MatrixXd Q;     // thin
  double cut = 0;
  explicit TallSvd(const Eigen::MatrixXd& A) {
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
    const Eigen::Index n = A.cols();
    Q = qr.householderQ() * Eigen::MatrixXd::Identity(A.rows(), n);
    const Eigen::MatrixXd R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    s = svd.singularValues();
    U = svd.matrixU();
    V = svd.matrixV();
    cut = (s.size() ? s[0] : 0.0) * kEps * static_cast<double>(std::max(A.rows(), A.cols()));
  }
  Eigen::VectorXd inv_s(int power) const {
    Eigen::VectorXd v(s.size());
    for (Eigen::Index i = 0; i < s.size(); ++i) v[i] = s[i] > cut ? std::pow(s[i], -power) : 0.0;
    return v;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const {
    return V * (inv_s(1).asDiagonal() * (U.transpose() * (Q.transpose() * b)));
  }
  Eigen::MatrixXd gram_inverse() const { return V * inv_s(2).asDiagonal() * V.transpose(); }
  // The diagonal of the projection onto A's column space (each row's leverage): the squared
  // row norms of Q U over the singular values above the cut.
  Eigen::VectorXd leverage() const {
    Eigen::Index r = 0;
    while (r < s.size() && s[r] > cut) ++r;
    return (Q * U.leftCols(r)).rowwise().squaredNorm();
  }
};

// The output error at one point: A factorised, the prediction on all lines, the whitened
// residual [Re; Im] on the fitted lines and its squared norm.
struct Point {
  std::unique_ptr<Fds> fds;
  Eigen::VectorXcd Yh;
  Eigen::VectorXd r;
  double cost = 0;
};

class OutputError {
 public:
  OutputError(const RecordProblem& pb, const Eigen::VectorXd& var) : pb_(pb), w_(var.size()) {
    for (Eigen::Index i = 0; i < var.size(); ++i) w_[i] = std::sqrt(2.0 / var[i]);  // Re, Im: var / 2 each
  }

  Point evaluate(const Eigen::VectorXd& x, int& evaluations) const {
    Point pt;
    const Eigen::VectorXcd theta = pb_.theta_of(x);
    ++evaluations;
    pt.fds = pb_.fds(theta);
    pt.Yh = pt.fds->solve_A(pb_.forcing(theta, x));
    const auto& lines = pb_.data().lines;
    const Eigen::Index n = static_cast<Eigen::Index>(lines.size());
    pt.r.resize(2 * n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const int l = pb_.index(lines[static_cast<size_t>(i)]);
      const cd e = pb_.Y()[l] - pt.Yh[l];
      pt.r[i] = w_[i] * e.real();
      pt.r[n + i] = w_[i] * e.imag();
    }
    pt.cost = pt.r.squaredNorm();
    if (!std::isfinite(pt.cost)) throw NumericalError("the prediction overflows");
    return pt;
  }

  // d r / d x = -w d Y_hat / d x: d Y_hat / d eta_p = A^-1 (B_p U - A_p Y_hat) = -A^-1 (J(Y_hat) Text)_p,
  // d Y_hat / d c_j = -A^-1 z^j; all right-hand sides through the point's one factorisation.
  Eigen::MatrixXd jacobian(const Point& pt) const {
    const int N = pb_.N(), nf = pb_.n_free(), nT = pb_.n_transient();
    const Parametrisation& p = pb_.par();
    Eigen::MatrixXcd rhs(N, nf + nT);
    std::vector<cd> jrow(static_cast<size_t>(p.n_theta())), xrow(static_cast<size_t>(p.n_xi()));
    for (int l = 0; l < N; ++l) {
      pb_.xi_row(pt.Yh, l, jrow.data(), xrow.data());
      for (int c = 0; c < nf; ++c) rhs(l, c) = -xrow[static_cast<size_t>(pb_.free()[static_cast<size_t>(c)])];
      for (int j = 0; j < nT; ++j) rhs(l, nf + j) = -pb_.t(l)[j];
    }
    const Eigen::MatrixXcd D = pt.fds->solve_A(rhs);
    const auto& lines = pb_.data().lines;
    const Eigen::Index n = static_cast<Eigen::Index>(lines.size());
    Eigen::MatrixXd J(2 * n, nf + nT);
    for (Eigen::Index i = 0; i < n; ++i) {
      const int l = pb_.index(lines[static_cast<size_t>(i)]);
      J.row(i) = -w_[i] * D.row(l).real();
      J.row(n + i) = -w_[i] * D.row(l).imag();
    }
    return J;
  }


 private:
  const RecordProblem& pb_;
  Eigen::VectorXd w_;
};

struct LmOutcome {
  Eigen::VectorXd x;
  Point pt;
  Eigen::MatrixXd J;  // at x
  bool converged = false;
  int iterations = 0;
};

// Levenberg-Marquardt with Marquardt's scaling (D the largest column norms of J met so far,
// as MINPACK keeps them) and Nielsen's update of the damping. Each iteration: one QR of J, then
// per damping the small problem [R; sqrt(lambda) D] (2p x p). Stops as MINPACK does with
// ftol = xtol = gtol = tol: the actual and predicted relative decrease both below tol, the
// scaled step below tol of the scaled x, or the largest cosine between r and a column of J
// below tol; and when the predicted decrease is at rounding level (8 eps of the cost), where
// no step can be told from rounding.
LmOutcome levenberg_marquardt(const OutputError& oe, Eigen::VectorXd x, Point pt, int max_iterations, double tol,
                              int& evaluations) {
  LmOutcome out;
  const Eigen::Index np = x.size();
  Eigen::MatrixXd J = oe.jacobian(pt);
  Eigen::VectorXd D = Eigen::VectorXd::Zero(np);
  double lambda = kLambdaStart, nu = 2.0;
  bool j_current = true;
  for (int it = 1; it <= max_iterations; ++it) {
    out.iterations = it;
    const double rnorm = std::sqrt(pt.cost);
    if (rnorm == 0.0) {
      out.converged = true;
      break;
    }
    Eigen::VectorXd colnorm = J.colwise().norm().transpose();
    const Eigen::VectorXd g = J.transpose() * pt.r;
    double gcos = 0.0;
    for (Eigen::Index c = 0; c < np; ++c) {
      if (colnorm[c] > 0) gcos = std::max(gcos, std::abs(g[c]) / (colnorm[c] * rnorm));
    }
    if (gcos <= tol) {
      out.converged = true;
      break;
    }
    for (Eigen::Index c = 0; c < np; ++c) D[c] = std::max(D[c], colnorm[c] > 0 ? colnorm[c] : 1.0);
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
    const Eigen::MatrixXd R = qr.matrixQR().topRows(np).triangularView<Eigen::Upper>();
    const Eigen::VectorXd qtr = (qr.householderQ().transpose() * pt.r).head(np);
    const double xnorm = D.cwiseProduct(x).norm();
    Eigen::MatrixXd S(2 * np, np);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * np);
    rhs.head(np) = -qtr;
    bool accepted = false, stop = false;
    for (int trial = 0; trial < kMaxTrials; ++trial) {
      S.topRows(np) = R;
      S.bottomRows(np) = (std::sqrt(lambda) * D).asDiagonal();
      const Eigen::VectorXd step = Eigen::HouseholderQR<Eigen::MatrixXd>(S).solve(rhs);
      const double dnorm = D.cwiseProduct(step).norm();
      const double predicted = qtr.squaredNorm() - (qtr + R * step).squaredNorm();
      if (!(predicted > 8 * kEps * pt.cost) || dnorm <= tol * xnorm) {
        out.converged = true;  // a minimum to rounding, or a step below xtol
        stop = true;
        break;
      }
      const Eigen::VectorXd xt = x + step;
      Point pt_t;
      bool ok = xt.allFinite();
      if (ok) {
        try {
          pt_t = oe.evaluate(xt, evaluations);
        } catch (const NumericalError&) {  // a step onto a pole of the record's grid
          ok = false;
        }
      }
      const double actual = ok ? pt.cost - pt_t.cost : -1.0;
      const double rho = actual / predicted;
      if (ok && rho > 1e-4) {
        const double cost_before = pt.cost;
        x = xt;
        pt = std::move(pt_t);
        accepted = true;
        j_current = false;
        lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
        lambda = std::max(lambda, 1e-16);
        nu = 2.0;
        if ((std::abs(actual) <= tol * cost_before && predicted <= tol * cost_before) || dnorm <= tol * xnorm) {
          out.converged = true;
          stop = true;
        }
        break;
      }
      lambda *= nu;
      nu *= 2.0;
    }
    if (stop || !accepted) break;
    J = oe.jacobian(pt);
    j_current = true;
  }
  if (!j_current) J = oe.jacobian(pt);
  out.x = std::move(x);
  out.pt = std::move(pt);
  out.J = std::move(J);
  return out;
}

void check_options(const RecordOptions& opt, Eigen::Index n_lines) {
  if (opt.max_iterations < 1) throw std::invalid_argument("max_iterations must be >= 1, got " + str(opt.max_iterations));
  if (!(opt.tol > 0 && opt.tol < 1)) throw std::invalid_argument("tol must lie in (0, 1), got " + std::to_string(opt.tol));
  if (opt.noise == RecordNoise::Residual) {
    if (opt.noise_width < 1) throw std::invalid_argument("noise_width must be >= 1, got " + str(opt.noise_width));
    if (opt.reweightings < 0) throw std::invalid_argument("reweightings must be >= 0, got " + str(opt.reweightings));
  } else {
    if (opt.noise_var.size() != n_lines) {
      throw std::invalid_argument("noise_var must hold one variance per line (" + str(n_lines) + "), got " +
                                  str(opt.noise_var.size()));
    }
    for (Eigen::Index i = 0; i < n_lines; ++i) {
      if (!(std::isfinite(opt.noise_var[i]) && opt.noise_var[i] > 0)) {
        throw std::invalid_argument("noise_var must be positive and finite, got " + std::to_string(opt.noise_var[i]) +
                                    " at line index " + str(i));
      }
    }
  }
}

// The equation error's regression on the fitted lines (record_regression).
RecordRegression regression(const Parametrisation& p, const RecordProblem& pb) {
  const auto& lines = pb.data().lines;
  const Eigen::Index n = static_cast<Eigen::Index>(lines.size());
  const int nf = pb.n_free(), nT = pb.n_transient();
  RecordRegression out{Eigen::MatrixXcd(n, nf + nT), Eigen::VectorXcd(n)};
  std::vector<cd> jrow(static_cast<size_t>(p.n_theta())), xrow(static_cast<size_t>(p.n_xi()));
  for (Eigen::Index i = 0; i < n; ++i) {
    const int l = pb.index(lines[static_cast<size_t>(i)]);
    pb.xi_row(pb.Y(), l, jrow.data(), xrow.data());
    for (int c = 0; c < nf; ++c) out.M(i, c) = xrow[static_cast<size_t>(pb.free()[static_cast<size_t>(c)])];
    for (int j = 0; j < nT; ++j) out.M(i, nf + j) = pb.t(l)[j];
    out.e0[i] = xrow[static_cast<size_t>(pb.norm())];
  }
  return out;
}

// The residual's noise level (METHOD.md section 17): each line's |Y - Y_hat|^2 over its share
// 1 - h_l of the noise the fit leaves (h_l the mean leverage of its Re and Im rows in the
// weighted Jacobian J at the fit; 1 - h_l at least kMinShare), averaged over the fitted lines
// within +-width positions (fewer at the ends).
constexpr double kMinShare = 0.05;
Eigen::VectorXd residual_variance(const RecordProblem& pb, const Point& pt, const Eigen::MatrixXd& J, int width) {
  const auto& lines = pb.data().lines;
  const Eigen::Index n = static_cast<Eigen::Index>(lines.size());
  const Eigen::VectorXd h = TallSvd(J).leverage();
  Eigen::VectorXd e2(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int l = pb.index(lines[static_cast<size_t>(i)]);
    const double share = std::max(1.0 - 0.5 * (h[i] + h[n + i]), kMinShare);
    e2[i] = std::norm(pb.Y()[l] - pt.Yh[l]) / share;
  }
  Eigen::VectorXd var(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index lo = std::max<Eigen::Index>(0, i - width), hi = std::min<Eigen::Index>(n - 1, i + width);
    double s = 0.0;
    for (Eigen::Index j = lo; j <= hi; ++j) s += e2[j];
    var[i] = std::max(s / static_cast<double>(hi - lo + 1), 1e-300);
  }
  return var;
}

}  // namespace

RecordRegression record_regression(const Parametrisation& p, const RecordData& d, bool transient,
                                   int transient_degree) {
  const RecordProblem pb(p, d, transient, transient_degree);
  pb.check_lines();
  return regression(p, pb);
}

Eigen::VectorXcd record_prediction(const Parametrisation& p, const RecordData& d, const Eigen::VectorXd& eta_free,
                                   const Eigen::VectorXd& c, int transient_degree) {
  const RecordProblem pb(p, d, c.size() > 0, transient_degree);
  if (eta_free.size() != pb.n_free()) {
    throw std::invalid_argument("eta_free must hold the " + str(pb.n_free()) + " free parameters, got " +
                                str(eta_free.size()));
  }
  if (c.size() != 0 && c.size() != pb.n_transient()) {
    throw std::invalid_argument("c must hold " + str(pb.n_transient()) + " coefficients (or none), got " + str(c.size()));
  }
  Eigen::VectorXd x(pb.n_par());
  x << eta_free, c;
  const Eigen::VectorXcd theta = pb.theta_of(x);
  return pb.fds(theta)->solve_A(pb.forcing(theta, x));
}

RecordFit fit_record(const Parametrisation& p, const RecordData& d, const RecordOptions& opt) {
  const RecordProblem pb(p, d, opt.transient, opt.transient_degree);
  pb.check_lines();
  const Eigen::Index n = static_cast<Eigen::Index>(d.lines.size());
  check_options(opt, n);
  const int nf = pb.n_free(), np = pb.n_par();
  RecordFit fit;
  Eigen::VectorXd var = opt.noise == RecordNoise::Given ? opt.noise_var : Eigen::VectorXd::Ones(n);

  // The start: E_l(eta) + T(z_l) = 0 is linear in x = [free eta, c]; weighted by 1 / sigma_l.
  {
    const RecordRegression reg = regression(p, pb);
    Eigen::MatrixXd Mr(2 * n, np);
    Eigen::VectorXd br(2 * n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double sc = 1.0 / std::sqrt(var[i]);
      Mr.row(i) = sc * reg.M.row(i).real();
      Mr.row(n + i) = sc * reg.M.row(i).imag();
      br[i] = -sc * reg.e0[i].real();
      br[n + i] = -sc * reg.e0[i].imag();
    }
    if (!Mr.allFinite() || !br.allFinite()) throw NumericalError("the equation error overflows");
    fit.start = TallSvd(Mr).solve(br);
  }

  int evaluations = 0;
  Eigen::VectorXd x = fit.start;
  auto run = [&](const OutputError& oe) {
    Point pt;
    try {
      pt = oe.evaluate(x, evaluations);
    } catch (const NumericalError& e) {
      throw NumericalError(std::string("the output-error fit met a singular model: ") + e.what());
    }
    ++fit.fits;
    return levenberg_marquardt(oe, x, std::move(pt), opt.max_iterations, opt.tol, evaluations);
  };
  LmOutcome lm = run(OutputError(pb, var));
  if (opt.noise == RecordNoise::Residual) {
    for (int k = 0; k < opt.reweightings; ++k) {
      var = residual_variance(pb, lm.pt, lm.J, opt.noise_width);
      x = lm.x;
      lm = run(OutputError(pb, var));
    }
    fit.noise_dof = 2 * opt.noise_width + 1;
  }
  x = lm.x;

  const Eigen::MatrixXd cov = TallSvd(lm.J).gram_inverse();
  const Eigen::VectorXd xi = pb.xi_of(x);
  fit.eta = xi;
  fit.theta = p.Text() * xi;
  fit.covariance = Eigen::MatrixXd::Zero(p.n_xi(), p.n_xi());
  for (int a = 0; a < nf; ++a)
    for (int b = 0; b < nf; ++b) fit.covariance(pb.free()[a], pb.free()[b]) = cov(a, b);
  fit.transient = x.tail(pb.n_transient());
  fit.transient_std.resize(pb.n_transient());
  for (int j = 0; j < pb.n_transient(); ++j) fit.transient_std[j] = std::sqrt(std::max(cov(nf + j, nf + j), 0.0));
  fit.noise_var = var;
  fit.Y_fit.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) fit.Y_fit[i] = lm.pt.Yh[pb.index(d.lines[static_cast<size_t>(i)])];
  fit.cost = lm.pt.cost;
  fit.dof = static_cast<int>(2 * n - np);
  fit.converged = lm.converged;
  fit.iterations = lm.iterations;
  fit.evaluations = evaluations;
  return fit;
}

}  // namespace lptv
