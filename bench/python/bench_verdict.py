"""Size and power of the verdict (res.model_ok) by Monte Carlo, on three systems.

For each system of lptv.examples (the paper's example, the third-order continuous-time
system, the discrete-time system), number of periods P and method (WGTLS, SML):

- size: the true structure is fitted; the fraction of realisations whose verdict rejects it
  (goal <= 1 %);
- power against a missing harmonic: the true system has one more harmonic on a_0, of 2 % of
  a_0's mean value, which the fitted structure leaves out (goal >= 80 %);
- power against a0 with one harmonic too few (the fit drops a_0's highest harmonic);
- power against a missing order: the fit drops b_nb.

Each rate is given with its binomial standard error sqrt(p (1 - p) / R).

    python bench/python/bench_verdict.py --runs 400 --periods 4 8 16 32
    python bench/python/bench_verdict.py --runs 500 --first-seed 500 --cases true   (the size alone)

``--noise moderated`` fits with ``lptv.identify(..., noise='moderated')`` (the verdict then reads
the fit's own moderated variances). ``--sample-variances`` judges the residues against each line's own sample (co)variances (the
verdict before the moderated variances of METHOD.md section 7), for comparison.
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
from lptv.examples import SYSTEMS, noisy_periods, system_measurements  # noqa: E402

CASES = ("true", "extra_harmonic", "a0_fewer", "missing_order")


def _extra_harmonic_model(m, fraction=0.02):
    """m with one more harmonic on a_0: fraction of a_0's mean value, phase 0.7 rad."""
    a, b = m.a, m.b
    K = a.shape[1] // 2
    a2 = np.zeros((a.shape[0], 2 * K + 3), complex)
    a2[:, 1:-1] = a
    c = fraction * abs(a[0, K]) * np.exp(0.7j)
    a2[0, -1], a2[0, 0] = c, np.conj(c)
    b2 = np.zeros((b.shape[0], 2 * K + 3), complex)
    b2[:, 1 + K - b.shape[1] // 2: 1 + K + b.shape[1] // 2 + 1] = b
    return lptv.Model(a2, b2, w0=m.w0, ts=m.ts if m.discrete else None)


def _structure(case, st):
    st = dict(st)
    ka = list(np.broadcast_to(st["ka"], (st["na"] + 1,)))
    kb = list(np.broadcast_to(st["kb"], (st["nb"] + 1,)))
    if case == "a0_fewer":
        ka[0] = max(ka[0] - 1, 0)
    if case == "missing_order":
        kb = kb[:-1]
        st["nb"] -= 1
    st["ka"], st["kb"] = [int(k) for k in ka], [int(k) for k in kb]
    return st


def one(args):
    system, P, seed, moderate, noise, cases = args
    import lptv.judgement.verdict
    lptv.judgement.verdict.MODERATE = moderate
    rng = np.random.default_rng([seed, P, SYSTEMS.index(system)])
    out = []
    base = system_measurements(system, seed=rng, periods=P)
    for case in cases:
        d = base
        if case == "extra_harmonic":
            m = _extra_harmonic_model(base["model"])
            y0 = lptv.time_signal(lptv.simulate(m, base["U0"]), base["u0"].size)
            u, y = noisy_periods(base["u0"], y0, P, seed=rng, **base["noise"])
            d = dict(base, u=u, y=y)
        st = _structure(case, base["structure"])
        for method in ("wgtls", "sml"):
            t = time.perf_counter()
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    r = lptv.identify(d["u"], d["y"], **st, w0=d["w0"], ts=d["ts"], lines=d["lines"],
                                      method=method, noise=noise)
                    ok = r.model_ok
                    rt = r.residue_tests
                    reason = ("residue" if rt is not None and rt.rejected else
                              ("cost/prediction" if not ok else ""))
            except Exception as err:  # a failed fit counts as a rejection, and is reported
                ok, reason = False, f"error: {err}"
            out.append((system, P, case, method, ok, reason, time.perf_counter() - t))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--periods", type=int, nargs="+", default=[4, 8, 16, 32])
    ap.add_argument("--systems", nargs="+", default=["paper", "third_order", "discrete"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--noise", default="sample", choices=("sample", "moderated"),
                    help="the noise the fits weigh by (lptv.identify's noise=)")
    ap.add_argument("--sample-variances", action="store_true",
                    help="judge against the lines' own sample variances (no moderation)")
    ap.add_argument("--first-seed", type=int, default=0, help="seeds first-seed .. first-seed + runs - 1")
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=CASES,
                    help="the cases fitted (default all; 'true' alone measures the size)")
    args = ap.parse_args(argv)
    moderate = not args.sample_variances
    cases = tuple(c for c in CASES if c in args.cases)
    tasks = [(s, P, seed, moderate, args.noise, cases) for s in args.systems for P in args.periods
             for seed in range(args.first_seed, args.first_seed + args.runs)]
    t0 = time.time()
    with ProcessPoolExecutor(args.workers) as ex:
        rows = [r for chunk in ex.map(one, tasks, chunksize=8) for r in chunk]
    print(f"# {len(tasks)} realisations (seeds {args.first_seed}..{args.first_seed + args.runs - 1}) in "
          f"{time.time() - t0:.0f} s; R = {args.runs} per cell; "
          f"verdict on {'moderated' if moderate else 'sample'} variances; fits weighed by {args.noise} noise")
    print("| system | P | method | size (true structure) | power: extra 2 % harmonic | power: a0 one harmonic "
          "too few | power: missing order | errors |")
    print("|---|---|---|---|---|---|---|---|")
    for s in args.systems:
        for P in args.periods:
            for method in ("wgtls", "sml"):
                cells, n_err = [], 0
                for case in CASES:
                    sel = [r for r in rows if r[0] == s and r[1] == P and r[2] == case and r[3] == method]
                    if not sel:
                        cells.append("-")
                        continue
                    rej = np.array([not r[4] for r in sel], float)
                    n_err += sum(r[5].startswith("error") for r in sel)
                    p = rej.mean()
                    cells.append(f"{100 * p:.1f} +- {100 * np.sqrt(p * (1 - p) / len(sel)):.1f} %")
                print(f"| {s} | {P} | {method} | " + " | ".join(cells) + f" | {n_err} |")
    reasons = {}
    for r in rows:
        if r[2] == "true" and not r[4]:
            reasons.setdefault((r[0], r[1], r[3]), []).append(r[5][:100])
    for k, v in reasons.items():
        print("# false rejections", k, v[:4])
    return 0


if __name__ == "__main__":
    sys.exit(main())
