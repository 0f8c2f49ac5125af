// lptv::frequency_data_from_record_spectra (METHOD.md section 20) against sums written out here:
// the record's DFT bins between the lines by direct summation, the periods' statistics for the
// lines 0 and N/2, the realisations' sums of squares equal to the (co)variances.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <random>
#include <stdexcept>

#include "lptv/noise.hpp"

using cd = std::complex<double>;

namespace {

// X(b) = (1 / M) sum_n x(n) exp(-j 2 pi b n / M), summed directly
cd dft(const Eigen::VectorXd& x, long b) {
  const long M = x.size();
  cd s = 0;
  for (long n = 0; n < M; ++n) s += x[n] * std::polar(1.0, -2.0 * M_PI * double((b * n) % M) / double(M));
  return s / double(M);
}

struct Case {
  lptv::PeriodSpectra Up, Yp;
  Eigen::VectorXcd Ur, Yr;
  Eigen::VectorXd u, y;
};

Case make_case(int P, int N, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  Case c;
  c.u.resize(P * N);
  c.y.resize(P * N);
  double state = 0;
  for (int n = 0; n < P * N; ++n) {  // a periodic part, white noise, and a slow random walk in y
    state = 0.97 * state + nd(gen);
    c.u[n] = std::cos(2 * M_PI * 3 * (n % N) / N) + 0.1 * nd(gen);
    c.y[n] = 0.5 * std::sin(2 * M_PI * 3 * (n % N) / N) + 0.1 * nd(gen) + 0.05 * state;
  }
  const int nl = N / 2 + 1;
  c.Up.resize(P, nl);
  c.Yp.resize(P, nl);
  for (int p = 0; p < P; ++p) {
    for (int l = 0; l < nl; ++l) {
      c.Up(p, l) = dft(c.u.segment(p * N, N), l);
      c.Yp(p, l) = dft(c.y.segment(p * N, N), l);
    }
  }
  const long nb = long(P) * N / 2 + 1;
  c.Ur.resize(nb);
  c.Yr.resize(nb);
  for (long b = 0; b < nb; ++b) {
    c.Ur[b] = dft(c.u, b);
    c.Yr[b] = dft(c.y, b);
  }
  return c;
}

}  // namespace

TEST_CASE("the record's statistics are the bins between the lines", "[noise][record]") {
  for (int P : {2, 3, 4, 7, 8}) {
    for (int N : {16, 17}) {
      const Case c = make_case(P, N, unsigned(100 * P + N));
      const auto d = lptv::frequency_data_from_record_spectra(c.Up, c.Yp, c.Ur, c.Yr, N);
      const auto dp = lptv::frequency_data_from_period_spectra(c.Up, c.Yp);
      const int nl = N / 2 + 1;
      REQUIRE(d.noiseU.rows() == P - 1);
      REQUIRE(d.noiseU.cols() == nl);
      const int last = (N % 2 == 0) ? nl - 2 : nl - 1;
      const double scale = (d.varY.maxCoeff() + d.varU.maxCoeff());
      for (int l = 0; l < nl; ++l) {
        CHECK(std::abs(d.U[l] - dp.U[l]) <= 1e-14);
        CHECK(std::abs(d.Y[l] - dp.Y[l]) <= 1e-14);
        double vu = 0, vy = 0;
        cd cyu = 0;
        if (l >= 1 && l <= last) {
          for (int q = -((P + 1) / 2) + 1; q <= P / 2; ++q) {
            if (q == 0) continue;
            const cd U = dft(c.u, long(l) * P + q), Y = dft(c.y, long(l) * P + q);
            vu += std::norm(U);
            vy += std::norm(Y);
            cyu += Y * std::conj(U);
          }
          vu /= (P - 1);
          vy /= (P - 1);
          cyu /= double(P - 1);
        } else {
          vu = dp.varU[l];
          vy = dp.varY[l];
          cyu = dp.covYU[l];
        }
        // sums of a few hundred products of numbers of order one: rounding of order 1e-15
        CHECK(std::abs(d.varU[l] - vu) <= 1e-12 * scale);
        CHECK(std::abs(d.varY[l] - vy) <= 1e-12 * scale);
        CHECK(std::abs(d.covYU[l] - cyu) <= 1e-12 * scale);
        CHECK(std::abs(d.noiseY.col(l).squaredNorm() - d.varY[l]) <= 1e-13 * scale);
        CHECK(std::abs(d.noiseU.col(l).squaredNorm() - d.varU[l]) <= 1e-13 * scale);
      }
      // the mean is the record's bin l P
      for (int l = 0; l < nl; ++l) CHECK(std::abs(d.U[l] - c.Ur[long(l) * P]) <= 1e-13);
      d.validate();
    }
  }
}

TEST_CASE("the record's statistics refuse inconsistent sizes", "[noise][record]") {
  const Case c = make_case(4, 16, 3);
  REQUIRE_THROWS_AS(lptv::frequency_data_from_record_spectra(c.Up, c.Yp, c.Ur, c.Yr, 18), std::invalid_argument);
  REQUIRE_THROWS_AS(lptv::frequency_data_from_record_spectra(c.Up, c.Yp, c.Ur.head(10), c.Yr, 16),
                    std::invalid_argument);
  Eigen::VectorXcd bad = c.Ur;
  bad[3] = cd(NAN, 0);
  REQUIRE_THROWS_AS(lptv::frequency_data_from_record_spectra(c.Up, c.Yp, bad, c.Yr, 16), std::invalid_argument);
}
