// Generalised singular value decomposition of a square pair through LAPACK's
// dggsvd3, and the smallest generalised pair min ||A x|| / ||B x||.
#pragma once
#include <Eigen/Dense>

namespace lptv {

struct GeneralizedPairs {
  // Finite generalised singular values alpha_i / beta_i (beta_i > 0), ascending,
  // with their vectors x_i (columns): A x_i = alpha_i u_i, B x_i = beta_i v_i.
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  int infinite = 0;  // pairs with beta = 0 (directions B does not see)
};

// A, B: n x n. Throws NumericalError when LAPACK fails or [A; B] is rank deficient
// (then the pair does not determine a unique direction).
GeneralizedPairs gsvd_pairs(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B);

}  // namespace lptv
