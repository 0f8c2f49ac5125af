// The exponents' first-order sensitivity to a(t) (METHOD.md section 22).
#include <cmath>
#include <limits>
#include <vector>

#include "lptv/errors.hpp"
#include "lptv/floquet.hpp"
#include "floquet_detail.hpp"
#include "monodromy.hpp"

namespace lptv {
namespace {

using cd = std::complex<double>;
constexpr double kInf = std::numeric_limits<double>::infinity();

double wrap(double im, double w0) {
  double r = im - w0 * std::round(im / w0);
  if (r <= -0.5 * w0) r += w0;
  if (r > 0.5 * w0) r -= w0;
  return r;
}

double exp_distance(cd a, cd b, double w0) {
  if (!std::isfinite(a.real()) || !std::isfinite(b.real())) {
    return (a.real() == b.real()) ? std::abs(wrap(a.imag() - b.imag(), w0)) : kInf;
  }
  return std::hypot(a.real() - b.real(), wrap(a.imag() - b.imag(), w0));
}

// order[r] = the index in `lam` of the exponent reported at position r (greedy by distance).
std::vector<int> match_to(const Eigen::VectorXcd& reported, const std::vector<cd>& lam, double w0) {
  const int n = static_cast<int>(lam.size());
  std::vector<int> order(n, -1);
  std::vector<bool> used(n, false);
  for (int round = 0; round < n; ++round) {
    double best = kInf;
    int br = -1, bi = -1;
    for (int r = 0; r < n; ++r) {
      if (order[r] >= 0) continue;
      for (int i = 0; i < n; ++i) {
        if (used[i]) continue;
        const double d = exp_distance(reported[r], lam[i], w0);
        if (br < 0 || d < best) best = d, br = r, bi = i;
      }
    }
    order[br] = bi;
    used[bi] = true;
  }
  return order;
}

// Continuous time. The bilinear form u^H dH v of Hill's matrix is the period's mean of
// conj(u(t))^T dF(t) v(t) with u(t), v(t) the trigonometric polynomials of the eigenvectors'
// blocks; only the last row of dF is nonzero, d(-a_n / a_na) = -(da_n - a_n da_na / a_na) / a_na.
// On Nt > 2M + KF + Ka points the mean of the band-limited product is exact (1/a_na's
// harmonics beyond KF lie below eps, as in Hill's matrix itself).
FloquetSensitivity sensitivity_ct(const Model& m, const FloquetOptions& opt) {
  detail::check_leading_ct(m);
  FloquetSensitivity out;
  const int na = m.na(), Ka = m.ka();
  if (na == 0) {
    out.floquet = detail::hill_floquet({}, m.w0(), opt);
    return out;
  }
  const std::vector<Eigen::MatrixXcd> F = detail::siso_companion_blocks(m);
  detail::HillVectors hv;
  out.floquet = detail::hill_floquet(F, m.w0(), opt, &hv);
  const int M = hv.truncation, KF = static_cast<int>(F.size() - 1) / 2;
  const double w0 = m.w0(), T0 = 2.0 * M_PI / w0;
  const int Nt = 4 * M + 2 * KF + 2 * Ka + 8;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(Nt, 0.0, T0 * (Nt - 1) / Nt);
  const Eigen::MatrixXd a = m.a_at(t);  // (Nt, na + 1)
  // e^{j p w0 t_j} for p = -M..M, by the recurrence of one step's rotation per row
  Eigen::MatrixXcd E(Nt, 2 * M + 1);
  for (int j = 0; j < Nt; ++j) {
    const cd step = std::polar(1.0, w0 * t[j]);
    cd z = std::polar(1.0, -M * w0 * t[j]);
    for (int p = 0; p <= 2 * M; ++p) {
      E(j, p) = z;
      z *= step;
      if ((p & 15) == 15) z = std::polar(1.0, (p + 1 - M) * w0 * t[j]);  // keep |z| = 1
    }
  }
  std::vector<cd> lam(na);
  for (int i = 0; i < na; ++i) lam[i] = hv.lambda[i];
  const std::vector<int> order = match_to(out.floquet.exponents, lam, w0);
  out.gradient.assign(na, Eigen::MatrixXcd::Zero(na + 1, 2 * Ka + 1));
  out.condition.resize(na);
  for (int r = 0; r < na; ++r) {
    const int i = order[r];
    const Eigen::VectorXcd u = hv.left.col(i), v = hv.right.col(i);
    const cd s = u.dot(v);  // u^H v
    out.condition[r] = std::abs(s) > 0 ? u.norm() * v.norm() / std::abs(s) : kInf;
    if (std::abs(s) == 0) continue;
    Eigen::VectorXcd ulast(2 * M + 1);
    Eigen::MatrixXcd vb(2 * M + 1, na);
    for (int p = 0; p <= 2 * M; ++p) {
      ulast[p] = std::conj(u[p * na + na - 1]);
      for (int n = 0; n < na; ++n) vb(p, n) = v[p * na + n];
    }
    const Eigen::VectorXcd U = E.conjugate() * ulast;  // sum_p conj(u_p) e^{-j p w0 t}
    const Eigen::MatrixXcd V = E * vb;                 // (Nt, na): v_n(t)
    Eigen::MatrixXcd g(Nt, na + 1);                    // the integrands before e^{j h w0 t}
    for (int j = 0; j < Nt; ++j) {
      const double lead = a(j, na);
      cd lin = 0.0;
      for (int n = 0; n < na; ++n) {
        g(j, n) = -U[j] * V(j, n) / lead;
        lin += a(j, n) * V(j, n);
      }
      g(j, na) = U[j] * lin / (lead * lead);
    }
    for (int h = -Ka; h <= Ka; ++h) {
      for (int n = 0; n <= na; ++n) {
        cd acc = 0.0;
        for (int j = 0; j < Nt; ++j) acc += g(j, n) * std::polar(1.0, h * w0 * t[j]);
        out.gradient[r](n, Ka + h) = acc / (static_cast<double>(Nt) * s);
      }
    }
  }
  return out;
}

// Discrete time: d mu = u^H dPhi v / (u^H v) with dPhi = sum_k S_{k+1} dG_k P_k, carried by the
// state x_k = P_k v forward and the adjoint y_k^H = u^H S_k backward.
FloquetSensitivity sensitivity_dt(const Model& m, const FloquetOptions& opt) {
  FloquetSensitivity out;
  out.floquet = floquet(m, opt);
  const int na = m.na(), Ka = m.ka(), N = m.samples_per_period();
  if (na == 0) return out;
  const double w0 = m.w0(), T0 = N * m.ts();
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * m.ts());
  const Eigen::MatrixXd a = m.a_at(t);
  const Eigen::MatrixXd rows = detail::dt_last_rows(m);
  std::vector<Eigen::MatrixXd> G(N, Eigen::MatrixXd::Zero(na, na));
  for (int k = 0; k < N; ++k) {
    for (int q = 0; q + 1 < na; ++q) G[k](q, q + 1) = 1.0;
    G[k].row(na - 1) = rows.row(k);
  }
  const Eigen::MatrixXd Phi = detail::product_of_steps(G).Phi;
  Eigen::EigenSolver<Eigen::MatrixXd> es(Phi, true);
  if (es.info() != Eigen::Success) throw NumericalError("eigenvalues of the monodromy matrix failed");
  const Eigen::VectorXcd mu = es.eigenvalues();
  const Eigen::MatrixXcd X = es.eigenvectors();
  const Eigen::FullPivLU<Eigen::MatrixXcd> lu(X);
  std::vector<cd> lam(na);
  for (int i = 0; i < na; ++i) {
    lam[i] = std::abs(mu[i]) == 0.0 ? cd(-kInf, 0.0) : std::log(mu[i]) / T0;
    if (std::abs(mu[i]) != 0.0) lam[i] = cd(lam[i].real(), wrap(lam[i].imag(), w0));
  }
  const std::vector<int> order = match_to(out.floquet.exponents, lam, w0);
  out.gradient.assign(na, Eigen::MatrixXcd::Zero(na + 1, 2 * Ka + 1));
  out.condition = Eigen::VectorXd::Constant(na, kInf);
  if (!lu.isInvertible()) return out;  // defective: no first-order derivative
  const Eigen::MatrixXcd Xinv = lu.inverse();
  Eigen::MatrixXcd x(N, na), y(N + 1, na);
  for (int r = 0; r < na; ++r) {
    const int i = order[r];
    out.condition[r] = X.col(i).norm() * Xinv.row(i).norm();
    if (std::abs(mu[i]) == 0.0) {
      out.condition[r] = kInf;
      continue;
    }
    Eigen::VectorXcd xk = X.col(i);
    for (int k = 0; k < N; ++k) {
      x.row(k) = xk.transpose();
      xk = G[k].cast<cd>() * xk;
    }
    Eigen::RowVectorXcd yk = Xinv.row(i);  // u^H, normalised so that u^H v = 1
    y.row(N) = yk;
    for (int k = N - 1; k >= 0; --k) {
      yk = yk * G[k].cast<cd>();
      y.row(k) = yk;
    }
    const cd scale = 1.0 / (mu[i] * T0);
    for (int h = -Ka; h <= Ka; ++h) {
      Eigen::VectorXcd acc = Eigen::VectorXcd::Zero(na + 1);
      for (int k = 0; k < N; ++k) {
        const cd e = std::polar(1.0, h * w0 * t[k]) * y(k + 1, na - 1) / a(k, na);
        cd lin = 0.0;
        for (int n = 0; n < na; ++n) {
          acc[n] -= e * x(k, n);
          lin += a(k, n) * x(k, n);
        }
        acc[na] += e * lin / a(k, na);
      }
      out.gradient[r].col(Ka + h) = acc * scale;
    }
  }
  return out;
}

}  // namespace

FloquetSensitivity floquet_sensitivity(const Model& m, const FloquetOptions& opt) {
  detail::check_floquet_options(opt);
  return m.discrete() ? sensitivity_dt(m, opt) : sensitivity_ct(m, opt);
}

}  // namespace lptv
