// FDS cost per line from 10^3 to 10^7 lines, KLU against UMFPACK, with peak memory.
//
// The paper-like model (7 diagonals in A and B) on a fixed grid -L..L with n = 2L+1 lines:
// build A and B, factorise A, solve A Y = B U for one random input; that is what lptv::Fds
// plus solve_full do. Each (size, solver) runs in its own child process, so that its peak
// resident memory (getrusage ru_maxrss) is its own; the child reports through a pipe.
//
// In the KLU child the factorisation is then broken down (KLU called directly: analysis and
// numeric factorisation; KLU with the natural order and no BTF, which for a band matrix is
// fill-free; LAPACK's band LU zgbsv), after the peak memory is recorded.
//
// Usage: bench_fds_scaling [max_lines]   (default 10^7)
#include <klu.h>
#include <lapacke.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "bench_common.hpp"
#include "lptv/fds.hpp"

namespace {

struct Measurement {
  double build = 0, factor = 0, solve = 0;  // seconds, fastest of the repetitions
  long rss_base_kb = 0, rss_peak_kb = 0;
  double residual = 0;                      // |A Y - B U| / (|A| |Y| + |B U|), max norms
  lptv::cd probe[4];                        // Y at fixed lines, compared across solvers
  // KLU child only: the factorisation broken down (seconds) and the largest relative
  // difference of the alternatives' solutions from Y.
  double klu_analyze = 0, klu_factor = 0, klu_natural_analyze = 0, klu_natural_factor = 0;
  double zgbsv = 0, alt_diff = 0;
  int ok = 0;
  char error[240] = {0};  // why the child failed
};

long max_rss_kb() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// KLU on A with the given ordering: analysis and numeric factorisation timed, then a solve.
Eigen::VectorXcd klu_direct(const lptv::SpMat& A, const Eigen::VectorXcd& rhs, bool natural,
                            double* t_analyze, double* t_factor) {
  klu_common common;
  klu_defaults(&common);
  const int n = static_cast<int>(A.rows());
  int* Ap = const_cast<int*>(A.outerIndexPtr());
  int* Ai = const_cast<int*>(A.innerIndexPtr());
  auto t0 = std::chrono::steady_clock::now();
  klu_symbolic* sym;
  if (natural) {
    common.btf = 0;
    sym = klu_analyze_given(n, Ap, Ai, nullptr, nullptr, &common);
  } else {
    sym = klu_analyze(n, Ap, Ai, &common);
  }
  *t_analyze = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  klu_numeric* num = sym ? klu_z_factor(Ap, Ai, reinterpret_cast<double*>(const_cast<lptv::cd*>(
                                                 A.valuePtr())), sym, &common)
                         : nullptr;
  if (!num) {
    if (sym) klu_free_symbolic(&sym, &common);
    throw std::runtime_error("KLU failed, status " + std::to_string(common.status));
  }
  *t_factor = seconds_since(t0);
  Eigen::VectorXcd x = rhs;
  klu_z_solve(sym, num, n, 1, reinterpret_cast<double*>(x.data()), &common);
  klu_z_free_numeric(&num, &common);
  klu_free_symbolic(&sym, &common);
  return x;
}

// LAPACK's band LU (zgbsv) on A, bandwidth K; the conversion to band storage is not timed.
Eigen::VectorXcd band_lu(const lptv::SpMat& A, int K, const Eigen::VectorXcd& rhs, double* t) {
  const lapack_int n = static_cast<lapack_int>(A.rows()), ldab = 3 * K + 1;
  std::vector<lapack_complex_double> ab(static_cast<size_t>(ldab) * n);
  std::fill(ab.begin(), ab.end(), lapack_make_complex_double(0.0, 0.0));
  for (int j = 0; j < A.outerSize(); ++j)
    for (lptv::SpMat::InnerIterator it(A, j); it; ++it)  // column-major band: row K + K + i - j
      ab[static_cast<size_t>(j) * ldab + 2 * K + it.row() - j] =
          lapack_make_complex_double(it.value().real(), it.value().imag());
  Eigen::VectorXcd x = rhs;
  std::vector<lapack_int> ipiv(n);
  const auto t0 = std::chrono::steady_clock::now();
  const lapack_int info = LAPACKE_zgbsv(LAPACK_COL_MAJOR, n, K, K, 1, ab.data(), ldab, ipiv.data(),
                                        reinterpret_cast<lapack_complex_double*>(x.data()), n);
  if (info != 0) throw std::runtime_error("zgbsv failed, info " + std::to_string(info));
  *t = seconds_since(t0);
  return x;
}

// A failed alternative keeps its times at -1 (reported as failed); it does not fail the row.
void breakdown(const lptv::SpMat& A, const Eigen::VectorXcd& BU, const Eigen::VectorXcd& Y,
               Measurement& m) {
  const double scale = Y.cwiseAbs().maxCoeff();
  auto attempt = [&](const char* name, auto&& f) {
    try {
      m.alt_diff = std::max(m.alt_diff, (f() - Y).cwiseAbs().maxCoeff() / scale);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "n = %ld, %s: %s\n", static_cast<long>(A.rows()), name, e.what());
    }
  };
  m.klu_analyze = m.klu_factor = m.klu_natural_analyze = m.klu_natural_factor = m.zgbsv = -1;
  // The fastest of a few runs below 10^6 lines (the first LAPACK call also sets up threads).
  const int reps = A.rows() < 1000000 ? 5 : 1;
  auto fastest = [&](double* t1, double* t2, auto&& run) {
    Eigen::VectorXcd x;
    double b1 = 1e300, b2 = 1e300;
    for (int r = 0; r < reps; ++r) {
      x = run();
      b1 = std::min(b1, *t1);
      if (t2) b2 = std::min(b2, *t2);
    }
    *t1 = b1;
    if (t2) *t2 = b2;
    return x;
  };
  attempt("KLU", [&] {
    return fastest(&m.klu_analyze, &m.klu_factor,
                   [&] { return klu_direct(A, BU, false, &m.klu_analyze, &m.klu_factor); });
  });
  attempt("KLU natural order", [&] {
    return fastest(&m.klu_natural_analyze, &m.klu_natural_factor, [&] {
      return klu_direct(A, BU, true, &m.klu_natural_analyze, &m.klu_natural_factor);
    });
  });
  attempt("zgbsv", [&] {
    return fastest(&m.zgbsv, nullptr, [&] { return band_lu(A, 3, BU, &m.zgbsv); });
  });
}

Measurement measure(const lptv::Model& model, int L, lptv::Solver solver) {
  Measurement m;
  m.rss_base_kb = max_rss_kb();
  const lptv::Grid g = lptv::make_grid(model, L);
  std::mt19937_64 gen(7);
  std::normal_distribution<double> nd;
  Eigen::VectorXcd U(g.N);
  for (int i = 0; i < g.N; ++i) U[i] = lptv::cd(nd(gen), nd(gen));
  // Repetitions for about a second of work at the small sizes, one at 10^7 lines; the fastest
  // counts (on a shared machine it is the least disturbed).
  const int reps = g.N > 5000000 ? 1 : std::max(3, std::min(21, 2000000 / g.N));
  std::vector<double> tb, tf, ts;
  Eigen::VectorXcd Y, BU;
  lptv::SpMat A;
  for (int r = 0; r < reps; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    A = lptv::build_A(model, g);
    const lptv::SpMat B = lptv::build_B(model, g);
    tb.push_back(seconds_since(t0));
    t0 = std::chrono::steady_clock::now();
    lptv::SparseLU lu(A, solver, [](int col) { return "column " + std::to_string(col); });
    tf.push_back(seconds_since(t0));
    t0 = std::chrono::steady_clock::now();
    BU = B * U;
    Y = lu.solve(BU);
    ts.push_back(seconds_since(t0));
  }
  auto fastest = [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); };
  m.build = fastest(tb);
  m.factor = fastest(tf);
  m.solve = fastest(ts);
  m.rss_peak_kb = max_rss_kb();
  double anorm = 0;
  for (int k = 0; k < A.outerSize(); ++k)
    for (lptv::SpMat::InnerIterator it(A, k); it; ++it) anorm = std::max(anorm, std::abs(it.value()));
  const Eigen::VectorXcd res = A * Y - BU;
  m.residual = res.cwiseAbs().maxCoeff() /
               (anorm * Y.cwiseAbs().maxCoeff() + BU.cwiseAbs().maxCoeff());
  const int idx[4] = {0, g.N / 3, g.N / 2, g.N - 1};
  for (int i = 0; i < 4; ++i) m.probe[i] = Y[idx[i]];
  if (solver == lptv::Solver::KLU) breakdown(A, BU, Y, m);
  m.ok = 1;
  return m;
}

// Runs measure() in a child process; ok = 0 when the child failed.
Measurement measure_in_child(const lptv::Model& model, int L, lptv::Solver solver) {
  int fd[2];
  if (pipe(fd) != 0) throw std::runtime_error("pipe failed");
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    close(fd[0]);
    Measurement m;
    try {
      m = measure(model, L, solver);
    } catch (const std::exception& e) {
      std::snprintf(m.error, sizeof m.error, "%s", e.what());
    }
    const ssize_t w = write(fd[1], &m, sizeof m);
    close(fd[1]);
    _exit(w == static_cast<ssize_t>(sizeof m) ? 0 : 1);
  }
  close(fd[1]);
  Measurement m;
  size_t got = 0;
  while (got < sizeof m) {
    const ssize_t r = read(fd[0], reinterpret_cast<char*>(&m) + got, sizeof m - got);
    if (r <= 0) break;
    got += static_cast<size_t>(r);
  }
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (got != sizeof m || !WIFEXITED(status) || WEXITSTATUS(status) != 0) m.ok = 0;
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const long max_lines = argc > 1 ? std::strtol(argv[1], nullptr, 10) : 10000000L;
  const lptv::Model model = bench::paper_model();
  std::printf("FDS scaling, paper-like model (A and B with 7 diagonals), grid of n lines, one "
              "input\n");
  std::printf("times are per line (total / n): build A,B + factorise A + solve; peak = extra "
              "resident memory (ru_maxrss)\n\n");
  std::printf("%10s %-8s %10s %10s %10s %12s %10s %10s %9s\n", "lines", "solver", "build",
              "factor", "solve", "total/line", "total", "peak [MB]", "residual");
  struct Row {
    long n;
    double per_line[2];
    long peak_kb[2];
    Measurement klu;
  };
  std::vector<Row> rows;
  bool failed = false;
  for (long n = 1000; n <= max_lines; n *= 10) {
    const int L = static_cast<int>((n - 1) / 2);
    Row row{2L * L + 1, {0, 0}, {0, 0}, {}};
    Measurement ms[2];
    const lptv::Solver solvers[2] = {lptv::Solver::KLU, lptv::Solver::UMFPACK};
    for (int s = 0; s < 2; ++s) {
      const Measurement& m = ms[s] = measure_in_child(model, L, solvers[s]);
      if (!m.ok) {
        // A solver that cannot handle the size is a result, not a failure of the benchmark.
        std::printf("%10ld %-8s failed: %s\n", row.n, lptv::solver_name(solvers[s]).c_str(),
                    m.error[0] ? m.error : "the child process died (out of memory?)");
        continue;
      }
      const double total = m.build + m.factor + m.solve;
      row.per_line[s] = total / double(row.n);
      row.peak_kb[s] = m.rss_peak_kb - m.rss_base_kb;
      std::printf("%10ld %-8s %8.0f ns %8.0f ns %8.0f ns %9.0f ns %8.3f s %10.1f %9.1e\n", row.n,
                  lptv::solver_name(solvers[s]).c_str(), 1e9 * m.build / double(row.n),
                  1e9 * m.factor / double(row.n), 1e9 * m.solve / double(row.n),
                  1e9 * row.per_line[s], total, row.peak_kb[s] / 1024.0, m.residual);
      if (!(m.residual < 1e-12)) {
        std::fprintf(stderr, "residual too large at n = %ld\n", row.n);
        failed = true;
      }
    }
    row.klu = ms[0];
    if (ms[0].ok && !(ms[0].alt_diff <= 1e-10)) {
      std::fprintf(stderr, "factorisation alternatives disagree at n = %ld: %.1e\n", row.n,
                   ms[0].alt_diff);
      failed = true;
    }
    if (ms[0].ok && ms[1].ok) {
      // The two factorisations must give the same solution.
      double diff = 0, scale = 0;
      for (int i = 0; i < 4; ++i) {
        diff = std::max(diff, std::abs(ms[0].probe[i] - ms[1].probe[i]));
        scale = std::max(scale, std::abs(ms[0].probe[i]));
      }
      if (!(diff <= 1e-10 * scale)) {
        std::fprintf(stderr, "KLU and UMFPACK disagree at n = %ld: %.1e\n", row.n, diff / scale);
        failed = true;
      }
    }
    rows.push_back(row);
  }
  std::printf("\n%10s %14s %14s %12s\n", "lines", "KLU ns/line", "UMFPACK ns/line",
              "UMFPACK/KLU");
  double lo[2] = {1e300, 1e300}, hi[2] = {0, 0};
  for (const Row& r : rows) {
    std::printf("%10ld", r.n);
    for (int s = 0; s < 2; ++s) {
      if (r.per_line[s] > 0) std::printf(" %14.0f", 1e9 * r.per_line[s]);
      else std::printf(" %14s", "failed");
    }
    if (r.per_line[0] > 0 && r.per_line[1] > 0) std::printf(" %12.2f\n", r.per_line[1] / r.per_line[0]);
    else std::printf(" %12s\n", "-");
    for (int s = 0; s < 2; ++s) {
      if (r.per_line[s] <= 0) continue;
      lo[s] = std::min(lo[s], r.per_line[s]);
      hi[s] = std::max(hi[s], r.per_line[s]);
    }
  }
  std::printf("\nthe factorisation of A alone, ns per line: KLU as lptv uses it (AMD + BTF "
              "ordering), KLU in the natural order without BTF, LAPACK band LU (zgbsv, with solve)"
              "\n%10s %12s %12s %12s %12s %12s %12s\n", "lines", "KLU analyze", "KLU factor",
              "natural an.", "natural fac.", "zgbsv", "max diff");
  for (const Row& r : rows) {
    if (!r.klu.ok) continue;
    const double n = double(r.n);
    std::printf("%10ld", r.n);
    for (double t : {r.klu.klu_analyze, r.klu.klu_factor, r.klu.klu_natural_analyze,
                     r.klu.klu_natural_factor, r.klu.zgbsv}) {
      if (t < 0) std::printf(" %12s", "failed");
      else std::printf(" %12.0f", 1e9 * t / n);
    }
    std::printf(" %12.1e\n", r.klu.alt_diff);
  }
  std::printf("\nspread of the time per line (max / min over sizes; goal: within 2x): KLU %.2fx, "
              "UMFPACK %.2fx\n", hi[0] / lo[0], hi[1] / lo[1]);
  return failed ? 1 : 0;
}
