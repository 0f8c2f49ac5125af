"""Crest factors reached by lptv.min_crest_multisine against Schroeder's phases and random phases,
and the time the design takes (the compiled core against the SciPy reference on the same objective).

    python bench/python/bench_crest.py table            # crest factors, one design per case
    python bench/python/bench_crest.py timing 50 [5]    # core and reference alternated, 5 pairs

The table: flat spectra of F consecutive lines (1..F) and odd-odd designs (every 4th line),
N = 16 F rounded up to a power of two, the peak taken on 16 points per period of the top line;
random phases: the median over 20 draws. The time of one design is printed too (in-process,
single run: for ratios use the two timing modes side by side).
"""
from __future__ import annotations

import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv.reference import excitation as rx  # noqa: E402


def case(F, kind):
    lines = np.arange(1, F + 1) if kind == "flat" else 1 + 4 * np.arange(F)
    N = int(2 ** np.ceil(np.log2(16 * lines.max() + 1)))
    return lines, N


def crest(x):
    return float(np.abs(x).max() / np.sqrt(np.mean(x**2)))


def table():
    print(f"{'lines':>6} {'kind':>8} {'N':>6} {'random':>7} {'Schroeder':>9} {'min_crest':>9} "
          f"{'evals':>6} {'time [ms]':>9} {'reference':>9}")
    for kind in ("flat", "odd-odd"):
        for F in (10, 20, 50, 100, 200, 500, 1000):
            lines, N = case(F, kind)
            rnd = np.median([lptv.multisine(lines, N, seed=s).crest_factor for s in range(20)])
            sch = lptv.schroeder_multisine(lines, N).crest_factor
            t = time.perf_counter()
            ms, d = lptv.min_crest_multisine(lines, N, return_design=True)
            el = time.perf_counter() - t
            ref = ""
            if F <= 50:
                _, c_ref = rx.minimize_crest_factor(lines, np.ones(F), rx.schroeder_phases(np.ones(F)), N,
                                                    oversample=d.oversample)
                ref = f"{c_ref:9.3f}"
            print(f"{F:6d} {kind:>8} {N:6d} {rnd:7.3f} {sch:9.3f} {d.crest_factor:9.3f} "
                  f"{d.evaluations:6d} {1e3 * el:9.1f} {ref:>9}", flush=True)


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else "table"
    if mode == "table":
        table()
        return
    F = int(sys.argv[2]) if len(sys.argv) > 2 else 50
    lines, N = case(F, "flat")
    if mode == "timing":
        # the same design in turn by the core and by the reference, in one process, 5 pairs
        pairs = int(sys.argv[3]) if len(sys.argv) > 3 else 5
        tc, tr = [], []
        for _ in range(pairs):
            t = time.perf_counter()
            ms = lptv.min_crest_multisine(lines, N)
            tc.append(time.perf_counter() - t)
            t = time.perf_counter()
            _, c = rx.minimize_crest_factor(lines, np.ones(F), rx.schroeder_phases(np.ones(F)), N)
            tr.append(time.perf_counter() - t)
        ratio = np.array(tr) / np.array(tc)
        print(f"{F} flat lines, N = {N}: core {1e3 * min(tc):.1f} ms (crest {ms.crest_factor:.4f}), "
              f"reference {1e3 * min(tr):.0f} ms (crest {c:.4f}); reference / core per pair "
              f"min {ratio.min():.0f} median {np.median(ratio):.0f} max {ratio.max():.0f}")
    else:
        raise SystemExit(f"unknown mode {mode!r}")


if __name__ == "__main__":
    main()
