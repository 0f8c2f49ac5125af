// What the data can say before anything is estimated: is the input excited on the fitted lines,
// does the output respond, do enough rows carry signal for the parameters, can the known
// coefficients fix the scale. lptv::identify runs it first, so degenerate data give a message
// naming the cause (METHOD.md section 15) instead of a failed decomposition further down.
#pragma once
#include <string>
#include <vector>

#include "lptv/noise.hpp"
#include "lptv/structure.hpp"

namespace lptv {

// Every threshold of the diagnostics, in one place.
struct DiagnosticThresholds {
  // A line carries signal when |X_l|^2 > kLineRatio var X_l (20 dB above the noise of the mean):
  // the rule of excited_lines. A noise-only line passes with probability
  // (1 + 100 / (P-1))^-(P-1): 1 % at P = 2, 3e-5 at P = 4, 4e-44 with known variances.
  static constexpr double kLineRatio = 100.0;
  // Without such a line, the channel still carries signal when its power summed over the lines
  // stands above the summed noise variance by more than kNoiseSigmas standard deviations of that
  // ratio under noise alone: sqrt(1/n + 1/(n (P-1))) with n = (sum v)^2 / sum v^2 the effective
  // number of lines (var X_l = v_l; the numerator's sum has n exponential terms, the
  // denominator's n (P-1) chi-square degrees of freedom; P = 0: known variances, no second
  // term). Five standard deviations: noise alone fails this with probability below 1e-6 in the
  // Gaussian limit, so the refusal is about the data, not chance.
  static constexpr double kNoiseSigmas = 5.0;
  // The count of lines above kLineRatio is clear of noise when it exceeds n q + kNoiseSigmas
  // sqrt(n q), q the probability above of a noise-only line (1 / 101 at P = 2: 2.4 of 243 lines).
  // A noise-free line (var X_l = 0) carries signal when |X_l|^2 exceeds this fraction of the
  // channel's largest |X|^2 (FFT rounding of an exactly zero line is ~1e-32 of it).
  static constexpr double kNoiseFreeFloor = 1e-20;
};

// Does the channel X (U or Y with its variances) carry signal on the given lines?
struct ChannelPower {
  int lines = 0;             // lines examined
  int above = 0;             // lines above kLineRatio times their noise (or above the floor)
  double power = 0;          // sum |X_l|^2
  double noise = 0;          // sum var X_l
  double limit = 0;          // power / noise must exceed this without a line above (inf: no noise)
  bool clear = false;        // more lines above than noise alone puts there (see channel_power)
  bool present = false;      // clear, or power / noise > limit
};
ChannelPower channel_power(const Eigen::VectorXcd& X, const Eigen::VectorXd& varX, int periods,
                           const std::vector<int>& lines);

struct DataDiagnosis {
  std::vector<int> region;          // the lines the fit reads: rows +- kmax, without line 0
  ChannelPower input, output;       // on the region
  std::vector<int> excited;         // lines of the whole input above kLineRatio times their noise
  int informative_rows = 0;         // rows with a signal-carrying input line within +- Kb or
                                    // output line within +- Ka
  std::vector<std::string> warnings;
};

// Throws std::invalid_argument naming the argument (u, y, known, lines) and the cause when the
// data cannot determine the model: no input power on the fitted lines (zero, or at the noise
// level: "u: ..."), an output without variation there ("y: ..."), fewer signal-carrying rows
// than the free parameters need ("lines: ..."), known coefficients that cannot fix the scale
// (all zero) or that zero the highest-order coefficient ("known: ..."). rows: the fit's rows,
// already checked against the data.
// check_row_count false: no "lines: ..." refusal (for one of several experiments, whose rows
// are counted together by lptv::identify).
DataDiagnosis diagnose_data(const FrequencyData& d, const Structure& s, const std::vector<int>& rows,
                            bool check_row_count = true);

// "10, 20, 30, ..., 240 (24 lines)": a list of lines for a message.
std::string format_lines(const std::vector<int>& lines, int head = 4);

}  // namespace lptv
