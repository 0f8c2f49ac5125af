// Many right-hand sides on one factorisation (HTF columns, several inputs, Monte Carlo): the
// small band LU's blocked solve (lptv::SmallBandLU::solve: 16 columns per pass over the
// factors, two threads from two blocks and 2e5 line-columns up) against the same blocks on one
// thread, column by column, and LAPACK's zgbtrs on all columns at once; the paper-like model's
// A on grids of 201 to 200 001 lines.
//
// Usage: bench_fds_many_inputs [max_lines]   (default 200001: grids of 201, 2001, 20 001 and 200 001 lines)
#include <cstdio>
#include <random>
#include <string>

#include "bench_common.hpp"
#include "lptv/band_lu.hpp"
#include "lptv/fds.hpp"

namespace {

std::vector<lptv::cd> band_storage(const lptv::SpMat& A, int K) {
  const int ld = lptv::BandLU::ldab(K, K);
  std::vector<lptv::cd> ab(static_cast<size_t>(ld) * A.cols(), lptv::cd(0.0, 0.0));
  for (int j = 0; j < A.outerSize(); ++j)
    for (lptv::SpMat::InnerIterator it(A, j); it; ++it)
      ab[static_cast<size_t>(j) * ld + 2 * K + it.row() - j] = it.value();
  return ab;
}

std::string label(int c) { return "column " + std::to_string(c); }

}  // namespace

int run(int argc, char** argv) {
  const long max_lines = bench::int_arg(argc, argv, 1, 200001, 201, 2000001, "bench_fds_many_inputs",
                                        "bench_fds_many_inputs [max_lines]");
  const lptv::Model model = bench::paper_model();
  const int K = model.ka();
  std::printf("many right-hand sides on one band factorisation, paper-like model (K = 3); ns per line "
              "and column, fastest of 5 calls\nblocked = SmallBandLU::solve (16 columns per pass; two "
              "threads from 2 blocks and 2e5 line-columns), 1 thread = the same blocks one after the "
              "other,\nby column = one solve per column, zgbtrs = LAPACK on all columns\n\n");
  std::printf("%8s %6s %10s %10s %10s %10s %9s %9s %10s\n", "lines", "cols", "blocked", "1 thread",
              "by column", "zgbtrs", "threads", "blocks", "max diff");
  bool failed = false;
  for (int L : {100, 1000, 10000, 100000}) {
    if (2L * L + 1 > max_lines) break;
    const lptv::Grid g = lptv::make_grid(model, L);
    const std::vector<lptv::cd> ab = band_storage(lptv::build_A(model, g), K);
    const lptv::SmallBandLU lu(g.N, K, ab, label);
    const lptv::BandLU lapack(g.N, K, K, ab, label);
    for (int ncol : {1, 8, 32, 128}) {
      if (static_cast<double>(g.N) * ncol > 3e6) continue;
      std::mt19937_64 gen(ncol);
      std::normal_distribution<double> nd;
      Eigen::MatrixXcd b(g.N, ncol);
      for (int j = 0; j < ncol; ++j)
        for (int i = 0; i < g.N; ++i) b(i, j) = lptv::cd(nd(gen), nd(gen));
      Eigen::MatrixXcd x, xr;
      const double t_block = bench::min_time(5, [&] { x = lu.solve(b); });
      const double t_seq = bench::min_time(5, [&] {
        for (int c0 = 0; c0 < ncol; c0 += 16) (void)lu.solve(b.middleCols(c0, std::min(16, ncol - c0)));
      });
      const double t_col = bench::min_time(5, [&] {
        for (int c = 0; c < ncol; ++c) (void)lu.solve(b.col(c));
      });
      const double t_lap = bench::min_time(5, [&] { xr = lapack.solve(b); });
      const double diff = (x - xr).cwiseAbs().maxCoeff() / xr.cwiseAbs().maxCoeff();
      const double nn = double(g.N) * ncol;
      std::printf("%8d %6d %10.1f %10.1f %10.1f %10.1f %8.2fx %8.2fx %10.1e\n", g.N, ncol,
                  1e9 * t_block / nn, 1e9 * t_seq / nn, 1e9 * t_col / nn, 1e9 * t_lap / nn,
                  t_seq / t_block, t_col / t_seq, diff);
      if (!(diff <= 1e-12)) {
        std::fprintf(stderr, "bench_fds_many_inputs: SmallBandLU::solve and zgbtrs differ by %.1e relative at %d lines, "
                     "%d columns (1e-12 at most expected)\n", diff, g.N, ncol);
        failed = true;
      }
    }
  }
  std::printf("\nthreads = 1 thread / blocked (> 1: the second thread pays), blocks = by column / "
              "1 thread\n");
  return failed ? 1 : 0;
}

int main(int argc, char** argv) {
  return bench::guarded_main("bench_fds_many_inputs", [&] { return run(argc, argv); });
}
