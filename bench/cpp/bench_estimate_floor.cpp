// WGTLS and SML of the core against their LAPACK floor, on the paper-like example.
//
// Data: the paper-like model (bench_common.hpp), lines 10..240 excited, N = 2048, P = 8
// periods with white noise on input and output (50 dB and 30 dB below the signals' rms);
// na = 2, nb = 1, K = 3 on every coefficient: 35 real columns (n_xi), rows = lines 1..243,
// so the real Jacobian is 486 x 35.
//
// The floor of one step (a WGTLS solve, an SML Gauss-Newton step) is the dense algebra no
// implementation of the method avoids: a QR of the 486 x 35 real Jacobian (LAPACK dgeqrt with
// blocks of 8, the faster of LAPACK's two QRs at this shape: dgeqrf leaves fewer than 128
// columns to its unblocked code; the floor took dgeqrf until the estimator moved to dgeqrt)
// and an SVD of the 35 x 35 triangle with its right singular vectors (dgesvd, jobvt = 'A'),
// both on one thread, as the estimator runs. A fit's floor is its number of steps times
// that: WGTLS, its GTLS start and each weighted solve (1 + iterations); SML, those of its
// WGTLS start (stopped at 1e-6, EstimateResult::start_iterations) and each accepted
// Levenberg-Marquardt step. Every route is timed in the same run,
// taking turns, each one's fastest round counting (the least disturbed by other work).
//
// Usage: bench_estimate_floor [seeds]   (default 3)
//        bench_estimate_floor --loop wgtls|sml SECONDS   (one method in a loop, for a profiler;
//        --loop identify-wgtls|identify-sml: lptv::identify, with the covariance and diagnostics)
#include <cstdio>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "lptv/estimators.hpp"
#include "lptv/fds.hpp"
#include "lptv/jacobian.hpp"
#include "lptv/likelihood.hpp"
#include "lptv/noise.hpp"
#include "rows.hpp"  // lptv::detail::SingleThreadedBlas (private: the benchmarks are in-tree)

extern "C" {
void dgeqrt_(const int* m, const int* n, const int* nb, double* a, const int* lda, double* t, const int* ldt,
             double* work, int* info);
void dgesvd_(const char* jobu, const char* jobvt, const int* m, const int* n, double* a, const int* lda,
             double* s, double* u, const int* ldu, double* vt, const int* ldvt, double* work,
             const int* lwork, int* info);
}

namespace {

constexpr int kPeriods = 8;

// P noisy periods of the paper-like example; seed picks the phases and the noise.
lptv::FrequencyData measurements(unsigned seed) {
  const int N = bench::kSamples;
  const Eigen::VectorXcd U0 = bench::paper_input(seed);
  const lptv::Model m = bench::paper_model();
  const lptv::SimulateResult sim = lptv::simulate(m, U0);
  Eigen::VectorXcd Y0 = Eigen::VectorXcd::Zero(U0.size());
  const Eigen::Index n = std::min<Eigen::Index>(Y0.size(), sim.Y.rows());
  Y0.head(n) = sim.Y.col(0).head(n);
  Y0[0] = Y0[0].real();
  Y0[N / 2] = Y0[N / 2].real();
  const Eigen::VectorXd u0 = lptv::time_signal(U0, N), y0 = lptv::time_signal(Y0, N);
  const double su = std::sqrt(u0.squaredNorm() / N) * std::pow(10.0, -50.0 / 20.0);
  const double sy = std::sqrt(y0.squaredNorm() / N) * std::pow(10.0, -30.0 / 20.0);
  std::mt19937_64 gen(1000 + seed);
  std::normal_distribution<double> nd;
  Eigen::MatrixXd u(kPeriods, N), y(kPeriods, N);
  for (int p = 0; p < kPeriods; ++p)
    for (int t = 0; t < N; ++t) {
      u(p, t) = u0[t] + su * nd(gen);
      y(p, t) = y0[t] + sy * nd(gen);
    }
  return lptv::frequency_data_from_periods(u, y);
}

lptv::Parametrisation paper_parametrisation() {
  lptv::Structure s;
  s.na = 2;
  s.nb = 1;
  s.ka.assign(3, 3);
  s.kb.assign(2, 3);
  s.w0 = bench::kW0;
  return lptv::Parametrisation(s);
}

// One floor step: dgeqrt (blocks of 8) of an m x n matrix, then dgesvd of its n x n triangle.
struct FloorStep {
  int m, n;
  Eigen::MatrixXd J, A, tri;
  Eigen::VectorXd s;
  Eigen::MatrixXd vt;
  std::vector<double> wq, tq, ws;
  static constexpr int kBlock = 8;
  FloorStep(const Eigen::MatrixXd& jac) : m(int(jac.rows())), n(int(jac.cols())), J(jac) {
    A = J;
    s.resize(n);
    vt.resize(n, n);
    tri = Eigen::MatrixXd::Zero(n, n);
    double q = 0, u = 0;
    int lw = -1, info = 0, one = 1;
    wq.resize(std::max(1, kBlock * n));   // dgeqrt's workspace
    tq.resize(std::max(1, kBlock * n));   // and its block reflectors
    dgesvd_("N", "A", &n, &n, tri.data(), &n, s.data(), &u, &one, vt.data(), &n, &q, &lw, &info);
    ws.resize(std::max(1, int(q)));
  }
  void run() {
    A = J;
    int lw = 0, info = 0, one = 1, nb = std::min(kBlock, std::min(m, n));
    dgeqrt_(&m, &n, &nb, A.data(), &m, tq.data(), &nb, wq.data(), &info);
    if (info != 0) throw std::runtime_error("the floor's dgeqrt failed, info " + std::to_string(info));
    tri = A.topRows(n).triangularView<Eigen::Upper>();
    double u = 0;
    lw = int(ws.size());
    dgesvd_("N", "A", &n, &n, tri.data(), &n, s.data(), &u, &one, vt.data(), &n, ws.data(), &lw, &info);
    if (info != 0) throw std::runtime_error("the floor's dgesvd failed, info " + std::to_string(info));
  }
};

}  // namespace

int run(int argc, char** argv) {
  const lptv::detail::SingleThreadedBlas one_thread(true);
  const lptv::Parametrisation p = paper_parametrisation();
  std::vector<int> rows;
  for (int l = 1; l <= 243; ++l) rows.push_back(l);
  if (argc > 3 && std::string(argv[1]) == "--loop" && std::string(argv[2]) == "covariance-terms") {
    // WGTLS's covariance terms at its estimate: the first-order sandwich and the second-order
    // terms, each timed alone (ms per call, fastest of 5 rounds of SECONDS / 10 each).
    const lptv::FrequencyData d = measurements(1);
    lptv::EstimateOptions o;
    o.tol = 1e-12;
    const lptv::EstimateResult er = lptv::estimate(d, p, rows, o);
    const lptv::ExactLikelihood lik(d, p, rows);
    Eigen::VectorXd w = lptv::residue_variance(d, p, rows, er.theta).cwiseInverse();
    auto time = [&](auto&& f) {
      double best = 1e30;
      for (int round = 0; round < 5; ++round) {
        const auto t0 = std::chrono::steady_clock::now();
        int n = 0;
        while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < std::atof(argv[3]) / 10) {
          f();
          ++n;
        }
        best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / n);
      }
      return best;
    };
    const double t1 = time([&] { (void)lik.sandwich_terms(er.theta, w); });
    const double t2 = time([&] { (void)lptv::second_order_meat(lik.second_order_terms(er.theta, w), p, er.theta); });
    std::printf("sandwich terms %.3f ms, second-order terms %.3f ms\n", t1, t2);
    return 0;
  }
  if (argc > 3 && std::string(argv[1]) == "--loop") {
    const lptv::FrequencyData d = measurements(1);
    const std::string what = argv[2];
    const bool whole = what.rfind("identify-", 0) == 0;
    lptv::EstimateOptions o;
    o.method = lptv::method_from_string(whole ? what.substr(9) : what);
    o.tol = 1e-12;
    lptv::IdentifyOptions io;
    io.method = o.method;
    io.tol = o.tol;
    io.rows = rows;
    const auto t0 = std::chrono::steady_clock::now();
    int n = 0;
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < std::atof(argv[3])) {
      if (whole) {
        (void)lptv::identify(d, p.structure(), io);
      } else {
        (void)lptv::estimate(d, p, rows, o);
      }
      ++n;
    }
    std::printf("%s: %d fits\n", argv[2], n);
    return 0;
  }
  const int n_seeds = static_cast<int>(bench::int_arg(argc, argv, 1, 3, 1, 1000, "bench_estimate_floor",
                                                      "bench_estimate_floor [seeds] | --loop WHAT SECONDS"));
  std::printf("WGTLS and SML of the core against their LAPACK floor (paper-like example, P = %d, "
              "rows 1..243, na=2 nb=1 K=3: %d x %d real Jacobian)\n",
              kPeriods, 2 * int(rows.size()), p.n_xi());
  std::printf("floor step = dgeqrt (blocks of 8) of the Jacobian + dgesvd (right vectors) of its triangle, one thread; "
              "times: fastest of 15 interleaved rounds\n\n");
  std::printf("%4s %6s %9s %9s %9s %6s %9s %9s %7s %7s\n", "seed", "step", "wgtls", "steps", "floor", "ratio",
              "sml", "steps", "floor", "ratio");
  double worst_w = 0, worst_s = 0;
  for (int seed = 1; seed <= n_seeds; ++seed) {
    const lptv::FrequencyData d = measurements(seed);
    lptv::EstimateOptions ow, os;
    ow.method = lptv::Method::WGTLS;
    ow.tol = 1e-12;
    os.method = lptv::Method::SML;
    os.tol = 1e-12;
    const lptv::EstimateResult rw = lptv::estimate(d, p, rows, ow);
    const lptv::EstimateResult rs = lptv::estimate(d, p, rows, os);
    std::mt19937_64 gen(seed);
    std::normal_distribution<double> nd;
    Eigen::MatrixXd J(2 * rows.size(), p.n_xi());
    for (Eigen::Index i = 0; i < J.size(); ++i) J.data()[i] = nd(gen);
    FloorStep floor(J);
    double tw = 1e300, ts = 1e300, tf = 1e300;
    for (int round = 0; round < 15; ++round) {
      tw = std::min(tw, bench::min_time(1, [&] { (void)lptv::estimate(d, p, rows, ow); }));
      ts = std::min(ts, bench::min_time(1, [&] { (void)lptv::estimate(d, p, rows, os); }));
      tf = std::min(tf, bench::min_time(3, [&] { floor.run(); }));
    }
    const int steps_w = 1 + rw.iterations, steps_s = 1 + rs.start_iterations + rs.iterations;
    const double fw = steps_w * tf, fs = steps_s * tf;
    std::printf("%4d %4.0fus %7.2fms %9d %7.2fms %5.2fx %7.2fms %9d %5.2fms %6.2fx\n", seed, 1e6 * tf, 1e3 * tw,
                steps_w, 1e3 * fw, tw / fw, 1e3 * ts, steps_s, 1e3 * fs, ts / fs);
    worst_w = std::max(worst_w, tw / fw);
    worst_s = std::max(worst_s, ts / fs);
  }
  std::printf("\nWGTLS / floor (goal <= 1.5x): worst %.2fx; SML / floor (goal <= 2x): worst %.2fx\n", worst_w,
              worst_s);
  return 0;
}

int main(int argc, char** argv) {
  return bench::guarded_main("bench_estimate_floor", [&] { return run(argc, argv); });
}
