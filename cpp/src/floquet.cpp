#include "lptv/floquet.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "lptv/errors.hpp"
#include "lptv/multisine.hpp"
#include "floquet_detail.hpp"
#include "monodromy.hpp"
#include "rows.hpp"

extern "C" {
// LAPACK; the trailing size_t arguments are the hidden lengths of the character arguments.
void zgeevx_(const char* balanc, const char* jobvl, const char* jobvr, const char* sense, const int* n,
             std::complex<double>* a, const int* lda, std::complex<double>* w, std::complex<double>* vl,
             const int* ldvl, std::complex<double>* vr, const int* ldvr, int* ilo, int* ihi, double* scale,
             double* abnrm, double* rconde, double* rcondv, std::complex<double>* work, const int* lwork,
             double* rwork, int* info, std::size_t, std::size_t, std::size_t, std::size_t);
}

namespace lptv {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Im part reduced to (-w0/2, w0/2].
double wrap(double im, double w0) {
  double r = im - w0 * std::round(im / w0);
  if (r <= -0.5 * w0) r += w0;
  if (r > 0.5 * w0) r -= w0;
  return r;
}

// |a - b| with the imaginary difference taken modulo w0: the distance of two exponents as
// multipliers see them.
double exp_distance(cd a, cd b, double w0) {
  return std::hypot(a.real() - b.real(), wrap(a.imag() - b.imag(), w0));
}

// ------------------------------------------------------------------ Hill's method
// Harmonics -KF..KF of the last row of F(t), -a_n(t) / a_na(t) (n = 0..na-1): na x (2KF+1).
// Exact when a_na is constant; otherwise sampled and transformed, with the grid doubled until
// every harmonic above eps of the largest lies below a quarter of it (the ratio is analytic,
// its harmonics decay geometrically, so the aliased tail is then below eps^2).
Eigen::MatrixXcd companion_harmonics(const Model& m) {
  const int na = m.na(), Ka = m.ka();
  const Eigen::MatrixXcd& a = m.a();
  bool constant_lead = true;
  for (int k = 1; k <= Ka; ++k) constant_lead = constant_lead && a(na, Ka + k) == cd(0.0, 0.0);
  if (constant_lead) {
    return -a.topRows(na) / a(na, Ka).real();
  }
  const double T0 = 2.0 * M_PI / m.w0();
  for (int Nf = 64; Nf <= (1 << 16); Nf *= 2) {
    const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(Nf, 0.0, T0 * (Nf - 1) / Nf);
    const Eigen::MatrixXd v = m.a_at(t);
    std::vector<Eigen::VectorXcd> X(na);
    double scale = 0.0;
    for (int n = 0; n < na; ++n) {
      X[n] = spectrum(Eigen::VectorXd(-v.col(n).array() / v.col(na).array()));
      scale = std::max(scale, X[n].cwiseAbs().maxCoeff());
    }
    int KF = 0;
    for (int n = 0; n < na; ++n) {
      for (int k = static_cast<int>(X[n].size()) - 1; k > KF; --k) {
        if (std::abs(X[n][k]) > kEps * scale) {
          KF = k;
          break;
        }
      }
    }
    if (KF > Nf / 4) continue;
    Eigen::MatrixXcd C(na, 2 * KF + 1);
    for (int n = 0; n < na; ++n) {
      C(n, KF) = X[n][0].real();
      for (int k = 1; k <= KF; ++k) {
        C(n, KF + k) = X[n][k];
        C(n, KF - k) = std::conj(X[n][k]);
      }
    }
    return C;
  }
  throw NumericalError("F(t) = -a_n(t)/a_na(t) needs more than 16384 harmonics: a_na(t) comes "
                       "too close to zero over the period for Hill's method");
}

struct HillEigen {
  Eigen::VectorXcd lambda;
  Eigen::VectorXd centroid;  // mean harmonic index of the eigenvector, weighted by |v_p|^2
  Eigen::VectorXd rounding;  // eps ||H|| / rcond (LAPACK's error bound), times T0
  Eigen::MatrixXcd left, right;  // the eigenvectors (columns; left: u^H H = lambda u^H)
};

HillEigen hill_eigen(const std::vector<Eigen::MatrixXcd>& F, int na, double w0, int M) {
  const int KF = static_cast<int>(F.size() - 1) / 2, n = na * (2 * M + 1);
  Eigen::MatrixXcd H = Eigen::MatrixXcd::Zero(n, n);
  for (int p = -M; p <= M; ++p) {
    const int row = (p + M) * na;
    for (int q = std::max(-M, p - KF); q <= std::min(M, p + KF); ++q) {
      H.block(row, (q + M) * na, na, na) = F[KF + p - q];
    }
    for (int r = 0; r < na; ++r) H(row + r, row + r) -= cd(0.0, p * w0);
  }
  HillEigen out;
  out.lambda.resize(n);
  Eigen::MatrixXcd VL(n, n), VR(n, n);
  Eigen::VectorXd scale(n), rconde(n), rcondv(n), rwork(2 * n);
  int ilo = 0, ihi = 0, info = 0, lwork = -1;
  double abnrm = 0.0;
  cd query;
  // Balancing (permutation and scaling) reduces the norm the rounding error is relative to.
  zgeevx_("B", "V", "V", "E", &n, H.data(), &n, out.lambda.data(), VL.data(), &n, VR.data(), &n, &ilo, &ihi,
          scale.data(), &abnrm, rconde.data(), rcondv.data(), &query, &lwork, rwork.data(), &info, 1, 1, 1, 1);
  lwork = std::max(1, static_cast<int>(query.real()));
  std::vector<cd> work(lwork);
  zgeevx_("B", "V", "V", "E", &n, H.data(), &n, out.lambda.data(), VL.data(), &n, VR.data(), &n, &ilo, &ihi,
          scale.data(), &abnrm, rconde.data(), rcondv.data(), work.data(), &lwork, rwork.data(), &info, 1, 1, 1,
          1);
  if (info != 0 || !out.lambda.allFinite()) {
    std::ostringstream msg;
    msg << "the eigenvalues of Hill's matrix (truncation M = " << M << ", zgeevx info " << info
        << ") could not be computed";
    throw NumericalError(msg.str());
  }
  const double T0 = 2.0 * M_PI / w0;
  out.centroid.resize(n);
  out.rounding.resize(n);
  for (int j = 0; j < n; ++j) {
    double mass = 0.0, moment = 0.0;
    for (int p = -M; p <= M; ++p) {
      const double wp = VR.col(j).segment((p + M) * na, na).squaredNorm();
      mass += wp;
      moment += p * wp;
    }
    out.centroid[j] = moment / mass;
    out.rounding[j] = rconde[j] > 0 ? kEps * abnrm / rconde[j] * T0 : kInf;
  }
  out.left = std::move(VL);
  out.right = std::move(VR);
  return out;
}

// One exponent per family lambda + j n w0. A family's eigenvectors are copies of one another
// shifted by n harmonics (centroid c - n for lambda + j n w0); the truncation at +-M disturbs
// least the copy centred nearest harmonic 0, so candidates are taken by increasing |c| and a
// candidate is dropped when it is a shifted copy of one already kept (its centroid differs by
// a nonzero whole n and its eigenvalue by -j n w0). Two eigenpairs at the same centroid are
// distinct families (a repeated exponent, e.g. an LTI double pole).
std::vector<int> select_family_representatives(const HillEigen& h, int na, double w0) {
  const int n = static_cast<int>(h.lambda.size());
  const double T0 = 2.0 * M_PI / w0;
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int i, int j) { return std::abs(h.centroid[i]) < std::abs(h.centroid[j]); });
  std::vector<int> kept;
  for (int j : order) {
    if (static_cast<int>(kept.size()) == na) break;
    bool copy = false;
    for (int i : kept) {
      const double shift = std::round(h.centroid[j] - h.centroid[i]);
      if (shift == 0.0) continue;
      const cd expected = h.lambda[i] - cd(0.0, shift * w0);
      const double tol = 1e-6 * (w0 + std::abs(h.lambda[i])) + (h.rounding[i] + h.rounding[j]) / T0;
      if (std::abs(h.lambda[j] - expected) <= tol) {
        copy = true;
        break;
      }
    }
    if (!copy) kept.push_back(j);
  }
  return kept;
}

// Greedy pairing of two small sets of exponents by the distance modulo j w0: match[i] is the
// index in `prev` paired with cur[i].
std::vector<int> match_exponents(const std::vector<cd>& cur, const std::vector<cd>& prev, double w0) {
  const int n = static_cast<int>(cur.size());
  std::vector<int> match(n, -1);
  std::vector<bool> used(prev.size(), false);
  for (int round = 0; round < n; ++round) {
    double best = kInf;
    int bi = -1, bj = -1;
    for (int i = 0; i < n; ++i) {
      if (match[i] >= 0) continue;
      for (size_t j = 0; j < prev.size(); ++j) {
        const double d = exp_distance(cur[i], prev[j], w0);
        if (!used[j] && d < best) best = d, bi = i, bj = static_cast<int>(j);
      }
    }
    match[bi] = bj;
    used[bj] = true;
  }
  return match;
}

// Exponents (reduced to the principal strip) with their errors -> the result. Continuous
// time (`snap`): an exponent within its error of Im = 0 or w0/2 is a real multiplier and is put
// there exactly, the others are made exact conjugate pairs (the model is real). `mu`, when
// given, are the multipliers in the order of `lam`; otherwise exp(lambda T0).
Floquet finish(std::vector<cd> lam, std::vector<double> err, std::vector<cd> mu, double w0, bool snap) {
  const int na = static_cast<int>(lam.size());
  const double T0 = 2.0 * M_PI / w0;
  std::vector<bool> real(na, false), paired(na, false);
  auto tol = [&](int i) { return 4.0 * err[i] + 16.0 * kEps * (1.0 + std::abs(lam[i].real()) * T0 + M_PI); };
  for (int i = 0; i < na && snap; ++i) {
    const double im = std::abs(lam[i].imag());
    if (im * T0 <= tol(i)) lam[i] = cd(lam[i].real(), 0.0), real[i] = true;
    else if ((0.5 * w0 - im) * T0 <= tol(i)) lam[i] = cd(lam[i].real(), 0.5 * w0), real[i] = true;
  }
  for (int i = 0; i < na && snap; ++i) {
    if (real[i] || paired[i]) continue;
    int best = -1;
    double best_d = kInf;
    for (int j = 0; j < na; ++j) {
      if (j == i || real[j] || paired[j]) continue;
      const double d = exp_distance(lam[j], std::conj(lam[i]), w0) * T0;
      if (d <= tol(i) + tol(j) && d < best_d) best = j, best_d = d;
    }
    if (best < 0) continue;
    // Both members from their mean (the imaginary parts averaged modulo w0).
    const double re = 0.5 * (lam[i].real() + lam[best].real());
    const double im = lam[i].imag() + 0.5 * wrap(-lam[best].imag() - lam[i].imag(), w0);
    lam[i] = cd(re, wrap(im, w0));
    lam[best] = cd(re, -lam[i].imag());
    err[i] = err[best] = std::max(err[i], err[best]);
    paired[i] = paired[best] = true;
  }
  std::vector<int> order(na);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int i, int j) {
    if (lam[i].real() != lam[j].real()) return lam[i].real() > lam[j].real();
    return lam[i].imag() > lam[j].imag();
  });
  Floquet f;
  f.multipliers.resize(na);
  f.exponents.resize(na);
  f.error_estimate.resize(na);
  for (int r = 0; r < na; ++r) {
    const int i = order[r];
    f.exponents[r] = lam[i];
    f.error_estimate[r] = err[i];
    const double mag = std::exp(lam[i].real() * T0);  // 0 for -inf
    if (!mu.empty()) {
      f.multipliers[r] = mu[i];
    } else if (real[i]) {
      f.multipliers[r] = cd(lam[i].imag() == 0.0 ? mag : -mag, 0.0);
    } else {
      f.multipliers[r] = std::polar(mag, lam[i].imag() * T0);
    }
    f.spectral_radius = std::max(f.spectral_radius, std::abs(f.multipliers[r]));
    // |mu_i| < 1 with room for its error: err bounds the change of ln(mu_i) in continuous
    // time; in discrete time it is a relative error of mu_i, possibly large for a tiny one.
    const double log_mag = lam[i].real() * T0;
    const double margin = snap ? err[i] : std::log1p(err[i]);
    if (!(log_mag == -kInf || log_mag + margin < 0.0)) f.is_stable = false;
  }
  return f;
}

// Companion form of the SISO model: the harmonics of F(t) as na x na blocks (ones on the
// superdiagonal of harmonic 0, the last row from companion_harmonics).
std::vector<Eigen::MatrixXcd> companion_blocks(const Model& m) {
  const int na = m.na();
  const Eigen::MatrixXcd C = companion_harmonics(m);
  const int KF = static_cast<int>(C.cols() - 1) / 2;
  std::vector<Eigen::MatrixXcd> F(2 * KF + 1, Eigen::MatrixXcd::Zero(na, na));
  for (int k = -KF; k <= KF; ++k) F[KF + k].row(na - 1) = C.col(KF + k).transpose();
  for (int r = 0; r + 1 < na; ++r) F[KF](r, r + 1) = 1.0;
  return F;
}

Floquet floquet_ct(const Model& m, const FloquetOptions& opt) {
  detail::check_leading_ct(m);
  if (m.na() == 0) return detail::hill_floquet({}, m.w0(), opt);
  return detail::hill_floquet(companion_blocks(m), m.w0(), opt);
}

// ------------------------------------------------------------------ discrete time
Floquet floquet_dt(const Model& m) {
  const int N = m.samples_per_period();
  if (m.na() == 0) {
    detail::dt_last_rows(m);
    return detail::product_floquet(detail::DtProduct{Eigen::MatrixXd(0, 0), 0.0}, m.w0(), N * m.ts());
  }
  return detail::product_floquet(detail::dt_product(m), m.w0(), N * m.ts());
}

void check_options(const FloquetOptions& opt) {
  if (!(std::isfinite(opt.tol) && opt.tol > 0)) {
    throw std::invalid_argument("tol must be positive and finite, got " + std::to_string(opt.tol));
  }
  if (opt.min_truncation < 1) {
    throw std::invalid_argument("min_truncation must be >= 1, got " + std::to_string(opt.min_truncation));
  }
  if (opt.max_truncation < opt.min_truncation) {
    throw std::invalid_argument("max_truncation must be >= min_truncation (" +
                                std::to_string(opt.min_truncation) + "), got " +
                                std::to_string(opt.max_truncation));
  }
}

}  // namespace

namespace detail {

Floquet hill_floquet(const std::vector<Eigen::MatrixXcd>& F, double w0, const FloquetOptions& opt,
                     HillVectors* vectors) {
  const double T0 = 2.0 * M_PI / w0;
  if (F.empty() || F[0].rows() == 0) {
    Floquet f = finish({}, {}, {}, w0, true);
    f.method = "hill";
    return f;
  }
  const int na = static_cast<int>(F[0].rows());
  const int KF = static_cast<int>(F.size() - 1) / 2;
  int M = std::max(opt.min_truncation, KF);
  if (M > opt.max_truncation) {
    std::ostringstream msg;
    msg << "F(t) has " << KF << " harmonics above eps: Hill's matrix needs a truncation M >= " << KF
        << ", more than max_truncation = " << opt.max_truncation;
    throw NumericalError(msg.str());
  }
  const SingleThreadedBlas single(true);  // dense work of a few hundred columns
  std::vector<cd> prev;
  std::vector<double> prev_rounding;
  for (;;) {
    const HillEigen h = hill_eigen(F, na, w0, M);
    const std::vector<int> kept = select_family_representatives(h, na, w0);
    if (static_cast<int>(kept.size()) != na) {
      throw NumericalError("Hill's matrix at truncation M = " + std::to_string(M) +
                           " has fewer distinct exponent families than states");
    }
    std::vector<cd> cur(na);
    std::vector<double> rounding(na);
    for (int i = 0; i < na; ++i) {
      cur[i] = cd(h.lambda[kept[i]].real(), wrap(h.lambda[kept[i]].imag(), w0));
      rounding[i] = h.rounding[kept[i]];
    }
    if (!prev.empty()) {
      const std::vector<int> match = match_exponents(cur, prev, w0);
      bool settled = true;
      double change = 0.0;
      std::vector<double> err(na);
      for (int i = 0; i < na; ++i) {
        const double d = exp_distance(cur[i], prev[match[i]], w0) * T0;
        const double allowed =
            opt.tol * (1.0 + std::abs(cur[i].real()) * T0) + rounding[i] + prev_rounding[match[i]];
        settled = settled && d <= allowed;
        change = std::max(change, d);
        err[i] = std::max(d, rounding[i]);
      }
      if (settled) {
        if (vectors) {
          vectors->truncation = M;
          vectors->lambda.resize(na);
          vectors->left.resize(h.left.rows(), na);
          vectors->right.resize(h.right.rows(), na);
          for (int i = 0; i < na; ++i) {
            vectors->lambda[i] = cur[i];
            vectors->left.col(i) = h.left.col(kept[i]);
            vectors->right.col(i) = h.right.col(kept[i]);
          }
        }
        Floquet f = finish(cur, err, {}, w0, true);
        f.method = "hill";
        f.truncation = M;
        f.harmonics = KF;
        f.convergence = change;
        return f;
      }
      if (M >= opt.max_truncation) {
        std::ostringstream msg;
        msg << "Floquet exponents by Hill's method did not converge by truncation M = " << M
            << ": ln(mu) still changed by " << change << " (tol " << opt.tol
            << "); raise max_truncation or tol";
        throw NumericalError(msg.str());
      }
    }
    prev = cur;
    prev_rounding = rounding;
    M = std::min(opt.max_truncation, M + std::max(8, M / 2));
  }
}

Floquet product_floquet(const DtProduct& prod, double w0, double T0) {
  const int na = static_cast<int>(prod.Phi.rows());
  if (na == 0) {
    Floquet f = finish({}, {}, {}, w0, false);
    f.method = "product";
    return f;
  }
  Eigen::EigenSolver<Eigen::MatrixXd> es(prod.Phi, true);
  if (es.info() != Eigen::Success) throw NumericalError("eigenvalues of the monodromy matrix failed");
  const Eigen::VectorXcd mu = es.eigenvalues();
  const Eigen::MatrixXcd X = es.eigenvectors();
  const Eigen::FullPivLU<Eigen::MatrixXcd> lu(X);
  const Eigen::MatrixXcd Xinv = lu.isInvertible() ? Eigen::MatrixXcd(lu.inverse()) : Eigen::MatrixXcd();
  std::vector<cd> lam(na);
  std::vector<double> err(na);
  for (int i = 0; i < na; ++i) {
    // First-order error kappa_i ||E||; a defective Phi (no eigenvector basis) moves its
    // eigenvalue by about sqrt(||E|| ||Phi||) instead.
    const double abs_err = Xinv.size() ? X.col(i).norm() * Xinv.row(i).norm() * prod.error
                                       : std::sqrt(prod.error * prod.Phi.norm());
    const double mag = std::abs(mu[i]);
    lam[i] = mag == 0.0 ? cd(-kInf, 0.0) : std::log(mu[i]) / T0;
    if (mag != 0.0) lam[i] = cd(lam[i].real(), wrap(lam[i].imag(), w0));
    err[i] = mag == 0.0 ? kInf : abs_err / mag;
  }
  std::vector<cd> mus(mu.data(), mu.data() + na);
  Floquet f = finish(lam, err, mus, w0, false);
  f.method = "product";
  return f;
}

void check_floquet_options(const FloquetOptions& opt) { check_options(opt); }

std::vector<Eigen::MatrixXcd> siso_companion_blocks(const Model& m) { return companion_blocks(m); }

}  // namespace detail

Floquet floquet(const Model& m, const FloquetOptions& opt) {
  check_options(opt);
  return m.discrete() ? floquet_dt(m) : floquet_ct(m, opt);
}

}  // namespace lptv
