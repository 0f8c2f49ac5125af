"""lptv.moderated_noise in the C++ core against its NumPy/SciPy reference.

    python bench/python/bench_moderation_core.py [rounds]

Data: P = 4 periods of noise on lines 0..L (L = 1024 and 16384), its variance a smooth
coloured trend with a log-normal spread (sigma 0.3) about it, input and output correlated
(rho 0.3), from lptv.FrequencyData.from_periods; the default window (+-10 lines). The routes,
on the same FrequencyData:

- ``core``: ``lptv.moderated_noise`` (the arguments in Python, the computation in
  ``lptv::moderated_noise``);
- ``reference``: ``lptv.reference.moderation.moderated_noise`` (NumPy, SciPy's polygamma and
  F quantile).

The routes take turns in each round; each one's fastest round counts (a shared machine). The
two must agree (the same outliers, d0 to 1e-8, moderated varY to 1e-10 relative; asserted).
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

import lptv
from lptv.reference import moderation as ref


def data(L: int, P: int = 4, seed: int = 0):
    rng = np.random.default_rng(seed)
    l = np.arange(L + 1)
    trend = 1e-2 / (1 + (l / (L / 8)) ** 2)
    var_u = trend * np.exp(0.3 * rng.standard_normal(L + 1))
    var_y = 0.1 * trend * np.exp(0.3 * rng.standard_normal(L + 1))
    def noise():
        return (rng.standard_normal((P, L + 1)) + 1j * rng.standard_normal((P, L + 1))) / np.sqrt(2)
    eu, ey = noise(), noise()
    ey = 0.3 * eu + np.sqrt(1 - 0.09) * ey
    Eu, Ey = eu * np.sqrt(var_u), ey * np.sqrt(var_y)
    for E in (Eu, Ey):
        E[:, 0], E[:, -1] = E[:, 0].real, E[:, -1].real
    u = np.array([lptv.time_signal(x, 2 * L) for x in Eu])
    y = np.array([lptv.time_signal(x, 2 * L) for x in Ey])
    return lptv.FrequencyData.from_periods(u, y, w0=1.0)


def main(rounds: int = 7):
    print(f"lptv.moderated_noise, P = 4, half_width 10; fastest of {rounds} interleaved rounds; load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    for L in (1024, 16384):
        d = data(L)
        routes = {"core": lambda: lptv.moderated_noise(d), "reference": lambda: ref.moderated_noise(d)}
        a, b = routes["core"](), routes["reference"]()
        assert np.array_equal(a.outliers, b.outliers), f"L = {L}: the core's outliers differ from the reference's"
        assert abs(a.prior_dof - b.prior_dof) <= 1e-8 * b.prior_dof, \
            f"L = {L}: prior degrees of freedom {a.prior_dof} (core) and {b.prior_dof} (reference)"
        diff = float(np.max(np.abs(np.asarray(a.data.varY) / np.asarray(b.data.varY) - 1)))
        assert diff <= 1e-10, f"L = {L}: the moderated variances differ by {diff:.1e} relative (1e-10 at most expected)"
        best = {k: np.inf for k in routes}
        for _ in range(rounds):
            for k, f in routes.items():
                t0 = time.perf_counter()
                f()
                best[k] = min(best[k], time.perf_counter() - t0)
        print(f"L = {L}: d0 = {b.prior_dof:.2f}, {b.outliers.size} outliers; varY agree to {diff:.1e}")
        for k, v in best.items():
            print(f"  {k:12s} {1e3 * v:8.3f} ms")
        print(f"  reference / core: {best['reference'] / best['core']:.1f}x")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
