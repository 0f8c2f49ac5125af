"""The verdict's tests one by one without a model error, on the sample and on the moderated noise
variances, paired (the same fits judged both ways).

For each system and P, R realisations of the true structure fitted by WGTLS (the default; or
SML with ``--method sml``); the
verdict (METHOD.md section 7) is formed once on each line's own sample (co)variances
(``lptv.judgement.verdict.MODERATE = False``) and once on the moderated ones (the default). Printed: the
family's size (any Holm-adjusted p-value below 1 %) with its binomial standard error, and per
test the mean and standard deviation of its statistic (residue groups: N(0, 1); score tests:
F(2, nu), mean and standard deviation about 1) and how often its own p-value falls below 5 %,
1 %, 0.1 %, then pooled over the tests.

    python bench/python/bench_verdict_tests.py --runs 400 --periods 4 --systems third_order
    python bench/python/bench_verdict_tests.py --runs 300 --periods 8 16 32 --systems discrete third_order
    python bench/python/bench_verdict_tests.py --runs 400 --periods 4 --systems discrete --noise moderated
    python bench/python/bench_verdict_tests.py --runs 500 --periods 4 8 16 32 --systems paper third_order discrete --method sml

``--noise moderated`` fits with ``lptv.identify(..., noise='moderated')``; the verdict then reads the
fit's own moderated variances (judged once).
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
import lptv.judgement.verdict  # noqa: E402
from lptv.examples import SYSTEMS, system_measurements  # noqa: E402


def one(args):
    system, P, seed, stream, noise, method = args
    rng = np.random.default_rng([seed, P, stream + SYSTEMS.index(system)])
    d = system_measurements(system, seed=rng, periods=P)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["lines"],
                            noise=noise, method=method)
    out = []
    for moderate in ((False, True) if noise == "sample" else (True,)):
        lptv.judgement.verdict.MODERATE = moderate
        t = lptv.judgement.verdict.residue_tests(res, res.structure)
        out.append((system, P, moderate, [(x.name, x.statistic, x.p_value, x.p_holm) for x in t.tests]))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=400)
    ap.add_argument("--periods", type=int, nargs="+", default=[4])
    ap.add_argument("--systems", nargs="+", default=["third_order"])
    ap.add_argument("--stream", type=int, default=11, help="seed stream (other than bench_verdict.py's)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--noise", default="sample", choices=("sample", "moderated"),
                    help="the noise the fits weigh by; 'moderated': judged once, on the fit's own moderation")
    ap.add_argument("--method", default="wgtls", choices=("wgtls", "sml"), help="the estimator fitted")
    args = ap.parse_args(argv)
    tasks = [(s, P, i, args.stream, args.noise, args.method) for s in args.systems for P in args.periods for i in range(args.runs)]
    with ProcessPoolExecutor(args.workers) as ex:
        rows = [o for chunk in ex.map(one, tasks, chunksize=8) for o in chunk]
    print(f"# {len(tasks)} realisations, {args.method.upper()} weighed by {args.noise} noise, seed stream {args.stream}")
    for moderate in ((False, True) if args.noise == "sample" else (True,)):
        sel = [r for r in rows if r[2] == moderate]
        rej = np.array([min(x[3] for x in r[3]) <= lptv.judgement.verdict.ALPHA for r in sel], float)
        p = rej.mean()
        print(f"\n{'moderated' if moderate else 'sample'} variances: size {100 * p:.2f} +- "
              f"{100 * np.sqrt(p * (1 - p) / rej.size):.2f} % ({int(rej.sum())} of {rej.size})")
        for s in args.systems:
            print("   " + "  ".join(f"{s} P={P}: {int(sum(min(x[3] for x in r[3]) <= lptv.judgement.verdict.ALPHA for r in sel if r[0] == s and r[1] == P))}"
                                  f"/{sum(1 for r in sel if r[0] == s and r[1] == P)}" for P in args.periods))
        names = sorted({x[0] for r in sel for x in r[3]})
        for n in names:
            st = np.array([x[1] for r in sel for x in r[3] if x[0] == n])
            pv = np.array([x[2] for r in sel for x in r[3] if x[0] == n])
            print(f"   {n[:46]:46s} mean {st.mean():6.2f} sd {st.std():5.2f}  p<0.05 {np.mean(pv < 0.05):.3f} "
                  f"p<0.01 {np.mean(pv < 0.01):.3f} p<0.001 {np.mean(pv < 0.001):.4f}")
        why = {}
        for r in sel:
            for x in r[3]:
                if x[3] <= lptv.judgement.verdict.ALPHA:
                    key = x[0] + (" (too small)" if x[1] < 0 and "harmonic" not in x[0] else "")
                    why.setdefault(key, []).append(f"{r[0][:5]}{r[1]}")
        for n, where in sorted(why.items()):
            print(f"   rejects: {n[:58]:58s} {len(where):3d}x  {' '.join(where)}")
        kk = np.array([len(r[3]) for r in sel])
        bonf = np.array([min(x[2] for x in r[3]) * k for r, k in zip(sel, kk)])
        print(f"   families whose smallest p-value is below 1 % / k (Bonferroni; k = {kk.min()}-{kk.max()} tests): "
              f"{100 * np.mean(bonf <= lptv.judgement.verdict.ALPHA):.2f} %")
        allp = np.array([x[2] for r in sel for x in r[3]])
        print(f"   pooled over the tests (n = {allp.size}): p<0.05 {np.mean(allp < 0.05):.4f} "
              f"p<0.01 {np.mean(allp < 0.01):.4f} p<0.001 {np.mean(allp < 0.001):.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
