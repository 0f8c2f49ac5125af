// Floquet multipliers of the matrix system sum_n A_n(t) d^n y = 0 (METHOD.md section 19,
// "Stability of the matrix system"): the observer form of a row-reduced A(t, s), a state of
// dimension sum_p d_p (the row degrees), then Hill's method or the product of one-step matrices
// that the SISO model uses (floquet_detail.hpp).
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

#include "floquet_detail.hpp"
#include "lptv/errors.hpp"
#include "lptv/floquet.hpp"
#include "lptv/mimo.hpp"
#include "lptv/multisine.hpp"

namespace lptv {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// The row degrees d_p (highest order with a nonzero coefficient in row p of A) and the state's
// layout: w_{p,1..d_p} at offset[p] .. offset[p] + d_p - 1.
struct Layout {
  int ny = 0, n = 0;
  std::vector<int> d, offset;
};

Layout layout_of(const MimoModel& m) {
  Layout s;
  s.ny = m.n_outputs();
  s.d.assign(s.ny, -1);
  s.offset.assign(s.ny, 0);
  for (int n = 0; n <= m.na(); ++n)
    for (int p = 0; p < s.ny; ++p)
      for (int q = 0; q < s.ny; ++q)
        for (int k = -m.ka(); k <= m.ka(); ++k)
          if (m.a_coef(n, p, q, k) != cd(0.0, 0.0)) s.d[p] = std::max(s.d[p], n);
  for (int p = 0; p < s.ny; ++p) {
    if (s.d[p] < 0) {
      throw std::invalid_argument("a: row " + std::to_string(p) + " of A(t, s) is zero at every order (output " +
                                  std::to_string(p) +
                                  " has no equation); every row must hold a nonzero coefficient");
    }
    s.offset[p] = s.n;
    s.n += s.d[p];
  }
  return s;
}

Eigen::Index arow(int ny, int n, int p, int q) { return (static_cast<Eigen::Index>(n) * ny + p) * ny + q; }

// The leading row coefficient matrix L (row p from A_{d_p}) out of the values of all entries of
// A at one time (or, discrete time, row p read at its own sample: see step_matrix).
Eigen::MatrixXd leading_rows(const Layout& s, const Eigen::MatrixXd& vals, const std::vector<int>& sample) {
  Eigen::MatrixXd L(s.ny, s.ny);
  for (int p = 0; p < s.ny; ++p)
    for (int q = 0; q < s.ny; ++q) L(p, q) = vals(sample[p], arow(s.ny, s.d[p], p, q));
  return L;
}

// F = S - R L^{-1} E1 (continuous time) or G = the same (discrete time): S the shifts
// w_{p,i} <- w_{p,i+1}, R's row for w_{p,i} the right-form coefficient row ta_{d_p - i}, and
// y = L^{-1} (w_{p,1})_p. coef(n, p, q) gives ta_n[p, q] at the step's time.
template <class Coef>
Eigen::MatrixXd state_matrix(const Layout& s, const Eigen::MatrixXd& L, Coef coef) {
  Eigen::MatrixXd E1 = Eigen::MatrixXd::Zero(s.ny, s.n);
  for (int p = 0; p < s.ny; ++p)
    if (s.d[p] > 0) E1(p, s.offset[p]) = 1.0;
  const Eigen::MatrixXd Y = L.partialPivLu().solve(E1);  // y = Y x
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(s.n, s.n);
  Eigen::RowVectorXd c(s.ny);
  for (int p = 0; p < s.ny; ++p) {
    for (int i = 1; i <= s.d[p]; ++i) {
      const int r = s.offset[p] + i - 1;
      if (i < s.d[p]) F(r, r + 1) = 1.0;
      for (int q = 0; q < s.ny; ++q) c[q] = coef(s.d[p] - i, p, q);
      F.row(r) -= c * Y;
    }
  }
  return F;
}

// Continuous time: the right-form coefficients ta_n = sum_{m >= n} (-1)^{m-n} C(m, n) A_m^{(m-n)}
// (row p up to d_p), harmonic k of A_m^{(j)} being (j k w0)^j a_{m,k}; the layout of MimoModel::a().
Eigen::MatrixXcd right_form(const MimoModel& m, const Layout& s) {
  const int K = m.ka(), ny = s.ny;
  Eigen::MatrixXcd r = Eigen::MatrixXcd::Zero(m.a().rows(), m.a().cols());
  for (int p = 0; p < ny; ++p)
    for (int n = 0; n <= s.d[p]; ++n)
      for (int q = 0; q < ny; ++q)
        for (int k = -K; k <= K; ++k) {
          cd sum = 0.0;
          double binom = 1.0;  // C(m, n), m = n first
          for (int mm = n; mm <= s.d[p]; ++mm) {
            const cd dk = std::pow(cd(0.0, k * m.w0()), mm - n);
            sum += ((mm - n) % 2 ? -1.0 : 1.0) * binom * dk * m.a_coef(mm, p, q, k);
            binom = binom * (mm + 1) / (mm + 1 - n);
          }
          r(arow(ny, n, p, q), K + k) = sum;
        }
  return r;
}

// Continuous time: L(t) must be invertible over the whole period (row-reduced A). Checked on
// 256 (Ka + 1) + 1 points: its smallest singular value against the largest over the period,
// and a sign change of det L(t) between two points (a crossing the grid steps over).
void check_row_reduced_ct(const MimoModel& m, const Layout& s) {
  const double T0 = 2.0 * M_PI / m.w0();
  const int npts = 256 * (m.ka() + 1) + 1;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(npts, 0.0, T0);
  const Eigen::MatrixXd vals = evaluate_fourier(m.a(), m.w0(), t);
  std::vector<double> smin(npts), det(npts);
  double smax = 0.0;
  for (int i = 0; i < npts; ++i) {
    const Eigen::MatrixXd L = leading_rows(s, vals, std::vector<int>(s.ny, i));
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(L).singularValues();
    smin[i] = sv[sv.size() - 1];
    smax = std::max(smax, sv[0]);
    det[i] = L.partialPivLu().determinant();
  }
  for (int i = 0; i < npts; ++i) {
    const bool flips = i > 0 && std::signbit(det[i]) != std::signbit(det[i - 1]);
    if (smin[i] <= 1e-12 * smax || flips) {
      const double tz = flips ? t[i - 1] + (t[i] - t[i - 1]) * det[i - 1] / (det[i - 1] - det[i]) : t[i];
      std::ostringstream msg;
      msg << "a: the leading row coefficient matrix of A(t, s) (row p from A_{d_p}, row degrees";
      for (int d : s.d) msg << " " << d;
      msg << ") is singular near t = " << tz << " s (period " << T0
          << " s); the state form needs a row-reduced A(t, s) over the whole period";
      throw std::invalid_argument(msg.str());
    }
  }
}

// The harmonics of F(t): sampled on Nf points and transformed, Nf doubled from 64 until every
// harmonic above eps of the largest lies below Nf / 4 (as companion_harmonics in floquet.cpp).
std::vector<Eigen::MatrixXcd> state_harmonics(const MimoModel& m, const Layout& s) {
  const Eigen::MatrixXcd right = right_form(m, s);
  const double T0 = 2.0 * M_PI / m.w0();
  const int n = s.n, ny = s.ny;
  for (int Nf = 64; Nf <= (1 << 16); Nf *= 2) {
    const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(Nf, 0.0, T0 * (Nf - 1) / Nf);
    const Eigen::MatrixXd vals = evaluate_fourier(right, m.w0(), t);
    std::vector<Eigen::MatrixXd> Fs(Nf);
    for (int i = 0; i < Nf; ++i) {
      const Eigen::MatrixXd L = leading_rows(s, vals, std::vector<int>(ny, i));
      Fs[i] = state_matrix(s, L, [&](int nn, int p, int q) { return vals(i, arow(ny, nn, p, q)); });
    }
    std::vector<Eigen::VectorXcd> X(static_cast<size_t>(n) * n);
    double scale = 0.0;
    Eigen::VectorXd series(Nf);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        for (int i = 0; i < Nf; ++i) series[i] = Fs[i](r, c);
        X[r * n + c] = spectrum(series);
        scale = std::max(scale, X[r * n + c].cwiseAbs().maxCoeff());
      }
    int KF = 0;
    for (const auto& x : X)
      for (int k = static_cast<int>(x.size()) - 1; k > KF; --k)
        if (std::abs(x[k]) > kEps * scale) {
          KF = k;
          break;
        }
    if (KF > Nf / 4) continue;
    std::vector<Eigen::MatrixXcd> F(2 * KF + 1, Eigen::MatrixXcd::Zero(n, n));
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        const Eigen::VectorXcd& x = X[r * n + c];
        F[KF](r, c) = x[0].real();
        for (int k = 1; k <= KF; ++k) {
          F[KF + k](r, c) = x[k];
          F[KF - k](r, c) = std::conj(x[k]);
        }
      }
    return F;
  }
  throw NumericalError("F(t) of the state form needs more than 16384 harmonics: the leading row "
                       "coefficient matrix comes too close to singular over the period for Hill's method");
}

// Discrete time: ta_n[k] = A_n[k - n] (q^n (ta_n y) = A_n[k] y[k + n]), so the step matrix of
// sample k reads row p's order-n coefficients at sample k - n, and L[k] row p at k - d_p.
std::vector<Eigen::MatrixXd> step_matrices(const MimoModel& m, const Layout& s) {
  const int N = m.samples_per_period(), ny = s.ny;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * m.ts());
  const Eigen::MatrixXd vals = m.a_at(t);
  auto at = [N](int k) { return ((k % N) + N) % N; };
  std::vector<Eigen::MatrixXd> G(N);
  double smax = 0.0;
  std::vector<double> smin(N);
  std::vector<Eigen::MatrixXd> Ls(N);
  for (int k = 0; k < N; ++k) {
    std::vector<int> sample(ny);
    for (int p = 0; p < ny; ++p) sample[p] = at(k - s.d[p]);
    Ls[k] = leading_rows(s, vals, sample);
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(Ls[k]).singularValues();
    smin[k] = sv[sv.size() - 1];
    smax = std::max(smax, sv[0]);
  }
  for (int k = 0; k < N; ++k) {
    if (smin[k] <= 1e-14 * smax) {
      std::ostringstream msg;
      msg << "a: the leading row coefficient matrix (row p from A_{d_p}[k - d_p]) is singular at sample k = "
          << k << "; the recursion cannot be solved for the outputs' newest samples there";
      throw std::invalid_argument(msg.str());
    }
    G[k] = state_matrix(s, Ls[k], [&](int nn, int p, int q) { return vals(at(k - nn), arow(ny, nn, p, q)); });
  }
  return G;
}

}  // namespace

std::vector<int> row_degrees(const MimoModel& m) { return layout_of(m).d; }

Floquet floquet(const MimoModel& m, const FloquetOptions& opt) {
  detail::check_floquet_options(opt);
  const Layout s = layout_of(m);
  if (m.discrete()) {
    const int N = m.samples_per_period();
    const std::vector<Eigen::MatrixXd> G = step_matrices(m, s);
    if (s.n == 0) return detail::product_floquet(detail::DtProduct{Eigen::MatrixXd(0, 0), 0.0}, m.w0(), N * m.ts());
    return detail::product_floquet(detail::product_of_steps(G), m.w0(), N * m.ts());
  }
  check_row_reduced_ct(m, s);
  if (s.n == 0) return detail::hill_floquet({}, m.w0(), opt);
  return detail::hill_floquet(state_harmonics(m, s), m.w0(), opt);
}

Eigen::MatrixXd monodromy(const MimoModel& m, int steps) {
  const Layout s = layout_of(m);
  if (m.discrete()) {
    const std::vector<Eigen::MatrixXd> G = step_matrices(m, s);
    return s.n == 0 ? Eigen::MatrixXd(0, 0) : detail::product_of_steps(G).Phi;
  }
  if (steps < 1 || steps > (1 << 24)) {
    throw std::invalid_argument("steps must be between 1 and 2^24, got " + std::to_string(steps));
  }
  check_row_reduced_ct(m, s);
  if (s.n == 0) return Eigen::MatrixXd(0, 0);
  const Eigen::MatrixXcd right = right_form(m, s);
  // The fourth-order Magnus step of monodromy.cpp (F at the two Gauss points of each of S
  // sub-intervals, Omega = h/2 (F1 + F2) + sqrt(3) h^2/12 [F2, F1]), and one Richardson step
  // from S and 2 S: (16 Phi_{h/2} - Phi_h) / 15.
  auto product = [&](int S) {
    const double T0 = 2.0 * M_PI / m.w0(), h = T0 / S, g = std::sqrt(3.0) / 6.0;
    Eigen::VectorXd t(2 * S);
    for (int k = 0; k < S; ++k) {
      t[2 * k] = (k + 0.5 - g) * h;
      t[2 * k + 1] = (k + 0.5 + g) * h;
    }
    const Eigen::MatrixXd vals = evaluate_fourier(right, m.w0(), t);
    auto F = [&](int i) {
      const Eigen::MatrixXd L = leading_rows(s, vals, std::vector<int>(s.ny, i));
      return state_matrix(s, L, [&](int nn, int p, int q) { return vals(i, arow(s.ny, nn, p, q)); });
    };
    Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(s.n, s.n);
    const double c1 = 0.5 * h, c2 = (std::sqrt(3.0) / 12.0) * h * h;
    for (int k = 0; k < S; ++k) {
      const Eigen::MatrixXd F1 = F(2 * k), F2 = F(2 * k + 1);
      const Eigen::MatrixXd Omega = c1 * (F1 + F2) + c2 * (F2 * F1 - F1 * F2);
      Phi = Eigen::MatrixXd(Omega.exp()) * Phi;
    }
    return Phi;
  };
  const Eigen::MatrixXd coarse = product(steps), fine = product(2 * steps);
  Eigen::MatrixXd Phi = fine + (fine - coarse) / 15.0;
  if (!Phi.allFinite()) throw NumericalError("the product of matrix exponentials overflowed");
  return Phi;
}

Eigen::MatrixXd state_matrix_at(const MimoModel& m, double t) {
  const Layout s = layout_of(m);
  if (m.discrete()) {
    const double k = t / m.ts();
    const int N = m.samples_per_period();
    if (!(std::abs(k - std::round(k)) <= 1e-9 * (1 + std::abs(k)))) {
      throw std::invalid_argument("t must be a whole number of samples ts for a discrete-time model");
    }
    return step_matrices(m, s)[((static_cast<long long>(std::round(k)) % N) + N) % N];
  }
  if (!std::isfinite(t)) throw std::invalid_argument("t must be finite");
  const Eigen::MatrixXd vals = evaluate_fourier(right_form(m, s), m.w0(), Eigen::VectorXd::Constant(1, t));
  const Eigen::MatrixXd L = leading_rows(s, vals, std::vector<int>(s.ny, 0));
  return state_matrix(s, L, [&](int nn, int p, int q) { return vals(0, arow(s.ny, nn, p, q)); });
}

}  // namespace lptv
