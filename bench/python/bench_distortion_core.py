"""The per-line regression of lptv.distortion in the C++ core against its NumPy reference.

    python bench/python/bench_distortion_core.py [rounds]

Data: the README's "From a real rig" example (the paper's model plus 0.02 y^3, M = 6
random-phase realisations of P = 4 periods, N = 2048, lines 10..240 excited; Kh = 19 branches
as lptv.distortion chooses). The routes, on the same period-mean spectra and variances:

- ``core``: ``lptv._core.distortion_lines`` (the regression of every output line on its
  excited neighbours across the realisations, METHOD.md section 16);
- ``reference``: ``lptv.reference.distortion.distortion_lines`` (the same in NumPy, one
  ``lstsq`` per line);
- ``distortion``: ``lptv.distortion(u, y, w0=...)`` as a user calls it (spectra from the
  periods, the core's regression, the F tests in SciPy).

The routes take turns in each round; each one's fastest round counts (a shared machine). The
two regressions must agree (BLA to 1e-10 relative, asserted).
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

import lptv
from lptv import _core
from lptv.examples import noisy_periods, paper_model
from lptv.reference import distortion as ref


def data():
    m = paper_model()
    u, y = [], []
    for r in range(6):
        ms = lptv.multisine(range(10, 241, 10), 2048, amplitudes=np.sqrt(2 / 24), seed=r)
        y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 2048)
        a, b = noisy_periods(ms.signal, y0 + 0.02 * y0 ** 3, 4, 50, 30, seed=100 + r)
        u.append(a)
        y.append(b)
    return m.w0, np.array(u), np.array(y)


def main(rounds: int = 7):
    w0, u, y = data()
    d = lptv.distortion(u, y, w0=w0)
    spectra = [np.array(x) for x in zip(*d.spectra)]          # U, Y, varU, varY, covYU: (M, L+1)
    excited, Kh = [int(c) for c in d.excited], int(d.branches)
    routes = {
        "core": lambda: _core.distortion_lines(*spectra, excited, Kh),
        "reference": lambda: ref.distortion_lines(*spectra, excited, Kh),
        "distortion": lambda: lptv.distortion(u, y, w0=w0),
    }
    a, b = routes["core"](), routes["reference"]()
    ga, gb = np.asarray(a.bla), np.asarray(b.bla)
    ok = np.isfinite(gb)
    diff = float(np.max(np.abs(ga[ok] - gb[ok])) / np.max(np.abs(gb[ok])))
    assert diff < 1e-10, f"the core's BLA differs from the reference's by {diff:.1e} relative (1e-10 at most expected)"
    best = {k: np.inf for k in routes}
    for _ in range(rounds):
        for k, f in routes.items():
            t0 = time.perf_counter()
            f()
            best[k] = min(best[k], time.perf_counter() - t0)
    print(f"lptv.distortion's regression, README example: M = 6, P = 4, N = 2048, Kh = {Kh}, "
          f"{len(excited)} excited lines; fastest of {rounds} rounds; load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    for k, v in best.items():
        print(f"  {k:12s} {1e3 * v:8.2f} ms")
    print(f"  reference / core: {best['reference'] / best['core']:.1f}x (BLA agree to {diff:.1e} relative)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
