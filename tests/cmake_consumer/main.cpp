// A user's program with the installed lptv: simulate 1/(s+1) driven by cos(t), then identify
// 2/(s+2) from noisy periods with the exact likelihood (method SML) and read the covariance.
#include <lptv/estimators.hpp>
#include <lptv/fds.hpp>
#include <lptv/multisine.hpp>
#include <lptv/noise.hpp>

#include <cmath>
#include <cstdio>
#include <random>

namespace {

int simulate_one() {
  Eigen::MatrixXcd a(2, 1), b(1, 1);
  a << 1.0, 1.0;
  b << 1.0;
  const lptv::Model m(a, b, /*w0=*/1.0);
  Eigen::MatrixXcd U = Eigen::MatrixXcd::Zero(3, 1);
  U(1, 0) = 0.5;
  const auto r = lptv::simulate(m, U);
  const std::complex<double> expected = 0.5 / std::complex<double>(1.0, 1.0);
  const double err = std::abs(r.Y(1, 0) - expected);
  std::printf("lptv consumer: Y_1 = %.6f%+.6fj, error %.1e\n", r.Y(1, 0).real(), r.Y(1, 0).imag(), err);
  return err < 1e-14 ? 0 : 1;
}

int identify_one() {
  // 2 / (s + 2) normalised as a_1 = 1: a = (2, 1), b = (2); 8 periods of N samples.
  Eigen::MatrixXcd a(2, 1), b(1, 1);
  a << 2.0, 1.0;
  b << 2.0;
  const double w0 = 0.1;
  const int N = 256, P = 8;
  const lptv::Model m(a, b, w0);
  std::vector<int> lines;
  for (int l = 1; l < 60; ++l) lines.push_back(l);
  std::mt19937 gen(2);
  std::uniform_real_distribution<double> phase(0.0, 2 * M_PI);
  Eigen::VectorXd phases(lines.size());
  for (auto& v : phases) v = phase(gen);
  Eigen::MatrixXcd U(N / 2 + 1, 1);
  U.col(0) = lptv::multisine_spectrum(lines, Eigen::VectorXd::Ones(lines.size()), phases, N);
  const Eigen::VectorXd u = lptv::time_signal(U.col(0), N);
  const Eigen::VectorXd y = lptv::time_signal(lptv::simulate(m, U).Y.col(0), N);
  std::normal_distribution<double> noise(0.0, 0.01);
  Eigen::MatrixXd up(P, N), yp(P, N);
  for (int p = 0; p < P; ++p)
    for (int t = 0; t < N; ++t) up(p, t) = u[t] + noise(gen), yp(p, t) = y[t] + noise(gen);
  const lptv::FrequencyData d = lptv::frequency_data_from_periods(up, yp);

  lptv::Structure s;
  s.na = 1, s.nb = 0, s.ka = {0, 0}, s.kb = {0}, s.w0 = w0;
  lptv::IdentifyOptions opt;
  opt.method = lptv::Method::SML;
  const lptv::Identification r = lptv::identify(d, s, opt);
  int bad = 0;
  for (int i = 0; i < r.eta.size(); ++i) {
    const double sd = std::sqrt(r.covariance(i, i));
    std::printf("lptv consumer: %s = %.5f +- %.5f\n", r.eta_names[i].c_str(), r.eta[i], sd);
    const double truth = i == 0 ? 2.0 : i == 1 ? 1.0 : 2.0;
    if (sd > 0 ? std::abs(r.eta[i] - truth) > 5 * sd : r.eta[i] != truth) ++bad;
  }
  return r.converged && bad == 0 ? 0 : 1;
}

}  // namespace

int main() { return simulate_one() | identify_one(); }
