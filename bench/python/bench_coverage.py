"""Coverage of the reported 95 % intervals of WGTLS and SML on three systems, by Monte Carlo.

For each system of lptv.examples (the paper's example, the third-order continuous-time system,
the discrete-time system), P in (4, 8, 16, 32) and method, R realisations fitted with the true
structure. Per cell: the coverage of the 95 % intervals pooled over the free parameters (its
sampling error sqrt(p (1 - p) / (R n)) for independent parameters) and for the worst
parameter; the median over the parameters of reported variance / Monte Carlo variance; the
largest |bias| / RMS.

    python bench/python/bench_coverage.py --runs 400
    python bench/python/bench_coverage.py --runs 200 --periods 4 8 --covariance bootstrap --bootstrap 100
    python bench/python/bench_coverage.py --runs 400 --noise sample moderated

``--noise``: the fits weigh by each line's sample (co)variances, by the moderated ones
(``lptv.identify(..., noise='moderated')``), or both on the same realisations (then a last
table gives the Monte Carlo variance of the moderated fit over the sample one's, per cell).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import lptv  # noqa: E402
from lptv import _core  # noqa: E402
from lptv.examples import SYSTEMS, system_measurements  # noqa: E402


def truth(res, model):
    par = _core.Parametrisation(res.structure)
    xi = np.asarray(par.xi_from_theta(np.asarray(par.theta_from_model(model._cpp))))
    return (xi / xi[par.norm_index])[:res.eta.size]


def one(args):
    system, P, seed, cov_kw, noises = args
    d = system_measurements(system, seed=np.random.default_rng([seed, P, SYSTEMS.index(system), 7]), periods=P)
    out = []
    for noise in noises:
        for method in ("wgtls", "sml"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["lines"],
                                  method=method, noise=noise, **cov_kw)
            out.append((system, P, method, r.eta - truth(r, d["model"]), r.parameter_std, noise))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=400)
    ap.add_argument("--periods", type=int, nargs="+", default=[4, 8, 16, 32])
    ap.add_argument("--systems", nargs="+", default=list(SYSTEMS))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--covariance", default="analytic", choices=("analytic", "bootstrap"))
    ap.add_argument("--bootstrap", type=int, default=100, help="refits per realisation (covariance='bootstrap')")
    ap.add_argument("--noise", nargs="+", default=["sample"], choices=("sample", "moderated"))
    args = ap.parse_args(argv)
    cov_kw = {} if args.covariance == "analytic" else dict(covariance="bootstrap", bootstrap=args.bootstrap)
    tasks = [(s, P, i, dict(cov_kw, **({"seed": i} if cov_kw else {})), tuple(args.noise))
             for s in args.systems for P in args.periods for i in range(args.runs)]
    t0 = time.time()
    with ProcessPoolExecutor(args.workers) as ex:
        rows = [r for chunk in ex.map(one, tasks, chunksize=16) for r in chunk]
    print(f"# {len(tasks)} realisations in {time.time() - t0:.0f} s; R = {args.runs} per cell; covariance "
          f"{args.covariance}" + (f" (B = {args.bootstrap})" if cov_kw else "") + f"; noise {' and '.join(args.noise)}")
    print("| system | P | method | noise | coverage (pooled) | worst parameter | reported / MC variance (median, range) "
          "| max abs(bias) / RMS |")
    print("|---|---|---|---|---|---|---|---|")
    for s, P, method, noise in ((s, P, m, n) for s in args.systems for P in args.periods
                                for m in ("wgtls", "sml") for n in args.noise):
            if True:
                sel = [r for r in rows if r[0] == s and r[1] == P and r[2] == method and r[5] == noise]
                err = np.array([r[3] for r in sel])
                std = np.array([r[4] for r in sel])
                free = std[0] > 0
                err, std = err[:, free], std[:, free]
                cov = np.abs(err) <= 1.959964 * std
                p = cov.mean()
                se = np.sqrt(p * (1 - p) / cov.size)
                worst = cov.mean(axis=0).min()
                ratio = np.mean(std ** 2, axis=0) / np.var(err, axis=0)
                rms = np.sqrt(np.mean(err ** 2, axis=0))
                bias = np.abs(err.mean(axis=0)) / rms
                print(f"| {s} | {P} | {method} | {noise} | {100 * p:.1f} +- {100 * se:.1f} % | {100 * worst:.1f} % "
                      f"| {np.median(ratio):.2f} ({ratio.min():.2f}-{ratio.max():.2f}) | {bias.max():.2f} |")
    if len(args.noise) == 2:
        print()
        print("Monte Carlo variance of the moderated fit / of the sample fit, same realisations "
              "(median over the parameters, range):")
        print("| system | P | WGTLS | SML |")
        print("|---|---|---|---|")
        for s in args.systems:
            for P in args.periods:
                cells = []
                for method in ("wgtls", "sml"):
                    v = {}
                    for noise in args.noise:
                        sel = [r for r in rows if r[0] == s and r[1] == P and r[2] == method and r[5] == noise]
                        err = np.array([r[3] for r in sel])
                        free = np.array(sel[0][4]) > 0
                        v[noise] = np.var(err[:, free], axis=0)
                    q = v["moderated"] / v["sample"]
                    cells.append(f"{np.median(q):.2f} ({q.min():.2f}-{q.max():.2f})")
                print(f"| {s} | {P} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
