"""lptv.identify_record in the C++ core against its NumPy and SciPy reference, side by side.

    python bench/python/bench_record_core.py [rounds] [periods ...]

Data: the discrete-time example (lptv.examples.discrete_model, N0 = 256), one record of L whole
periods from a random initial state under white-noise input, output noise std 0.01 (seed 1);
the defaults (transient term, noise level from the residual: three output-error fits). Routes,
on the same u, y:

- ``identify_record``: ``lptv.identify_record(u, y, ...)`` as a user calls it (argument checks,
  DFTs, ``_core.fit_record``, the result's arrays);
- ``core``: ``_core.fit_record`` alone, on spectra taken once;
- ``reference``: ``lptv.reference.record.identify_record`` (SciPy's MINPACK Levenberg-Marquardt,
  SuperLU per residue class of the lines, numpy.linalg.lstsq for the start): the route
  ``lptv.identify_record`` had before.

The routes take turns in each round (a shared machine); the fastest and the median round of
each are printed. The estimates must agree within 1e-3 of their std (asserted; the tolerance of
tests/python/test_record_core.py). NumPy's BLAS is held to one thread (OPENBLAS_NUM_THREADS=1
unless set): the reference's small dense products gain nothing from threads, and a second
thread on a loaded two-core machine made the reference's SuperLU solves ten times slower.
"""
from __future__ import annotations

import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv import _core  # noqa: E402
from lptv import reference as ref  # noqa: E402
from lptv.examples import DISCRETE_STRUCTURE, discrete_model, transient_record  # noqa: E402


def main(rounds: int = 7, periods=(4, 8)):
    m = discrete_model()
    s = DISCRETE_STRUCTURE
    par = _core.Parametrisation(s["na"], s["nb"], s["ka"], s["kb"], [], m.w0, 1.0)
    print(f"lptv.identify_record, discrete-time example, noise from the residual; {rounds} rounds, "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}; OPENBLAS_NUM_THREADS="
          f"{os.environ['OPENBLAS_NUM_THREADS']}")
    for L in periods:
        u, y = transient_record(m, periods=L, noise_std=0.01, seed=1)
        N = u.size
        U, Y = np.fft.fft(u) / N, np.fft.fft(y) / N
        lines = list(range(1, N // 2))
        routes = {
            "identify_record": lambda: lptv.identify_record(u, y, **s, w0=m.w0, ts=1.0),
            "core": lambda: _core.fit_record(par, U, Y, L, lines),
            "reference": lambda: ref.record.identify_record(u, y, **s, w0=m.w0, ts=1.0),
        }
        a, r = routes["identify_record"](), routes["reference"]()
        free = a.parameter_std > 0
        diff = float(np.max(np.abs(a.eta - r.eta)[free] / a.parameter_std[free]))
        assert diff <= 1e-3, f"the core's and the reference's estimates differ by {diff:.1e} std (1e-3 at most expected)"
        times = {k: [] for k in routes}
        for _ in range(rounds):
            for k, f in routes.items():
                t0 = time.perf_counter()
                f()
                times[k].append(time.perf_counter() - t0)
        fit = routes["core"]()
        print(f"L = {L} periods, N = {N} samples, {len(lines)} lines, {fit.start.size} parameters; core: "
              f"{fit.fits} fits, {fit.iterations} iterations in the last, {fit.evaluations} factorisations; "
              f"reference: {r.iterations} function evaluations in the last fit")
        print(f"  {'route':16s} {'min ms':>9s} {'median ms':>10s}")
        for k, v in times.items():
            print(f"  {k:16s} {1e3 * min(v):9.2f} {1e3 * float(np.median(v)):10.2f}")
        print(f"  reference / identify_record: {min(times['reference']) / min(times['identify_record']):.1f}x "
              f"(fastest rounds), {np.median(times['reference']) / np.median(times['identify_record']):.1f}x "
              f"(medians); estimates agree to {diff:.1e} std")


if __name__ == "__main__":
    args = [int(a) for a in sys.argv[1:]]
    main(args[0] if args else 7, tuple(args[1:]) or (4, 8))
