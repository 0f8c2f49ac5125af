"""The verdict's tests one by one on one cell (system, P) of bench/python/periodic_records.py's
records, with the default noise route (bench_verdict_tests.py does the same on lptv's own
examples, sample and moderated variances paired): how often
each test's p-value falls below 1 % and 0.1 % on a right structure, and which tests reject.

    python bench/python/bench_verdict_cells.py [--system lti4] [--periods 16] [--seeds 0 2000]
        [--method wgtls]

Each record is fitted by ``lptv.identify`` (the default noise route) with the system's right
structure; the verdict's tests are read from ``res.residue_tests``: the residue sum over the rows
with signal, the offset groups, and the score tests for one more harmonic per coefficient.
Without a model error every p-value is uniform: 1 % below 0.01, 0.1 % below 0.001.
"""
from __future__ import annotations

import argparse
import collections
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import lptv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from periodic_records import SYSTEMS, record  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--system", default="lti4", choices=SYSTEMS)
    ap.add_argument("--periods", type=int, default=16)
    ap.add_argument("--seeds", type=int, nargs=2, default=[0, 2000])
    ap.add_argument("--method", default="wgtls", choices=("wgtls", "sml"))
    args = ap.parse_args(argv)
    t0 = time.time()
    stat, pv = collections.defaultdict(list), collections.defaultdict(list)
    who, rejected = collections.Counter(), []
    for seed in range(*args.seeds):
        d = record(args.system, args.periods, [seed, args.periods, SYSTEMS.index(args.system), 3], noise="smooth")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["rows"],
                              method=args.method)
        rejected.append(not r.model_ok)
        for t in r.residue_tests.tests:
            key = t.name if t.kind == "score" else ("the rows with signal" if t.name == "rows with signal"
                                                     else "offset groups")
            stat[key].append(t.statistic)
            pv[key].append(t.p_value)
            if t.rejects:
                who[key] += 1
    n = len(rejected)
    p = float(np.mean(rejected))
    print(f"bench_verdict_cells.py --system {args.system} --periods {args.periods} --seeds {args.seeds[0]} "
          f"{args.seeds[1]} --method {args.method}: {n} records in {time.time() - t0:.0f} s")
    print(f"rejected: {100 * p:.2f} +- {100 * np.sqrt(max(p, 1 / n) * (1 - p) / n):.2f} %")
    print(f"{'test':<36} {'count':>6} {'mean statistic':>15} {'p < 0.01':>9} {'p < 0.001':>10} {'rejects':>8}")
    for k in stat:
        s, q = np.array(stat[k]), np.array(pv[k])
        print(f"{k:<36} {s.size:>6} {s.mean():>15.3f} {100 * np.mean(q < 0.01):>8.2f}% {100 * np.mean(q < 0.001):>9.3f}% "
              f"{who[k]:>8}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
