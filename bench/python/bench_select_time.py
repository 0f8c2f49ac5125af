"""The time of lptv.select over many realisations: the slowest selection against the median.

An over-fitted, unconverged candidate whose a_na(t) nearly vanishes once sent the stability
check into Hill's method for 25-55 s (METHOD.md section 15); the check now has a cost bound.
50 realisations of the paper's example (P = 8, lines 1..243), grid na = 1..4, nb = 0..2,
k = 0..3 (48 structures), serial, each selection timed as a whole.

    python bench/python/bench_select_time.py [runs]     (default 50)
"""
from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import lptv
from lptv.examples import PAPER_ID_LINES, paper_measurements


def main(runs=50):
    times = []
    for seed in range(runs):
        m = paper_measurements(seed=seed + 7000, periods=8)
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sel = lptv.select(m["u"], m["y"], na=range(1, 5), nb=range(0, 3), k=range(0, 4), w0=m["w0"],
                              lines=PAPER_ID_LINES, executor="serial", progress=False)
        times.append(time.perf_counter() - t)
        print(f"seed {seed}: {times[-1]:.2f} s, chosen {sel.choice}", flush=True)
    t = np.array(times)
    print(f"{runs} selections: median {np.median(t):.2f} s, min {t.min():.2f} s, max {t.max():.2f} s, "
          f"max / median {t.max() / np.median(t):.2f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 50)
