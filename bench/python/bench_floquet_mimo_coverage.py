"""Coverage of the Floquet exponents' 95 % intervals of a fit with two inputs and two outputs
(METHOD.md section 22: several outputs by central differences of the core's exponents), by Monte
Carlo on the two masses of lptv.examples.mimo ("2-in-2-out": M = diag(1, 2), C = diag(1, 2),
coupling spring 2 (1 + 0.3 cos t)), whose steady state SciPy's solve_ivp computes from the
equations written by hand; the truth's exponents from solve_ivp's monodromy matrix of the same
equations. Per realisation: two orthogonal experiments (lptv.mimo_multisines), white noise of
``--level`` times each channel's rms, SML with the true structure, lptv.floquet(res).

    python bench/python/bench_floquet_mimo_coverage.py --runs 100 --periods 4 8
"""
from __future__ import annotations

import argparse
import os
import sys
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import lptv  # noqa: E402
from lptv.examples import mimo as mx  # noqa: E402
from lptv.model.floquet_uncertainty import match  # noqa: E402

SYSTEM = "2-in-2-out"
N, LINES = 32, np.arange(2, 14, 2)
STRUCTURE = dict(na=2, nb=0, ka=[1, 0, 0], kb=0)


def true_exponents():
    from scipy.integrate import solve_ivp

    _, ode, n = mx.SYSTEMS[SYSTEM]()
    f = ode(lambda t: np.zeros(2), lambda t: np.zeros(2))
    T = 2 * np.pi / mx.W0
    Phi = np.column_stack([solve_ivp(lambda t, x: f(t, x, False), (0, T), e, method="DOP853", rtol=1e-12,
                                     atol=1e-14).y[:, -1] for e in np.eye(n)])
    lam = np.log(np.linalg.eigvals(Phi).astype(complex)) / T
    return lam


def world():
    rng = np.random.default_rng(5)
    d = lptv.mimo_multisines(LINES, N, 2, seed=rng)
    exps = []
    for e in range(d.n_experiments):
        y = mx.steady_state(SYSTEM, d.spectra[e], N)
        exps.append((d.signals[e], y))
    return exps


def one(args):
    exps, P, level, seed = args
    rng = np.random.default_rng(seed)
    pairs = []
    for u1, y1 in exps:
        u = u1[None] + level * u1.std(axis=0) * rng.standard_normal((P,) + u1.shape)
        y = y1[None] + level * y1.std(axis=0) * rng.standard_normal((P,) + y1.shape)
        pairs.append((u, y))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify(pairs, w0=mx.W0, method="sml", **STRUCTURE)
    f = lptv.floquet(res)
    return f.exponents, f.confidence_interval(0.95), bool(f.first_order_ok)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--periods", nargs="+", type=int, default=[4, 8])
    ap.add_argument("--level", type=float, default=0.03)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args(argv)
    truth = true_exponents()
    exps = world()
    print(f"# {SYSTEM}: true exponents (solve_ivp monodromy) {np.round(truth, 5)}")
    print(f"{'P':>2} {'R':>4}  {'Re cover':>15}  {'Im cover':>15}  {'1st ok':>6}")
    for P in a.periods:
        tasks = [(exps, P, a.level, 7000 * P + i) for i in range(a.runs)]
        if a.workers > 1:
            with ProcessPoolExecutor(a.workers) as ex:
                out = list(ex.map(one, tasks, chunksize=4))
        else:
            out = [one(t) for t in tasks]
        re, im = [], []
        for lam, ci, _ in out:
            t = match(lam, truth, mx.W0)
            re.append((ci[:, 0, 0] <= t.real) & (t.real <= ci[:, 0, 1]))
            im.append((ci[:, 1, 0] <= t.imag) & (t.imag <= ci[:, 1, 1]))
        re, im = np.concatenate(re).mean(), np.concatenate(im).mean()
        ok = np.mean([o[2] for o in out])
        se = lambda p: np.sqrt(p * (1 - p) / a.runs)  # noqa: E731 (a conjugate pair counts once)
        print(f"{P:2d} {a.runs:4d}  {re:6.3f} +- {se(re):5.3f}  {im:6.3f} +- {se(im):5.3f}  {ok:6.3f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
