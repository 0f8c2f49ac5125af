"""``lptv montecarlo``: a Monte Carlo study of the estimators, on local processes or a cluster.

Without ``--model`` the design is the paper's example (:mod:`lptv.examples`: model, 24-line
multisine, lines 1..243 of the fit); with ``--model model.json`` it is that model under a
random-phase multisine on ``--excited`` lines of ``--samples`` samples (rms 1). The noise
options default to the paper's noise (50 dB in, 30 dB out, poles 0.6 and 0.8, correlation 0.5).
Writes into ``--out`` (default ``lptv-montecarlo/``): ``report.html`` (the overview, the
per-parameter summary, error histograms and coverage), ``estimates.csv`` (or .parquet: one row
per run, method and parameter), ``fits.csv`` (one row per run and method, failures with their
message), ``summary.csv``, ``overview.csv`` and ``summary.json``.

Example::

    lptv montecarlo --runs 2000 --periods 8 --method wgtls,sml --workers 2
    lptv montecarlo --runs 2000 --method wgtls --scheduler tcp://10.0.0.5:8786
"""
from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

import numpy as np

from lptv import METHODS, Model, NumericalError, montecarlo, multisine
from lptv.apps.options import parse_lines
from lptv.apps.options import Interrupted, in_option_terms, integer, interruptible, output_folder
from lptv.apps.manyid import executor_of
from lptv.apps.report import Report, write_json
from lptv.batch.executors import LOST
from lptv.batch.parts import CheckpointError, clear, stored_items
from lptv.examples.siso import (PAPER_ID_LINES, PAPER_NOISE, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB,
                           paper_model, paper_multisine)
from lptv.records.measurements import FileError


def add_parser(sub):
    p = sub.add_parser(
        "montecarlo", help="Monte Carlo study of the estimators (bias, variance / CRB, coverage)",
        description="R noise realisations of a design, each fitted by the given methods; the "
                    "paper's example unless --model is given (then a random-phase multisine on "
                    "--excited lines). Results are the same whatever the executor and the number of "
                    "workers. Writes report.html (needs matplotlib: pip install 'lptv[plots]'), the "
                    "estimates, fits and summaries as CSV or Parquet, and summary.json into --out.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
               "  lptv montecarlo --runs 200 --method wgtls,sml --workers 2\n"
               "  lptv montecarlo --runs 2000 --method wgtls --scheduler tcp://10.0.0.5:8786\n"
               "  lptv montecarlo --model model.json --excited 1-60 --samples 1024 --snr-out 20")
    p.add_argument("--runs", type=int, default=200, metavar="R", help="realisations (default 200)")
    p.add_argument("--periods", type=int, default=8, metavar="P", help="measured periods (default 8)")
    p.add_argument("--method", default="wgtls", metavar="M[,M...]",
                   help=f"methods, comma separated, of {', '.join(METHODS)} (default wgtls)")
    p.add_argument("--model", metavar="model.json", help="the true model (default: the paper's)")
    p.add_argument("--excited", metavar="LINES", help="with --model: the multisine's lines, e.g. 1-60")
    p.add_argument("--samples", type=int, metavar="N",
                   help="with --model: samples per period (default 2048; a discrete model's own)")
    p.add_argument("--multisine-seed", type=int, default=1, help="seed of the multisine's phases (default 1)")
    p.add_argument("--snr-in", type=float, default=PAPER_SNR_IN_DB, metavar="DB",
                   help=f"input SNR in dB, inf for none (default {PAPER_SNR_IN_DB:g})")
    p.add_argument("--snr-out", type=float, default=PAPER_SNR_OUT_DB, metavar="DB",
                   help=f"output SNR in dB (default {PAPER_SNR_OUT_DB:g})")
    p.add_argument("--pole-in", type=float, default=PAPER_NOISE["pole_in"],
                   help=f"input noise colour, 0 white (default {PAPER_NOISE['pole_in']:g})")
    p.add_argument("--pole-out", type=float, default=PAPER_NOISE["pole_out"],
                   help=f"output noise colour (default {PAPER_NOISE['pole_out']:g})")
    p.add_argument("--correlation", type=float, default=PAPER_NOISE["correlation"],
                   help=f"input-output noise correlation (default {PAPER_NOISE['correlation']:g})")
    p.add_argument("--lines", help="lines of the fit (default: the paper's 1-243, or identify's default)")
    p.add_argument("--seed", type=int, default=2024, help="root seed of the realisations (default 2024)")
    b = p.add_mutually_exclusive_group()
    b.add_argument("--workers", type=int, metavar="N", help="local processes (default all cores; 1: serially)")
    b.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--chunk-size", type=int, metavar="C", help="realisations per task (default: automatic)")
    p.add_argument("--format", default="csv", choices=["csv", "parquet"], help="of the tables (default csv)")
    p.add_argument("--out", default="lptv-montecarlo", help="output folder (default lptv-montecarlo/)")
    p.add_argument("--resume", action="store_true",
                   help="complete an interrupted study: the chunks finished so far are in --out/parts/ (a rerun "
                        "with the same options and --out does the same); the tables are those of an "
                        "uninterrupted run, bit for bit")
    return p


OPTION_NAMES = {"runs": "--runs", "periods": "--periods", "snr_in_db": "--snr-in",
                "snr_out_db": "--snr-out", "pole_in": "--pole-in", "pole_out": "--pole-out",
                "correlation": "--correlation", "seed": "--seed", "chunk_size": "--chunk-size",
                "lines": "--lines", "n_samples": "--samples", "workers": "--workers", "checkpoint": "--out"}


def _error(problem) -> int:
    print(f"lptv montecarlo: error: {in_option_terms(' '.join(str(problem).split()), OPTION_NAMES)}",
          file=sys.stderr)
    return 2


def _design(args):
    if args.model is None:
        for opt in ("excited", "samples"):
            if getattr(args, opt) is not None:
                raise FileError(f"--{opt} applies with --model only (the paper's example has its own)")
        lines = parse_lines(args.lines) if args.lines is not None else PAPER_ID_LINES
        return paper_model(), paper_multisine(seed=args.multisine_seed), lines, "the paper's example"
    try:
        model = Model.load(args.model)
    except OSError as e:
        raise FileError(f"--model {args.model}: {e.strerror or e}") from None
    except ValueError as e:
        raise FileError(f"--model {args.model}: {e}") from None
    if args.excited is None:
        raise FileError("--model needs --excited, the lines of the multisine (e.g. 1-60)")
    excited = parse_lines(args.excited, "--excited")
    if isinstance(excited, str):
        raise FileError("--excited must list the multisine's lines, e.g. 1-60")
    N = args.samples or (model.samples_per_period if model.discrete else 2048)
    if model.discrete and N != model.samples_per_period:
        raise FileError(f"--samples {N}: the discrete model has {model.samples_per_period} samples per period")
    if excited.max() >= N / 2:
        raise FileError(f"--excited: line {excited.max()} is not below N/2 = {N / 2:g} (--samples {N})")
    ms = multisine(excited, N, amplitudes=np.sqrt(2.0 / excited.size), seed=args.multisine_seed)
    lines = parse_lines(args.lines) if args.lines is not None else None
    return model, ms, lines, f"{args.model} under a {excited.size}-line multisine, N = {N}"


def run(args) -> int:
    try:
        if args.runs < 1:
            raise FileError(f"--runs must be >= 1, got {args.runs}")
        if args.periods < 2:
            raise FileError(f"--periods must be >= 2, got {args.periods}")
        integer(args.runs, "--runs", minimum=1)
        integer(args.periods, "--periods", minimum=2)
        integer(args.samples, "--samples", minimum=1)
        integer(args.seed, "--seed", maximum=2**63)
        integer(args.multisine_seed, "--multisine-seed", maximum=2**63)
        output_folder(args.out)
        # the tables need pandas (and Parquet pyarrow): checked before any fit runs, not after
        from lptv.batch.executors import require

        require("pandas", "lptv montecarlo's tables", load=False)
        if args.format == "parquet":
            require("pyarrow", "--format parquet", load=False)
        model, ms, lines, what = _design(args)
        executor, workers = executor_of(args)
        parts = Path(args.out) / "parts"
        held = stored_items(parts)
        if args.resume and held is None:
            raise FileError(f"--resume: {parts} holds no study to resume")
    except (FileError, ValueError, ImportError) as e:
        return _error(e)
    except OSError as e:
        return _error(f"{e.filename or args.out}: {e.strerror or e}")
    with interruptible():
        try:
            return _study(args, model, ms, lines, what, executor, workers, parts, held)
        except Interrupted as e:
            done = stored_items(parts) or 0
            print(f"lptv montecarlo: interrupted by {signal.Signals(e.signum).name}: {done} of {args.runs} "
                  f"realisations are kept in {parts}/; rerun the same command with --resume to complete the "
                  "study", file=sys.stderr)
            return e.status


def _study(args, model, ms, lines, what, executor, workers, parts, held) -> int:
    print(f"lptv montecarlo: {what}; {args.runs} runs x {args.method}, P = {args.periods}, "
          f"SNR {args.snr_in:g} / {args.snr_out:g} dB -> {args.out}/", flush=True)
    try:
        if held:
            print(f"resuming: {held} of {args.runs} realisations are done in {parts}/", flush=True)
        study = dict(periods=args.periods, runs=args.runs, methods=args.method, snr_in_db=args.snr_in,
                     snr_out_db=args.snr_out, pole_in=args.pole_in, pole_out=args.pole_out,
                     correlation=args.correlation, lines=lines, seed=args.seed, executor=executor,
                     workers=workers, chunk_size=args.chunk_size, checkpoint=parts)
        try:
            mc = montecarlo(model, ms, **study)
        except CheckpointError:
            if args.resume:
                raise
            # a new study in the same --out replaces the old one's parts, as it replaces its tables
            print(f"{parts}/ held the parts of another study: replaced", flush=True)
            clear(parts)
            mc = montecarlo(model, ms, **study)
        lost = {f["run"]: f["error"] for f in mc.fits if f["error"].startswith(LOST)}
        if lost:
            first = next(iter(lost.values()))
            print(f"lptv montecarlo: error: {len(lost)} of {args.runs} realisations were lost ({first}); "
                  f"the {args.runs - len(lost)} finished are kept in {parts}/: rerun the same command with "
                  "--resume to complete the study", file=sys.stderr)
            return 1
        paths = mc.save(args.out, format=args.format)
        overview = mc.overview()
    except (FileError, ValueError, ImportError) as e:
        return _error(e)
    except NumericalError as e:     # the design itself (its Cramer-Rao bound), before any fit
        print(f"lptv montecarlo: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 1
    except OSError as e:   # a file that cannot be written, or a scheduler that cannot be reached
        return _error(f"{e.filename}: {e.strerror or e}" if e.filename else e)
    print(mc.report())
    out = Path(args.out)
    write_json(out / "summary.json", {
        "design": what, "runs": mc.runs, "periods": mc.periods, "methods": list(mc.methods),
        "snr_in_db": args.snr_in, "snr_out_db": args.snr_out, "pole_in": args.pole_in,
        "pole_out": args.pole_out, "correlation": args.correlation, "seed": args.seed,
        "executor": mc.executor, "seconds": mc.elapsed, "fits_per_minute": mc.fits_per_minute,
        "overview": {m: {k: (None if isinstance(v, float) and np.isnan(v) else v)
                         for k, v in row.items()}
                     for m, row in overview.to_dict(orient="index").items()}})
    try:
        _report(mc, what, overview).write(out)
        wrote = "report.html, "
    except ImportError:
        wrote = "(no report.html: it needs matplotlib, pip install 'lptv[plots]') "
    print(f"wrote {out}/: {wrote}" + ", ".join(p.name for p in paths.values()) + ", summary.json")
    failed = [f for f in mc.fits if not f["ok"]]
    if failed:
        print(f"lptv montecarlo: error: {len(failed)} of {len(mc.fits)} fits failed (run {failed[0]['run']}, "
              f"{failed[0]['method']}: {failed[0]['error']}); each is a row of {out / 'fits.csv'}", file=sys.stderr)
        return 1
    return 0


def _report(mc, what, overview) -> Report:
    d = mc.design
    rep = Report("lptv montecarlo")
    rep.paragraph(
        f"{mc.runs} noise realisations of {what}, P = {mc.periods} periods each, fitted by "
        f"{', '.join(m.upper() for m in mc.methods)} on {len(d['fit_lines'])} lines "
        f"({int(mc.free.sum())} free parameters). Noise: {d['snr_in_db']:g} dB on the input, "
        f"{d['snr_out_db']:g} dB on the output, poles {d['pole_in']:g} and {d['pole_out']:g}, "
        f"correlation {d['correlation']:g}. The Cramer-Rao bound uses the noise's true per-line "
        f"(co)variances; with variances estimated from P periods the ML estimator's variance is "
        f"about (P-2)/(P-3) = {(mc.periods - 2) / max(mc.periods - 3, 1e-9):.3f} times the bound "
        f"(for P > 3). Seeds: numpy SeedSequence({d['entropy']}).spawn({mc.runs}). Ran on "
        f"{mc.executor} in {mc.elapsed:.1f} s ({mc.fits_per_minute:.0f} fits per minute).")
    rep.preformatted(mc.report())
    cols = list(overview.columns)
    rep.heading("Per method")
    rep.table(["method"] + cols, [[m] + [overview.loc[m, c] for c in cols] for m in mc.methods])
    s = mc.summary().reset_index()
    keep = ["method", "parameter", "true", "bias", "bias_se", "std", "crb_std", "var_over_crb",
            "reported_std", "coverage"]
    rep.heading("Per parameter")
    rep.table(keep, s[keep].values.tolist())
    ax = mc.plot_errors()
    rep.figure(ax.figure, "errors.png",
               "Errors of every free parameter divided by its Cramer-Rao standard deviation, pooled, "
               "against the standard normal law: an efficient, unbiased estimator matches it.")
    ax = mc.plot_coverage()
    rep.figure(ax.figure, "coverage.png",
               f"Coverage of the reported {100 * mc.level:g} % intervals per parameter (methods with a "
               "covariance), with +-2 binomial standard deviations of the level.")
    return rep
