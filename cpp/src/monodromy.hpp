// Private helpers shared by floquet.cpp (Hill's method) and monodromy.cpp (the product routes).
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/model.hpp"

namespace lptv {
namespace detail {

// Throws std::invalid_argument naming the time where a continuous-time model's a_na(t)
// vanishes or changes sign over the period (checked on a grid fine for its harmonics).
void check_leading_ct(const Model& m);

// The last rows -a_n[k] / a_na[k] (N x na) of a discrete-time model's one-step companion
// matrices; throws std::invalid_argument naming the sample where a_na[k] vanishes.
Eigen::MatrixXd dt_last_rows(const Model& m);

// Phi = C_{N-1} ... C_0 and a bound on the rounding error of the product (Frobenius norm).
struct DtProduct {
  Eigen::MatrixXd Phi;
  double error = 0;
};
DtProduct dt_product(const Model& m);

// The same for any one-step matrices: Phi = G_{N-1} ... G_0 with its rounding bound.
DtProduct product_of_steps(const std::vector<Eigen::MatrixXd>& G);

}  // namespace detail
}  // namespace lptv
