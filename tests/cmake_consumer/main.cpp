// A user's program: simulate 1/(s+1) driven by cos(t) with the installed lptv.
#include <lptv/fds.hpp>

#include <cmath>
#include <cstdio>

int main() {
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
