"""Noise that passes through the system, two inputs and two outputs (METHOD.md sections 19 and
20): the verdict and the intervals on records of a 2 x 2 rig with disturbances entering before
its time-varying dynamics, in open loop and under decentralised proportional feedback, simulated
by SciPy's solve_ivp (tests/python/process_rig2.py), never by lptv.

Per cell (loop, P, disturbance level) R records, each a pair of experiments (the orthogonal
pattern of section 19), fitted with the true structure by the default method (WGTLS; ``--methods``
adds SML) on three noise routes: 'sample' (the periods' (co)variances, section 19), 'full' (the
whole record's, section 20) and 'auto' (the default: the line test chooses, then the moderation).
Reported per method and route: the verdict's rejections of the true structure (its size;
binomial standard error), the 95 % intervals' pooled coverage and the lowest and highest per
parameter (the parameters named), the largest |mean| and the range of the spreads of the
standardised errors, and for 'auto' how often it took the record's statistics and how often it
moderated them.

    python bench/python/bench_process_noise_mimo.py --runs 400 --periods 8 4 16 --loop open feedback
    python bench/python/bench_process_noise_mimo.py --runs 400 --routes auto full-no-T --methods wgtls sml
    python bench/python/bench_process_noise_mimo.py --rows --runs 100 --periods 8 --loop feedback --process 0 5
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "python"))
import process_rig2 as pr  # noqa: E402  (tests/python/process_rig2.py: the 2 x 2 rig by solve_ivp)

import lptv  # noqa: E402

ROUTES = ("sample", "full", "auto")
# a route's name: its noise= and transient= (METHOD.md section 20: the record's routes fit the
# transient term by default; 'full-no-T' is the record's noise without it)
ROUTE_ARGS = {"sample": ("sample", "auto"), "full": ("full", "auto"), "auto": ("auto", "auto"),
              "full-no-T": ("full", False), "auto-no-T": ("auto", False)}


def cell(loop, P, process, runs, methods, seed0, routes=ROUTES):
    truth = pr.truth()
    out = {(m, r): dict(rej=0, cov=[], z=[], full=0, moderated=0, n=0, failed=0) for m in methods for r in routes}
    batch = 25
    for start in range(0, runs, batch):
        seeds = [seed0 + i for i in range(start, min(runs, start + batch))]
        for rec in pr.records(seeds, periods=P, loop=loop, process=process):
            for m in methods:
                for route in routes:
                    o = out[(m, route)]
                    noise, transient = ROUTE_ARGS[route]
                    try:
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore")
                            res = lptv.identify(rec["experiments"], **pr.STRUCTURE, w0=pr.W0,
                                                lines=pr.fit_lines(), method=m, noise=noise,
                                                transient=transient)
                    except ValueError as err:      # counted and said, not hidden
                        o["failed"] += 1
                        print(f"#   {loop} P={P} {m} {route}: {err}", flush=True)
                        continue
                    o["n"] += 1
                    o["rej"] += res.model_ok is False
                    o["full"] += res.noise.startswith("full")
                    o["moderated"] += res.noise.endswith("moderated")
                    std = res.parameter_std
                    free = std > 0
                    ci = res.confidence_interval(0.95)
                    o["cov"].append(((truth >= ci[:, 0]) & (truth <= ci[:, 1]))[free])
                    o["z"].append(((res.eta - truth) / np.where(free, std, 1))[free])
    return out


def rows(args) -> int:
    """The residues at the true parameters on the record's statistics (noise='full'), per cell:
    their Monte Carlo mean square over the residue covariance eq. 19.12, and the correlation
    between the rows of one output and experiment, |E{e_l conj(e_l')}| normalised, by the lag
    between the rows (independent residues: about 0.9 / sqrt(R))."""
    from lptv.estimation.mimo_fit import core_data, core_structure, residues
    from lptv.spectra.mimo_frequency_data import MimoFrequencyData, MimoStructure, as_entry_counts

    st = MimoStructure(2, 0, as_entry_counts(pr.STRUCTURE["ka"], 2, 2, 2, "ka"), as_entry_counts(0, 0, 2, 2, "kb"),
                       2, 2, pr.W0)
    lines, xi = pr.fit_lines(), pr.truth()
    n = lines.size
    print(f"# rows at the truth, record's statistics, {args.runs} records a cell (independent |corr| about "
          f"{0.89 / np.sqrt(args.runs):.2f})")
    print("loop      P  dist  out exp   E|e|^2 / C_e [min median max]   |corr| at row lag 1 2 5 10   rows 2-7")
    for P in args.periods:
        for loop in args.loop:
            for proc in args.process:
                E, C = [], []
                for start in range(0, args.runs, 25):
                    seeds = [args.seed + 2000 + i for i in range(start, min(args.runs, start + 25))]
                    for rec in pr.records(seeds, periods=P, loop=loop, process=proc):
                        ds = [MimoFrequencyData.from_periods(u, y, w0=pr.W0, statistics="record")
                              for u, y in rec["experiments"]]
                        res, Ce = residues(core_data(ds, [lines, lines]), core_structure(st), xi)
                        E.append(res)
                        C.append(np.real(np.diagonal(Ce, axis1=1, axis2=2)))
                E, C = np.array(E), np.array(C)
                ratio = np.mean(np.abs(E) ** 2, axis=0) / C.mean(axis=0)
                for o in range(2):
                    for e in range(2):
                        Z = E[:, e * n:(e + 1) * n, o]
                        G = Z.T @ Z.conj() / len(Z)
                        d = np.sqrt(np.real(np.diag(G)))
                        Cn = np.abs(G) / np.outer(d, d)
                        r = ratio[e * n:(e + 1) * n, o]
                        low = Cn[:6, :6][~np.eye(6, dtype=bool)].mean()
                        print(f"{loop:9s} {P:2d} {proc:5.1f}   {o}   {e}    {r.min():5.2f} {np.median(r):5.2f} {r.max():5.2f}"
                              f"        " + " ".join(f"{np.diag(Cn, k).mean():4.2f}" for k in (1, 2, 5, 10))
                              + f"        {low:4.2f}", flush=True)
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--periods", type=int, nargs="+", default=[8])
    ap.add_argument("--loop", nargs="+", default=["open", "feedback"], choices=["open", "feedback"])
    ap.add_argument("--process", type=float, nargs="+", default=[5.0],
                    help="each disturbance's rms in N (0: sensor noise alone)")
    ap.add_argument("--methods", nargs="+", default=["wgtls"], choices=["wgtls", "sml"])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--routes", nargs="+", default=list(ROUTES), choices=list(ROUTE_ARGS),
                    help="noise routes ('full-no-T', 'auto-no-T': without the record's transient term)")
    ap.add_argument("--rows", action="store_true",
                    help="only the residues at the true parameters (seeds from 2000 + seed): their variance "
                         "against eq. 19.12 on the record's statistics and their correlation between rows")
    args = ap.parse_args(argv)
    if args.rows:
        return rows(args)
    names = np.array(pr.NAMES)[np.flatnonzero(~np.isin(pr.NAMES, ["a2[0,0].re0", "a2[0,1].re0", "a2[1,0].re0",
                                                                   "a2[1,1].re0"]))]
    print(f"# bench_process_noise_mimo: runs {args.runs}, methods {' '.join(args.methods)}")
    print("loop      P  dist  method route   reject (+-se)   cover (+-se)  [min  max]   mean z  std z      "
          "record / moderated   lowest, highest")
    for P in args.periods:
        for loop in args.loop:
            for proc in args.process:
                t0 = time.time()
                out = cell(loop, P, proc, args.runs, args.methods, args.seed, args.routes)
                for (m, route), o in out.items():
                    n = o["n"]
                    cov = np.array(o["cov"])
                    z = np.array(o["z"])
                    rej = o["rej"] / n
                    se = np.sqrt(max(rej * (1 - rej), 1.0 / n) / n)
                    per = cov.mean(0)
                    pooled = cov.mean()
                    # the pooled figure's error: binomial over the records (the parameters of one
                    # record are not independent; this is the error if they were)
                    se_c = np.sqrt(pooled * (1 - pooled) / cov.size)
                    fail = f"  ({o['failed']} failed)" if o["failed"] else ""
                    print(f"{loop:9s} {P:2d} {proc:5.1f}  {m:6s} {route:9s} {100 * rej:5.1f} (+-{100 * se:3.1f})  "
                          f"{100 * pooled:5.1f} (+-{100 * se_c:3.1f})  [{100 * per.min():4.1f} {100 * per.max():5.1f}]  "
                          f"{np.abs(z.mean(0)).max():6.2f}  {z.std(0).min():4.2f}-{z.std(0).max():4.2f}   "
                          f"{o['full']}/{n} {o['moderated']}/{n}   {names[np.argmin(per)]}, {names[np.argmax(per)]}"
                          f"{fail}", flush=True)
                print(f"#   cell time {time.time() - t0:.0f} s (per-parameter binomial error at this R: "
                      f"+-{100 * np.sqrt(0.95 * 0.05 / args.runs):.1f} %)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
