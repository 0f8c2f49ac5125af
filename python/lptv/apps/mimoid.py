"""``lptv identify FILES... --input f1,f2 --output x1,x2``: a model of several inputs and outputs.

Each file holds every channel of one experiment (P >= 2 steady-state periods; CSV columns, NPZ
arrays or MAT variables named by ``--input`` and ``--output``, comma lists, matched as for one
channel: up to case and a trailing unit). The files are experiments of one system (the same
period), fitted together into one :class:`lptv.MimoModel` by :func:`lptv.identify` on the list
of (u, y) pairs, u of shape (P, N, nu) and y (P, N, ny) (METHOD.md section 19); ``--joint`` says
the same and may be given. A single file is one experiment (enough for one input, or when the
inputs excite different lines). Writes ``model.json`` (:meth:`lptv.MimoModel.load`) and
``summary.json`` and ``report.html`` (the verdict, the parameters, each output's normalised
residue, the Floquet multipliers and frozen poles; not with ``--no-report``), prints the
parameters with their standard deviations and 95 % intervals (each entry's unit where the
channels' names state theirs, ``force [N]``), the verdict and the estimate's stability;
``--scale b0=1`` adds them in physical form (the equation multiplied from the left so that the
mean of B_0 is the identity: M, C, K of M y'' + C y' + K(t) y = F). Exit status as for one
channel: 0 consistent, 3 MODEL ERRORS, 4 NOT DETERMINED (no noise statistics, or the data do
not determine the model), 2 a file or option that cannot be used (a one-line error), 1 a
computation that failed.

Example::

    lptv identify exp1.csv exp2.csv --input f1,f2 --output x1,x2 --w0 1 --na 2 --nb 0 --ka 1,0,0
"""
from __future__ import annotations

import copy
import dataclasses
import re
import sys
import warnings
from pathlib import Path

import numpy as np

import lptv
from lptv import NumericalError
from lptv.apps.options import (MODEL_REJECTED, NOT_DETERMINED, OPTION_NAMES, count, fundamental, in_option_terms, integer,
                               output_folder, parse_counts, parse_lines, positive, read_options, refuse_same_file)
from lptv.apps import inspectrec, units
from lptv.apps.mimoreport import physical_table
from lptv.apps.report import write_fit
from lptv.apps.stability import stability_summary, stability_text
from lptv.records.measurements import FileError, read_measurements

NEEDS_FIT = ("several inputs or outputs need the MIMO fit (lptv.identify on arrays (P, N, nu), (P, N, ny)), "
             "which this lptv does not have yet")
"""The error when lptv.identify does not take several channels."""

# Options of the one-channel fit that the fit of several channels does not take (and their
# value when not given).
_NOT_FOR_MIMO = {"one_record": False, "input_noise": None, "remove_disturbances": False, "known": None,
                 "workers": None, "scheduler": None, "resume": False}


def several_channels(args) -> bool:
    """Whether ``--input`` or ``--output`` names several channels (a comma list)."""
    return any(v is not None and "," in v for v in (args.input, args.output))


def channel_list(text, opt):
    """['f1', 'f2'] from 'f1, f2'; FileError for an empty name."""
    if text is None:
        return None
    names = [n.strip() for n in text.split(",")]
    if any(not n for n in names):
        raise FileError(f"{opt} '{text}': an empty channel name in the comma list")
    return names


def mimo_fit_available() -> bool:
    """Whether :func:`lptv.identify` fits several inputs and outputs (the MIMO estimators)."""
    return hasattr(lptv, "MimoIdentificationResult")


def _fail(problem, status=2) -> int:
    print(f"lptv identify: error: {' '.join(str(problem).split())}", file=sys.stderr)
    return status


def _check_options(args):
    for key, default in _NOT_FOR_MIMO.items():
        if getattr(args, key, default) != default:
            opt = "--" + key.replace("_", "-")
            if key in ("workers", "scheduler", "resume"):
                raise FileError(f"{opt} runs a batch, one fit per file; with several channels the files are the "
                                "experiments of one system fitted together into one model (a batch of fits of "
                                "several channels each is not built): give the files without it")
            raise FileError(f"{opt} is for one input and one output; several channels take the files, "
                            "--input, --output, the structure, --lines, --method, --noise, --scale, --max-iter, --tol "
                            "and --out")
    if getattr(args, "referred", "auto") not in ("auto",):
        raise FileError("--referred is for records of realisations of one input and one output")
    if args.covariance != "analytic":
        raise FileError(f"--covariance {args.covariance} is for one input and one output; several channels "
                        "take the analytic covariance")
    if args.max_iter < 0:
        raise FileError(f"--max-iter must be >= 0, got {args.max_iter}")
    for opt in ("na", "nb", "max_iter"):
        integer(getattr(args, opt), "--" + opt.replace("_", "-"))
    positive(args.tol, "--tol")


def read_experiments(args):
    """(file, Measurements) per file, u (P, N, nu) and y (P, N, ny), and the common w0 and ts."""
    inputs = channel_list(args.input, "--input") or ["u"]
    outputs = channel_list(args.output, "--output") or ["y"]
    records, w0s = [], []
    ts = args.ts
    check = not getattr(args, "no_period_check", False)
    first = copy.copy(args)             # the record's own diagnosis reads the first input and output
    first.input, first.output = inputs[0], outputs[0]
    for src in args.files:
        diag = inspectrec.diagnose(src, first) if check else None
        try:
            kw = read_options(args)
            kw.update(u=inputs, y=outputs)
            try:
                meas = read_measurements(src, **kw)
            except FileError as e:      # a period or fs that contradicts the record: its cause instead
                cause = inspectrec.read_failure_cause(diag, first, e)
                raise FileError(cause if cause == str(e) else f"{cause} (--no-period-check skips the check)") from None
            N = meas.u.shape[1]
            checked = inspectrec.setup_problem(diag, first, N) if diag is not None else None
            if checked:
                raise FileError(f"{checked} (--no-period-check fits the record as cut anyway)")
            P, ny = meas.u.shape[0], meas.y.shape[2]
            if diag is not None and diag.repeats and ny > 1 and P <= ny and N > diag.period_samples \
                    and N % diag.period_samples == 0:
                fix = f"--period {diag.period:.12g}" if diag.period is not None else f"--periods {diag.periods}"
                raise FileError(f"the record repeats every {diag.seconds(diag.period_samples)}; the period given holds "
                                f"{N // diag.period_samples} of them and leaves {P} periods, and {ny} outputs need more "
                                f"than {ny}: use {fix}")
            if args.discrete:
                if args.ts is not None:
                    raise FileError("--discrete takes the sample period from --fs / --dt; do not give --ts as well")
                if meas.fs is None:
                    raise FileError("--discrete needs the sampling frequency --fs (or --dt)")
                ts = 1.0 / meas.fs
            saved, args.ts = args.ts, ts
            try:      # the samples per period are read from a channel's (P, N) periods
                w0s.append(fundamental(args, dataclasses.replace(meas, u=meas.u[..., 0], y=meas.y[..., 0])))
            finally:
                args.ts = saved
        except (FileError, ValueError) as e:
            raise FileError(f"{src}: {e}") from None
        records.append((src, meas))
    for (src, _), w in zip(records[1:], w0s[1:]):
        if not np.isclose(w, w0s[0], rtol=1e-9, atol=0):
            raise FileError(f"{src}: w0 = {w:.10g} rad/s, but {records[0][0]} has {w0s[0]:.10g}: the experiments of "
                            "one fit share the period")
    return records, w0s[0], ts


def run(args) -> int:
    try:
        output_folder(args.out)
    except OSError as e:
        return _fail(f"{e.filename or args.out}: {e.strerror or e}")
    try:
        _check_options(args)
        lines = parse_lines(args.lines) if args.lines is not None else None
        ka, kb = parse_counts(args.ka, "--ka"), parse_counts(args.kb, "--kb")
        scale = units.parse_scale(getattr(args, "scale", None))
        records, w0, ts = read_experiments(args)
        refuse_same_file(args.files)
        if not mimo_fit_available():
            raise FileError(NEEDS_FIT)
    except (FileError, ValueError) as e:
        return _fail(e)
    files = [r[0] for r in records]
    experiments = [(m.u, m.y) for _, m in records]
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = lptv.identify(experiments, na=args.na, nb=args.nb, ka=ka, kb=kb, w0=w0, ts=ts,
                                lines=lines, method=args.method, tol=args.tol, max_iter=args.max_iter,
                                noise=getattr(args, "noise", None) or "auto",
                                transient={"on": True, "off": False}.get(getattr(args, "transient", "auto"), "auto"))
    except NumericalError as e:
        return _fail(in_option_terms(_named(e, files), OPTION_NAMES), status=1)
    except ValueError as e:
        return _fail(in_option_terms(_named(e, files), OPTION_NAMES))
    notes = [str(w.message) for w in caught if str(w.message) not in getattr(res, "warnings", ())]
    first = records[0][1]
    u_units = [units.channel_unit(n) for n in first.input]
    y_units = [units.channel_unit(n) for n in first.output]
    try:
        physical = units.scaled_mimo(res, *scale) if scale else None
    except FileError as e:
        return _fail(e)

    out = Path(args.out) if args.out else Path(Path(files[0]).stem + "-lptv")
    print(f"lptv identify: {count(len(files), 'experiment')}, "
          f"{count(res.model.n_inputs, 'input')} ({', '.join(first.input)}), {count(res.model.n_outputs, 'output')} "
          f"({', '.join(first.output)}), w0 = {w0:.6g} rad/s"
          + (f", discrete-time model with ts = {ts:g} s" if ts else ", continuous-time model") + f" -> {out}/")
    for e, (src, meas) in enumerate(records):
        print(f"  #{e} {src} ({meas.format}): {count(meas.u.shape[0], 'period')} of {meas.u.shape[1]} samples")
    print(text_summary(res, u_units, y_units))
    if physical is not None:
        print(physical_text(physical, u_units, y_units))
    stability = stability_of(res.model)
    print(f"stability: {stability['text']}")
    stab = stability_summary(res)
    if stab is not None:
        print(stability_text(stab))
    for msg in list(getattr(res, "warnings", ())) + notes:
        print(f"warning: {msg}")
    summary = json_summary(args, records, w0, ts, ka, kb, res, notes)
    summary["scale"] = None if scale is None else {"coefficient": scale[0], "value": scale[1]}
    summary["parameters_scaled"] = None if physical is None else physical_rows(physical, u_units, y_units)
    summary["stability"] = {k: v for k, v in stability.items() if k != "text"}
    summary["stability_uncertainty"] = stab
    if getattr(args, "no_report", False):
        report = None
    else:
        def report():
            from lptv.apps.mimoreport import build
            return build(res, files=files, inputs=list(first.input), outputs=list(first.output), w0=w0,
                         stability=stability, physical=physical, experiments=experiments)
    failed = write_fit(out, res.model, summary, report)
    if failed:
        return _fail(failed[1] if failed[0] is None else f"{failed[0]}: {failed[1]}")
    return status_of(res)


def stability_of(model) -> dict:
    """The Floquet multipliers of the estimate (:func:`lptv.floquet` of the matrix system) as
    plain values, with a sentence; ``is_stable`` None when they could not be computed."""
    try:
        f = lptv.floquet(model)
    except (ValueError, NumericalError) as e:
        return {"is_stable": None, "spectral_radius": None, "multipliers": None,
                "text": f"not decided ({' '.join(str(e).split())})"}
    word = "stable" if f.is_stable else "NOT stable"
    return {"is_stable": bool(f.is_stable), "spectral_radius": float(f.spectral_radius),
            "multipliers": [[float(m.real), float(m.imag)] for m in f.multipliers],
            "text": f"{word}: {f.multipliers.size} Floquet multipliers, the largest of magnitude "
                    f"{f.spectral_radius:.6g} (lptv.floquet)"}


def status_of(res) -> int:
    """As for one channel (:func:`lptv.apps.options.verdict_status`): MODEL_REJECTED (3) for model
    errors, NOT_DETERMINED (4) when the data give no verdict or do not determine the model, 0
    when the verdict calls the model consistent."""
    if res.model_ok is False:
        return MODEL_REJECTED
    return 0 if res.model_ok and getattr(res, "undetermined", None) is None else NOT_DETERMINED


def _named(e, files) -> str:
    """The library's message with the list positions replaced by the files."""
    return re.sub(r"experiments?\[(\d+)\]|experiment (\d+)",
                  lambda m: files[int(m.group(1) or m.group(2))] if int(m.group(1) or m.group(2)) < len(files)
                  else m.group(0), str(e))


def text_summary(res, u_units=(), y_units=()) -> str:
    """:meth:`lptv.MimoIdentificationResult.summary`: the method, convergence, the noise route, the
    parameters with their std and 95 % intervals (each entry's unit where the channels state
    theirs) and the verdict."""
    return res.summary(units=units.mimo_coefficient_units(res.model, u_units, y_units))


def physical_rows(physical, u_units, y_units) -> list:
    """summary.json's ``parameters_scaled``: the rows of the scaled parameters with their unit."""
    unit_of = units.mimo_coefficient_units(physical.model, u_units, y_units, physical.scale)
    rows = physical_table(physical, u_units, y_units)
    for r in rows:
        r["unit"] = unit_of.get(r["name"].split(".")[0], "")
        if r["kind"] == "normalised":
            r["kind"] = "scaled"
    return rows


def physical_text(physical, u_units, y_units) -> str:
    """What ``--scale`` prints: the scaled parameters with their std, 95 % intervals and units."""
    from lptv.judgement.mimo_result import format_table

    name, value = physical.scale
    unit_of = units.mimo_coefficient_units(physical.model, u_units, y_units, physical.scale)
    return (f"parameters in physical form (--scale {name}={value:g}: the mean of {name} is {value:g} times the "
            "identity):\n" + format_table(physical_table(physical, u_units, y_units), 0.95, unit_of)
            .replace("(normalised)", "(by --scale)"))


def json_summary(args, records, w0, ts, ka, kb, res, notes) -> dict:
    first = records[0][1]
    unit_of = units.mimo_coefficient_units(res.model, [units.channel_unit(n) for n in first.input],
                                           [units.channel_unit(n) for n in first.output])
    return {
        "files": [str(src) for src, _ in records], "n_experiments": len(records),
        "experiments": [{"file": str(src), "format": m.format, "periods": int(m.u.shape[0]),
                         "samples_per_period": int(m.u.shape[1]), "fs": m.fs, "fs_source": m.fs_source}
                        for src, m in records],
        "inputs": list(first.input), "outputs": list(first.output),
        "n_inputs": res.model.n_inputs, "n_outputs": res.model.n_outputs,
        "w0": w0, "ts": ts, "na": res.model.na, "nb": res.model.nb, "ka": ka, "kb": kb,
        "method": res.method, "noise": getattr(res, "noise", "sample"), "noise_choice": getattr(res, "noise_choice", ""),
        "transient": None if getattr(res, "transient", None) is None else {
            "powers": list(res.transient_powers), "variable": "z" if res.model.ts else "s",
            "coefficients": np.asarray(res.transient).tolist(), "note": res.transient_note},
        "n_rows": int(res.lines.size), "converged": bool(res.converged),
        "cost": float(res.cost),
        "parameters": [dict(r, unit=unit_of.get(r["name"].split(".")[0], "")) for r in res.parameters(0.95)],
        "verdict": res.verdict, "model_ok": res.model_ok, "model_errors": list(res.model_errors),
        "undetermined": res.undetermined,
        "warnings": list(getattr(res, "warnings", ())) + notes,
    }
