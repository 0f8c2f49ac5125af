"""The cost of the record's noise (METHOD.md section 20) on the paper's example, side by side in
one process: lptv.identify with noise='sample' (the periods' per-line variances), 'full' (the
whole record's), 'auto' (the default, which now runs the line test first; on sensor noise it stays
on the periods' statistics) and lptv.correlated_lines alone, WGTLS and SML, alternating rounds,
one BLAS thread; medians and the ratios to noise='sample'.

    python bench/python/bench_noise_cost.py --rounds 30
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv.examples import noisy_periods, paper_model, paper_multisine  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=30)
    ap.add_argument("--periods", type=int, default=8)
    args = ap.parse_args(argv)
    model = paper_model()
    ms = paper_multisine(seed=1)
    y0 = lptv.time_signal(lptv.simulate(model, ms.spectrum), ms.n_samples)
    u, y = noisy_periods(ms.signal, y0, args.periods, 50, 30, seed=2)
    kw = dict(na=2, nb=1, ka=3, kb=3, w0=model.w0, lines=range(1, 244))
    d = lptv.FrequencyData.from_periods(u, y, w0=model.w0)
    cases = {f"{m} {n}": (lambda m=m, n=n: lptv.identify(u, y, **kw, method=m, noise=n))
             for m in ("wgtls", "sml") for n in ("sample", "full", "auto")}
    cases["correlated_lines"] = lambda: lptv.correlated_lines(d)
    cases["from_periods periods"] = lambda: lptv.FrequencyData.from_periods(u, y, w0=model.w0)
    cases["from_periods record"] = lambda: lptv.FrequencyData.from_periods(u, y, w0=model.w0, statistics="record")
    times = {k: [] for k in cases}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for f in cases.values():
            f()
        for _ in range(args.rounds):
            for k, f in cases.items():
                t0 = time.perf_counter()
                f()
                times[k].append(time.perf_counter() - t0)
        routes = {n: lptv.identify(u, y, **kw, noise=n).noise for n in ("auto",)}
    print(f"# bench_noise_cost: the paper's example, P = {args.periods}, N = {ms.n_samples}, {args.rounds} rounds; "
          f"noise='auto' took {routes['auto']!r}")
    print(f"{'case':24s} {'median ms':>10s} {'ratio to sample':>16s}")
    for k, t in times.items():
        med = np.median(t) * 1e3
        m = k.split()[0]
        base = np.median(times[f"{m} sample"]) * 1e3 if m in ("wgtls", "sml") else np.nan
        print(f"{k:24s} {med:10.2f} {med / base:16.2f}" if np.isfinite(base) else f"{k:24s} {med:10.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
