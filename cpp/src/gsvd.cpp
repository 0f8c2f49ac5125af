#include "lptv/gsvd.hpp"

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "lptv/errors.hpp"

extern "C" {
// LAPACK (Fortran): the trailing arguments are the hidden lengths of the character
// arguments (gfortran ABI).
void dggsvd3_(const char* jobu, const char* jobv, const char* jobq, const int* m, const int* n,
              const int* p, int* k, int* l, double* a, const int* lda, double* b, const int* ldb,
              double* alpha, double* beta, double* u, const int* ldu, double* v, const int* ldv,
              double* q, const int* ldq, double* work, const int* lwork, int* iwork, int* info,
              std::size_t, std::size_t, std::size_t);
}

namespace lptv {

GeneralizedPairs gsvd_pairs(const Eigen::MatrixXd& A_in, const Eigen::MatrixXd& B_in) {
  const int n = static_cast<int>(A_in.cols());
  if (A_in.rows() != n || B_in.rows() != n || B_in.cols() != n) {
    throw std::invalid_argument("gsvd_pairs: A and B must be square of the same size");
  }
  if (!A_in.allFinite() || !B_in.allFinite()) {
    throw NumericalError("GSVD: the matrices contain NaN or inf");
  }
  Eigen::MatrixXd A = A_in, B = B_in, Q(n, n);
  Eigen::VectorXd alpha(n), beta(n);
  std::vector<int> iwork(n);
  int k = 0, l = 0, info = 0, one = 1, lwork = -1;
  double dummy = 0, wq = 0;
  dggsvd3_("N", "N", "Q", &n, &n, &n, &k, &l, A.data(), &n, B.data(), &n, alpha.data(), beta.data(),
           &dummy, &one, &dummy, &one, Q.data(), &n, &wq, &lwork, iwork.data(), &info, 1, 1, 1);
  if (info != 0) throw NumericalError("GSVD (dggsvd3) workspace query failed: info " + std::to_string(info));
  lwork = std::max(1, static_cast<int>(wq));
  std::vector<double> work(lwork);
  dggsvd3_("N", "N", "Q", &n, &n, &n, &k, &l, A.data(), &n, B.data(), &n, alpha.data(), beta.data(),
           &dummy, &one, &dummy, &one, Q.data(), &n, work.data(), &lwork, iwork.data(), &info, 1, 1, 1);
  if (info != 0) {
    throw NumericalError("GSVD (dggsvd3) failed to converge: info " + std::to_string(info));
  }
  const int r = k + l;
  if (r < n) {
    throw NumericalError("GSVD: the pair is rank deficient (rank " + std::to_string(r) + " of " +
                         std::to_string(n) + "): some parameter combination enters neither the "
                         "residue nor its noise");
  }
  // [A; B] Q = [U S1; V S2] [0 R]; with r = n, R = A(0:n, 0:n) upper triangular
  // (M - K - L >= 0 here). The vectors are the columns of X = Q R^-1.
  const Eigen::MatrixXd R = A.topLeftCorner(n, n).triangularView<Eigen::Upper>();
  std::vector<int> finite;
  GeneralizedPairs out;
  for (int i = k; i < r; ++i) {
    if (beta[i] > 0) finite.push_back(i);
  }
  out.infinite = r - static_cast<int>(finite.size());
  std::vector<double> ratio(n, 0.0);
  for (int i : finite) ratio[i] = alpha[i] / beta[i];
  std::sort(finite.begin(), finite.end(), [&](int a, int b) { return ratio[a] < ratio[b]; });
  out.values.resize(finite.size());
  out.vectors.resize(n, finite.size());
  for (size_t j = 0; j < finite.size(); ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
    e[finite[j]] = 1.0;
    const Eigen::VectorXd z = R.triangularView<Eigen::Upper>().solve(e);
    out.values[j] = ratio[finite[j]];
    out.vectors.col(j) = Q * z;
  }
  return out;
}

}  // namespace lptv
