"""The verdict of a fit of the best linear approximation by Monte Carlo: size and power of the
lack-of-fit test (DistortionResult.lack_of_fit, METHOD.md section 16, "Judging the parametric
BLA"), against the residue tests of section 7 that judged these fits before.

Systems: an LPTV system followed by a cubic (Wiener: y + c y^3, whose best linear approximation
is the LPTV system times a periodic gain, outside the fitted class) or preceded by one
(Hammerstein: the actuator x = u + c u^3, whose best linear approximation is the LPTV system with
b scaled by the actuator's linear gain g, inside the fitted class). M = 6 random-phase
realisations of one flat amplitude spectrum, P periods each, noise as in bench_bla.py. Each run
estimates the distortion, fits SML over the realisations (DistortionResult.experiments()) and
reads:

- "lack of fit": the new verdict's test (res.lack_of_fit; permutation p-value of the lines'
  summed normal scores), its rejections at 1 % and 5 %;
- "true BLA": the same test of the exact BLA model (Hammerstein only: g measured from the cubic
  over 400 realisations of the multisine), which isolates the test from the estimate;
- "residue tests": the rejections of section 7's family on the same fits (what the verdict said
  before);
- the lines' own p-values below 5 % and 1 % (per line, F(2 q, 2 (M - q)));
- Hammerstein: the SML estimate's bias against the exact BLA, |mean - truth| / std per
  parameter (the fit's own bias is what the test sees beyond the true BLA's rate).

    python bench/python/bench_bla_verdict.py --runs 400
    python bench/python/bench_bla_verdict.py --runs 100 --cases third_order/hammerstein/true
"""
from __future__ import annotations

import argparse
import os
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv import examples as ex  # noqa: E402
from bench_bla import actuator_gain, exact_bla_eta  # noqa: E402  (the exact BLA: one definition)

M = 6   # the default number of realisations per run (--realisations)
SYSTEMS = ex.BLA_SYSTEMS
STRUCTURES = {   # the fitted structure: true, one harmonic / one order short, or richer
    ("paper", "true"): dict(na=2, nb=1, ka=3, kb=3),
    ("paper", "harmonic"): dict(na=2, nb=1, ka=[3, 2, 3], kb=3),
    ("paper", "order"): dict(na=1, nb=1, ka=3, kb=3),
    ("third_order", "true"): ex.THIRD_ORDER_STRUCTURE,
    ("third_order", "harmonic"): dict(na=3, nb=1, ka=[1, 1, 0, 0], kb=[2, 0]),
    ("third_order", "order"): dict(na=2, nb=1, ka=[2, 1, 0], kb=[2, 0]),
    # the Wiener system's BLA wants more harmonics (the score tests of section 7 name a3's and b0's)
    ("third_order", "richer"): dict(na=3, nb=1, ka=[2, 1, 0, 1], kb=[3, 0]),
    ("discrete", "true"): ex.DISCRETE_STRUCTURE,
    ("discrete", "harmonic"): dict(na=2, nb=1, ka=[1, 1, 0], kb=[2, 0]),
    ("discrete", "order"): dict(na=1, nb=1, ka=[2, 0], kb=[2, 0]),
}
CASES = [   # system / kind / fitted structure, cubic c, periods
    ("third_order/hammerstein/true", 0.05, 8), ("third_order/hammerstein/harmonic", 0.05, 8),
    ("third_order/hammerstein/order", 0.05, 8), ("third_order/wiener/true", 0.03, 8),
    ("third_order/wiener/richer", 0.03, 8),
    ("paper/hammerstein/true", 0.05, 4), ("paper/hammerstein/true", 0.05, 16),
    ("paper/hammerstein/harmonic", 0.05, 4), ("paper/hammerstein/order", 0.05, 4),
    ("paper/wiener/true", 0.02, 4), ("paper/wiener/true", 0.02, 16),
    ("discrete/hammerstein/true", 0.05, 8), ("discrete/hammerstein/harmonic", 0.05, 8),
    ("discrete/hammerstein/order", 0.05, 8),
]


def one(args):
    run, case, c, P, g, referred, M = args
    system, kind, fitted = case.split("/")
    rows = SYSTEMS[system][3]
    structure = STRUCTURES[(system, fitted)]
    r = ex.cubic_realisations(system, c, "input" if kind == "hammerstein" else "output", M, P, seed=[run, 77])
    m, u, y = r["model"], r["u"], r["y"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = lptv.distortion(np.array(u), np.array(y), w0=m.w0, ts=m.ts)
        true_p = np.nan
        if kind == "hammerstein":
            bla = lptv.Model(np.array(m.a), np.array(m.b) * g, w0=m.w0, ts=m.ts)
            true_p = d.lack_of_fit(bla, lines=rows).p_value
        refused = dict(p=0.0, stat=np.nan, p_lines=np.array([]), true_p=true_p, old_rejects=True,
                       detected=bool(d.detected), eta=None, std=None, names=None, n_lines=0, refused=True)
        try:        # refused where one common level swamps a weak realisation (the discrete-time system)
            res = lptv.identify(d.experiments(referred="none" if referred == "none" else "output"),
                                lines=[rows] * M, method="sml", **structure)
        except ValueError:
            res = None
        if referred == "input":   # the level referred to the input through a first fit: the output-
            # referred one, or the plain fit of the realisations' noise alone where that is refused or
            # its branches are unreliable (as the messages advise)
            firsts = ([res] if res is not None else []) + [None]
            exps = None
            for first in firsts:
                if first is None:
                    first = lptv.identify([(u[i], y[i]) for i in range(M)], w0=m.w0, ts=m.ts, lines=[rows] * M,
                                          method="sml", **structure)
                try:
                    exps = d.experiments(referred="input", model=first)
                    break
                except ValueError as e:
                    if not str(e).startswith("model: its branches cannot refer"):
                        raise
            if exps is None:
                return refused
            try:
                res = lptv.identify(exps, lines=[rows] * M, method="sml", **structure)
            except ValueError:
                return refused
        elif res is None:
            return refused
        lof = res.lack_of_fit
        old = res.residue_tests
    return dict(p=lof.p_value, stat=lof.statistic, p_lines=lof.p_lines, true_p=true_p,
                old_rejects=bool(old is not None and any(t.rejects for t in old.tests)),
                detected=bool(d.detected), eta=np.asarray(res.eta), std=np.asarray(res.parameter_std),
                names=tuple(res.eta_names), n_lines=lof.lines.size, refused=False)


def pct(x, n):
    return f"{100 * x:5.1f} +- {100 * np.sqrt(max(x * (1 - x), 1e-12) / n):.1f} %"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cases", nargs="*", help="system/kind/structure[:P] (default: every case)")
    ap.add_argument("--realisations", type=int, default=6, help="M per run")
    ap.add_argument("--referred", default="output", choices=("output", "input", "none"),
                    help="DistortionResult.experiments(referred=...): input refers the level through a first fit; "
                         "none fits the realisations with their noise alone")
    args = ap.parse_args()
    cases = CASES
    if args.cases:
        want = [(s.split(":")[0], int(s.split(":")[1]) if ":" in s else None) for s in args.cases]
        cases = [cs for cs in CASES if any(cs[0] == w and (p is None or cs[2] == p) for w, p in want)]
    M = args.realisations
    print(f"# M = {M} realisations, R = {args.runs} runs per case; the level referred to the {args.referred}; load average "
          f"{' '.join(open('/proc/loadavg').read().split()[:3])} at the start")
    print("| case | c | P | lines | lack of fit rejects at 1 % | at 5 % | true BLA at 1 % | at 5 % | residue tests "
          "reject | lines p < 5 % | p < 1 % | mean z | max abs(bias) / std |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    gains = {}
    with ProcessPoolExecutor(args.workers) as pool:
        for case, c, P in cases:
            t0 = time.time()
            system, kind, fitted = case.split("/")
            g = gains.setdefault((system, c), actuator_gain(system, c)) if kind == "hammerstein" else 1.0
            out = list(pool.map(one, [(r, case, c, P, g, args.referred, M) for r in range(args.runs)], chunksize=2))
            R = len(out)
            refused = sum(o["refused"] for o in out)
            fitted_out = [o for o in out if not o["refused"]]
            p = np.array([o["p"] for o in out])
            tp = np.array([o["true_p"] for o in out])
            pl = np.concatenate([o["p_lines"] for o in out])
            old = np.mean([o["old_rejects"] for o in out])
            z = np.nanmean([o["stat"] for o in out])
            bias = ""
            if kind == "hammerstein" and fitted == "true":
                eta = np.array([o["eta"] for o in fitted_out])
                free = fitted_out[0]["std"] > 0
                t = exact_bla_eta(system, g, fitted_out[0]["names"])
                b = np.abs(eta.mean(0) - t)[free] / eta.std(0, ddof=1)[free]
                bias = f"{b.max():.2f} (median {np.median(b):.2f}; se of a mean 1/sqrt(R) = {1 / np.sqrt(R):.2f})"
            true_cols = (f"{pct(np.mean(tp <= 0.01), R)} | {pct(np.mean(tp <= 0.05), R)}" if kind == "hammerstein"
                         else "- | -")
            print(f"| {case} | {c} | {P} | {max(o['n_lines'] for o in out)} | {pct(np.mean(p <= 0.01), R)} | "
                  f"{pct(np.mean(p <= 0.05), R)} | {true_cols} | {pct(old, R)} | {100 * np.mean(pl < 0.05):.2f} % | "
                  f"{100 * np.mean(pl < 0.01):.2f} % | {z:+.2f} | {bias or '-'} |", flush=True)
            print(f"#   {case} P = {P}: {time.time() - t0:.0f} s, distortion detected in "
                  f"{100 * np.mean([o['detected'] for o in out]):.0f} % of the runs"
                  + (f"; the fit refused in {refused} (a realisation below the common level, or the first fit's "
                     "branches unreliable; counted as rejections)" if refused else ""), flush=True)


if __name__ == "__main__":
    main()
