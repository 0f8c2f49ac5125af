"""Structure selection (lptv.select) on a 3 x 3 x 4 grid, serial and on 2 processes; htf_estimate.

    python bench/python/bench_select.py [rounds] [--small]   (default 3)

``--small``: the grid na = 2, nb = 1, k = 3..4 and 20 / 200 calls of htf_estimate (a quick run).

1. The paper example (lptv.examples.paper_measurements, seed 1, P = 8), the grid na = 1..3,
   nb = 0..2, k = 1..4 (36 structures, WGTLS; then SML on the best 2 per k: 8 more fits), MDL,
   on (a) the default rows, those of the largest k (lines 5..1019), and (b) the paper's lines
   1..243. ``lptv.select(..., executor=E)`` as a user calls it, E = "serial" and "processes"
   with 2 workers (the pool started and stopped inside each of the two run_tasks calls, as the
   default does). The two must give identical rankings (asserted). They take turns for
   ``rounds`` rounds; the fastest round counts.
2. ``lptv.htf_estimate`` on the same data (branches 0..4 at the 24 excited lines): the median
   of 200 calls from the periods and of 2000 from a FrequencyData.
"""
from __future__ import annotations

import sys
import time

import numpy as np

import lptv
from lptv.examples import paper_measurements


def load():
    return " ".join(open("/proc/loadavg").read().split()[:3])


def main(rounds=3, small=False):
    m = paper_measurements(seed=1, periods=8)
    grid = dict(na=range(2, 3), nb=range(1, 2), k=range(3, 5)) if small else dict(na=range(1, 4), nb=range(0, 3), k=range(1, 5))
    print(f"lptv.select on the paper example (seed 1, P = 8), grid na {grid['na'][0]}..{grid['na'][-1]} x nb "
          f"{grid['nb'][0]}..{grid['nb'][-1]} x k {grid['k'][0]}..{grid['k'][-1]}, MDL; "
          f"load at start {load()}")
    for label, lines in (("default rows (largest k: 5..1019)", None), ("lines 1..243", range(1, 244))):
        best, ref = {}, None
        for r in range(rounds):
            for name, kw in (("serial", dict(executor="serial")),
                             ("2 processes", dict(executor="processes", workers=2))):
                t = time.perf_counter()
                sel = lptv.select(m["u"], m["y"], w0=m["w0"], lines=lines, progress=False, **grid, **kw)
                dt = time.perf_counter() - t
                best[name] = min(best.get(name, np.inf), dt)
                ref = ref or sel
                assert sel.rows == ref.rows, f"{name}: the ranking differs from the first run's"
                assert sel.choice == (2, 1, 3), f"{name}: chose {sel.choice}, not the true (2, 1, 3)"
                print(f"  {label}, round {r + 1}: {name:12s} {dt:6.2f} s (load {load()})")
        n_sml = sum(r["method"] == "sml" for r in ref.rows)
        print(f"{label}: {len(ref.rows)} WGTLS + {n_sml} SML fits; serial {best['serial']:.2f} s, "
              f"2 processes {best['2 processes']:.2f} s ({best['serial'] / best['2 processes']:.2f}x); "
              f"choice {ref.choice}, identical rankings")
    d = lptv.FrequencyData.from_periods(m["u"], m["y"], w0=m["w0"])
    calls = (20, 200) if small else (200, 2000)
    for label, call, n in (("from the periods (8 x 2048)", lambda: lptv.htf_estimate(m["u"], m["y"], w0=m["w0"], branches=4), calls[0]),
                           ("from a FrequencyData", lambda: lptv.htf_estimate(d, branches=4), calls[1])):
        ts = []
        for _ in range(n):
            t = time.perf_counter()
            call()
            ts.append(time.perf_counter() - t)
        print(f"htf_estimate, branches 4, {label}: median {1e3 * np.median(ts):.3f} ms "
              f"(min {1e3 * np.min(ts):.3f} ms, {n} calls)")
    print(f"load at the end: {load()}")


if __name__ == "__main__":
    args = sys.argv[1:]
    main(*[int(a) for a in args if a != "--small"][:1], small="--small" in args)
