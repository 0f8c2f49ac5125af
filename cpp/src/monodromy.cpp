// The monodromy matrix by products: of matrix exponentials (continuous time) and of the
// one-step companion matrices (discrete time); the checks of a_na that floquet.cpp shares.
#include "monodromy.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

#include "lptv/errors.hpp"
#include "lptv/floquet.hpp"

namespace lptv {
namespace detail {

void check_leading_ct(const Model& m) {
  const int na = m.na();
  const double T0 = 2.0 * M_PI / m.w0();
  // a_na(t) is a trigonometric polynomial of degree Ka: 256 points per harmonic resolve it.
  const int n = 256 * (m.ka() + 1) + 1;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(n, 0.0, T0);
  const Eigen::VectorXd v = evaluate_fourier(m.a().row(na), m.w0(), t).col(0);
  const double vmax = v.cwiseAbs().maxCoeff();
  for (int i = 0; i < n; ++i) {
    const bool flips = i > 0 && std::signbit(v[i]) != std::signbit(v[i - 1]);
    if (std::abs(v[i]) <= 1e-12 * vmax || flips) {
      // Where it crosses zero (linear interpolation over the grid step), else the sample.
      const double tz = flips ? t[i - 1] + (t[i] - t[i - 1]) * v[i - 1] / (v[i - 1] - v[i]) : t[i];
      std::ostringstream msg;
      msg << "a: the leading coefficient a_" << na << "(t) vanishes near t = " << tz << " s (period "
          << T0 << " s); the companion form x' = F(t) x needs a_na(t) != 0 over the whole period";
      throw std::invalid_argument(msg.str());
    }
  }
}

// The one-step companion matrices' last rows -a_n[k] / a_na[k] (N x na) of a discrete-time
// model, after checking that a_na[k] vanishes at no sample.
Eigen::MatrixXd dt_last_rows(const Model& m) {
  const int N = m.samples_per_period(), na = m.na();
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * m.ts());
  const Eigen::MatrixXd a = m.a_at(t);
  const double amax = a.col(na).cwiseAbs().maxCoeff();
  Eigen::MatrixXd rows(N, na);
  for (int k = 0; k < N; ++k) {
    if (std::abs(a(k, na)) <= 1e-14 * amax) {
      std::ostringstream msg;
      msg << "a: the leading coefficient a_" << na << "[k] vanishes at sample k = " << k
          << "; the recursion cannot be solved for y[k + " << na << "] there";
      throw std::invalid_argument(msg.str());
    }
    for (int n = 0; n < na; ++n) rows(k, n) = -a(k, n) / a(k, na);
  }
  return rows;
}

DtProduct dt_product(const Model& m) {
  const int na = m.na();
  const Eigen::MatrixXd rows = dt_last_rows(m);
  const int N = static_cast<int>(rows.rows());
  std::vector<Eigen::MatrixXd> G(N, Eigen::MatrixXd::Zero(na, na));
  for (int k = 0; k < N; ++k) {
    for (int r = 0; r + 1 < na; ++r) G[k](r, r + 1) = 1.0;
    G[k].row(na - 1) = rows.row(k);
  }
  return product_of_steps(G);
}

DtProduct product_of_steps(const std::vector<Eigen::MatrixXd>& G) {
  const int N = static_cast<int>(G.size());
  const Eigen::Index na = N ? G[0].rows() : 0;
  // Forward products P_k = G_{k-1}..G_0 and backward S_k = G_{N-1}..G_k: rounding in step k
  // (na eps |G_k| |P_k| at most) reaches Phi through S_{k+1}.
  std::vector<double> before(N), after(N + 1);
  Eigen::MatrixXd P = Eigen::MatrixXd::Identity(na, na);
  for (int k = 0; k < N; ++k) {
    before[k] = P.norm();
    P = G[k] * P;
  }
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(na, na);
  after[N] = S.norm();
  DtProduct out;
  for (int k = N - 1; k >= 0; --k) {
    out.error += na * std::numeric_limits<double>::epsilon() * after[k + 1] * G[k].norm() * before[k];
    S = S * G[k];
    after[k] = S.norm();
  }
  out.Phi = P;
  if (!out.Phi.allFinite()) throw NumericalError("the product of the one-step matrices overflowed");
  return out;
}

}  // namespace detail

namespace {

// exp(A) of a 1 x 1 or 2 x 2 real A in closed form (a tenth of the cost of the Pade
// approximant with scaling and squaring at this size): with c = tr A / 2 and
// d^2 = c^2 - det A, exp(A) = e^c [ch(d) I + sh(d)/d (A - c I)], ch, sh the hyperbolic
// functions for d^2 >= 0 and the circular ones of sqrt(-d^2) for d^2 < 0; sh(d)/d -> 1 at d = 0.
void small_exp(const Eigen::MatrixXd& A, Eigen::MatrixXd& E) {
  if (A.rows() == 1) {
    E(0, 0) = std::exp(A(0, 0));
    return;
  }
  const double c = 0.5 * (A(0, 0) + A(1, 1));
  const double p = 0.5 * (A(0, 0) - A(1, 1));
  const double d2 = p * p + A(0, 1) * A(1, 0);  // c^2 - det A, without the cancellation
  double ech, eshd;  // e^c ch(d), e^c sh(d)/d
  if (d2 > 1.0) {     // as exp(c + d) and exp(c - d): no overflow of e^c or ch(d) alone
    const double d = std::sqrt(d2), ep = std::exp(c + d), em = std::exp(c - d);
    ech = 0.5 * (ep + em);
    eshd = 0.5 * (ep - em) / d;
  } else if (d2 >= 0) {
    const double d = std::sqrt(d2), e = std::exp(c);
    ech = e * std::cosh(d);
    eshd = e * (d > 0 ? std::sinh(d) / d : 1.0);
  } else {
    const double d = std::sqrt(-d2), e = std::exp(c);
    ech = e * std::cos(d);
    eshd = e * std::sin(d) / d;
  }
  E(0, 0) = ech + eshd * p;
  E(1, 1) = ech - eshd * p;
  E(0, 1) = eshd * A(0, 1);
  E(1, 0) = eshd * A(1, 0);
}

// The product of the matrix exponentials of S fourth-order Magnus steps over one period
// (Blanes, Casas, Oteo, Ros, Phys. Rep. 470 (2009) 151-238): Omega = h/2 (F1 + F2)
// + sqrt(3) h^2 / 12 [F2, F1], F1, F2 at the Gauss points t + (1/2 -+ sqrt(3)/6) h. The
// leading coefficient is checked by the caller. The matrices of the steps are allocated once.
Eigen::MatrixXd magnus_product(const Model& m, int S) {
  const int na = m.na();
  const double T0 = 2.0 * M_PI / m.w0();
  const double h = T0 / S, g = std::sqrt(3.0) / 6.0;
  Eigen::VectorXd t(2 * S);
  for (int k = 0; k < S; ++k) {
    t[2 * k] = (k + 0.5 - g) * h;
    t[2 * k + 1] = (k + 0.5 + g) * h;
  }
  const Eigen::MatrixXd a = m.a_at(t);
  Eigen::MatrixXd F1 = Eigen::MatrixXd::Zero(na, na), F2 = F1, Omega(na, na), E(na, na), next(na, na);
  for (int r = 0; r + 1 < na; ++r) F1(r, r + 1) = F2(r, r + 1) = 1.0;
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(na, na);
  const double c1 = 0.5 * h, c2 = (std::sqrt(3.0) / 12.0) * h * h;
  for (int k = 0; k < S; ++k) {
    for (int n = 0; n < na; ++n) {
      F1(na - 1, n) = -a(2 * k, n) / a(2 * k, na);
      F2(na - 1, n) = -a(2 * k + 1, n) / a(2 * k + 1, na);
    }
    Omega.noalias() = c1 * (F1 + F2);
    Omega.noalias() += c2 * (F2 * F1);
    Omega.noalias() -= c2 * (F1 * F2);
    if (na <= 2) {
      small_exp(Omega, E);
    } else {
      E = Omega.exp();
    }
    next.noalias() = E * Phi;
    Phi.swap(next);
  }
  return Phi;
}

// The symmetric method's global error has only even powers of h, so one Richardson step
// (16 Phi_{h/2} - Phi_h) / 15 from S and 2 S steps makes it sixth order.
Eigen::MatrixXd extrapolated(const Eigen::MatrixXd& coarse, const Eigen::MatrixXd& fine) {
  Eigen::MatrixXd Phi = fine + (fine - coarse) / 15.0;
  if (!Phi.allFinite()) throw NumericalError("the product of matrix exponentials overflowed");
  return Phi;
}

double spectral_radius_of(const Eigen::MatrixXd& Phi) {
  if (Phi.size() == 0) return 0.0;
  return Eigen::EigenSolver<Eigen::MatrixXd>(Phi, false).eigenvalues().cwiseAbs().maxCoeff();
}

}  // namespace

Eigen::MatrixXd monodromy(const Model& m, int steps) {
  if (m.discrete()) return detail::dt_product(m).Phi;
  if (steps < 1 || steps > (1 << 28)) {
    throw std::invalid_argument("steps must be between 1 and 2^28, got " + std::to_string(steps));
  }
  detail::check_leading_ct(m);
  if (m.na() == 0) return Eigen::MatrixXd(0, 0);
  return extrapolated(magnus_product(m, steps), magnus_product(m, 2 * steps));
}

ProductRadius product_spectral_radius(const Model& m, int first_steps, int max_steps) {
  if (first_steps < 1 || max_steps < first_steps || max_steps > (1 << 27)) {
    throw std::invalid_argument("need 1 <= first_steps <= max_steps <= 2^27, got " + std::to_string(first_steps) +
                                ", " + std::to_string(max_steps));
  }
  ProductRadius out;
  if (m.discrete()) {  // the product is exact: one evaluation decides unless it sits on 1
    out.steps = 0;
    try {
      out.rho = spectral_radius_of(detail::dt_product(m).Phi);
      out.settled = std::isfinite(out.rho) && out.rho != 1.0;
    } catch (const NumericalError& e) {
      out.reason = e.what();
    }
    return out;
  }
  detail::check_leading_ct(m);
  if (m.na() == 0) {
    out.settled = true;
    return out;
  }
  // monodromy(m, s) for s = first, 2 first, ... up to max_steps, each run of 2 s steps kept
  // for the next s; stop when two successive spectral radii differ by less than a tenth of
  // their distance to 1 (an overflow, or a radius that is not finite, starts the pair anew).
  double prev = std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd coarse = magnus_product(m, first_steps);
  for (long long s = first_steps; s <= max_steps; s *= 2) {
    const Eigen::MatrixXd fine = magnus_product(m, static_cast<int>(2 * s));
    out.steps = static_cast<int>(s);
    double rho;
    try {
      rho = spectral_radius_of(extrapolated(coarse, fine));
    } catch (const NumericalError& e) {
      out.reason = e.what();
      prev = std::numeric_limits<double>::quiet_NaN();
      coarse = fine;
      continue;
    }
    coarse = fine;
    if (!std::isfinite(rho)) {
      prev = std::numeric_limits<double>::quiet_NaN();
    } else if (std::isfinite(prev) && std::abs(rho - prev) < 0.1 * std::abs(rho - 1.0)) {
      out.rho = rho;
      out.settled = true;
      return out;
    } else {
      prev = rho;
    }
  }
  return out;
}

}  // namespace lptv
