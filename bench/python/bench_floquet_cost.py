"""The cost of the Floquet exponents' intervals against the fit's, on the paper's example
(METHOD.md section 22): lptv.identify (SML, the true structure, its covariance) and
lptv.floquet(res) side by side, each its fastest round (machines are shared); also
lptv.floquet(res.model) (the exponents alone) and the bootstrap with 100 draws.

    python bench/python/bench_floquet_cost.py [--rounds R]

Goal: intervals (lptv.floquet(res)) <= 0.5 x the fit.
"""
import argparse
import os
import time
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv.examples import paper_measurements  # noqa: E402


def fastest(fns, rounds):
    best = {k: np.inf for k in fns}
    for _ in range(rounds):
        for k, f in fns.items():
            t0 = time.perf_counter()
            f()
            best[k] = min(best[k], time.perf_counter() - t0)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--bootstrap", type=int, default=100)
    a = ap.parse_args(argv)
    m = paper_measurements(seed=1, periods=8)

    def fit():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return lptv.identify(m["u"], m["y"], na=2, nb=1, ka=3, kb=3, w0=m["w0"], lines=range(1, 244),
                                 method="sml")

    res = fit()
    f = lptv.floquet(res)
    print("exponents", np.round(f.exponents, 5), "std", np.round(f.exponents_std, 6),
          "P(stable)", f.stable_probability, "first order ok", f.first_order_ok)
    fns = {"fit (identify, sml)": fit, "floquet(res.model)": lambda: lptv.floquet(res.model),
           "floquet(res) first order": lambda: lptv.floquet(res)}
    best = fastest(fns, a.rounds)
    tb = fastest({"b": lambda: lptv.floquet(res, method="bootstrap", draws=a.bootstrap, seed=0)}, 1)["b"]
    for k, v in best.items():
        print(f"{k:28s} {1e3 * v:9.2f} ms")
    print(f"{'floquet(res) bootstrap ' + str(a.bootstrap):28s} {1e3 * tb:9.2f} ms")
    ratio = best["floquet(res) first order"] / best["fit (identify, sml)"]
    print(f"intervals / fit = {ratio:.3f} (goal <= 0.5)")
    fb = lptv.floquet(res, method="bootstrap", draws=a.bootstrap, seed=0)
    print("bootstrap std", np.round(fb.exponents_std, 6), "over first order",
          np.round(fb.exponents_std[:, 0] / f.exponents_std[:, 0], 3))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
