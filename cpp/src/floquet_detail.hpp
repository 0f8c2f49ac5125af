// Private: the Floquet routes floquet.cpp (SISO) and floquet_mimo.cpp (several outputs) share.
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "lptv/floquet.hpp"
#include "monodromy.hpp"

namespace lptv {
namespace detail {

// Hill's method on x' = F(t) x given the harmonics -KF..KF of F(t) (F[KF + k], n x n each;
// empty for n = 0): the truncation grows until the kept exponents settle (METHOD.md section 12).
// `vectors`, when given, receives the kept eigenpairs of the last (settled) Hill matrix.
struct HillVectors {
  int truncation = 0;
  Eigen::VectorXcd lambda;        // the kept eigenvalues, imaginary part reduced to (-w0/2, w0/2]
  Eigen::MatrixXcd left, right;   // their left and right eigenvectors, blocks p = -M..M of n
};
Floquet hill_floquet(const std::vector<Eigen::MatrixXcd>& F, double w0, const FloquetOptions& opt,
                     HillVectors* vectors = nullptr);

// The multipliers of a discrete-time monodromy matrix with its rounding bound; T0 = N ts.
Floquet product_floquet(const DtProduct& prod, double w0, double T0);

// The harmonics of the SISO companion matrix F(t) (F[KF + k], na x na), as Hill's method uses them.
std::vector<Eigen::MatrixXcd> siso_companion_blocks(const Model& m);

// std::invalid_argument for options out of range.
void check_floquet_options(const FloquetOptions& opt);

}  // namespace detail
}  // namespace lptv
