"""lptv.simulate against scipy.linalg.solve_banded on a prebuilt band at one L, many rounds.

The goal's ratio of bench_simulate.py (sim/pre at L = 10^5) with more rounds than that script
gives a route of 20-40 ms: the adaptive call, the call with the guard it ends with, and
solve_banded alone on the band and right-hand side bench_simulate.prebuilt_banded builds
beforehand, taking turns; the fastest of each (the least disturbed by other work).

Usage: python bench_simulate_ratio.py [rounds] [L]   (default 15, 10^5)
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

import lptv
import lptv.examples as ex

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import prebuilt_banded  # noqa: E402


def main(rounds: int = 15, L: int = 100_000):
    model = ex.paper_model()
    rng = np.random.default_rng(0)
    U = np.exp(2j * np.pi * rng.uniform(size=L + 1)) / np.sqrt(L)  # as bench_simulate.py
    U[0] = U[0].real
    g = lptv.simulate(model, U, full_output=True).guard
    pre = prebuilt_banded(model, U, g)
    calls = {"sim": lambda: lptv.simulate(model, U), "sim/g": lambda: lptv.simulate(model, U, guard=g),
             "prebuilt": pre}
    Y = {k: f() for k, f in calls.items()}
    peak = np.max(np.abs(Y["prebuilt"]))
    for k in ("sim", "sim/g"):
        assert np.max(np.abs(Y[k] - Y["prebuilt"])) <= 1e-10 * peak, f"{k} differs from solve_banded's solution beyond 1e-10"
    best = dict.fromkeys(calls, np.inf)
    for _ in range(rounds):
        for k, f in calls.items():
            t0 = time.perf_counter()
            f()
            best[k] = min(best[k], time.perf_counter() - t0)
    print(f"L = {L}, guard {g}, fastest of {rounds} rounds: "
          + " ".join(f"{k} {1e3 * v:.2f} ms" for k, v in best.items())
          + f"; sim/pre {best['sim'] / best['prebuilt']:.2f}, sim/g/pre {best['sim/g'] / best['prebuilt']:.2f}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))
