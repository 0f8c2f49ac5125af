"""WGTLS of the C++ core against the NumPy reference, on the paper-like example, side by side.

The data are the demo's measurements (``lptv.examples.paper_measurements(seed, periods=8)``:
8 noisy periods of N = 2048 samples); the model na = 2, nb = 1, 3 harmonics on every
coefficient (35 free real parameters); rows = lines 1..243; WGTLS to tol = 1e-12. The routes:

- ``identify``: ``lptv.identify(u, y, ...)`` as a user calls it - spectra and noise statistics
  from the periods, the estimate, then the residue, its variance and the validation figures;
- ``id none``: the same with ``covariance='none'`` (no covariance: what ``lptv.select``'s
  candidate fits run);
- ``core``: ``lptv._core.estimate`` on data and a parametrisation built beforehand (the
  compiled estimator alone, no Python around it);
- ``reference``: ``lptv.reference.identification`` from the periods - ``frequency_data``,
  ``Parametrisation``, ``estimate`` (the same stopping rule as the core);
- ``ref est``: its ``estimate`` alone, on data built beforehand.

The pairs compared are identify vs reference (whole calls from the periods), core vs ref est
(the estimator alone), and identify vs core: what ``lptv.identify`` adds around the compiled
estimate (the argument checks, the spectra from the periods, the covariance, the residue
diagnostics and the stability check; goal <= 1.2x). The routes take turns in each round and each one's fastest
round counts (the least disturbed by other work on the machine). Both must give the same
estimate: theta to 1e-9 relative (asserted). Their iteration counts are shown (C++/reference):
the change of theta that stops WGTLS falls below 1e-12 within rounding of the tolerance, so
they may differ by one.

NumPy's BLAS (the reference's) and the system OpenBLAS (the core's) each keep a pool of
threads that spin for a while after a call; on a machine with few cores the two pools interleaved
slow the reference down. ``make bench`` runs this script twice, as is and with
OPENBLAS_NUM_THREADS=1 (the reference's faster setting here).

Usage: python bench_wgtls.py [seeds] [rounds]   (default 3 7: seeds 1..3, 7 rounds)
       python bench_wgtls.py --phases   (where lptv.identify's time goes, seed 1: its parts
       wrapped with timers, mean of 200 calls after 20)
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

import lptv
from lptv import _core
from lptv.spectra.frequency_data import FrequencyData
from lptv.examples import paper_measurements
from lptv.reference import identification as ref

NA, NB, K = 2, 1, 3
LINES = range(1, 244)
TOL = 1e-12
AGREE = 1e-9
ROUNDS = 7


def routes(u, y, w0):
    rows = list(LINES)
    core_data = FrequencyData.from_periods(u, y, w0=w0)
    core_par = _core.Parametrisation(NA, NB, [K] * (NA + 1), [K] * (NB + 1), [], w0, 0.0)
    ref_data = ref.frequency_data(u, y)
    ref_par = ref.Parametrisation(NA, NB, [K] * (NA + 1), [K] * (NB + 1), w0=w0)

    def identify():
        r = lptv.identify(u, y, na=NA, nb=NB, ka=K, kb=K, w0=w0, lines=LINES, method="wgtls",
                          tol=TOL, noise="sample")     # the sample variances, as the routes compared
        return np.asarray(r.theta), r.iterations

    def identify_none():
        r = lptv.identify(u, y, na=NA, nb=NB, ka=K, kb=K, w0=w0, lines=LINES, method="wgtls",
                          tol=TOL, covariance="none", noise="sample")
        return np.asarray(r.theta), r.iterations

    def core():
        r = _core.estimate(core_data._cpp, core_par, rows, method="wgtls", tol=TOL, max_iter=50)
        return np.asarray(r.theta), r.iterations

    def reference():
        data = ref.frequency_data(u, y)
        par = ref.Parametrisation(NA, NB, [K] * (NA + 1), [K] * (NB + 1), w0=w0)
        r = ref.estimate(data, par, np.asarray(rows), method="wgtls", tol=TOL)
        return r["theta"], r["iterations"]

    def ref_est():
        r = ref.estimate(ref_data, ref_par, np.asarray(rows), method="wgtls", tol=TOL)
        return r["theta"], r["iterations"]

    return {"identify": identify, "id none": identify_none, "core": core, "reference": reference,
            "ref est": ref_est}


def main(n_seeds: int = 3, rounds: int = ROUNDS):
    print("WGTLS, C++ core vs NumPy reference (lptv.reference.identification), paper-like example")
    print(f"data: lptv.examples.paper_measurements(seed, periods=8); na={NA}, nb={NB}, ka=kb={K} "
          f"(35 parameters), lines {LINES.start}..{LINES.stop - 1}, tol={TOL:g}")
    print(f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', '(unset: one thread per core)')}"
          " - NumPy's BLAS threads (the core's own BLAS runs single-threaded at this size)")
    print(f"times: the fastest of {rounds} interleaved rounds, calls timed whole; "
          "reference/identify (goal: >= 25x) and ref est/core (goal: >= 20x) are the ratios\n")
    print(f"{'seed':>4} {'iter':>5} {'identify':>10} {'id none':>10} {'core':>10} {'reference':>10} {'ref est':>10} "
          f"{'ref/identify':>12} {'ref est/core':>12} {'identify/core':>13} {'none/core':>9} {'theta diff':>10}")
    ratios_whole, ratios_core, overhead, overhead_none = [], [], [], []
    for seed in range(1, n_seeds + 1):
        m = paper_measurements(seed, periods=8)
        fns = routes(m["u"], m["y"], m["w0"])
        results = {name: f() for name, f in fns.items()}  # warm-up, and the results compared
        theta0 = results["identify"][0]
        diff = max(np.linalg.norm(th - theta0) / np.linalg.norm(theta0) for th, _ in results.values())
        assert diff <= AGREE, f"seed {seed}: the estimates differ by {diff:.1e}"
        its = f"{results['core'][1]}/{results['ref est'][1]}"
        best = {name: np.inf for name in fns}
        for _ in range(rounds):
            for name, f in fns.items():
                t0 = time.perf_counter()
                f()
                best[name] = min(best[name], time.perf_counter() - t0)
        rw = best["reference"] / best["identify"]
        rc = best["ref est"] / best["core"]
        ic = best["identify"] / best["core"]
        nc = best["id none"] / best["core"]
        ratios_whole.append(rw)
        ratios_core.append(rc)
        overhead.append(ic)
        overhead_none.append(nc)
        print(f"{seed:>4} {its:>5} " + " ".join(f"{1e3 * best[n]:>8.2f}ms" for n in fns) +
              f" {rw:>11.1f}x {rc:>11.1f}x {ic:>12.2f}x {nc:>8.2f}x {diff:>10.1e}", flush=True)
    print(f"\nreference / C++ (goals: >= 25x with lptv.identify, >= 20x with the estimator): {min(ratios_whole):.1f}x .. {max(ratios_whole):.1f}x "
          f"with lptv.identify, {min(ratios_core):.1f}x .. {max(ratios_core):.1f}x with "
          f"_core.estimate alone")
    print(f"lptv.identify / _core.estimate (goal: <= 1.2x): {min(overhead):.2f}x .. {max(overhead):.2f}x; "
          f"with covariance='none' {min(overhead_none):.2f}x .. {max(overhead_none):.2f}x")


def phases(n: int = 200):
    """lptv.identify split into the spectra from the periods, the compiled identify (estimate,
    covariance, residues, diagnostics), the stability check and the rest; and the estimate alone."""
    mod = sys.modules["lptv.estimation.identify"]
    m = paper_measurements(1, periods=8)
    u, y, w0 = m["u"], m["y"], m["w0"]
    spent = {}

    def timed(name, f):
        def g(*a, **k):
            t0 = time.perf_counter()
            try:
                return f(*a, **k)
            finally:
                spent[name] = spent.get(name, 0.0) + time.perf_counter() - t0
        return g

    saved = {k: getattr(mod, k) for k in ("frequency_data_of", "stability_check")}
    saved_core = mod._core.identify
    mod.frequency_data_of = timed("spectra from the periods", saved["frequency_data_of"])
    mod.stability_check = timed("stability check", saved["stability_check"])
    mod._core.identify = timed("_core.identify (estimate, covariance, residues)", saved_core)
    try:
        call = lambda: lptv.identify(u, y, na=NA, nb=NB, ka=K, kb=K, w0=w0, lines=LINES, tol=TOL, noise="sample")
        for _ in range(20):
            call()
        spent.clear()
        t0 = time.perf_counter()
        for _ in range(n):
            call()
        total = time.perf_counter() - t0
    finally:
        for k, f in saved.items():
            setattr(mod, k, f)
        mod._core.identify = saved_core
    data = FrequencyData.from_periods(u, y, w0=w0)
    par = _core.Parametrisation(NA, NB, [K] * (NA + 1), [K] * (NB + 1), [], w0, 0.0)
    rows = list(LINES)
    t0 = time.perf_counter()
    for _ in range(n):
        _core.estimate(data._cpp, par, rows, method="wgtls", tol=TOL, max_iter=50)
    est = time.perf_counter() - t0
    print(f"lptv.identify (WGTLS, paper example seed 1, tol {TOL:g}), mean of {n} calls after 20:")
    print(f"  {'whole call':48s} {1e3 * total / n:7.3f} ms")
    for k, v in spent.items():
        print(f"  {k:48s} {1e3 * v / n:7.3f} ms")
    print(f"  {'the rest (Python)':48s} {1e3 * (total - sum(spent.values())) / n:7.3f} ms")
    print(f"  {'_core.estimate alone (same data)':48s} {1e3 * est / n:7.3f} ms")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--phases":
        phases()
    else:
        main(*(int(a) for a in sys.argv[1:3]))
