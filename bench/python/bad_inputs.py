"""Bad inputs: counts per outcome over the table of tests/python/bad_input_cases.py
(run by tests/python/bad_input_runner.py).

Runs every case of the suite tests/python/test_bad_inputs.py (the Python API in child
interpreters, each command-line case as ``python -m lptv ...`` in its own process from scratch)
and prints how many gave each outcome: clear error, warning with a meaningful result, correct
result, unclear error, silent wrong result, crash; then the counts per class of bad value, and
every case whose outcome is not the expected one.

    PYTHONPATH=python python bench/python/bad_inputs.py [--fork] [--limit N]

``--fork`` runs the command-line cases as the test suite does (forked from one process that has
imported lptv), which is faster on a loaded machine.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "python"))

import bad_input_cases as table  # noqa: E402
import bad_input_runner as runner  # noqa: E402

LABELS = {"warning": "warning with meaningful result"}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fork", action="store_true", help="fork the command-line cases (as the tests do)")
    ap.add_argument("--python", metavar="DIR", help="the lptv package to test (default: this tree's python/)")
    ap.add_argument("--limit", type=int, metavar="N", help="the first N cases of each kind only (a quick run)")
    args = ap.parse_args(argv)
    if args.python:
        table.PYTHONPATH = str(Path(args.python).resolve())

    t0 = time.perf_counter()
    py, cli = table.python_cases(), table.cli_cases()
    if args.limit is None:
        out = runner.run_all(workers=2, fork=args.fork)
    else:
        py, cli = py[:args.limit], cli[:args.limit]
        out = {**runner.run_python_cases([c.id for c in py]), **runner.run_cli_cases(cli, 2, fork=args.fork)}
    elapsed = time.perf_counter() - t0

    cases = py + cli
    total = Counter(out[c.id][0] for c in cases)
    print(f"{len(cases)} bad or edge-case inputs: {len(py)} through the Python API, {len(cli)} through the "
          f"command line ({'forked' if args.fork else 'python -m lptv'}, one process each); "
          f"{elapsed:.0f} s, load average {os.getloadavg()[0]:.1f}")
    print()
    print(f"{'outcome':32s} {'all':>5s} {'Python':>7s} {'CLI':>5s}")
    for o in runner.OUTCOMES:
        n_py = sum(out[c.id][0] == o for c in py)
        n_cli = sum(out[c.id][0] == o for c in cli)
        print(f"{LABELS.get(o, o):32s} {total[o]:5d} {n_py:7d} {n_cli:5d}")
    print()
    classes = sorted({c.klass for c in cases}, key=lambda k: [c.klass for c in cases].index(k))
    print(f"{'class of input':16s} {'cases':>5s}  " + "  ".join(LABELS.get(o, o) for o in runner.OUTCOMES))
    for k in classes:
        ks = [c for c in cases if c.klass == k]
        cnt = Counter(out[c.id][0] for c in ks)
        print(f"{k:16s} {len(ks):5d}  " + "  ".join(f"{cnt[o]:{len(LABELS.get(o, o))}d}" for o in runner.OUTCOMES))
    wrong = [c for c in cases if out[c.id][0] != c.expected]
    print()
    print(f"cases whose outcome is not the expected one: {len(wrong)}")
    for c in wrong:
        print(f"  {c.id}: {out[c.id][0]} (expected {c.expected}): {out[c.id][1][:200]}")
    if wrong:
        c = wrong[0]
        print(f"bad_inputs: {len(wrong)} of {len(cases)} cases with another outcome than the expected one; the first, "
              f"{c.id}: {out[c.id][0]} (expected {c.expected}): {out[c.id][1][-200:]}", file=sys.stderr)
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
