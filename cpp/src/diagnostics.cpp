// The data diagnostics lptv::identify runs before estimating (see diagnostics.hpp).
#include "lptv/diagnostics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "lptv/htf_estimate.hpp"

namespace lptv {

namespace {

using T = DiagnosticThresholds;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string coefficient_name(const Structure::Known& k) {
  return std::string(k.is_a ? "a" : "b") + std::to_string(k.order);
}

// Per-line test of one channel (see DiagnosticThresholds).
bool line_above(double p, double v, double floor) {
  return v > 0 ? p > T::kLineRatio * v : p > floor && p > 0;
}

void check_known(const Structure& s) {
  if (s.known.empty()) return;
  bool any_nonzero = false;
  std::string names;
  for (const auto& k : s.known) {
    const bool zero = k.coef.isZero(0.0);
    any_nonzero = any_nonzero || !zero;
    names += (names.empty() ? "" : ", ") + coefficient_name(k) + (zero ? " = 0" : "");
    if (k.is_a && k.order == s.na && zero) {
      throw std::invalid_argument(
          "known: a" + std::to_string(s.na) + " = 0 makes the highest-order coefficient a_na(t) vanish, "
          "so the equation is not of order na = " + std::to_string(s.na) + ": lower na instead");
    }
  }
  if (!any_nonzero) {
    throw std::invalid_argument(
        "known: " + names + " cannot fix the scale of the model: the equation is homogeneous in its "
        "coefficients (a and b scaled together fit the data equally), and a known coefficient sets "
        "the scale only when it is nonzero, so the normalisation is impossible; give a nonzero "
        "known value, or leave known out (the estimate is then normalised so that a_na has mean 1)");
  }
}

}  // namespace

std::string format_lines(const std::vector<int>& lines, int head) {
  std::string out;
  const int n = static_cast<int>(lines.size());
  for (int i = 0; i < n; ++i) {
    if (i == head && n > head + 1) {
      out += ", ..., " + std::to_string(lines.back());
      break;
    }
    out += (i ? ", " : "") + std::to_string(lines[i]);
  }
  return out + " (" + std::to_string(n) + (n == 1 ? " line)" : " lines)");
}

ChannelPower channel_power(const Eigen::VectorXcd& X, const Eigen::VectorXd& varX, int periods,
                           const std::vector<int>& lines) {
  ChannelPower c;
  const double floor = T::kNoiseFreeFloor * X.cwiseAbs2().maxCoeff();
  double v2 = 0;
  for (int l : lines) {
    const double p = std::norm(X[l]), v = varX[l];
    ++c.lines;
    c.above += line_above(p, v, floor);
    c.power += p;
    c.noise += v;
    v2 += v * v;
  }
  if (c.noise > 0) {
    const double n = c.noise * c.noise / v2;
    const double var = 1.0 / n + (periods >= 2 ? 1.0 / (n * (periods - 1)) : 0.0);
    c.limit = 1.0 + T::kNoiseSigmas * std::sqrt(var);
  } else {
    c.limit = std::numeric_limits<double>::infinity();
  }
  // Noise alone puts a line above kLineRatio with probability q (F(2, 2(P-1)), or exponential
  // with known variances); the count is clear of it beyond n q + kNoiseSigmas sqrt(n q).
  const double q = periods >= 2 ? std::pow(1.0 + T::kLineRatio / (periods - 1), -(periods - 1.0))
                                : std::exp(-T::kLineRatio);
  const double nq = q * c.lines;
  c.clear = c.above > nq + T::kNoiseSigmas * std::sqrt(nq);
  c.present = c.clear || (c.noise > 0 && c.power > c.limit * c.noise);
  return c;
}

DataDiagnosis diagnose_data(const FrequencyData& d, const Structure& s, const std::vector<int>& rows,
                            bool check_row_count) {
  check_known(s);
  DataDiagnosis out;
  const int L = d.max_line(), K = s.kmax();
  const int Ka = *std::max_element(s.ka.begin(), s.ka.end());
  const int Kb = *std::max_element(s.kb.begin(), s.kb.end());
  std::vector<char> in_region(L + 1, 0);
  for (int r : rows) {
    for (int l = std::max(1, r - K); l <= std::min(L, r + K); ++l) in_region[l] = 1;
  }
  for (int l = 1; l <= L; ++l) {
    if (in_region[l]) out.region.push_back(l);
  }
  const std::string where = "the fitted lines " + format_lines(rows) +
                            (K ? " and their +-" + std::to_string(K) + " neighbours" : "");
  out.input = channel_power(d.U, d.varU, d.periods, out.region);
  out.excited = excited_lines(d, T::kLineRatio);
  if (!out.input.present) {
    // Excited lines elsewhere, when the whole input's count of them is clear of the noise.
    std::vector<int> all(L), elsewhere;
    for (int l = 1; l <= L; ++l) all[l - 1] = l;
    for (int l : out.excited) {
      if (!in_region[l]) elsewhere.push_back(l);
    }
    if (!elsewhere.empty() && channel_power(d.U, d.varU, d.periods, all).clear) {
      throw std::invalid_argument(
          "u: the input is not excited on " + where + ": it is excited on lines " +
          format_lines(elsewhere) + "; fit lines at or next to those (lines='excited' in Python)");
    }
    if (out.input.power == 0) {
      throw std::invalid_argument("u: the input spectrum is zero on " + where +
                                  ": no input power at all (a dead or disconnected input channel?); "
                                  "the system is not excited, so nothing can be identified");
    }
    throw std::invalid_argument(
        "u: the input spectrum on " + where + " is at the level of its noise (power " +
        num(out.input.power / out.input.noise) + " times the noise variance summed over " +
        std::to_string(out.input.lines) + " lines, no line 20 dB above it; noise alone reaches " +
        num(out.input.limit) + "): the input does not excite the system (a dead input channel, or "
        "an excitation far below the noise)");
  }
  out.output = channel_power(d.Y, d.varY, d.periods, out.region);
  if (!out.output.present) {
    if (out.output.power == 0) {
      throw std::invalid_argument("y: the output is constant: its spectrum is zero on " + where +
                                  ", so it shows no response to the input (a dead output channel, "
                                  "or a sensor stuck at one value)");
    }
    throw std::invalid_argument(
        "y: the output shows no variation above its noise on " + where + " (power " +
        num(out.output.power / out.output.noise) + " times the noise variance summed over " +
        std::to_string(out.output.lines) + " lines, no line 20 dB above it; noise alone reaches " +
        num(out.output.limit) + "): it does not respond to the input (a dead output channel, "
        "or a response far below the noise)");
  }

  // Rows that carry signal: a line within reach of the row's equation above its noise.
  const double ufloor = T::kNoiseFreeFloor * d.U.cwiseAbs2().maxCoeff();
  const double yfloor = T::kNoiseFreeFloor * d.Y.cwiseAbs2().maxCoeff();
  auto any_above = [&](const Eigen::VectorXcd& X, const Eigen::VectorXd& v, double floor, int r, int k) {
    for (int l = std::max(1, r - k); l <= std::min(L, r + k); ++l) {
      if (line_above(std::norm(X[l]), v[l], floor)) return true;
    }
    return false;
  };
  int rows_with_input = 0;
  for (int r : rows) {
    const bool u = any_above(d.U, d.varU, ufloor, r, Kb);
    rows_with_input += u;
    out.informative_rows += u || any_above(d.Y, d.varY, yfloor, r, Ka);
  }
  const long long n_free = s.n_unknowns();
  if (check_row_count && out.input.clear && 2LL * out.informative_rows <= n_free) {
    throw std::invalid_argument(
        "lines: only " + std::to_string(out.informative_rows) + " of the " + std::to_string(rows.size()) +
        " fitted lines carry signal (an input line 20 dB above its noise within +-" + std::to_string(Kb) +
        " or an output line within +-" + std::to_string(Ka) + "): " +
        std::to_string(2 * out.informative_rows) + " real equations for " + std::to_string(n_free) +
        " free parameters; fit lines next to the excited ones (" + format_lines(out.excited) +
        "), excite more lines, or use fewer harmonics / lower orders");
  }
  if (out.input.clear && rows_with_input == 0) {
    out.warnings.push_back(
        "none of the fitted lines has an input line 20 dB above its noise within +-" + std::to_string(Kb) +
        " (the input is excited on lines " + format_lines(out.excited) +
        "): the input side b is fitted to what the output's coupling leaves, mostly noise");
  }
  return out;
}

}  // namespace lptv
