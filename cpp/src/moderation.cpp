#include "lptv/moderation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "lptv/errors.hpp"

namespace lptv {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Below this the polygammas step up by their recurrence, from it on their asymptotic series
// (Bernoulli numbers B2..B14; the first term left out is below 1e-19 relative at 20).
constexpr double kAsymptotic = 20.0;

double log_beta(double a, double b) { return std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b); }

// The continued fraction of I_x(a, b) (modified Lentz; Numerical Recipes' betacf), converging
// fast for x < (a + 1) / (a + b + 2).
double beta_fraction(double a, double b, double x) {
  constexpr double tiny = 1e-300, eps = 1e-16;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0, d = 1.0 - qab * x / qap;
  if (std::abs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 100000; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < eps) return h;
  }
  throw NumericalError("incomplete beta: the continued fraction did not converge");
}

// I_x(a, b) with y = 1 - x given separately (so that neither loses digits to 1 - x).
double incomplete_beta_xy(double a, double b, double x, double y) {
  if (x <= 0.0) return 0.0;
  if (y <= 0.0) return 1.0;
  const double front = std::exp(a * std::log(x) + b * std::log(y) - log_beta(a, b));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_fraction(a, b, x) / a;
  return 1.0 - front * beta_fraction(b, a, y) / b;
}

// Per position i: the sum of x[j] and the count over |j - i| <= W, j != i, keep[j], from
// running sums (the reference's order of operations, so that both see the same sums).
void window_sums(const Eigen::VectorXd& x, const std::vector<char>& keep, long long W,
                 Eigen::VectorXd& s, Eigen::VectorXi& n) {
  const Eigen::Index m = x.size();
  std::vector<double> cs(m + 1, 0.0);
  std::vector<long long> cn(m + 1, 0);
  for (Eigen::Index j = 0; j < m; ++j) {
    const double xs = keep[j] ? x[j] : 0.0;
    cs[j + 1] = cs[j] + xs;
    cn[j + 1] = cn[j] + (keep[j] ? 1 : 0);
  }
  s.resize(m);
  n.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const long long lo = std::clamp<long long>(i - W, 0, m), hi = std::clamp<long long>(i + W + 1, 0, m);
    const double xs = keep[i] ? x[i] : 0.0;
    s[i] = cs[hi] - cs[lo] - xs;
    n[i] = static_cast<int>(cn[hi] - cn[lo] - (keep[i] ? 1 : 0));
  }
}

// The local log-quadratic trend that corrects the neighbours' mean for the spectrum's shape is
// fitted over +-kShapeWidth * W lines (the reference's SHAPE_WIDTH).
constexpr long long kShapeWidth = 2;

// Per position i: k[i], the factor that turns the arithmetic mean of the neighbours' variances
// (|j - i| <= W, j != i, keep[j]) into the trend's value at i, and v[i], the variance of log
// k[i]. The trend z_j = alpha + beta x + c x^2 (x = j - i) is fitted by least squares to the
// log variances z over |x| <= kShapeWidth W (j != i, ok[j]); k = 1 / mean_j exp(beta x_j +
// c x_j^2 - q_j / 2), q_j the fitted shape's variance at x_j. Near the first and last lines the
// window holds the lines on one side only and the trend is extrapolated to i (its variance
// enters v). Fewer than 2 W points in the window, or a singular fit: k = 1, v = 0. The
// reference's _shape.
// resid (optional): z[i] less the trend's value at i where ok[i] and at least W of the fitted
// lines lie on either side, NaN elsewhere (the reference's _trend_residuals).
void shape_factors(const Eigen::VectorXd& z, const std::vector<char>& ok, const std::vector<char>& keep,
                   long long W, double var_log, Eigen::VectorXd& k, Eigen::VectorXd& v,
                   Eigen::VectorXd* resid = nullptr) {
  const Eigen::Index m = z.size();
  const long long S = kShapeWidth * W;
  k = Eigen::VectorXd::Ones(m);
  v = Eigen::VectorXd::Zero(m);
  if (resid) *resid = Eigen::VectorXd::Constant(m, std::numeric_limits<double>::quiet_NaN());
  std::vector<long long> left(m, 0), right(m, 0);
  for (long long x = 1; x <= S; ++x)
    for (Eigen::Index i = 0; i < m; ++i) {
      if (i - x >= 0 && ok[i - x]) ++left[i];
      if (i + x < m && ok[i + x]) ++right[i];
    }
  // The window's moments C and their inverse depend only on which of its lines are ok: where
  // every line of the window is (the interior of a clean spectrum) they are the same from one
  // line to the next, and the previous line's are reused (the same sums in the same order, so the
  // same bits as computing them again).
  bool have_full = false, full_invertible = false;
  Eigen::Matrix3d full_inverse;
  for (Eigen::Index i = 0; i < m; ++i) {
    if (left[i] + right[i] < 2 * W) continue;
    const bool full = left[i] == S && right[i] == S;
    double T[3] = {0, 0, 0};
    for (long long x = -S; x <= S; ++x) {
      const long long j = i + x;
      if (x == 0 || j < 0 || j >= m || !ok[j]) continue;
      const double xf = static_cast<double>(x);
      T[0] += z[j];
      T[1] += z[j] * xf;
      T[2] += z[j] * (xf * xf);
    }
    Eigen::Matrix3d Ai;
    if (full && have_full) {
      if (!full_invertible) continue;
      Ai = full_inverse;
    } else {
      double C[5] = {0, 0, 0, 0, 0};
      for (long long x = -S; x <= S; ++x) {
        const long long j = i + x;
        if (x == 0 || j < 0 || j >= m || !ok[j]) continue;
        const double xf = static_cast<double>(x);
        double p = 1.0;
        for (int q = 0; q < 5; ++q, p *= xf) C[q] += p;
      }
      Eigen::Matrix3d A;
      A << C[0], C[1], C[2], C[1], C[2], C[3], C[2], C[3], C[4];
      const Eigen::FullPivLU<Eigen::Matrix3d> lu(A);
      const bool invertible = lu.isInvertible();
      if (invertible) Ai = lu.inverse();
      const bool usable = invertible && Ai.allFinite();
      if (full) have_full = true, full_invertible = usable, full_inverse = Ai;
      if (!usable) continue;
    }
    const Eigen::Vector3d theta = Ai * Eigen::Vector3d(T[0], T[1], T[2]);
    if (resid && ok[i] && left[i] >= W && right[i] >= W) (*resid)[i] = z[i] - theta[0];
    const Eigen::Matrix2d V = var_log * Ai.bottomRightCorner<2, 2>();
    double e_sum = 0.0, ex = 0.0, ex2 = 0.0;
    long long count = 0;
    for (long long x = -W; x <= W; ++x) {
      const long long j = i + x;
      if (x == 0 || j < 0 || j >= m || !keep[j]) continue;
      const Eigen::Vector2d X(static_cast<double>(x), static_cast<double>(x) * x);
      const double e = std::exp(X.dot(theta.tail<2>()) - 0.5 * X.dot(V * X));
      e_sum += e;
      ex += e * X[0];
      ex2 += e * X[1];
      ++count;
    }
    if (count == 0) continue;
    k[i] = static_cast<double>(count) / e_sum;
    const Eigen::Vector2d a(ex / e_sum, ex2 / e_sum);
    v[i] = a.dot(V * a);
  }
}

}  // namespace

double digamma(double x) {
  if (!(x > 0.0)) return kNaN;
  if (std::isinf(x)) return kInf;
  double r = 0.0;
  for (; x < kAsymptotic; x += 1.0) r -= 1.0 / x;
  const double x2 = 1.0 / (x * x);
  // ln x - 1/(2x) - sum_k B_2k / (2k x^2k)
  const double series =
      x2 * (1.0 / 12 - x2 * (1.0 / 120 - x2 * (1.0 / 252 - x2 * (1.0 / 240 - x2 * (1.0 / 132 - x2 * (691.0 / 32760 - x2 / 12))))));
  return r + (std::log(x) - 0.5 / x - series);
}

double trigamma(double x) {
  if (!(x > 0.0)) return kNaN;
  if (std::isinf(x)) return 0.0;
  double r = 0.0;
  for (; x < kAsymptotic; x += 1.0) r += 1.0 / (x * x);
  const double x2 = 1.0 / (x * x);
  // 1/x + 1/(2x^2) + sum_k B_2k / x^(2k+1)
  const double series =
      x2 * (1.0 / 6 - x2 * (1.0 / 30 - x2 * (1.0 / 42 - x2 * (1.0 / 30 - x2 * (5.0 / 66 - x2 * (691.0 / 2730 - x2 * 7.0 / 6))))));
  return r + (1.0 + 0.5 / x + series) / x;
}

double tetragamma(double x) {
  if (!(x > 0.0)) return kNaN;
  if (std::isinf(x)) return 0.0;
  double r = 0.0;
  for (; x < kAsymptotic; x += 1.0) r -= 2.0 / (x * x * x);
  const double x2 = 1.0 / (x * x);
  // -(1/x^2 + 1/x^3 + sum_k (2k + 1) B_2k / x^(2k+2))
  const double series =
      x2 * (1.0 / 2 - x2 * (1.0 / 6 - x2 * (1.0 / 6 - x2 * (3.0 / 10 - x2 * (5.0 / 6 - x2 * (691.0 / 210 - x2 * 35.0 / 2))))));
  return r - x2 * (1.0 + 1.0 / x + series);
}

double trigamma_inverse(double x) {
  if (!(x > 0.0)) return kNaN;
  if (x > 1e7) return 1.0 / std::sqrt(x);
  if (x < 1e-6) return 1.0 / x;
  double y = 0.5 + 1.0 / x;
  for (int it = 0; it < 50; ++it) {
    const double tri = trigamma(y);
    const double dif = tri * (1.0 - tri / x) / tetragamma(y);
    y += dif;
    if (-dif / y < 1e-10) break;
  }
  return y;
}

double incomplete_beta(double a, double b, double x) {
  if (!(a > 0.0) || !(b > 0.0) || !(x >= 0.0 && x <= 1.0)) return kNaN;
  return incomplete_beta_xy(a, b, x, 1.0 - x);
}

double f_upper_quantile(double p, double d1, double d2) {
  if (!(p > 0.0 && p < 1.0) || !(d1 > 0.0) || !(d2 > 0.0) || std::isinf(d1) || std::isinf(d2)) return kNaN;
  const double a = 0.5 * d1, b = 0.5 * d2, lb = log_beta(a, b);
  // P(F > f) = I_y(b, a), y = d2 / (d1 f + d2), x = 1 - y = d1 f / (d1 f + d2); its derivative
  // in f is minus the density x^a y^b / (f B(a, b)).
  auto tail = [&](double f, double& density) {
    const double den = d1 * f + d2, x = d1 * f / den, y = d2 / den;
    density = (x > 0.0 && y > 0.0) ? std::exp(a * std::log(x) + b * std::log(y) - lb) / f : 0.0;
    return incomplete_beta_xy(b, a, y, x);
  };
  double lo = 0.0, hi = 1.0, density = 0.0;
  for (int it = 0; tail(hi, density) > p; ++it) {
    if (it > 2000) throw NumericalError("F quantile: no upper bracket");
    lo = hi;
    hi *= 2.0;
  }
  // Newton's iteration on P(F > f) - p, kept within the bracket by bisection.
  double f = 0.5 * (lo + hi);
  for (int it = 0; it < 400; ++it) {
    const double s = tail(f, density);
    if (s == p) return f;
    if (s > p) lo = f; else hi = f;
    double next = (density > 0.0) ? f + (s - p) / density : kNaN;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - f) <= 1e-15 * next || hi - lo <= 1e-15 * hi) return next;
    f = next;
  }
  return f;
}

Eigen::MatrixXd ModeratedNoise::error_covariance(const std::vector<int>& lines) const {
  const int L = data.max_line();
  const Eigen::Index k = static_cast<Eigen::Index>(lines.size());
  for (int l : lines) {
    if (l < 0 || l > L)
      throw std::invalid_argument("lines must be within 0.." + std::to_string(L) + ", got " + std::to_string(l));
  }
  const int P = data.periods;
  if (P < 2) return Eigen::MatrixXd::Zero(k, k);
  // Row i of the mixing matrix M (each moderated variance's weights on the sample variances)
  // is nonzero only on lines lo_i..hi_i (l_i +- half_width): the rows kept as those windows,
  // and (M M^T)(i, j) summed over the overlap of two windows (O(k^2 + k w^2), not O(k^2 L)).
  const Eigen::Index width = 2 * static_cast<Eigen::Index>(half_width) + 1;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(k, width);
  std::vector<long long> first(k), last(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    const int l = lines[i];
    const double w = own_weight.size() ? own_weight[l] : 1.0;
    const long long lo = std::max<long long>(0, static_cast<long long>(l) - half_width);
    const long long hi = std::min<long long>(L, static_cast<long long>(l) + half_width);
    first[i] = lo;
    last[i] = hi;
    int n = 0;
    for (long long j = lo; j <= hi; ++j) n += (j != l && (neighbour.size() == 0 || neighbour[j])) ? 1 : 0;
    const double share = (1.0 - w) / std::max(n, 1);
    for (long long j = lo; j <= hi; ++j)
      if (j != l && (neighbour.size() == 0 || neighbour[j])) M(i, j - lo) = share;
    M(i, l - lo) = w;
  }
  const double scale = 2.0 / (2.0 * (P - 1));
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index i = 0; i < k; ++i) {
    for (Eigen::Index j = i; j < k; ++j) {
      const long long lo = std::max(first[i], first[j]), hi = std::min(last[i], last[j]);
      double sum = 0.0;
      for (long long c = lo; c <= hi; ++c) sum += M(i, c - first[i]) * M(j, c - first[j]);
      out(i, j) = out(j, i) = scale * sum;
    }
  }
  return out;
}

ModeratedNoise moderated_noise(const FrequencyData& data, int half_width) {
  if (half_width < 1) throw std::invalid_argument("half_width must be >= 1, got " + std::to_string(half_width));
  data.validate();
  const long long W = half_width;
  const int P = data.periods;
  const int L = data.max_line();
  ModeratedNoise out;
  out.data = data;
  out.half_width = half_width;
  out.source_varU = data.varU;
  out.source_varY = data.varY;
  const double own = P >= 2 ? 2.0 * (P - 1) : kInf;
  out.dof = Eigen::VectorXd::Constant(L + 1, own);
  if (P >= 2) out.dof[0] = out.dof[L] = P - 1.0;
  if (P < 2 || L < 3 * W + 2) return out;

  const double d = own;
  const Eigen::Index m = L - 1;  // the inner lines 1..L-1, index i for line i + 1
  const double mean_log = digamma(d / 2) - std::log(d / 2);  // E log(chi2_d / d)
  const double var_log = trigamma(d / 2);                    // Var log(chi2_d / d)
  std::vector<Eigen::VectorXd> channels;
  for (const Eigen::VectorXd* v : {&data.varU, &data.varY}) {
    Eigen::VectorXd inner = v->segment(1, m);
    if ((inner.array() > 0).count() >= 3 * W) channels.push_back(std::move(inner));
  }
  if (channels.empty()) return out;

  // Lines above their neighbours' mean by more than F(d, n d) (noise alone) allows keep their
  // own variance; the second pass leaves the first one's outliers out of the means.
  std::vector<char> outlier(m, 0), ok(m);
  std::map<int, double> quantile;  // per neighbour count n
  Eigen::VectorXd s;
  Eigen::VectorXi n;
  for (int pass = 0; pass < 2; ++pass) {
    for (const Eigen::VectorXd& v : channels) {
      for (Eigen::Index i = 0; i < m; ++i) ok[i] = v[i] > 0 && !outlier[i];
      window_sums(v, ok, W, s, n);
      for (Eigen::Index i = 0; i < m; ++i) {
        if (n[i] <= 0) continue;
        auto q = quantile.find(n[i]);
        if (q == quantile.end())
          q = quantile.emplace(n[i], f_upper_quantile(kModerationOutlierRate, d, n[i] * d)).first;
        if (v[i] > q->second * (s[i] / n[i])) outlier[i] = 1;
      }
    }
  }
  // d0 from the spread of the log variances about their local (leave-one-out) mean.
  std::vector<double> r2;
  for (const Eigen::VectorXd& v : channels) {
    Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      ok[i] = v[i] > 0 && !outlier[i];
      if (ok[i]) z[i] = std::log(v[i]) - mean_log;
    }
    window_sums(z, ok, W, s, n);
    for (Eigen::Index i = 0; i < m; ++i) {
      if (!ok[i] || n[i] < W) continue;
      const double r = z[i] - s[i] / n[i];
      r2.push_back(r * r / (1.0 + 1.0 / n[i]));
    }
  }
  if (static_cast<long long>(r2.size()) < 3 * W) return out;
  double sum = 0.0;
  for (double r : r2) sum += r;
  const double excess = sum / static_cast<double>(r2.size()) - var_log;
  const double d0 = excess <= 0 ? kModerationMaxPriorDof
                                : std::min(2.0 * trigamma_inverse(excess), kModerationMaxPriorDof);

  // The prior scale: (d0 - 2) / d0 times the neighbours' mean (the mean of a scaled inverse
  // chi-square prior is d0 / (d0 - 2) times its scale).
  std::vector<char> keep(m);
  for (Eigen::Index i = 0; i < m; ++i) keep[i] = !outlier[i];
  const double scale = std::max(d0 - 2.0, 0.0) / d0;
  const double w = d / (d + d0);
  // The neighbours' arithmetic mean, turned by each channel's shape factor into the trend's
  // value at the line (a log spectrum that slopes or bends within the window biases the mean).
  Eigen::VectorXd kch[2], vch[2];
  {
    int c = 0;
    for (const Eigen::VectorXd* src : {&data.varU, &data.varY}) {
      const Eigen::VectorXd vi = src->segment(1, m);
      std::vector<char> okv(m);
      Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
      long long count = 0;
      for (Eigen::Index i = 0; i < m; ++i) {
        okv[i] = vi[i] > 0 && keep[i];
        if (okv[i]) {
          z[i] = std::log(vi[i]) - mean_log;
          ++count;
        }
      }
      if (count >= 3 * W) {
        shape_factors(z, okv, keep, W, var_log, kch[c], vch[c],
                      c == 0 ? &out.trend_residual_u : &out.trend_residual_y);
      } else {
        kch[c] = Eigen::VectorXd::Ones(m);
        vch[c] = Eigen::VectorXd::Zero(m);
      }
      ++c;
    }
  }
  FrequencyData& mod = out.data;
  Eigen::VectorXd su, sy, sr, si;
  window_sums(data.varU.segment(1, m), keep, W, su, n);
  window_sums(data.varY.segment(1, m), keep, W, sy, n);
  window_sums(data.covYU.segment(1, m).real(), keep, W, sr, n);
  window_sums(data.covYU.segment(1, m).imag(), keep, W, si, n);
  out.own_weight = Eigen::VectorXd::Ones(L + 1);
  out.neighbour = Eigen::Matrix<bool, Eigen::Dynamic, 1>::Constant(L + 1, false);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Index l = i + 1;
    if (keep[i]) out.neighbour[l] = true;
    if (!keep[i] || n[i] <= 0) continue;
    const double c = (1.0 - w) * scale;
    const double ku = kch[0][i], ky = kch[1][i], kc = std::sqrt(ku * ky);
    mod.varU[l] = w * data.varU[l] + c * ku * su[i] / n[i];
    mod.varY[l] = w * data.varY[l] + c * ky * sy[i] / n[i];
    mod.covYU[l] = w * data.covYU[l] + c * kc * std::complex<double>(sr[i], si[i]) / static_cast<double>(n[i]);
    // Satterthwaite: relative variance 2/d of the own part, 2/d0 + 2/(n d) + v of the prior's
    // (v the variance of the log shape factor).
    const double nn = n[i];
    const double vk = std::max(vch[0][i], vch[1][i]);
    out.dof[l] = (d + d0) * (d + d0) / (d + d0 + d0 * d0 * (1.0 / (nn * d) + vk / 2.0));
    out.own_weight[l] = w;
  }
  for (Eigen::Index l = 0; l <= L; ++l) {
    const double a = std::abs(mod.covYU[l]), uy = mod.varU[l] * mod.varY[l];
    if (a * a > uy) mod.covYU[l] *= std::sqrt(uy) / a;
  }
  for (Eigen::Index i = 0; i < m; ++i)
    if (outlier[i]) out.outliers.push_back(static_cast<int>(i + 1));
  out.prior_dof = d0;
  out.moderated = true;
  return out;
}

ModeratedCovariances moderated_covariances(const Eigen::MatrixXcd& C, int n_outputs, int periods, int half_width) {
  const Eigen::Index c = C.cols();
  if (c < 2) throw std::invalid_argument("C must have at least 2 columns (channels), got " + std::to_string(c));
  if (C.rows() < c || C.rows() % c != 0)
    throw std::invalid_argument("C must have (L+1) c rows for c = " + std::to_string(c) + " channels, got " +
                                std::to_string(C.rows()));
  if (n_outputs < 1 || n_outputs >= c)
    throw std::invalid_argument("n_outputs must be within 1.." + std::to_string(c - 1) + ", got " +
                                std::to_string(n_outputs));
  if (periods < 0) throw std::invalid_argument("periods must be >= 0, got " + std::to_string(periods));
  if (half_width < 1) throw std::invalid_argument("half_width must be >= 1, got " + std::to_string(half_width));
  if (!C.allFinite()) throw std::invalid_argument("C must be finite");
  const long long W = half_width;
  const int P = periods;
  const int L = static_cast<int>(C.rows() / c) - 1;
  ModeratedCovariances out;
  out.covariance = C;
  out.half_width = half_width;
  const double own = P >= 2 ? 2.0 * (P - 1) : kInf;
  out.dof = Eigen::VectorXd::Constant(L + 1, own);
  if (P >= 2) out.dof[0] = out.dof[L] = P - 1.0;
  out.own_weight = Eigen::VectorXd::Ones(L + 1);
  out.neighbour = Eigen::Matrix<bool, Eigen::Dynamic, 1>::Constant(L + 1, false);
  if (P < 2 || L < 3 * W + 2) return out;

  const double d = own;
  const Eigen::Index m = L - 1;  // the inner lines 1..L-1, index i for line i + 1
  const double mean_log = digamma(d / 2) - std::log(d / 2);
  const double var_log = trigamma(d / 2);
  // every channel's variances on the inner lines, inputs first (the pair (u, y) of one channel each)
  std::vector<Eigen::VectorXd> var;
  for (Eigen::Index k = 0; k < c; ++k) {
    const Eigen::Index q = (k + n_outputs) % c;
    Eigen::VectorXd v(m);
    for (Eigen::Index i = 0; i < m; ++i) v[i] = C((i + 1) * c + q, q).real();
    var.push_back(std::move(v));
  }
  std::vector<const Eigen::VectorXd*> channels;
  for (const Eigen::VectorXd& v : var)
    if ((v.array() > 0).count() >= 3 * W) channels.push_back(&v);
  if (channels.empty()) return out;

  std::vector<char> outlier(m, 0), ok(m);
  std::map<int, double> quantile;
  Eigen::VectorXd s;
  Eigen::VectorXi n;
  for (int pass = 0; pass < 2; ++pass) {
    for (const Eigen::VectorXd* v : channels) {
      for (Eigen::Index i = 0; i < m; ++i) ok[i] = (*v)[i] > 0 && !outlier[i];
      window_sums(*v, ok, W, s, n);
      for (Eigen::Index i = 0; i < m; ++i) {
        if (n[i] <= 0) continue;
        auto q = quantile.find(n[i]);
        if (q == quantile.end())
          q = quantile.emplace(n[i], f_upper_quantile(kModerationOutlierRate, d, n[i] * d)).first;
        if ((*v)[i] > q->second * (s[i] / n[i])) outlier[i] = 1;
      }
    }
  }
  std::vector<double> r2;
  for (const Eigen::VectorXd* v : channels) {
    Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      ok[i] = (*v)[i] > 0 && !outlier[i];
      if (ok[i]) z[i] = std::log((*v)[i]) - mean_log;
    }
    window_sums(z, ok, W, s, n);
    for (Eigen::Index i = 0; i < m; ++i) {
      if (!ok[i] || n[i] < W) continue;
      const double r = z[i] - s[i] / n[i];
      r2.push_back(r * r / (1.0 + 1.0 / n[i]));
    }
  }
  if (static_cast<long long>(r2.size()) < 3 * W) return out;
  double sum = 0.0;
  for (double r : r2) sum += r;
  const double excess = sum / static_cast<double>(r2.size()) - var_log;
  const double d0 = excess <= 0 ? kModerationMaxPriorDof
                                : std::min(2.0 * trigamma_inverse(excess), kModerationMaxPriorDof);

  std::vector<char> keep(m);
  for (Eigen::Index i = 0; i < m; ++i) keep[i] = !outlier[i];
  const double scale = std::max(d0 - 2.0, 0.0) / d0;
  const double w = d / (d + d0);
  // each channel's shape factor (in C's channel order) and the largest variance of its log
  Eigen::MatrixXd k = Eigen::MatrixXd::Ones(m, c);
  Eigen::VectorXd vk = Eigen::VectorXd::Zero(m);
  for (Eigen::Index q = 0; q < c; ++q) {
    std::vector<char> okv(m);
    Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
    long long count = 0;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double vi = C((i + 1) * c + q, q).real();
      okv[i] = vi > 0 && keep[i];
      if (okv[i]) {
        z[i] = std::log(vi) - mean_log;
        ++count;
      }
    }
    if (count < 3 * W) continue;
    Eigen::VectorXd kq, vq;
    shape_factors(z, okv, keep, W, var_log, kq, vq);
    k.col(q) = kq;
    vk = vk.cwiseMax(vq);
  }
  // the neighbours' sums of every entry (real and imaginary parts as the reference sums them)
  std::vector<Eigen::VectorXd> sr(c * c), si(c * c);
  Eigen::VectorXd xr(m), xi(m);
  for (Eigen::Index p = 0; p < c; ++p)
    for (Eigen::Index q = 0; q < c; ++q) {
      for (Eigen::Index i = 0; i < m; ++i) {
        xr[i] = C((i + 1) * c + p, q).real();
        xi[i] = C((i + 1) * c + p, q).imag();
      }
      window_sums(xr, keep, W, sr[p * c + q], n);
      window_sums(xi, keep, W, si[p * c + q], n);
    }
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Index l = i + 1;
    if (keep[i]) out.neighbour[l] = true;
    if (!keep[i] || n[i] <= 0) continue;
    const double a = (1.0 - w) * scale / static_cast<double>(n[i]);
    for (Eigen::Index p = 0; p < c; ++p)
      for (Eigen::Index q = 0; q < c; ++q) {
        const double kk = std::sqrt(k(i, p) * k(i, q));
        out.covariance(l * c + p, q) =
            w * C(l * c + p, q) + a * kk * std::complex<double>(sr[p * c + q][i], si[p * c + q][i]);
      }
    const double nn = n[i];
    out.dof[l] = (d + d0) * (d + d0) / (d + d0 + d0 * d0 * (1.0 / (nn * d) + vk[i] / 2.0));
    out.own_weight[l] = w;
  }
  for (Eigen::Index i = 0; i < m; ++i)
    if (outlier[i]) out.outliers.push_back(static_cast<int>(i + 1));
  out.prior_dof = d0;
  out.moderated = true;
  return out;
}

}  // namespace lptv
