"""``lptv identify FILE --one-record``: one record that does not repeat (a start-up transient,
an input that is not periodic), fitted with its transient (:func:`lptv.identify_record`).

The file's channels are read as for periodic records (``--input``, ``--output``, ``--time`` or
``--fs``) and the record is taken whole: L periods of the parameters' period ``--period`` (s)
or ``--w0`` (rad/s), its first samples dropped to keep whole periods. The model is
continuous-time (the input must be band-limited below a quarter of the sampling frequency's
Nyquist; the fit uses the lines below it) or, with ``--discrete``, discrete-time with the
sampling period. Writes ``model.json``, ``summary.json`` and ``report.html`` (the verdict, the
parameters with their std, the measured and predicted output spectra, the normalised residual)
into ``--out``; exit status 0 when the verdict finds the model consistent with the record, 3
when it finds model errors, 1 on a numerical failure, 2 for bad options or files.

Example::

    lptv identify rig.csv --one-record --input force --output disp --period 5 --na 2 --nb 0 --ka 1,0,0
"""
from __future__ import annotations

import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from lptv import NumericalError, identify_record, read_measurements
from lptv.apps.options import count, in_option_terms, integer, output_folder, refuse_given
from lptv.apps.report import FIT_FILES, Report, write_json
from lptv.atomic import staged_folder
from lptv.apps import units
from lptv.records.measurements import FileError
from lptv.use.modelfile import context_of

MODEL_ERRORS = 3
REFUSED = {
    "method": "the one-record fit is the output-error maximum likelihood of lptv.identify_record; --method "
              "chooses the estimator of records of periods",
    "known": "the one-record fit takes no known coefficients; --scale b0=1 gives the parameters in physical form",
    "noise": "the one-record fit weighs by the noise level of its own residual; --noise chooses the noise "
             "variances of records of periods",
    "covariance": "the one-record fit's covariance is its inverse Fisher information",
    "bootstrap": "the one-record fit's covariance is its inverse Fisher information",
    "referred": "it is for a record of M x P x N random-phase realisations",
    "remove_disturbances": "it is for records of periods",
    "no_period_check": "the one-record fit does not check the record's period (it fits the record as cut)",
    "periods": "the record is taken whole, in periods of --period (or --w0)",
    "tol": "the one-record fit's iterations are bounded by --max-iter alone",
    "lines": "--one-record fits the record's own lines",
}
"""The options of lptv identify that the one-record route does not honour, with the reason it
refuses them (an option given and ignored would change nothing while the user thinks it did)."""


def _fail(src, problem, status=2, names=None) -> int:
    text = " ".join(str(problem).split())
    print(f"lptv identify: error: {src}: {in_option_terms(text, names or {})}", file=sys.stderr)
    return status


def _counts(text, opt):
    try:
        ks = [int(t) for t in str(text).split(",")]
    except ValueError:
        raise FileError(f"{opt}: '{text}' must be an integer or a comma list of integers, one per coefficient") \
            from None
    if any(k < 0 for k in ks):
        raise FileError(f"{opt}: harmonic counts must be >= 0, got '{text}'")
    return ks[0] if len(ks) == 1 else ks


def run(args, names=None) -> int:
    src = args.files[0]
    try:
        output_folder(args.out)
    except OSError as e:
        return _fail(e.filename or args.out, e.strerror or e)
    try:
        noise_std = getattr(args, "input_noise", None)
        if noise_std is not None and not (np.isfinite(noise_std) and noise_std > 0):
            raise FileError(f"--input-noise must be a positive number (the input noise's std), got {noise_std}")
        for opt in ("na", "nb", "max_iter"):
            integer(getattr(args, opt), "--" + opt.replace("_", "-"))
        if args.max_iter < 1:
            raise FileError(f"--max-iter must be >= 1, got {args.max_iter}")
        ka, kb = _counts(args.ka, "--ka"), _counts(args.kb, "--kb")
        period = args.period if args.period is not None else (2 * np.pi / args.w0 if args.w0 else None)
        if period is None:
            raise FileError("--one-record needs the parameters' period: --period (s) or --w0 (rad/s)")
        if args.lines is not None:
            raise FileError("--lines is for periodic records; --one-record fits the record's own lines")
        refuse_given(args, REFUSED, "--one-record")
        scale = units.parse_scale(getattr(args, "scale", None))
        integer(args.skip_periods, "--skip-periods")
        meas = read_measurements(src, fs=args.fs, dt=args.dt, period=period, trim=True, u=args.input,
                                 y=args.output, time=args.time, skip_periods=args.skip_periods,
                                 detrend=bool(getattr(args, "detrend", False)))
        if meas.fs is None:
            raise FileError("--one-record needs the sampling frequency: a time column, a stored fs, or --fs")
        u, y = meas.u.ravel(), meas.y.ravel()
        discrete = bool(getattr(args, "discrete", False)) or args.ts is not None
        ts = args.ts if args.ts is not None else 1.0 / meas.fs
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = identify_record(u, y, na=args.na, nb=args.nb, ka=ka, kb=kb, w0=2 * np.pi / period, ts=ts,
                                  continuous=not discrete, max_iterations=max(args.max_iter, 1),
                                  input_noise_std=noise_std, seed=0)
        physical = units.scaled(_corrected(res), *scale) if scale else None
    except NumericalError as e:
        return _fail(src, e, status=1, names=names)
    except (FileError, ValueError) as e:
        return _fail(src, e, names=names)
    extra = [str(w.message) for w in caught if str(w.message) not in res.warnings]
    out = Path(args.out) if args.out else Path(Path(src).stem + "-lptv")
    L, N0 = meas.u.shape
    dropped = ([count(meas.trimmed, "sample")] if meas.trimmed else []) \
        + ([f"{count(meas.skipped, 'period')} (--skip-periods)"] if meas.skipped else [])
    print(f"lptv identify: {src} ({meas.format}, one record of {count(L, 'period')} of {N0} samples, "
          f"fs = {meas.fs:g} Hz, "
          f"{'discrete' if discrete else 'continuous'}-time model, {res.lines.size} lines"
          + (f", {' and '.join(dropped)} dropped at the start" if dropped else "") + ")")
    print(f"  verdict: {res.verdict}")
    corrected = res.input_noise_bias is not None
    u_unit, y_unit = units.channel_unit(meas.input), units.channel_unit(meas.output)
    if corrected:
        print("  parameters corrected for the input's noise (the output-error estimate in summary.json):")
    print(units.format_parameters(_corrected(res), u_unit, y_unit))
    if physical is not None:
        print(f"  parameters in physical form (--scale {scale[0]}={scale[1]:g}):")
        print(units.format_parameters(physical, u_unit, y_unit, scale=scale))
    for msg in list(res.warnings) + extra:
        print(f"  warning: {msg}")
    res.model.context = context_of({"route": "one record", "input": meas.input, "output": meas.output, "fs": meas.fs,
                                    "samples_per_period": N0, "ka": ka, "kb": kb, "method": "output error",
                                    "noise": "residual"}, res.model)
    unit_of = units.coefficient_units(res.model, u_unit, y_unit)
    summary = {
        "file": str(src), "route": "one record", "periods": L, "samples_per_period": N0, "fs": meas.fs,
        "trimmed": meas.trimmed, "continuous": not discrete, "verdict": res.verdict, "model_ok": res.model_ok,
        "model_errors": list(res.model_errors), "cost_ratio": res.cost_ratio, "converged": res.converged,
        "iterations": res.iterations,
        "verdict_test": {"F": res.record_verdict.statistic, "dof": list(res.record_verdict.dof),
                         "p_value": res.record_verdict.p_value, "alpha": res.record_verdict.alpha},
        "parameters": {n: {"value": float(v), "std": float(s), "unit": unit_of.get(n.split(".")[0], "")}
                       for n, v, s in zip(res.eta_names, res.eta, res.parameter_std)},
        "scale": None if scale is None else {"coefficient": scale[0], "value": scale[1]},
        "parameters_scaled": None if physical is None else units.table_with_units(physical, u_unit, y_unit, scale),
        "parameters_corrected_for_input_noise": None if not corrected else {
            n: {"value": float(v), "std": float(s), "bias": float(b)}
            for n, v, s, b in zip(res.eta_names, res.eta_corrected, res.std_corrected, res.input_noise_bias)},
        "warnings": list(res.warnings) + extra}
    wrote = "model.json, summary.json"
    try:
        # written together or not at all (a full disk, a second command into the same folder)
        with staged_folder(out, replaces=FIT_FILES) as stage:
            res.model.save(stage / "model.json")
            write_json(stage / "summary.json", summary)
            if not getattr(args, "no_report", False):
                try:
                    _report(res, src, L, N0, meas.fs, discrete, u_unit, y_unit).write(stage)
                    wrote += ", report.html"
                except ImportError:
                    wrote += " (no report.html: it needs matplotlib, pip install 'lptv[plots]')"
    except OSError as e:
        return _fail(e.filename or out, e.strerror or e)
    print(f"wrote {out}/: {wrote}")
    return 0 if res.model_ok else MODEL_ERRORS


def _corrected(res):
    """The parameters the command reports: the input-noise corrected ones when measured, with
    their std (the bias estimate's own variance added), else the fit's."""
    if res.input_noise_bias is None:
        return res
    cov = res.covariance + np.diag(res.std_corrected ** 2 - res.parameter_std ** 2)
    return SimpleNamespace(model=res.model, eta_names=res.eta_names, eta=res.eta_corrected, covariance=cov)


def _report(res, src, L, N0, fs, discrete, u_unit=None, y_unit=None) -> Report:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rep = Report("lptv identify: one record")
    rep.paragraph(f"{src}: one record of {count(L, 'period')} of {N0} samples at {fs:g} Hz, fitted with its "
                  "transient "
                  f"(output-error maximum likelihood, {'discrete' if discrete else 'continuous'}-time model) on "
                  f"{res.lines.size} lines of the record's grid.")
    rep.heading("Verdict")
    rep.paragraph(res.verdict)
    rep.paragraph("The verdict regresses the residual on the input and on the input shifted by each harmonic of "
                  "the parameters' period, in windows of lines: a right structure leaves a residual the input "
                  "does not explain (an F test of size 1 %, which needs no noise level); an order too few "
                  "shows on the same line, a missing harmonic k on the input shifted by k w0.")
    rep.heading("Parameters")
    rep.paragraph("Normalised so that the mean of the highest output coefficient a_na is 1 (its std 0). To read "
                  "them in physical units, multiply every coefficient by the mean of a_na you know (e.g. the "
                  "mass, for a2 of m x'' + c x' + k x = F), or divide it by the mean of b0 (lptv identify "
                  "--scale b0=1 does this, with the covariance).")
    unit_of = units.coefficient_units(res.model, u_unit, y_unit)
    rep.table(["parameter", "estimate", "std", "unit"],
              [[n, *units.value_and_std(v, s), unit_of.get(n.split(".")[0], "")]
               for n, v, s in zip(res.eta_names, res.eta, res.parameter_std)])
    w = res.lines * 2 * np.pi * fs / (L * N0)
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.semilogy(w, np.abs(res.Y), ".", ms=3, label="measured |Y|")
    ax.semilogy(w, np.abs(res.Y_fit), "-", lw=1, label="predicted |Y| (with the transient)")
    ax.semilogy(w, np.abs(res.Y - res.Y_fit), ".", ms=2, label="|residual|")
    ax.semilogy(w, np.sqrt(res.noise_var), "--", lw=1, label="noise level")
    ax.set_xlabel("angular frequency (rad/s)")
    ax.legend(fontsize=8)
    ax.set_title("the record's output spectrum, measured and predicted")
    fig.tight_layout()
    rep.figure(fig, "spectrum.png", "The output's DFT on the fitted lines, the model's prediction (with the "
               "transient term), the residual and the noise level it implies.")
    plt.close(fig)
    return rep
