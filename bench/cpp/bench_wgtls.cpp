// One WGTLS iteration (METHOD.md section 6: residue variance, weighted R factor, column
// covariance CJ_W, GSVD) as the number of rows and of parameters grows. Each size runs in a
// child process so that its peak memory (ru_maxrss) is its own.
//
// The data are random spectra with random variances: the cost of an iteration depends on the
// sizes only. The whole iteration is timed as lptv::estimate runs it, and each of its four
// steps alone; each time is the fastest of several runs (the least disturbed by other work).
// The weighted R factor runs on two threads from 20 000 rows (lptv's row split).
//
// Usage: bench_wgtls [max_rows]   rows 10^3..max_rows (default 10^6) at 35 parameters, and 5..295
//        parameters at min(10^4, max_rows) rows
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "lptv/estimators.hpp"

namespace {

lptv::FrequencyData random_data(int lines, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> nd;
  lptv::FrequencyData d;
  d.U.resize(lines + 1);
  d.Y.resize(lines + 1);
  d.varU.resize(lines + 1);
  d.varY.resize(lines + 1);
  d.covYU.resize(lines + 1);
  for (int l = 0; l <= lines; ++l) {
    d.U[l] = {nd(gen), l ? nd(gen) : 0.0};
    d.Y[l] = {nd(gen), l ? nd(gen) : 0.0};
    d.varU[l] = 1e-4 * (1 + std::abs(nd(gen)));
    d.varY[l] = 1e-3 * (1 + std::abs(nd(gen)));
    d.covYU[l] = {1e-4 * nd(gen), 1e-4 * nd(gen)};
  }
  return d;
}

struct Run {
  double whole = 0, variance = 0, r_factor = 0, covariance = 0, gsvd = 0;  // seconds
  long maxrss_kb = 0, data_kb = 0;
  int params = 0;
  char error[200] = {0};  // why the child failed (empty when it did not)
};

// Fastest of at least 3 calls (after a warm-up), more while they add up to under a second.
template <class F>
double fastest(F&& f) {
  f();
  double best = 1e300, total = 0;
  for (int r = 0; r < 21 && (r < 3 || total < 1.0); ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, t);
    total += t;
  }
  return best;
}

Run one_iteration(int rows, int na, int nb, int K) {
  lptv::Structure s;
  s.na = na;
  s.nb = nb;
  s.ka.assign(na + 1, K);
  s.kb.assign(nb + 1, K);
  s.w0 = 1e-3;
  const lptv::Parametrisation p(s);
  const lptv::FrequencyData d = random_data(rows + 2 * K + 2, 1);
  std::vector<int> r;
  for (int l = K + 1; l <= K + rows; ++l) r.push_back(l);
  Eigen::VectorXcd theta = Eigen::VectorXcd::Zero(p.n_theta());
  theta[p.theta_index(true, na, 0)] = 1.0;
  theta[p.theta_index(false, 0, 0)] = 1.0;
  Run out;
  out.params = p.n_xi();
  out.data_kb = static_cast<long>(d.U.size()) * (3 * 16 + 2 * 8) / 1024;
  out.whole = fastest([&] {
    const Eigen::VectorXd v = lptv::residue_variance(d, p, r, theta);
    const Eigen::VectorXd w = v.cwiseInverse();
    const Eigen::MatrixXd R = lptv::weighted_r_factor(d, p, r, w);
    const Eigen::MatrixXd CJ = lptv::real_column_covariance(d, p, r, w);
    const auto g = lptv::gtls_from_r(R, CJ);
    if (!g.x.allFinite())
      throw std::runtime_error("the GSVD's solution is not finite at " + std::to_string(rows) + " rows, K = " +
                               std::to_string(K));
  });
  const Eigen::VectorXd w = lptv::residue_variance(d, p, r, theta).cwiseInverse();
  const Eigen::MatrixXd R = lptv::weighted_r_factor(d, p, r, w);
  const Eigen::MatrixXd CJ = lptv::real_column_covariance(d, p, r, w);
  out.variance = fastest([&] { (void)lptv::residue_variance(d, p, r, theta); });
  out.r_factor = fastest([&] { (void)lptv::weighted_r_factor(d, p, r, w); });
  out.covariance = fastest([&] { (void)lptv::real_column_covariance(d, p, r, w); });
  out.gsvd = fastest([&] { (void)lptv::gtls_from_r(R, CJ); });
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  out.maxrss_kb = ru.ru_maxrss;
  return out;
}

Run in_child(int rows, int na, int nb, int K) {
  int fd[2];
  if (pipe(fd) != 0) throw std::runtime_error(std::string("pipe failed: ") + std::strerror(errno));
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    close(fd[0]);
    Run r;
    try {
      r = one_iteration(rows, na, nb, K);
    } catch (const std::exception& e) {
      r = Run();
      std::snprintf(r.error, sizeof r.error, "%s", e.what());
    }
    _exit(write(fd[1], &r, sizeof r) == sizeof r ? 0 : 1);
  }
  close(fd[1]);
  Run r{};
  size_t got = 0;
  while (got < sizeof r) {
    const ssize_t n = read(fd[0], reinterpret_cast<char*>(&r) + got, sizeof r - got);
    if (n <= 0) break;
    got += static_cast<size_t>(n);
  }
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string what = std::to_string(rows) + " rows, K = " + std::to_string(K);
  if (got != sizeof r) {
    throw std::runtime_error("the child process for " + what + " ended without its result (" +
                             (WIFSIGNALED(status) ? "signal " + std::string(strsignal(WTERMSIG(status)))
                                                  : "exit status " + std::to_string(WEXITSTATUS(status))) +
                             "; out of memory?)");
  }
  if (r.error[0]) throw std::runtime_error(std::string(r.error));
  return r;
}

void print(long first, const Run& r, long rows) {
  std::printf("%9ld %6d %10.4f %10.3f %10.2f %10.2f %10.2f %10.2f %9.1f %9.1f\n", first, r.params,
              r.whole, 1e6 * r.whole / double(rows), 1e3 * r.variance, 1e3 * r.r_factor,
              1e3 * r.covariance, 1e3 * r.gsvd, r.maxrss_kb / 1024.0, r.data_kb / 1024.0);
}

const char* kHead = "%9s %6s %10s %10s %10s %10s %10s %10s %9s %9s\n";

}  // namespace

int run(int argc, char** argv) {
  const long max_rows = bench::int_arg(argc, argv, 1, 1000000, 1000, 10000000, "bench_wgtls", "bench_wgtls [max_rows]");
  std::printf("One WGTLS iteration: residue variance (var e) + weighted R factor (QR) + column "
              "covariance (CJ_W) + GSVD\nsteps timed alone in ms; fastest of several runs; "
              "peak = the child's ru_maxrss, data = the spectra and variances it holds\n\n");
  std::printf("na=2, nb=1, K=3 on every coefficient (35 parameters)\n");
  std::printf(kHead, "rows", "params", "iter [s]", "us/row", "var e", "R factor", "CJ_W", "GSVD",
              "peak MB", "data MB");
  double at_1e6 = -1;
  for (int rows : {1000, 10000, 100000, 1000000}) {
    if (rows > max_rows) break;
    const Run r = in_child(rows, 2, 1, 3);
    print(rows, r, rows);
    if (rows == 1000000) at_1e6 = r.whole;
  }
  const int rows_k = static_cast<int>(std::min(10000L, max_rows));
  std::printf("\n%d rows, na=2, nb=1, K harmonics on every coefficient\n", rows_k);
  std::printf(kHead, "K", "params", "iter [s]", "us/row", "var e", "R factor", "CJ_W", "GSVD",
              "peak MB", "data MB");
  for (int K : {0, 1, 3, 7, 14, 29}) print(K, in_child(rows_k, 2, 1, K), rows_k);
  if (at_1e6 > 0) {
    std::printf("\ngoal: one iteration at 10^6 rows x 35 parameters under 1 s: %.2f s (%s)\n",
                at_1e6, at_1e6 < 1.0 ? "met" : "not met");
  } else {
    std::printf("\ngoal: one iteration at 10^6 rows x 35 parameters under 1 s: not judged (rows up to %ld only)\n",
                max_rows);
  }
  return 0;
}

int main(int argc, char** argv) {
  return bench::guarded_main("bench_wgtls", [&] { return run(argc, argv); });
}
