#include "lptv/jacobian.hpp"
#include "lptv/errors.hpp"
#include "rows.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

namespace lptv {

namespace {

std::string coef_name(bool is_a, int order) {
  return std::string(is_a ? "a" : "b") + std::to_string(order);
}

}  // namespace

int Structure::kmax() const {
  int k = 0;
  for (int v : ka) k = std::max(k, v);
  for (int v : kb) k = std::max(k, v);
  return k;
}

void Structure::validate() const {
  if (na < 0) throw std::invalid_argument("na must be >= 0, got " + std::to_string(na));
  if (nb < 0) throw std::invalid_argument("nb must be >= 0, got " + std::to_string(nb));
  if (static_cast<int>(ka.size()) != na + 1) {
    throw std::invalid_argument("ka must give one harmonic count per a_n (na+1 = " +
                                std::to_string(na + 1) + "), got " + std::to_string(ka.size()));
  }
  if (static_cast<int>(kb.size()) != nb + 1) {
    throw std::invalid_argument("kb must give one harmonic count per b_m (nb+1 = " +
                                std::to_string(nb + 1) + "), got " + std::to_string(kb.size()));
  }
  for (int v : ka) if (v < 0) throw std::invalid_argument("ka: harmonic counts must be >= 0");
  for (int v : kb) if (v < 0) throw std::invalid_argument("kb: harmonic counts must be >= 0");
  if (!(std::isfinite(w0) && w0 > 0)) throw std::invalid_argument("w0 must be finite and > 0");
  if (!(std::isfinite(ts) && ts >= 0)) throw std::invalid_argument("ts must be finite and >= 0");
  std::set<std::pair<bool, int>> seen;
  for (const auto& kn : known) {
    const int maxo = kn.is_a ? na : nb;
    const std::string nm = coef_name(kn.is_a, kn.order);
    if (kn.order < 0 || kn.order > maxo) {
      throw std::invalid_argument("known: " + nm + " is not a coefficient of the model (order " +
                                  std::string(kn.is_a ? "na" : "nb") + " = " + std::to_string(maxo) + ")");
    }
    if (!seen.insert({kn.is_a, kn.order}).second) {
      throw std::invalid_argument("known: " + nm + " is given twice");
    }
    const int K = kn.is_a ? ka[kn.order] : kb[kn.order];
    if (kn.coef.size() != 2 * K + 1) {
      throw std::invalid_argument("known: " + nm + " needs " + std::to_string(2 * K + 1) +
                                  " Fourier values (its harmonic count is " + std::to_string(K) +
                                  "), got " + std::to_string(kn.coef.size()));
    }
    if (!kn.coef.allFinite()) throw std::invalid_argument("known: " + nm + " contains NaN or inf");
    for (int k = 0; k <= K; ++k) {
      if (std::abs(kn.coef[K + k] - std::conj(kn.coef[K - k])) >
          1e-12 * std::max(1.0, kn.coef.cwiseAbs().maxCoeff())) {
        throw std::invalid_argument("known: " + nm + " is not conjugate-symmetric");
      }
    }
  }
  if (static_cast<int>(known.size()) == na + nb + 2) {
    throw std::invalid_argument("known: every coefficient is known; nothing to estimate");
  }
}

Parametrisation::Parametrisation(const Structure& s) : s_(s) {
  s_.validate();
  auto is_known = [&](bool is_a, int order) -> const Structure::Known* {
    for (const auto& kn : s_.known) if (kn.is_a == is_a && kn.order == order) return &kn;
    return nullptr;
  };
  // theta: every coefficient's harmonics, known or not.
  for (int side = 0; side < 2; ++side) {
    const bool is_a = side == 0;
    const std::vector<int>& K = is_a ? s_.ka : s_.kb;
    std::vector<int>& off = is_a ? offset_a_ : offset_b_;
    for (int n = 0; n < static_cast<int>(K.size()); ++n) {
      off.push_back(static_cast<int>(params_.size()));
      for (int k = -K[n]; k <= K[n]; ++k) params_.push_back({is_a, n, k});
    }
  }
  const int nth = n_theta();
  int neta = 0;
  for (int side = 0; side < 2; ++side) {
    const bool is_a = side == 0;
    const std::vector<int>& K = is_a ? s_.ka : s_.kb;
    for (int n = 0; n < static_cast<int>(K.size()); ++n) {
      if (!is_known(is_a, n)) neta += 2 * K[n] + 1;
    }
  }
  T_ = Eigen::MatrixXcd::Zero(nth, neta);
  d_ = Eigen::VectorXcd::Zero(nth);
  int col = 0;
  for (int side = 0; side < 2; ++side) {
    const bool is_a = side == 0;
    const std::vector<int>& K = is_a ? s_.ka : s_.kb;
    for (int n = 0; n < static_cast<int>(K.size()); ++n) {
      const int base = theta_index(is_a, n, 0);
      if (const auto* kn = is_known(is_a, n)) {
        for (int k = -K[n]; k <= K[n]; ++k) d_[base + k] = kn->coef[K[n] + k];
        has_known_ = true;
        continue;
      }
      if (is_a && n == s_.na) norm_index_ = col;  // Re a_{na,0}
      T_(base, col++) = 1.0;
      for (int k = 1; k <= K[n]; ++k) {
        // c_k = x + j y, c_-k = x - j y
        T_(base + k, col) = 1.0;
        T_(base - k, col) = 1.0;
        ++col;
        T_(base + k, col) = cd(0.0, 1.0);
        T_(base - k, col) = cd(0.0, -1.0);
        ++col;
      }
    }
  }
  if (has_known_) {
    Text_.resize(nth, neta + 1);
    Text_ << T_, d_;
    norm_index_ = neta;
  } else {
    Text_ = T_;
    if (norm_index_ < 0) throw std::logic_error("no normalisation parameter");
  }
}

int Parametrisation::theta_index(bool is_a, int order, int k) const {
  const std::vector<int>& K = is_a ? s_.ka : s_.kb;
  if (order < 0 || order >= static_cast<int>(K.size()) || std::abs(k) > K[order]) return -1;
  return (is_a ? offset_a_ : offset_b_)[order] + K[order] + k;
}

Eigen::VectorXcd Parametrisation::theta_from_xi(const Eigen::VectorXd& xi) const {
  return T_ * eta_from_xi(xi) + d_;
}

Eigen::VectorXd Parametrisation::eta_from_xi(const Eigen::VectorXd& xi) const {
  if (xi.size() != n_xi()) throw std::invalid_argument("xi has the wrong size");
  const double s = xi[norm_index_];
  if (!(std::abs(s) > 1e-300) || !std::isfinite(s)) {
    throw NumericalError("normalisation failed: the estimate has a zero " +
                                    std::string(has_known_ ? "weight on the known coefficients"
                                                           : "a_{na,0}"));
  }
  Eigen::VectorXd x = xi / s;
  if (has_known_) return x.head(n_eta());
  return x;
}

Model Parametrisation::to_model(const Eigen::VectorXcd& theta) const {
  int Ka = 0, Kb = 0;
  for (int v : s_.ka) Ka = std::max(Ka, v);
  for (int v : s_.kb) Kb = std::max(Kb, v);
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(s_.na + 1, 2 * Ka + 1);
  Eigen::MatrixXcd b = Eigen::MatrixXcd::Zero(s_.nb + 1, 2 * Kb + 1);
  for (int p = 0; p < n_theta(); ++p) {
    const Param& q = params_[p];
    if (q.is_a) a(q.order, Ka + q.k) = theta[p];
    else b(q.order, Kb + q.k) = theta[p];
  }
  return Model(a, b, s_.w0, s_.ts);
}

cd line_power(const Structure& s, int line, int n) {
  const double w = s.w0 * line;
  const cd z = s.ts > 0 ? std::polar(1.0, w * s.ts) : cd(0.0, w);
  cd p(1.0, 0.0);
  for (int i = 0; i < n; ++i) p *= z;
  return p;
}

std::vector<int> default_rows(const Parametrisation& p, int max_line) {
  const int K = p.structure().kmax();
  std::vector<int> rows;
  for (int l = K + 1; l <= max_line - K; ++l) rows.push_back(l);
  return rows;
}

void check_rows(const Parametrisation& p, const std::vector<int>& rows, int max_line) {
  const int K = p.structure().kmax();
  if (rows.empty()) throw std::invalid_argument("lines: no rows to fit");
  std::set<int> seen;
  for (int l : rows) {
    if (l < 1) {
      throw std::invalid_argument("lines: row " + std::to_string(l) +
                                  " is not a positive line (rows are lines >= 1)");
    }
    if (l + K > max_line) {
      throw std::invalid_argument("lines: row " + std::to_string(l) + " needs lines up to " +
                                  std::to_string(l + K) + " (K = " + std::to_string(K) +
                                  " harmonics) but the data has lines 0.." + std::to_string(max_line));
    }
    if (l - K < -max_line) {
      throw std::invalid_argument("lines: row " + std::to_string(l) + " needs line " +
                                  std::to_string(l - K) + " beyond the data");
    }
    if (!seen.insert(l).second) throw std::invalid_argument("lines: row " + std::to_string(l) + " repeats");
  }
  const int eq = 2 * static_cast<int>(rows.size());
  const int unknowns = p.n_xi() - 1;
  if (eq <= unknowns) {
    throw std::invalid_argument(
        "the orders and harmonic counts leave " + std::to_string(unknowns) + " free parameters for " +
        std::to_string(eq) + " real equations (" + std::to_string(rows.size()) +
        " lines): use more lines or fewer harmonics / lower orders");
  }
}

Eigen::MatrixXcd jacobian(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows) {
  const detail::Lines X{d};
  const Structure& s = p.structure();
  Eigen::MatrixXcd J(rows.size(), p.n_theta());
  for (size_t r = 0; r < rows.size(); ++r) {
    for (int q = 0; q < p.n_theta(); ++q) {
      const Param& pr = p.params()[q];
      const int i = rows[r] - pr.k;
      const cd f = line_power(s, i, pr.order);
      J(r, q) = pr.is_a ? f * X.Y(i) : -f * X.U(i);
    }
  }
  return J;
}

namespace {

// A_{l,i} and B_{l,i} for i = l - k, k = -K..K (index K + k), from the row's powers.
void band_row(const Parametrisation& p, const Eigen::VectorXcd& theta, const detail::RowPowers& pw,
              std::vector<cd>& A, std::vector<cd>& B) {
  const int K = pw.K();
  A.assign(2 * K + 1, cd(0.0, 0.0));
  B.assign(2 * K + 1, cd(0.0, 0.0));
  for (int q = 0; q < p.n_theta(); ++q) {
    const Param& pr = p.params()[q];
    (pr.is_a ? A : B)[K + pr.k] += theta[q] * pw(pr.k, pr.order);
  }
}

// Calls f(r, pw, A, B) for every row r with the row's powers and band entries, on up to
// two threads (f writes only to row r's outputs).
template <class F>
void for_each_row(const Parametrisation& p, const std::vector<int>& rows, const Eigen::VectorXcd& theta,
                  F&& f) {
  detail::parallel_rows(rows.size(), [&](size_t begin, size_t end, int) {
    detail::RowPowers pw(p.structure());
    std::vector<cd> A, B;
    for (size_t r = begin; r < end; ++r) {
      pw.compute(rows[r]);
      band_row(p, theta, pw, A, B);
      f(r, pw, A, B);
    }
  });
}

}  // namespace

Eigen::VectorXcd residue(const FrequencyData& d, const Parametrisation& p, const std::vector<int>& rows,
                         const Eigen::VectorXcd& theta) {
  const detail::Lines X{d};
  Eigen::VectorXcd e(rows.size());
  const int K = p.structure().kmax();
  for_each_row(p, rows, theta, [&](size_t r, const detail::RowPowers&, const std::vector<cd>& A,
                                   const std::vector<cd>& B) {
    cd v(0.0, 0.0);
    for (int k = -K; k <= K; ++k) {
      const int i = rows[r] - k;
      v += A[K + k] * X.Y(i) - B[K + k] * X.U(i);
    }
    e[r] = v;
  });
  return e;
}

Eigen::VectorXd residue_variance(const FrequencyData& d, const Parametrisation& p,
                                 const std::vector<int>& rows, const Eigen::VectorXcd& theta) {
  const detail::Lines X{d};
  Eigen::VectorXd v(rows.size());
  const int K = p.structure().kmax();
  for_each_row(p, rows, theta, [&](size_t r, const detail::RowPowers&, const std::vector<cd>& A,
                                   const std::vector<cd>& B) {
    double s = 0;
    for (int k = -K; k <= K; ++k) {
      const int i = rows[r] - k;
      const cd a = A[K + k], b = B[K + k];
      s += std::norm(a) * X.varY(i) + std::norm(b) * X.varU(i) -
           2.0 * (a * std::conj(b) * X.covYU(i)).real();
    }
    v[r] = s;
  });
  return v;
}

Eigen::MatrixXcd residue_variance_gradient(const FrequencyData& d, const Parametrisation& p,
                                           const std::vector<int>& rows, const Eigen::VectorXcd& theta) {
  const detail::Lines X{d};
  Eigen::MatrixXcd G(rows.size(), p.n_theta());
  const int K = p.structure().kmax();
  for_each_row(p, rows, theta, [&](size_t r, const detail::RowPowers& pw, const std::vector<cd>& A,
                                   const std::vector<cd>& B) {
    for (int q = 0; q < p.n_theta(); ++q) {
      const Param& pr = p.params()[q];
      const int i = rows[r] - pr.k;
      // dJ = f dX with f = +s^n (a) or -s^n (b); sum_q f_q theta_q over the harmonic's
      // group is A_li on the Y side and -B_li on the U side.
      const cd SY = A[K + pr.k], SU = -B[K + pr.k];
      const cd f = (pr.is_a ? 1.0 : -1.0) * pw(pr.k, pr.order);
      const cd e = pr.is_a ? X.varY(i) * SY + std::conj(X.covYU(i)) * SU
                           : X.covYU(i) * SY + X.varU(i) * SU;
      G(static_cast<Eigen::Index>(r), q) = std::conj(f) * e;
    }
  });
  return G;
}

Eigen::MatrixXcd column_covariance(const FrequencyData& d, const Parametrisation& p,
                                   const std::vector<int>& rows, const Eigen::VectorXd& weights) {
  if (weights.size() != static_cast<Eigen::Index>(rows.size())) {
    throw std::invalid_argument("weights must have one entry per row");
  }
  const detail::Lines X{d};
  const int K = p.structure().kmax();
  // Parameters grouped by harmonic: only those share a noisy line within a row.
  std::vector<std::vector<int>> by_k(2 * K + 1);
  for (int q = 0; q < p.n_theta(); ++q) by_k[K + p.params()[q].k].push_back(q);
  Eigen::MatrixXcd parts[2];
  parts[0] = parts[1] = Eigen::MatrixXcd::Zero(p.n_theta(), p.n_theta());
  detail::parallel_rows(rows.size(), [&](size_t begin, size_t end, int part) {
    Eigen::MatrixXcd& C = parts[part];
    detail::RowPowers pw(p.structure());
    std::vector<cd> f;
    for (size_t r = begin; r < end; ++r) {
      const double w = weights[r];
      if (w == 0.0) continue;
      pw.compute(rows[r]);
      for (int k = -K; k <= K; ++k) {
        const auto& group = by_k[K + k];
        const int i = rows[r] - k;
        const double vy = X.varY(i), vu = X.varU(i);
        const cd cyu = X.covYU(i);
        f.resize(group.size());
        for (size_t a = 0; a < group.size(); ++a) {
          const Param& pr = p.params()[group[a]];
          f[a] = (pr.is_a ? 1.0 : -1.0) * pw(k, pr.order);  // dJ = f dX
        }
        for (size_t a = 0; a < group.size(); ++a) {
          const bool ya = p.params()[group[a]].is_a;
          const cd wfa = w * std::conj(f[a]);
          for (size_t b = 0; b < group.size(); ++b) {
            const bool yb = p.params()[group[b]].is_a;
            // E{conj(dX_a) dX_b}
            const cd e = ya ? (yb ? cd(vy, 0.0) : std::conj(cyu)) : (yb ? cyu : cd(vu, 0.0));
            C(group[a], group[b]) += wfa * f[b] * e;
          }
        }
      }
    }
  });
  return parts[0] + parts[1];
}

}  // namespace lptv
