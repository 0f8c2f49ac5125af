"""``lptv identify FILES... --joint``: several records of one system fitted into one model.

Each file is one experiment (its own multisine, amplitude, number of periods P and samples per
period N); all must share the period. The options are those of ``lptv identify FILE``
(:mod:`lptv.apps.fileid`), the same for every file; ``--lines`` applies to each record. Writes
``model.json``, ``summary.json`` (with one entry per experiment) and ``report.html``, prints the
fit's summary, and exits 0, or 2 with a one-line error (a file that cannot be read, records
that disagree on the period or the time domain).

Example::

    lptv identify low.npz high.npz --joint --na 2 --nb 1 --method sml --out both
"""
from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import numpy as np

from lptv import FrequencyData, NumericalError, identify, parameter_table, plots
from lptv.apps.options import fundamental, parse_counts, parse_known, parse_lines, positive, read_record
from lptv.apps.options import refuse_same_file, verdict_status
from lptv.apps.report import Report, model_figures, write_fit
from lptv.records.measurements import FileError


def _fail(problem) -> int:
    print(f"lptv identify: error: {' '.join(str(problem).split())}", file=sys.stderr)
    return 2


def _records(args):
    """(file, Measurements, FrequencyData) per file, each with its own w0 (and ts)."""
    out = []
    for src in args.files:
        try:
            meas = read_record(src, args)
            ts = args.ts
            if args.discrete:
                if args.ts is not None:
                    raise FileError("--discrete takes the sample period from --fs / --dt; do not give --ts as well")
                if meas.fs is None:
                    raise FileError("--discrete needs the sampling frequency --fs (or --dt)")
                ts = 1.0 / meas.fs
            saved, args.ts = args.ts, ts
            try:
                w0 = fundamental(args, meas)
            finally:
                args.ts = saved
            data = FrequencyData.from_periods(meas.u, meas.y, w0=w0, ts=ts)
        except (FileError, ValueError) as e:
            raise FileError(f"{src}: {e}") from None
        out.append((src, meas, data))
    return out


def run(args) -> int:
    try:
        lines = parse_lines(args.lines) if args.lines is not None else None
        ka, kb, known = parse_counts(args.ka, "--ka"), parse_counts(args.kb, "--kb"), parse_known(args.known)
        if args.max_iter < 0:
            raise FileError(f"--max-iter must be >= 0, got {args.max_iter}")
        positive(args.tol, "--tol")
        records = _records(args)
        refuse_same_file(args.files)
    except (FileError, ValueError) as e:
        return _fail(e)
    files = [r[0] for r in records]
    datas = [r[2] for r in records]
    per_file = lines if lines is None or isinstance(lines, str) else [lines] * len(datas)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # identify's warnings are in res.warnings
            res = identify(datas, na=args.na, nb=args.nb, ka=ka, kb=kb, lines=per_file, method=args.method,
                           known=known, tol=args.tol, max_iter=args.max_iter,
                           noise=getattr(args, "noise", "auto"))
    except (ValueError, NumericalError) as e:
        # name the files, not the list positions
        msg = re.sub(r"experiments?\[(\d+)\]|experiment (\d+)",
                     lambda m: files[int(m.group(1) or m.group(2))], str(e))
        return _fail(msg)

    out = Path(args.out) if args.out else Path("lptv-joint")
    model = res.model
    print(f"lptv identify: {len(files)} files fitted together into one model, w0 = {model.w0:.6g} rad/s"
          + (f", discrete-time model with ts = {model.ts:g} s" if model.discrete else ", continuous-time model")
          + f" -> {out}/")
    for e, (src, meas, d) in enumerate(records):
        print(f"  #{e} {src}: {meas.u.shape[0]} periods of {meas.u.shape[1]} samples, "
              f"{int(np.sum(res.experiment == e))} lines")
    print(res.summary())
    summary = _summary(args, records, ka, kb, res)
    failed = write_fit(out, model, summary, lambda: _report(records, res, summary))
    if failed:
        return _fail(failed[1] if failed[0] is None else f"{failed[0]}: {failed[1]}")
    return verdict_status(res)


def _experiment_rows(res, e):
    idx = np.flatnonzero(res.experiment == e)
    return idx, res.lines[idx]


def _summary(args, records, ka, kb, res):
    exps = []
    for e, (src, meas, d) in enumerate(records):
        idx, rows = _experiment_rows(res, e)
        r = res.normalized_residue[idx]
        exps.append({"file": str(src), "format": meas.format, "periods": int(meas.u.shape[0]),
                     "samples_per_period": int(meas.u.shape[1]), "n_lines": int(rows.size),
                     "first_line": int(rows.min()), "last_line": int(rows.max()),
                     "fraction_above_0db": float(np.mean(r[np.isfinite(r)] > 1.0))})
    return {
        "files": [str(r[0]) for r in records], "n_experiments": res.n_experiments, "experiments": exps,
        "w0": res.model.w0, "ts": res.model.ts, "na": res.model.na, "nb": res.model.nb, "ka": ka, "kb": kb,
        "method": res.method, "n_lines": int(res.lines.size), "n_free_parameters": res.n_free_parameters,
        "iterations": res.iterations, "converged": res.converged, "cost": res.cost,
        "fraction_above_0db": res.fraction_above_0db, "fraction_expected": res.fraction_expected,
        "fraction_band": list(res.fraction_band), "residue_ok": res.residue_ok,
        "prediction_error_vs_noise_db": res.prediction_error_db,
        "verdict": res.verdict, "model_ok": res.model_ok, "model_errors": list(res.model_errors),
        "parameters": parameter_table(res), "warnings": list(res.warnings),
    }


def _report(records, res, summary) -> Report:
    model = res.model
    rep = Report(f"lptv identify --joint: {len(records)} records, one model")
    rep.paragraph(
        f"One model with na = {model.na}, nb = {model.nb}, {summary['ka']} harmonics on the a_n and "
        f"{summary['kb']} on the b_m ({res.n_free_parameters} free parameters) identified by "
        f"{res.method.upper()} from {len(records)} records of the same system fitted together "
        f"({res.lines.size} lines in all): the records' residues are independent, so their equations "
        "stack and their informations add (METHOD.md section 14).")
    rep.paragraph("Verdict: " + res.verdict + ".")
    rep.table(["record", "periods x samples", "lines of the fit", "residues above 0 dB"],
              [[f"#{e} {x['file']} ({x['format']})", f"{x['periods']} x {x['samples_per_period']}",
                f"{x['n_lines']} ({x['first_line']} to {x['last_line']})",
                f"{100 * x['fraction_above_0db']:.1f} %"] for e, x in enumerate(summary["experiments"])])
    rep.preformatted(res.summary())
    fig = plots.bode(res)
    rep.figure(fig, "bode.png",
               "Bode plot: each record's measured FRF Y/U on its excited lines (+-2 std from its periods), "
               "the joint model's time-averaged response and its 95 % band from the parameter covariance.")
    for e, (src, meas, d) in enumerate(records):
        idx, rows = _experiment_rows(res, e)
        excited = rows[res.verdict_mask[idx]]
        ax = plots.normalized_residue(rows, res.normalized_residue[idx], w0=model.w0, excited=excited)
        ax.set_title(f"record #{e}: {Path(src).name}", fontsize="medium")
        rep.figure(ax.figure, f"normalized_residue_{e}.png",
                   f"Normalised residue |e_l| / sqrt(var e_l) of record #{e} ({src}) against frequency, with "
                   "the 0 dB line; the excited lines marked (the verdict judges every row that reads a line "
                   "with signal).")
    model_figures(rep, model, "the joint model")
    return rep
