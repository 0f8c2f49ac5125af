#include "lptv/structure.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include "lptv/errors.hpp"

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

Structure Structure::of(const Model& m) {
  Structure s;
  s.na = m.na();
  s.nb = m.nb();
  s.ka.assign(s.na + 1, m.ka());
  s.kb.assign(s.nb + 1, m.kb());
  s.w0 = m.w0();
  s.ts = m.ts();
  return s;
}

long long Structure::n_complex_parameters() const {
  long long n = 0;
  for (int v : ka) n += 2LL * v + 1;
  for (int v : kb) n += 2LL * v + 1;
  return n;
}

long long Structure::n_unknowns() const {
  long long n = 0;
  for (int side = 0; side < 2; ++side) {
    const std::vector<int>& K = side == 0 ? ka : kb;
    for (int c = 0; c < static_cast<int>(K.size()); ++c) {
      bool is_known = false;
      for (const auto& kn : known) is_known = is_known || (kn.is_a == (side == 0) && kn.order == c);
      if (!is_known) n += 2LL * K[c] + 1;
    }
  }
  return known.empty() ? n - 1 : n;
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
    if (kn.coef.size() != 2LL * K + 1) {
      throw std::invalid_argument("known: " + nm + " needs " + std::to_string(2LL * K + 1) +
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
  // The parametrisation is dense (n_theta x n_eta complex): refuse sizes that would exhaust
  // memory before allocating anything (na = 6000 took 1.2 GB before the rows check refused it).
  constexpr long long kMaxParameters = 4000;
  const long long n = s_.n_complex_parameters();
  if (n > kMaxParameters) {
    const double gb = 16.0 * static_cast<double>(n) * static_cast<double>(n) / 1e9;
    throw std::invalid_argument(
        "the orders and harmonic counts give " + std::to_string(n) + " complex parameters (at most " +
        std::to_string(kMaxParameters) + "): their parametrisation alone would take " +
        std::to_string(gb).substr(0, std::to_string(gb).find('.') + 2) +
        " GB; lower na, nb or the harmonic counts");
  }
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
    throw NumericalError(
        has_known_ ? "normalisation failed: the estimate gives the known coefficients zero weight, so "
                     "they cannot set its scale (the data are explained without them: check the known "
                     "values and their orders)"
                   : "normalisation failed: the estimate's a_na has mean a_{na,0} = 0, so it cannot be "
                     "scaled to 1 (the data point to a lower order, or a_na(t) averaging zero: lower na, "
                     "or fix a nonzero coefficient with known)");
  }
  Eigen::VectorXd x = xi / s;
  if (has_known_) return x.head(n_eta());
  return x;
}

Eigen::VectorXd Parametrisation::xi_from_theta(const Eigen::VectorXcd& theta) const {
  if (theta.size() != n_theta()) {
    throw std::invalid_argument("theta must have " + std::to_string(n_theta()) + " entries, got " +
                                std::to_string(theta.size()));
  }
  Eigen::VectorXd xi(n_xi());
  // Each column of T has its first nonzero at c_k (k >= 0): 1 for Re, j for Im.
  for (int c = 0; c < n_eta(); ++c) {
    for (int q = 0; q < n_theta(); ++q) {
      const cd t = T_(q, c);
      if (t == cd(0.0, 0.0) || params_[q].k < 0) continue;
      xi[c] = t.imag() != 0.0 ? theta[q].imag() : theta[q].real();
      break;
    }
  }
  if (has_known_) xi[n_eta()] = 1.0;
  return xi;
}

Eigen::VectorXcd Parametrisation::theta_from_model(const Model& m) const {
  if (m.na() != s_.na || m.nb() != s_.nb) {
    throw std::invalid_argument("model: orders (na, nb) = (" + std::to_string(m.na()) + ", " +
                                std::to_string(m.nb()) + ") differ from the structure's (" +
                                std::to_string(s_.na) + ", " + std::to_string(s_.nb) + ")");
  }
  Eigen::VectorXcd theta(n_theta());
  for (int q = 0; q < n_theta(); ++q) {
    const Param& pr = params_[q];
    theta[q] = pr.is_a ? m.a_coef(pr.order, pr.k) : m.b_coef(pr.order, pr.k);
  }
  // Harmonics of the model beyond the structure's counts would be silently dropped.
  for (int side = 0; side < 2; ++side) {
    const bool is_a = side == 0;
    const Eigen::MatrixXcd& c = is_a ? m.a() : m.b();
    const int K = static_cast<int>(c.cols() - 1) / 2;
    for (int n = 0; n < c.rows(); ++n)
      for (int k = -K; k <= K; ++k)
        if (theta_index(is_a, n, k) < 0 && c(n, K + k) != cd(0.0, 0.0)) {
          throw std::invalid_argument("model: " + coef_name(is_a, n) + " has harmonic " +
                                      std::to_string(k) + " beyond the structure's harmonic count");
        }
  }
  return theta;
}

std::vector<std::string> Parametrisation::eta_names() const {
  std::vector<std::string> names;
  for (int side = 0; side < 2; ++side) {
    const bool is_a = side == 0;
    const std::vector<int>& K = is_a ? s_.ka : s_.kb;
    for (int n = 0; n < static_cast<int>(K.size()); ++n) {
      bool known = false;
      for (const auto& kn : s_.known) known = known || (kn.is_a == is_a && kn.order == n);
      if (known) continue;
      const std::string c = coef_name(is_a, n);
      names.push_back(c + ".re0");
      for (int k = 1; k <= K[n]; ++k) {
        names.push_back(c + ".re" + std::to_string(k));
        names.push_back(c + ".im" + std::to_string(k));
      }
    }
  }
  return names;
}

std::vector<int> Parametrisation::free_indices() const {
  std::vector<int> out;
  for (int j = 0; j < n_xi(); ++j)
    if (j != norm_index_) out.push_back(j);
  return out;
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

std::vector<int> default_rows(const Parametrisation& p, int max_line) {
  const int K = p.structure().kmax();
  std::vector<int> rows;
  for (int l = K + 1; l <= max_line - K; ++l) rows.push_back(l);
  return rows;
}

void check_rows(const Parametrisation& p, const std::vector<int>& rows, int max_line) {
  check_row_lines(p.structure(), rows, max_line);
  const long long eq = 2 * static_cast<long long>(rows.size());
  const long long unknowns = p.n_xi() - 1;
  if (eq <= unknowns) {
    throw std::invalid_argument(
        "the orders and harmonic counts leave " + std::to_string(unknowns) + " free parameters for " +
        std::to_string(eq) + " real equations (" + std::to_string(rows.size()) +
        " lines): use more lines or fewer harmonics / lower orders");
  }
}

void check_row_lines(const Structure& s, const std::vector<int>& rows, int max_line) {
  // 64-bit: a row near INT_MAX plus K must not wrap around and pass the check.
  const long long K = s.kmax();
  if (rows.empty()) throw std::invalid_argument("lines: no rows to fit");
  // Repeats by a flag per line (each row is checked to lie in 1..max_line before its flag is
  // read): a std::set cost as much as a cost evaluation of an LTI fit on 500 lines.
  std::vector<char> seen(static_cast<size_t>(std::max(max_line, 0)) + 1, 0);
  for (const long long l : rows) {
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
    char& flag = seen[static_cast<size_t>(l)];
    if (flag) throw std::invalid_argument("lines: row " + std::to_string(l) + " repeats");
    flag = 1;
  }
}

}  // namespace lptv
