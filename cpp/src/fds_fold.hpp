// The FDS's one-pass band solve on half the grid (METHOD.md section 3, "half the grid"). A
// real model has conjugate-symmetric coefficients, so A_{-l,-i} = conj(A_{l,i}); a real input
// has U_{-l} = conj(U_l), and the solution then has Y_{-l} = conj(Y_l). Lines 0..L carry all
// of it: rows l = L..K of A, written in the unknowns Y_0..Y_L, are ordinary band rows; rows
// 0..K-1 also hold conj(Y_1..Y_K). The small band kernel eliminates Y_L down to Y_2K from the
// top (rows L..K), the 2K rows left form a real system of 4K - 1 unknowns (Re Y_0; Re and Im
// of Y_1..Y_2K-1) solved densely, and one back substitution gives the rest: half the rows,
// half the work of the full grid.
//
// The conditioning check's right-hand side is the full grid's (Fds::condition) with its unit
// phases exp(j g l) taken by line instead of by grid index: on the grid -L..L the two differ
// by the constant factor exp(j g L), so the solution's magnitudes are the same, and by line it
// is conjugate-symmetric like the rest. Since A maps conjugate-symmetric vectors to
// conjugate-symmetric ones and j times them to j times them, A^-1 has the same size on both:
// the symmetric right-hand side probes all of it.
//
// Private to the library; fds.cpp decides when to use it and owns the check's decision.
#pragma once
#include <Eigen/Dense>

#include "lptv/fds.hpp"
#include "lptv/model.hpp"

namespace lptv {
namespace detail {

// The unit phase step of the conditioning check's right-hand side (the golden angle).
constexpr double kCheckPhaseStep = 2.399963229728653;

// Whether solve_folded applies to the model on the grid: continuous time, at least 2K + 1
// lines each side, 1 <= K (= Ka) <= SmallBandLU::kMaxK.
bool can_fold(const Model& m, const Grid& g);
// Whether the full-grid input is conjugate-symmetric about line 0, exactly (U_0 real), as
// simulate builds it from one-sided spectra.
bool real_input(const Grid& g, const Eigen::MatrixXcd& U_full);

// One-sided input: row l is line l (U_0 real), lines beyond the last row are zero.
using HalfInput = Eigen::Ref<const Eigen::MatrixXcd>;

struct FoldedSolution {
  Eigen::MatrixXcd Y;      // lines 0..L (the negative lines are their conjugates); empty with `full`
  double condition = 0.0;  // max |x| of the check's solution
  int where = 0;           // its grid index (a line >= 0)
};

// Y = A^-1 B U on the grid with the check. Throws ZeroPivot (band_kernel.hpp) with the grid
// index of the first exactly zero pivot. With `full` (g.N x U.cols(), sized by the caller) the
// solution goes there on the whole grid, grid index L + l for line l, instead of into Y.
FoldedSolution solve_folded(const Model& m, const Grid& g, const HalfInput& U,
                            Eigen::MatrixXcd* full = nullptr);

}  // namespace detail
}  // namespace lptv
