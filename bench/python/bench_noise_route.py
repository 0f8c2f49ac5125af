"""The noise route of periodic records (METHOD.md section 7, "The default noise route"), by Monte Carlo.

On systems simulated outside lptv (bench/python/periodic_records.py: a third-order continuous-time
LPTV system integrated by solve_ivp, a discrete-time LPTV system run by a NumPy loop, a
fourth-order LTI system from its exact transfer function), P periods per record with white input
noise and coloured output noise, each record is fitted with the true structure on the excited
lines +-K by WGTLS and SML, with each noise route asked for. Per cell:

- the route the fit took (``res.noise``) when asked for 'auto';
- the coverage of the 95 % intervals pooled over the free parameters (its binomial standard error
  for independent parameters in brackets) and for the worst parameter;
- the median of reported / Monte Carlo variance over the parameters;
- the verdict's rejection rate on the right structure (its size, nominal 1 %), with its standard
  error sqrt(p (1 - p) / R).

    python bench/python/bench_noise_route.py --runs 400
    python bench/python/bench_noise_route.py --runs 400 --noise sample moderated auto --periods 4
    python bench/python/bench_noise_route.py --runs 200 --kind rough --noise auto
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import lptv  # noqa: E402
from lptv import _core  # noqa: E402
from periodic_records import SYSTEMS, record, truth  # noqa: E402


def true_model(system, w0, ts):
    a, b = truth(system)
    K = max(max(abs(k) for k in row) for row in a + b)

    def arr(rows):
        x = np.zeros((len(rows), 2 * K + 1), complex)
        for n, row in enumerate(rows):
            for k, v in row.items():
                x[n, K + k] = v
                x[n, K - k] = np.conj(v)
        return x
    return lptv.Model(arr(a), arr(b), w0=w0, ts=ts)


def eta_true(res, model):
    par = _core.Parametrisation(res.structure)
    xi = np.asarray(par.xi_from_theta(np.asarray(par.theta_from_model(model._cpp))))
    return (xi / xi[par.norm_index])[:res.eta.size]


def one(args):
    system, P, seed, noises, kind = args
    d = record(system, P, [seed, P, SYSTEMS.index(system), 3], noise=kind)
    m = true_model(system, d["w0"], d["ts"])
    out = []
    for noise in noises:
        for method in ("wgtls", "sml"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["rows"],
                                  method=method, noise=noise)
                ok = r.model_ok
            out.append((system, P, method, noise, r.eta - eta_true(r, m), r.parameter_std, bool(ok), r.noise))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=400)
    ap.add_argument("--periods", type=int, nargs="+", default=[4, 8, 16, 32])
    ap.add_argument("--systems", nargs="+", default=list(SYSTEMS), choices=SYSTEMS)
    ap.add_argument("--noise", nargs="+", default=["auto"], choices=("sample", "moderated", "auto"))
    ap.add_argument("--kind", default="smooth", choices=("smooth", "rough", "white"),
                    help="the output noise's spectrum")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--first-seed", type=int, default=0, help="the realisations' seeds start here")
    args = ap.parse_args(argv)
    tasks = [(s, P, i, tuple(args.noise), args.kind) for s in args.systems for P in args.periods
             for i in range(args.first_seed, args.first_seed + args.runs)]
    t0 = time.time()
    with ProcessPoolExecutor(args.workers) as ex:
        rows = [r for chunk in ex.map(one, tasks, chunksize=8) for r in chunk]
    R = args.runs
    print(f"# {len(tasks)} records in {time.time() - t0:.0f} s; R = {R} per cell (seeds {args.first_seed}.."
          f"{args.first_seed + R - 1}); output noise {args.kind}")
    print("| system | P | method | asked | taken | coverage (pooled) | worst parameter | reported / MC variance "
          "(median) | verdict's size |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in args.systems:
        for P in args.periods:
            for method in ("wgtls", "sml"):
                for noise in args.noise:
                    sel = [r for r in rows if r[0] == s and r[1] == P and r[2] == method and r[3] == noise]
                    std = np.array([r[5] for r in sel])
                    free = np.all(std > 0, 0)      # the normalised parameter has none
                    err = np.array([r[4] for r in sel])[:, free]
                    std = std[:, free]
                    cover = np.abs(err) <= 1.959964 * std
                    pooled = cover.mean()
                    se = np.sqrt(pooled * (1 - pooled) / cover.size)
                    worst = cover.mean(0).min()
                    ratio = np.median(np.mean(std ** 2, 0) / np.var(err, 0))
                    rej = 1 - np.mean([r[6] for r in sel])
                    taken = {t: sum(r[7] == t for r in sel) for t in ("sample", "moderated")}
                    tk = ", ".join(f"{k} {v}" for k, v in taken.items() if v)
                    print(f"| {s} | {P} | {method} | {noise} | {tk} | {100 * pooled:.1f} % (+-{100 * se:.1f}) | "
                          f"{100 * worst:.1f} % | {ratio:.2f} | {100 * rej:.1f} +- "
                          f"{100 * np.sqrt(max(rej, 1 / R) * (1 - rej) / R):.1f} % |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
