"""lptv.floquet on the paper's example, and the independent product route beside it.

    python bench/python/bench_floquet.py [--rounds R] [--inner N]   (default 7 rounds of 5 calls)

- ``lptv.floquet(paper_model())``: Hill's method in the core (harmonics of F(t) from 1/a_2(t),
  the truncation grown until the exponents settle), as a user calls it;
- ``monodromy + eig``: ``lptv.model.floquet.monodromy`` (the product of 2 x 2000 fourth-order Magnus
  exponentials and a Richardson step) and ``numpy.linalg.eigvals``;
- the same two on the damped Mathieu example (``lptv.examples.mathieu_model()``, unstable).

The routes take turns over rounds; each one's fastest round counts (machines are shared). The
multipliers must agree to 1e-9 of ||Phi|| (asserted): Hill's own error bound on the paper's
example is 2.8e-9 relative to its multipliers, measured agreement 1.3e-10.
"""
import argparse
import os
import time

import numpy as np

import lptv
from lptv.examples import mathieu_model, paper_model
from lptv.model.floquet import monodromy

AGREE = 1e-9


def fastest(fns, rounds=7, inner=5):
    best = {k: np.inf for k in fns}
    for _ in range(rounds):
        for k, f in fns.items():
            t0 = time.perf_counter()
            for _ in range(inner):
                f()
            best[k] = min(best[k], (time.perf_counter() - t0) / inner)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--inner", type=int, default=5, help="calls per round")
    args = ap.parse_args(argv)
    print(f"load average at start: {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} cores")
    for name, model in [("paper example (na=2, 3 harmonics on a_0..a_2, w0=0.04)", paper_model()),
                        ("damped Mathieu (zeta=0.02, eps=0.1, w0=2 wn)", mathieu_model())]:
        f = lptv.floquet(model)
        P = monodromy(model, 2000)
        mu = np.linalg.eigvals(P)
        diff = min(np.max(np.abs(f.multipliers - mu[list(p)])) for p in ([0, 1], [1, 0]))
        rel = diff / np.linalg.norm(P, 2)
        assert rel <= AGREE, f"{name}: Hill's and the product's multipliers differ by {rel:.1e} of ||Phi|| ({AGREE:g} at most expected)"
        t = fastest({
            "floquet (Hill)": lambda: lptv.floquet(model),
            "monodromy + eig": lambda: np.linalg.eigvals(monodromy(model, 2000)),
        }, args.rounds, args.inner)
        print(name)
        print(f"  multipliers {np.array2string(f.multipliers, precision=4)}, stable {f.is_stable}")
        print(f"  Hill: truncation M = {f.truncation} (matrix {model.na * (2 * f.truncation + 1)}), "
              f"harmonics of F {f.harmonics}, error estimate {f.error_estimate.max():.1e}, "
              f"|mu_Hill - mu_product| / ||Phi|| = {rel:.1e}")
        for k, v in t.items():
            print(f"  {k:16s} {1e3 * v:8.2f} ms  (fastest of {args.rounds} rounds of {args.inner} calls)")


if __name__ == "__main__":
    main()
