// Noise (co)variances moderated across neighbouring lines (METHOD.md section 7, "The variances
// the tests divide by: moderated across lines"): each line's sample (co)variances combined with
// its neighbours' by the empirical-Bayes rule of Smyth (2004), made local in frequency. The
// NumPy reference is python/lptv/reference/moderation.py.
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/noise.hpp"

namespace lptv {

// A line whose sample variance exceeds its neighbours' mean beyond the upper quantile
// F(d, n d) at this probability keeps its own (co)variances.
constexpr double kModerationOutlierRate = 1e-3;
// Cap on the prior degrees of freedom d0 (noise exactly as smooth as its trend).
constexpr double kModerationMaxPriorDof = 1e6;

struct ModeratedNoise {
  FrequencyData data;            // the same spectra and periods, the variances moderated
  // Per line 0..Lmax: real degrees of freedom of the moderated variances (Satterthwaite);
  // 2 (P - 1) where a line kept its own, P - 1 on lines 0 and Lmax, inf when P < 2.
  Eigen::VectorXd dof;
  double prior_dof = 0.0;        // d0 (0: no moderation; kModerationMaxPriorDof at the cap)
  std::vector<int> outliers;     // lines that kept their own variance, ascending
  int half_width = 0;            // the neighbours of l: the lines within +-half_width
  bool moderated = false;        // false: data is the input unchanged, own_weight and
                                 // neighbour are empty
  Eigen::VectorXd own_weight;    // per line: the weight d / (d + d0) of its own (1 where kept)
  Eigen::Matrix<bool, Eigen::Dynamic, 1> neighbour;  // per line: may serve as a neighbour
  Eigen::VectorXd source_varU;   // the input's own variances the moderation started from
  Eigen::VectorXd source_varY;
  // Per inner line 1..Lmax - 1 (index l - 1) of the input (output): its log variance less the
  // value at l of the local log-quadratic trend fitted to the other lines over +-2 half_width
  // (the fit the shape factors use); NaN where the line is outlying or zero, or fewer than
  // half_width lines lie on either side. Empty where the channel has too few lines to fit.
  // The smoothness check of noise='auto' reads the correlation of neighbours' residuals.
  Eigen::VectorXd trend_residual_u;
  Eigen::VectorXd trend_residual_y;

  // Covariance of the relative sampling errors of the moderated variances on `lines` (one
  // channel): each line's sample variance is off by a relative error of variance 1 / (P - 1),
  // independently of the others; a moderated variance mixes its own (weight w) with its
  // neighbours' mean (1 - w). Zeros when P < 2. Throws std::invalid_argument for a line
  // outside 0..Lmax.
  Eigen::MatrixXd error_covariance(const std::vector<int>& lines) const;
};

// Per line l in 1..Lmax - 1 the moderated covariance matrix of the mean input and output is
// (d C_l + d0 C0_l) / (d + d0), d = 2 (P - 1), C0_l = (d0 - 2) / d0 times the mean of C over
// the lines within +-half_width of l (l itself and outlying lines left out), d0 estimated from
// the spread of log varU and log varY about their local means. Returns the data unchanged
// (moderated false, prior_dof 0) when P < 2, Lmax < 3 half_width + 2, or fewer than
// 3 half_width lines carry noise. Throws std::invalid_argument when half_width < 1 or the data
// do not validate.
ModeratedNoise moderated_noise(const FrequencyData& data, int half_width);

// The moderated covariance matrices of several channels (METHOD.md section 19, "Moderated noise
// for several channels").
struct ModeratedCovariances {
  Eigen::MatrixXcd covariance;   // (L+1) c x c: rows l c .. l c + c - 1 the matrix of line l
  Eigen::VectorXd dof;           // per line, as ModeratedNoise::dof
  double prior_dof = 0.0;        // d0 (0: not moderated)
  std::vector<int> outliers;     // lines that kept their own matrix (outlying in some channel)
  int half_width = 0;
  bool moderated = false;        // false: covariance is the input unchanged
  Eigen::VectorXd own_weight;    // per line: d / (d + d0) (1 where kept)
  Eigen::Matrix<bool, Eigen::Dynamic, 1> neighbour;  // per line: may serve as a neighbour
};

// Section 7's rule for the covariance matrices C_l of the means of c channels (outputs 0..ny-1,
// then inputs) from P periods: per line l in 1..L-1, (d C_l + d0 C0_l) / (d + d0) with one
// weight for the whole matrix, C0_l = (d0 - 2) / d0 times the neighbours' mean with entry (p, q)
// scaled by sqrt(k_p k_q) (k the channels' shape factors); d0 from the log variances of every
// channel with enough noise (inputs first, then outputs); a line outlying in any channel keeps
// its own matrix. With c = 2 and C_l = [[varY, covYU], [conj covYU, varU]] this is
// moderated_noise. Throws std::invalid_argument for a C whose rows are not (L+1) c with c =
// C.cols() >= 2, n_outputs outside 1..c-1, periods < 0, half_width < 1, or entries not finite.
ModeratedCovariances moderated_covariances(const Eigen::MatrixXcd& C, int n_outputs, int periods, int half_width);

// The special functions the moderation needs (x > 0; NaN otherwise).
double digamma(double x);
double trigamma(double x);
double tetragamma(double x);
// y > 0 with trigamma(y) = x (Smyth 2004's Newton iteration on 1 / y), x > 0.
double trigamma_inverse(double x);
// The regularized incomplete beta function I_x(a, b), a, b > 0, 0 <= x <= 1.
double incomplete_beta(double a, double b, double x);
// The upper p-quantile of F(d1, d2): f with P(F > f) = p, 0 < p < 1, d1, d2 > 0.
double f_upper_quantile(double p, double d1, double d2);

}  // namespace lptv
