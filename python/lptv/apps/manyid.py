"""``lptv identify FILES... [--workers N | --scheduler ADDRESS]``: many records, one row each.

The options are those of ``lptv identify FILE`` (:mod:`lptv.apps.fileid`), the same for every
file. The fits run on local processes (``--workers``, default all cores; 1 runs them here) or on
a Dask cluster (``--scheduler``: the files are read by the workers, so their paths must exist
there). Writes ``results.csv`` (one row per file: the verdict (``model_ok``), the parameters and their std,
or the error message), ``models/<name>.json`` for each file that was fitted (the file's stem, with a hash of its
path when two files of the batch share the stem) and ``summary.json`` (which also maps each file
to its model); prints one line per file. Exit status 0 when every file was fitted and
every model is consistent with its data, 3 when every file was fitted but the verdict finds model
errors in some (their rows' ``model_ok`` is False), 1 when some failed (their rows say why), 2 for
bad options.

Example::

    lptv identify runs/*.npz --na 2 --nb 1 --ka 3 --kb 3 --lines 1-243 --workers 2 --out fleet
"""
from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

import numpy as np

from lptv import identify_many
from lptv.apps.options import OPTION_NAMES, parse_counts, parse_known, parse_lines, positive, read_options
from lptv.apps.options import Interrupted, in_option_terms, integer, interruptible, output_folder
from lptv.batch.executors import LOST
from lptv.batch.parts import CheckpointError, clear, stored_items
from lptv.apps.report import write_json
from lptv.records.measurements import FileError


MODEL_ERRORS = 3
"""The exit status when every file was fitted but the verdict finds model errors in some (as
lptv identify FILE's)."""


def _error(problem) -> int:
    print(f"lptv identify: error: {in_option_terms(' '.join(str(problem).split()), OPTION_NAMES)}",
          file=sys.stderr)
    return 2


def executor_of(args):
    """(executor, workers) from --workers / --scheduler. With a scheduler, the Dask client's own
    log is silenced (a traceback per failed reconnection when the scheduler is lost, from
    distributed.client; the closed batched stream's, from distributed.batched; tornado's callbacks):
    the command says what was lost and how to resume in one line."""
    if args.scheduler is not None:
        import contextlib
        import logging

        with contextlib.suppress(ImportError):
            import distributed  # noqa: F401 - its import configures its loggers: set the levels after
        for name in ("distributed", "distributed.client", "tornado", "tornado.application"):
            logging.getLogger(name).setLevel(logging.CRITICAL)
        return args.scheduler, None
    if args.workers is not None:
        if args.workers < 1:
            raise FileError(f"--workers must be >= 1, got {args.workers}")
        return ("serial", None) if args.workers == 1 else ("processes", args.workers)
    return "processes", None


def _stems(files):
    """Unique, stable names for the models: a file's stem where no other file of the batch has
    it (up to case, for file systems that ignore it), else the stem and the first hex digits of
    a hash of the file's absolute path (``rec-3f2a91c0``): the same file gets the same name in
    every batch it is part of, and two files never share one. A file given twice gets one name."""
    import hashlib

    def hashed(f, digits):
        path = os.path.abspath(os.fspath(f))
        return f"{Path(f).stem}-{hashlib.sha256(path.encode('utf-8', 'surrogateescape')).hexdigest()[:digits]}"

    count = {}
    for f in dict.fromkeys(os.path.abspath(os.fspath(f)) for f in files):
        count[Path(f).stem.casefold()] = count.get(Path(f).stem.casefold(), 0) + 1
    names = {}
    for f in files:
        key = os.path.abspath(os.fspath(f))
        if key not in names:
            names[key] = Path(f).stem if count[Path(f).stem.casefold()] == 1 else hashed(f, 8)
    # a plain stem may equal another file's hashed name (a file named rec-3f2a91c0.npz): longer hashes
    taken = {}
    for key, name in names.items():
        taken.setdefault(name.casefold(), []).append(key)
    for name, keys in taken.items():
        if len(keys) > 1:
            for key in keys:
                names[key] = hashed(key, 16)
    return [names[os.path.abspath(os.fspath(f))] for f in files]


def _read(args) -> dict:
    """The options that say how to read each file (channels, fs, trim ...), for identify_many."""
    o = read_options(args)
    return {k: v for k, v in o.items()
            if k != "periods" and v is not None and v is not False and not (k == "skip_periods" and v == 0)}


def run(args) -> int:
    try:
        lines = parse_lines(args.lines) if args.lines is not None else None
        ka, kb = parse_counts(args.ka, "--ka"), parse_counts(args.kb, "--kb")
        known = parse_known(args.known)
        if args.max_iter < 0:
            raise FileError(f"--max-iter must be >= 0, got {args.max_iter}")
        positive(args.tol, "--tol")
        w0 = positive(args.w0, "--w0")
        if positive(args.period, "--period") is not None:
            w0 = 2 * np.pi / args.period
        positive(args.ts, "--ts")
        if args.periods is not None and args.periods < 1:
            raise FileError(f"--periods must be a positive integer, got {args.periods}")
        for opt in ("na", "nb", "max_iter"):
            integer(getattr(args, opt), "--" + opt.replace("_", "-"))
        executor, workers = executor_of(args)
        output_folder(args.out)
        out = Path(args.out) if args.out else Path("lptv-identify")
        parts = out / "parts"
        held = stored_items(parts)
        if args.resume and held is None:
            raise FileError(f"--resume: {parts} holds no batch to resume")
        batch = dict(na=args.na, nb=args.nb, ka=ka, kb=kb, w0=w0, ts=args.ts, lines=lines, method=args.method,
                     known=known, tol=args.tol, max_iter=args.max_iter, periods=args.periods, read=_read(args),
                     executor=executor, workers=workers, checkpoint=parts, noise=getattr(args, "noise", "auto"))
    except (FileError, ValueError, ImportError, OSError) as e:
        return _error(e)
    seen = {}

    def said(status):
        seen["status"] = status
        if status.reused:
            print(f"resuming: {status.reused} of {status.total} files are fitted in {parts}/", flush=True)
        if status.changed:
            print(f"{status.changed} of {status.total} files changed since their fits: refitting them", flush=True)

    batch["on_resume"] = said
    with interruptible():
        try:
            try:
                result = identify_many(args.files, **batch)
            except CheckpointError:
                if args.resume:
                    raise
                print(f"{parts}/ held the fits of another batch: replaced", flush=True)
                clear(parts)
                held = 0
                result = identify_many(args.files, **batch)
            return _write(args, out, parts, result)
        except (FileError, ValueError, ImportError, OSError) as e:
            return _error(e)
        except Interrupted as e:
            # the files of this batch on disk: those read back, and every part written since
            kept = (seen["status"].reused + (stored_items(parts) or 0) - (held or 0)) if "status" in seen else 0
            print(f"lptv identify: interrupted by {signal.Signals(e.signum).name}: {kept} of "
                  f"{len(args.files)} files are fitted and kept in {parts}/; rerun the same command with --resume "
                  "to complete the batch", file=sys.stderr)
            return e.status


def _write(args, out, parts, result) -> int:
    lost = [r["record"] for r in result.rows if not r["ok"] and str(r["error"]).startswith(LOST)]
    if lost:
        print(f"lptv identify: error: {len(lost)} of {len(result.rows)} files were lost ({lost[0]}: "
              f"{next(r['error'] for r in result.rows if r['record'] == lost[0])}); the others are kept in "
              f"{parts}/: rerun the same command with --resume to complete the batch", file=sys.stderr)
        return 1
    print(f"lptv identify: {len(args.files)} files, {args.method}, {result.executor}, "
          f"{result.elapsed:.1f} s -> {out}/")
    for row in result.rows:
        if row["ok"]:
            verdict = ("model consistent with the data" if row["model_ok"] else "MODEL ERRORS") + (
                "" if row["residue_ok"] else ", residue OUTSIDE the band")
            conv = "" if row["converged"] else ", NOT converged"
            print(f"  ok      {row['record']}: {row['periods']} x {row['samples']}, {verdict}{conv}")
        else:
            print(f"  FAILED  {row['record']}: {row['error']}")
    try:
        (out / "models").mkdir(parents=True, exist_ok=True)
        result.save(out / "results.csv")
        models = {}
        for f, stem, model in zip(args.files, _stems(args.files), result.models):
            if model is not None:
                model.save(out / "models" / f"{stem}.json")
                models[f] = f"models/{stem}.json"
        write_json(out / "summary.json", {
            "files": len(result.rows), "fitted": len(result.rows) - result.n_failed,
            "failed": result.n_failed, "not_converged": sum(1 for r in result.rows if r["ok"] and not r["converged"]),
            "residue_outside_band": sum(1 for r in result.rows if r["ok"] and not r["residue_ok"]),
            "model_errors": sum(1 for r in result.rows if r["ok"] and not r["model_ok"]),
            "method": args.method, "executor": result.executor, "seconds": result.elapsed,
            "failures": [{"file": f, "error": e} for f, e in result.failures], "models": models})
    except OSError as e:
        return _error(f"{e.filename or out}: {e.strerror or e}")
    rejected = sum(1 for r in result.rows if r["ok"] and not r["model_ok"])
    print(f"{len(result.rows) - result.n_failed} of {len(result.rows)} files fitted"
          + (f", {rejected} with model errors (column model_ok)" if rejected else "") + "; wrote "
          f"{out / 'results.csv'}, {out / 'models'}/, {out / 'summary.json'}")
    return 1 if result.n_failed else (MODEL_ERRORS if rejected else 0)
