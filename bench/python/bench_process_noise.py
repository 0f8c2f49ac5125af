"""Noise that passes through the system (METHOD.md section 20): the verdict and the intervals on
records of a rig with a disturbance entering before its time-varying dynamics, in open loop and
under proportional feedback, simulated by SciPy's solve_ivp (tests/python/process_rig.py), never by lptv.

Per cell (loop, P, disturbance level) R records, each fitted with the true structure by WGTLS
and SML on three noise routes: 'sample' (the periods' per-line variances, section 4), 'full'
(the whole record's per-line statistics, section 20) and 'auto' (the default: the line test
chooses). Reported per method and route: the verdict's rejections of the true structure (its
size; binomial standard error), the 95 % intervals' pooled coverage and the lowest and highest
per parameter, the mean and the spread of the standardised errors, and for 'auto' how often the
line test chose the record. ``--second 0.02`` adds a 2 % second harmonic to the stiffness, which
the fitted structure (ka = 1) leaves out: the rejections are then the verdict's power.

    python bench/python/bench_process_noise.py --runs 200 --periods 4 8 16 --loop open feedback
    python bench/python/bench_process_noise.py --line-test --runs 200 --periods 4 8 16 --process 0 0.3 1 5
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "python"))
import process_rig as pr  # noqa: E402  (tests/python/process_rig.py: the rig by solve_ivp)

import lptv  # noqa: E402

ROUTES = ("sample", "full", "full-rows", "auto")
METHODS = ("wgtls", "sml")


def cell(loop, P, process, runs, second, seed0):
    truth = pr.truth()
    out = {(m, r): dict(rej=0, cov=[], z=[], full=0, n=0) for m in METHODS for r in ROUTES}
    batch = 25
    for start in range(0, runs, batch):
        seeds = [seed0 + i for i in range(start, min(runs, start + batch))]
        for rec in pr.records(seeds, periods=P, loop=loop, process=process, second=second):
            for m in METHODS:
                for route in ROUTES:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        res = lptv.identify(rec["u"], rec["y"], **pr.STRUCTURE, w0=pr.W0, lines=pr.fit_lines(),
                                            method=m, noise=route)
                    o = out[(m, route)]
                    o["n"] += 1
                    o["rej"] += res.model_ok is False
                    o["full"] += res.noise.startswith("full")
                    std = res.parameter_std
                    free = std > 0
                    ci = res.confidence_interval(0.95)
                    o["cov"].append(((truth >= ci[:, 0]) & (truth <= ci[:, 1]))[free])
                    o["z"].append(((res.eta - truth) / np.where(free, std, 1))[free])
    return out


def line_test(args) -> int:
    """The line test's rejections on the rig's records and on white noise (its size)."""
    print(f"# the line test (size {lptv.spectra.frequency_data.LINES_ALPHA:g}), {args.runs} records per cell")
    print("loop      P  dist   correlated (+-se)")
    for loop in args.loop:
        for P in args.periods:
            for proc in args.process:
                hits = 0
                for start in range(0, args.runs, 25):
                    seeds = [args.seed + i for i in range(start, min(args.runs, start + 25))]
                    for rec in pr.records(seeds, periods=P, loop=loop, process=proc):
                        d = lptv.FrequencyData.from_periods(rec["u"], rec["y"], w0=pr.W0)
                        hits += lptv.correlated_lines(d).correlated
                p = hits / args.runs
                print(f"{loop:9s} {P:2d} {proc:5.1f}   {100 * p:5.1f} (+-{100 * np.sqrt(max(p * (1 - p), 1 / args.runs) / args.runs):3.1f})")
    rng = np.random.default_rng(args.seed)
    for P in args.periods:
        hits = 0
        for _ in range(args.runs):
            u = rng.standard_normal((P, 256))
            y = np.roll(u, 1, axis=1) + 0.3 * rng.standard_normal((P, 256))
            hits += lptv.correlated_lines(lptv.FrequencyData.from_periods(u, y, w0=1.0)).correlated
        p = hits / args.runs
        print(f"white     {P:2d}    -    {100 * p:5.1f} (+-{100 * np.sqrt(max(p * (1 - p), 1 / args.runs) / args.runs):3.1f})")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--periods", type=int, nargs="+", default=[8])
    ap.add_argument("--loop", nargs="+", default=["open", "feedback"], choices=["open", "feedback"])
    ap.add_argument("--process", type=float, nargs="+", default=[5.0],
                    help="the disturbance's rms in N (0: sensor noise alone)")
    ap.add_argument("--second", type=float, default=0.0, help="a second harmonic of the stiffness left out of the fit")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--line-test", action="store_true",
                    help="only the line test (lptv.correlated_lines): how often it finds the lines correlated, "
                         "per loop, P and disturbance level, and on white noise")
    args = ap.parse_args(argv)
    if args.line_test:
        return line_test(args)
    print(f"# bench_process_noise: runs {args.runs}, second harmonic {args.second}")
    print("loop      P  dist  method route   reject (+-se)   cover  [min  max]   mean z  std z   record chosen")
    for loop in args.loop:
        for P in args.periods:
            for proc in args.process:
                t0 = time.time()
                out = cell(loop, P, proc, args.runs, args.second, args.seed)
                for (m, route), o in out.items():
                    n = o["n"]
                    cov = np.array(o["cov"])
                    z = np.array(o["z"])
                    rej = o["rej"] / n
                    se = np.sqrt(max(rej * (1 - rej), 1.0 / n) / n)
                    per = cov.mean(0)
                    print(f"{loop:9s} {P:2d} {proc:5.1f}  {m:6s} {route:7s} {100 * rej:5.1f} (+-{100 * se:3.1f})  "
                          f"{100 * cov.mean():5.1f}  [{100 * per.min():4.1f} {100 * per.max():5.1f}]  "
                          f"{np.abs(z.mean(0)).max():6.2f}  {z.std(0).min():4.2f}-{z.std(0).max():4.2f}   "
                          f"{o['full']}/{n}")
                print(f"#   cell time {time.time() - t0:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
