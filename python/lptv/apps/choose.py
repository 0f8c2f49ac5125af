"""``lptv select FILE``: choose the orders and the harmonic count from a measurement file.

Fits every structure of the grid ``--na`` x ``--nb`` x ``--k`` (ranges like ``1-3`` or lists like
``0,2``; without ``--k`` the nonparametric HTF of the data sets it) with :func:`lptv.select`,
prints the ranking and the choice, and writes into ``--out`` (default ``<file stem>-select/``):
``selection.csv`` (the ranked table), ``model.json`` (the chosen structure's fit) and
``summary.json``. The file formats and the period options are those of ``lptv identify``.
Exit status 0 with a choice the verdict accepts, 1 when every candidate is rejected (the
least bad is still written), 2 for bad options or files.

Example (the paper's simulation example as a measurement file)::

    python -c "import numpy as np, lptv.examples as ex; m = ex.paper_measurements(); \\
               np.savez('meas.npz', u=m['u'], y=m['y'], w0=m['w0'])"
    lptv select meas.npz --na 1-3 --nb 0-2 --k 1-4 --lines 1-243 --workers 2
"""
from __future__ import annotations

import argparse
import csv
import re
import sys
import warnings
from pathlib import Path

from lptv import select
from lptv.atomic import atomic_open
from lptv.apps.options import add_record_options, fundamental, parse_lines, read_record, sample_period
from lptv.apps.options import bounded_range, describe_record, dropped_note, in_option_terms, integer, output_folder
from lptv.apps.manyid import executor_of
from lptv.apps.report import write_json
from lptv.records.measurements import FileError


GRID_MAX = 10_000
"""The most values one grid option may hold (every combination is a fit)."""
OPTION_NAMES = {"na": "--na", "nb": "--nb", "k": "--k", "refine": "--refine", "lines": "--lines",
                "criterion": "--criterion", "w0": "--w0", "ts": "--ts", "workers": "--workers",
                "periods": "--periods", "skip_periods": "--skip-periods", "fs": "--fs", "dt": "--dt"}


def parse_grid(text, opt):
    """'1-3', '0,2' or '2' -> the sorted values."""
    out = []
    for tok in str(text).split(","):
        m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", tok)
        if not m or (m.group(2) and int(m.group(2)) < int(m.group(1))):
            raise FileError(f"{opt}: '{tok.strip()}' is not a non-negative integer or a range like 1-3")
        out.extend(bounded_range(int(m.group(1)), int(m.group(2) or m.group(1)), opt, tok.strip(), GRID_MAX))
    if len(set(out)) != len(out):
        raise FileError(f"{opt}: a value is given twice in '{text}'")
    return sorted(out)


def add_parser(sub):
    p = sub.add_parser(
        "select", help="choose the orders and harmonic count of a model from a measurement file",
        description="Fits a grid of structures (na, nb, k harmonics on every coefficient) by WGTLS, "
                    "the best per k again by SML, ranks them by MDL (or AIC) with the verdict "
                    "first, and writes the ranking (selection.csv), the chosen model.json and "
                    "summary.json into --out; exit status 1 when the verdict rejects every candidate.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
               "  lptv select meas.npz --na 1-3 --nb 0-2 --k 0-4\n"
               "  lptv select record.csv --periods 8 --period 10 --na 1-3 --nb 0-2 --k 0 --criterion aic\n"
               "  lptv select meas.npz --na 2 --nb 1 --k 0-4 --workers 2")
    p.add_argument("file", metavar="FILE", help="measurements: .csv, .npz or .mat (as for lptv identify)")
    p.add_argument("--na", default="1-3", help="orders of the output side to try (default 1-3)")
    p.add_argument("--nb", default="0-2", help="orders of the input side to try (default 0-2)")
    p.add_argument("--k", help="harmonic counts to try, e.g. 0-4 (default: from the data's HTF branches)")
    add_record_options(p)
    p.add_argument("--criterion", default="mdl", choices=["mdl", "aic"], help="ranking criterion (default mdl)")
    p.add_argument("--refine", type=int, default=2, metavar="N",
                   help="structures per harmonic count refitted by SML (default 2; 0: WGTLS only)")
    p.add_argument("--out", help="output folder (default: <file stem>-select/)")
    b = p.add_mutually_exclusive_group()
    b.add_argument("--workers", type=int, metavar="N", help="local processes (default: all cores; 1: serially)")
    b.add_argument("--scheduler", metavar="ADDRESS", help="a Dask cluster, e.g. tcp://10.0.0.5:8786")
    return p


def _error(problem) -> int:
    msg = in_option_terms(' '.join(str(problem).split()) or type(problem).__name__, OPTION_NAMES)
    print(f"lptv select: error: {msg}", file=sys.stderr)
    return 2


def run(args) -> int:
    src = args.file
    several = [f"{opt} {v}" for opt, v in (("--input", getattr(args, "input", None)),
                                          ("--output", getattr(args, "output", None))) if v and "," in v]
    if several:
        return _error(f"{several[0]}: several channels: lptv select ranks structures of one input and one output (its "
                      "guide, the nonparametric HTF, and its grid of orders and one harmonic count are the "
                      "one-channel model's; a matrix model has a count per entry); fit each candidate structure with "
                      "lptv identify FILES --input ... --output ... and compare their verdicts")
    try:
        na, nb = parse_grid(args.na, "--na"), parse_grid(args.nb, "--nb")
        k = parse_grid(args.k, "--k") if args.k is not None else None
        lines = parse_lines(args.lines) if args.lines is not None else None
        if args.refine < 0:
            raise FileError(f"--refine must be >= 0, got {args.refine}")
        integer(args.refine, "--refine")
        try:
            output_folder(args.out)
        except OSError as e:
            raise FileError(f"{e.filename or args.out}: {e.strerror or e}") from None
        executor, workers = executor_of(args)
        meas = read_record(src, args)
        ts = sample_period(args, meas)
        w0 = fundamental(args, meas)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # the result says the same in its warnings
            sel = select(meas.u, meas.y, w0=w0, ts=ts, na=na, nb=nb, k=k, lines=lines,
                         criterion=args.criterion, refine=args.refine, executor=executor, workers=workers)
    except FileError as e:
        return _error(f"{src}: {e}")
    except (ValueError, ImportError) as e:
        return _error(e)
    out = Path(args.out) if args.out else Path(Path(src).stem + "-select")
    P, N = meas.u.shape
    print(f"lptv select: {src} ({meas.format}, {P} periods of {N} samples, w0 = {w0:.6g} rad/s"
          + describe_record(meas) + (f", discrete-time models with ts = {ts:g} s" if ts else "") + "), "
          f"{len(sel.rows)} structures on {sel.lines.size} lines, {sel.executor}, {sel.elapsed:.1f} s -> {out}/")
    if dropped_note(meas):
        print(dropped_note(meas))
    print(sel.summary())
    try:
        out.mkdir(parents=True, exist_ok=True)
        with atomic_open(out / "selection.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(sel.rows[0]))
            w.writeheader()
            w.writerows(sel.rows)
        sel.result.model.save(out / "model.json")
        write_json(out / "summary.json", {
            "file": str(src), "periods": P, "samples_per_period": N, "w0": w0, "ts": ts,
            "fs": meas.fs, "input": meas.input, "output": meas.output, "trimmed_samples": meas.trimmed,
            "skipped_periods": meas.skipped,
            "criterion": sel.criterion, "choice": dict(zip(("na", "nb", "k"), sel.choice)),
            "choice_ok": sel.choice_ok, "method": sel.result.method, "n_lines": int(sel.lines.size),
            "correction": sel.correction, "htf_harmonics": sel.htf_harmonics,
            "structures": len(sel.rows), "executor": sel.executor, "seconds": sel.elapsed,
            "warnings": list(sel.warnings)})
    except OSError as e:
        return _error(f"{e.filename or out}: {e.strerror or e}")
    print(f"wrote {out / 'selection.csv'}, {out / 'model.json'}, {out / 'summary.json'}")
    return 0 if sel.choice_ok else 1
