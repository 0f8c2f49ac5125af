"""``lptv identify FILE``: an LPTV model from your own periodic measurements.

(Several files, ``lptv identify FILES... [--workers N | --scheduler ADDRESS]``, are fitted as a
batch by :mod:`lptv.apps.manyid`; with ``--joint`` they are records of one system fitted into one
model by :mod:`lptv.apps.jointid`.)

The file holds P >= 2 steady-state periods of the input u and the output y:

- CSV: a header row naming the columns (``u`` and ``y``, or ``--input NAME --output NAME``;
  other columns are ignored), one sample per row, the periods one after another.
- NPZ: arrays (``u`` and ``y`` or as named) of shape (P, N) or long vectors, optionally a scalar
  ``w0`` (rad/s). Arrays of shape (M, P, N) hold M random-phase realisations of one amplitude
  spectrum: the nonlinear distortion is separated from the noise and the best linear
  (time-periodic) approximation identified with it (:mod:`lptv.apps.blaid`).
- MATLAB ``.mat`` (v4/v5/v7 via scipy, v7.3 via h5py): variables as in NPZ.

A long record is split by ``--periods`` or by the sampling frequency and the period: fs is
``--fs`` / ``--dt``, else the file's time column or variable (``t``, ``time``, ``--time NAME``;
checked uniform) or its stored ``fs`` / ``dt`` / ``Ts``, said in the first line of the output.
The period comes from ``--w0`` (rad/s), ``--period`` (s), the file's ``w0`` or, in discrete time,
from ``--ts`` and the samples per period. The command writes ``model.json`` (readable by
:meth:`lptv.Model.load`), ``report.html`` with the validation figures, and ``summary.json``, and
prints the validation verdict. Exit status: 0 when the verdict calls the model consistent with
the data, 3 when it finds model errors (MODEL ERRORS), 4 when the data do not determine the
model (NOT DETERMINED), 2 for a file or options that cannot be used (a one-line error), 1 for a
computation that failed. Before the fit the record
is diagnosed as ``lptv inspect`` does: a period (``--period``, ``--w0``, ``--periods``, the
file's) that is not the one the input repeats at, nor a multiple of it, an ``--fs`` that
contradicts the file's time, and a record that does not repeat are errors that name the cause
(``--no-period-check`` fits the record as cut anyway, with the contradiction as a warning);
so are the fit's refusals of an output that shows no periodic response.

Example (the paper's simulation example as a measurement file, then its identification)::

    python -c "import numpy as np, lptv.examples as ex; m = ex.paper_measurements(); \\
               np.savez('meas.npz', u=m['u'], y=m['y'], w0=m['w0'])"
    lptv identify meas.npz --na 2 --nb 1 --ka 3 --kb 3 --lines 1-243 --out meas-lptv
"""
from __future__ import annotations

import argparse
import re
import sys
import warnings
from pathlib import Path

import numpy as np

from lptv import (NumericalError, check_record, compare, frozen_poles, frozen_zeros, identify, lti_table,
                  parameter_table, plots, simulate)
from lptv.apps.stability import stability_section, stability_summary, stability_text
from lptv.apps.options import (OPTION_NAMES, describe_record, fundamental, in_option_terms, integer,  # noqa: F401
                               output_folder, parse_counts, parse_known, parse_lines, positive, read_options,
                               read_record, add_record_options, sample_period, dropped_note)
from lptv.apps import inspectrec
from lptv.apps.options import verdict_status
from lptv.apps import units
from lptv.apps.report import Report, write_fit
from lptv import METHODS
from lptv.judgement.parameters import format_parameter_table
from lptv.records.measurements import FileError

# ------------------------------------------------------------------------------ options

_HELP = """\
Identify an LPTV model from P >= 2 measured steady-state periods of input u and output y.
  .csv  header row naming the columns (u and y, or --input NAME --output NAME), periods one
        after another; a time column (t, time, time [s], or --time NAME) gives fs
  .npz  arrays u, y (or as named) of shape (P, N) or one long vector each; optional scalars w0
        (rad/s) and fs (Hz) or dt / Ts (s), or a time vector t. Shape (M, P, N): M random-phase
        realisations; the report then shows the nonlinear distortion and the model is the best
        linear approximation with its variance
  .mat  MATLAB v5 or v7.3: variables as in .npz
A long record is split into periods by --periods, or by fs (--fs / --dt, else the file's time
or stored fs) and the period (--period / --w0); the first line of the output says which fs.
Writes model.json, report.html and summary.json, and prints the validation verdict. The period
is checked against the one the input repeats at (lptv inspect FILE shows it; --no-period-check
skips the check). Exit status 0: the model is consistent with the data; 3: the verdict finds
model errors; 4: the data do not determine the model; 2: a file or option that cannot be used;
1: a computation that failed.
Several inputs and outputs: --input f1,f2 --output x1,x2 (comma lists); every file is then one
experiment of one system and all are fitted together into one matrix model (model.json,
summary.json, the parameters with their std and the verdict printed).
Several files (or --workers / --scheduler) make a batch: one row per file in results.csv,
each model in models/, the fits on local processes or a Dask cluster. With --joint the files
are records of one system (same period) fitted together into one model and one report."""


def add_parser(sub):
    p = sub.add_parser(
        "identify", help="identify an LPTV model from a measurement file (CSV, NPZ, MAT)",
        description=_HELP, formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
               "  lptv identify record.csv --fs 100 --period 10 --na 2 --nb 0 --method sml\n"
               "  lptv identify record.csv --fs 100 --period 10 --trim --skip-periods 1 --na 2 --nb 0\n"
               "  lptv identify rig.csv --input force --output displacement --period 10 --na 2 --nb 0 --ka 1\n"
               "  lptv identify meas.npz --na 2 --nb 1 --ka 3 --kb 3 --lines 1-243\n"
               "  lptv identify runs/*.npz --na 2 --nb 1 --ka 3 --kb 3 --workers 2\n"
               "  lptv identify low.npz high.npz --joint --na 2 --nb 1 --method sml\n"
               "  lptv identify e1.csv e2.csv --input f1,f2 --output x1,x2 --w0 1 --na 2 --nb 0 --ka 1,0,0")
    p.add_argument("files", nargs="+", metavar="FILE",
                   help="measurements: .csv, .npz or .mat; several files are fitted as a batch")
    p.add_argument("--na", type=int, required=True, help="order of the output side")
    p.add_argument("--nb", type=int, required=True, help="order of the input side")
    p.add_argument("--ka", default="0", help="harmonics of every a_n, or a comma list one per a_n (default 0)")
    p.add_argument("--kb", default="0", help="harmonics of every b_m, or a comma list one per b_m (default 0)")
    add_record_options(p, several=True)
    p.add_argument("--one-record", action="store_true",
                   help="the file is one record that does not repeat (a start-up transient, an input that is "
                   "not periodic): fit it whole with its transient (lptv.identify_record); needs --period "
                   "or --w0 and the sampling frequency")
    p.add_argument("--input-noise", type=float, metavar="STD",
                   help="with --one-record: the std of the input's measurement noise, when known; its bias "
                   "is measured and removed (the corrected parameters are printed and saved)")
    p.add_argument("--method", default="wgtls", choices=METHODS, help="estimator (default wgtls)")
    p.add_argument("--covariance", default="analytic", choices=("analytic", "bootstrap", "realisations"),
                   help="WGTLS/SML parameter covariance: the analytic sandwich (default), a parametric "
                   "bootstrap of --bootstrap refits (one record; better calibrated at few periods), or, for "
                   "a record of M >= 4 random-phase realisations, the jackknife over the realisations "
                   "(intervals that include the nonlinear distortion's correlation across lines)")
    p.add_argument("--bootstrap", type=int, default=200, metavar="B",
                   help="refits for --covariance bootstrap (default 200)")
    p.add_argument("--noise", default="auto", choices=("auto", "sample", "moderated", "full", "full-moderated", "full-rows"),
                   help="the noise variances the fit weighs by: each line's own from its periods (sample), "
                   "or moderated across neighbouring lines (smooth noise spectra; more precise estimates and "
                   "calibrated intervals at few periods); full, full-moderated: the same from the whole "
                   "record's bins between the lines (a disturbance that passes through the system, or a "
                   "loop under feedback), full-rows: full with each row read on the record's noise "
                   "realisations; auto (default): the record's when the periods' noise is "
                   "correlated between neighbouring lines, moderated when the noise spectrum passes a "
                   "smoothness check; the summary says which and why")
    p.add_argument("--transient", default="auto", choices=("auto", "on", "off"),
                   help="several channels: fit the record's transient term (a real polynomial in s or z per output "
                   "and experiment, which a disturbance that passes through the system leaves in every row): "
                   "auto (default) on the whole record's noise, on, off (METHOD.md section 20); one input and "
                   "output: auto or off")
    p.add_argument("--referred", default="auto", choices=("auto", "output", "input", "none"),
                   help="a record of M x P x N realisations: the nonlinear distortion weighed as output noise "
                   "(output: a nonlinearity after the dynamics), referred to the input through a first fit "
                   "(input: a nonlinearity before them, such as an actuator's), or none: the realisations "
                   "weighed by their noise alone with intervals from the jackknife over them (consistent where "
                   "the realisations' output powers differ widely). Default auto: none where they differ more "
                   "than 4 times (a response that depends on the phases), output otherwise (METHOD.md "
                   "section 16)")
    p.add_argument("--remove-disturbances", action="store_true",
                   help="find the sinusoids that are not periodic in the record (off the period's grid, "
                   "such as mains hum) and subtract them before the fit (lptv.disturbances; one record)")
    p.add_argument("--no-period-check", action="store_true",
                   help="fit the record as the options cut it even where the record says otherwise (a period "
                   "or --fs that contradicts the one found in the data, a record that does not repeat); "
                   "the contradiction is then printed as a warning")
    p.add_argument("--reference", metavar="NAME",
                   help="a recorded reference column (the loop's external periodic excitation under "
                   "feedback): the period check reads where it repeats, not the input, which under "
                   "feedback holds the loop's response to its disturbance (guide page 14)")
    p.add_argument("--known", metavar="a2=1.5,b0=1", help="coefficients known to be constant")
    p.add_argument("--scale", metavar="b0=1",
                   help="report the parameters in physical form: all scaled so that the mean of this "
                   "coefficient has this value (the fit sets the mean of a_na to 1; for m x'' + c x' + k x = F, "
                   "--scale b0=1 gives a2 = m, a1 = c, a0 = k); the fit and its verdict are unchanged")
    p.add_argument("--no-report", action="store_true",
                   help="write model.json and summary.json only (no report.html and figures: faster)")
    p.add_argument("--out", help="output folder (default: <file stem>-lptv/)")
    p.add_argument("--max-iter", type=int, default=50, help="WGTLS iterations at most (default 50)")
    p.add_argument("--tol", type=float, default=1e-10, help="WGTLS relative tolerance (default 1e-10)")
    b = p.add_mutually_exclusive_group()
    b.add_argument("--joint", action="store_true",
                   help="several files: records of ONE system (same period; own multisine, P and N each) "
                        "fitted together into one model and one report, instead of one fit per file")
    b.add_argument("--workers", type=int, metavar="N",
                   help="batch: fit the files on N local processes (default: all cores; 1: serially)")
    b.add_argument("--scheduler", metavar="ADDRESS",
                   help="batch: fit the files on a Dask cluster, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--resume", action="store_true",
                   help="batch: complete an interrupted batch from the fits kept in --out/parts/ (a rerun with "
                        "the same files, options and --out does the same)")
    return p


def _one_line(problem) -> str:
    """A message on one line (the command's errors are one line), or the exception's type."""
    return " ".join(str(problem).split()) or type(problem).__name__


def _fail(name, problem, status=2) -> int:
    print(f"lptv identify: error: {name}: {in_option_terms(_one_line(problem), OPTION_NAMES)}", file=sys.stderr)
    return status


# ------------------------------------------------------------------------------ running

def run(args) -> int:
    from lptv.apps import mimoid

    if mimoid.several_channels(args):      # --input f1,f2 / --output x1,x2: one fit of all the files
        if getattr(args, "reference", None):
            print("lptv identify: error: --reference: the period check by a reference column is built for one "
                  "input and one output (several channels: --no-period-check with --period)", file=sys.stderr)
            return 2
        return mimoid.run(args)
    if args.covariance != "analytic" and (args.joint or len(args.files) > 1 or args.workers is not None
                                          or args.scheduler is not None):
        print(f"lptv identify: error: --covariance {args.covariance} takes one record at a time (not several "
              "files, --joint, --workers or --scheduler)", file=sys.stderr)
        return 2

    if args.remove_disturbances and (args.joint or len(args.files) > 1 or args.workers is not None
                                     or args.scheduler is not None):
        print("lptv identify: error: --remove-disturbances takes one record (not several files, --joint, "
              "--workers or --scheduler)", file=sys.stderr)
        return 2
    if args.resume and (args.joint or (len(args.files) == 1 and args.workers is None and args.scheduler is None)):
        print("lptv identify: error: --resume applies to a batch of files (several files, --workers or "
              "--scheduler), not to one record or --joint", file=sys.stderr)
        return 2
    if getattr(args, "transient", "auto") == "on":
        print("lptv identify: error: --transient on is built for several channels (--input f1,f2 or --output x1,x2); "
              "one input and one output fit without the record's transient term (METHOD.md section 20 says why)",
              file=sys.stderr)
        return 2
    if getattr(args, "input_noise", None) is not None and not getattr(args, "one_record", False):
        print("lptv identify: error: --input-noise is for --one-record (records of periods measure the input's "
              "noise themselves)", file=sys.stderr)
        return 2
    if getattr(args, "one_record", False):
        if args.joint or len(args.files) > 1 or args.workers is not None or args.scheduler is not None:
            print("lptv identify: error: --one-record takes one file (not several files, --joint, --workers or "
                  "--scheduler)", file=sys.stderr)
            return 2
        from lptv.apps import recordid

        return recordid.run(args, OPTION_NAMES)
    if args.joint:
        from lptv.apps import jointid

        return jointid.run(args)
    if len(args.files) > 1 or args.workers is not None or args.scheduler is not None:
        from lptv.apps import manyid

        return manyid.run(args)
    src = args.files[0]
    diag = meas = None
    try:
        output_folder(args.out)
    except OSError as e:
        return _fail(e.filename or args.out, e.strerror or e)
    try:
        lines = parse_lines(args.lines) if args.lines is not None else None
        ka, kb, known = parse_counts(args.ka, "--ka"), parse_counts(args.kb, "--kb"), parse_known(args.known)
        scale = units.parse_scale(getattr(args, "scale", None))
        if scale and known:
            raise FileError("--scale: the known coefficients (--known) already fix the scale of the parameters")
        if args.max_iter < 0:
            raise FileError(f"--max-iter must be >= 0, got {args.max_iter}")
        for opt in ("na", "nb", "max_iter"):
            integer(getattr(args, opt), "--" + opt.replace("_", "-"))
        positive(args.tol, "--tol")
        diag = inspectrec.diagnose(src, args)
        try:
            meas = read_record(src, args, realisations=True)
        except FileError as e:
            cause = inspectrec.read_failure_cause(diag, args, e)
            raise FileError(cause if cause == str(e) else f"{cause} (--no-period-check skips the check)") from None
        if meas.realisations:
            diag = None
        checked = inspectrec.setup_problem(diag, args, meas.u.shape[-1])
        if checked and not args.no_period_check:
            raise FileError(f"{checked} (--no-period-check fits the record as cut anyway)")
        output_note = inspectrec.output_period_note(diag, meas.u.shape[-1])
        ts = sample_period(args, meas)
        w0 = fundamental(args, meas)
        if meas.realisations and args.remove_disturbances:
            raise FileError("--remove-disturbances takes a record of periods of one realisation, not M x P x N "
                            "realisations")
        if meas.realisations:
            from lptv.apps import blaid

            return blaid.run(args, src, meas, w0=w0, ts=ts, lines=lines, ka=ka, kb=kb, known=known)
        if args.covariance == "realisations":
            raise FileError("--covariance realisations is for a record of M x P x N random-phase realisations; "
                            "this one holds periods of one realisation")
        if getattr(args, "referred", "auto") not in ("auto", "output"):
            raise FileError(f"--referred {args.referred} is for a record of M x P x N random-phase realisations; "
                            "this one holds periods of one realisation")
        record = check_record(meas.u, meas.y, warn=False)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = identify(meas.u, meas.y, na=args.na, nb=args.nb, ka=ka, kb=kb, w0=w0, ts=ts,
                           lines=lines, method=args.method, known=known, tol=args.tol,
                           max_iter=args.max_iter, covariance=args.covariance, bootstrap=args.bootstrap,
                           seed=0, noise=args.noise,
                           disturbances="remove" if args.remove_disturbances else None)
            Y_pred = simulate(res.model, res.data.U, warn_unstable=False)
        physical = units.scaled(res, *scale) if scale else None
    except NumericalError as e:
        return _fail(src, e, status=1)
    except (FileError, ValueError) as e:
        if not isinstance(e, FileError) and diag is not None and meas is not None \
                and re.match(r"(u|y): |lines: only", str(e)):
            cause = inspectrec.failure_cause(diag, args, meas.u.shape[-1])
            if cause and args.no_period_check:
                e = f"{e}; the record itself says: {cause}"
            elif cause:
                e = cause
        return _fail(src, e)
    # identify's own warnings are in res.warnings (and so in its summary); keep the others
    transient = inspectrec.transient_note(diag, meas.u.shape[-1], meas.skipped, res.model_ok)
    multiple = inspectrec.period_multiple_note(diag, args, meas.u.shape[-1], res.model_ok)
    swapped = diag.swapped if diag is not None and diag.repeats and not res.model_ok \
        and getattr(args, "reference", None) is None else None
    extra = ([f"{checked} (kept by --no-period-check)"] if checked else []) \
        + ([output_note] if output_note else []) + ([multiple] if multiple else []) \
        + ([transient] if transient else []) + ([swapped] if swapped else []) \
        + [m for m in record.messages if not (transient and "transient" in m)] \
        + [str(w.message) for w in caught if str(w.message) not in res.warnings]

    P, N = meas.u.shape
    out = Path(args.out) if args.out else Path(Path(src).stem + "-lptv")
    print(f"lptv identify: {src} ({meas.format}, {P} periods of {N} samples, w0 = {w0:.6g} rad/s"
          + describe_record(meas)
          + (f", discrete-time model with ts = {args.ts:g} s" if args.ts else ", continuous-time model")
          + f") -> {out}/")
    if dropped_note(meas):
        print(dropped_note(meas))
    print(res.summary())
    stab = stability_summary(res)
    if stab is not None:
        print(stability_text(stab))
    if physical is not None:
        print(units.physical_form(physical, meas)[0])
    for msg in extra:
        print(f"warning: {msg}")
    if not args.remove_disturbances and any("too small" in e for e in res.model_errors):
        print("hint: residues below the noise: if the structure is not over-fitted, a sinusoid that is not "
              "periodic in the record may inflate the noise estimate; --remove-disturbances finds and removes it")
    summary = _summary(args, meas, w0, ka, kb, res, Y_pred, extra)
    summary["scale"] = None if scale is None else {"coefficient": scale[0], "value": scale[1]}
    summary["parameters_scaled"] = None if physical is None else units.physical_form(physical, meas)[1]
    summary["stability_uncertainty"] = stab
    failed = write_fit(out, res.model, summary, None if getattr(args, "no_report", False) else
                       lambda: _report(src, meas, res, Y_pred, summary, known=known))
    return _fail(failed[0] or src, failed[1]) if failed else verdict_status(res)


def _prediction_gap_db(res, Y_pred):
    """Mean power of Y - Y_pred over that of the mean's output noise, on the fit rows (dB)."""
    rows = res.lines
    err = np.mean(np.abs(res.data.Y[rows] - Y_pred[rows]) ** 2)
    noise = np.mean(res.data.varY[rows])
    return float(10 * np.log10(err / noise)) if noise > 0 and err > 0 else None


def _summary(args, meas, w0, ka, kb, res, Y_pred, extra):
    P, N = meas.u.shape
    return {
        "file": str(args.files[0]), "format": meas.format, "periods": P, "samples_per_period": N,
        "w0": w0, "ts": args.ts, "na": res.model.na, "nb": res.model.nb,
        "ka": ka, "kb": kb, "method": res.method, "noise": res.noise, "noise_choice": res.noise_choice,
        "disturbances_removed": [{"signal": d.signal, "line": d.line, "amplitude": d.amplitude, "phase": d.phase}
                                 for d in res.disturbances],
        "n_lines": int(res.lines.size), "first_line": int(res.lines.min()),
        "last_line": int(res.lines.max()), "n_free_parameters": res.n_free_parameters,
        "iterations": res.iterations, "converged": res.converged, "cost": res.cost,
        "fraction_above_0db": res.fraction_above_0db, "fraction_expected": res.fraction_expected,
        "fraction_band": list(res.fraction_band), "residue_ok": res.residue_ok,
        "prediction_error_vs_noise_db": _prediction_gap_db(res, Y_pred),
        "fs": meas.fs, "fs_source": meas.fs_source, "input": meas.input, "output": meas.output,
        "trimmed_samples": meas.trimmed, "skipped_periods": meas.skipped,
        "verdict": res.verdict, "model_ok": res.model_ok, "model_errors": list(res.model_errors),
        "undetermined": res.undetermined,
        "n_verdict_lines": int(res.verdict_lines.size), "verdict_fraction_above_0db": res.verdict_fraction,
        "verdict_band": list(res.verdict_band),
        "residue_tests": _json_residue_tests(res),
        "parameters": parameter_table(res),
        "lti": _json_lti(res),
        "warnings": list(res.warnings) + extra,
    }


def _json_lti(res):
    if not res.model.is_lti:
        return None
    t = lti_table(res)
    for p in t["poles"]:
        p["pole"] = [p["pole"].real, p["pole"].imag]
    return t


def _report(src, meas, res, Y_pred, summary, known=None) -> Report:
    from lptv.apps.report import coefficient_figure, parameter_section, residue_tests_section
    from lptv.apps.units import channel_unit

    model, rows = res.model, res.lines
    P, N = meas.u.shape
    lo, hi = res.fraction_band
    u_unit, y_unit = channel_unit(meas.input), channel_unit(meas.output)
    rep = Report(f"lptv identify: {Path(src).name}")
    rep.paragraph(
        f"A model with na = {model.na}, nb = {model.nb}, {summary['ka']} harmonics on the a_n and "
        f"{summary['kb']} on the b_m ({res.n_free_parameters} free parameters) identified by "
        f"{res.method.upper()} from {P} periods of {N} samples in {src}, on {rows.size} lines "
        f"({rows.min()} to {rows.max()}).")
    rep.verdict(res.verdict, res.model_ok)
    var = "y[t+n]" if model.discrete else "d^n y/dt^n"
    rep.preformatted(f"model: sum_n a_n(t) {var} = sum_m b_m(t) {var.replace('y', 'u').replace('n', 'm')}, "
                     f"n = 0..{model.na}, m = 0..{model.nb}, a_n(t) = sum_k a_n,k exp(j k w0 t)")
    scale = summary.get("scale")
    physical = parameter_section(rep, res, scale=(scale["coefficient"], scale["value"]) if scale else None,
                                 known=known, u_unit=u_unit, y_unit=y_unit)
    rep.heading("The model against the data")
    try:
        if model.is_lti:
            caption = ("Measured frequency response Y/U on the excited lines (+-2 standard deviations from the "
                       "periods, input and output noise) and the model's, with its 95 % band from the parameter "
                       "covariance.")
        else:
            caption = ("Top: the measured Y/U on the excited lines (+-2 standard deviations from the periods) and "
                       "the model's output predicted from the measured input over that input, with its 95 % band "
                       "from the parameter covariance. For a time-varying system Y/U on a line holds every "
                       "excited line's contribution through the branches G_k, so it is this prediction, not the "
                       "branch G_0 alone, that the measured points must follow. Bottom: the model's HTF branches "
                       "G_k (input line l to output line l + k)"
                       ", with their nonparametric estimates (lptv.htf_estimate) where the record separates them.")
        rep.figure(plots.bode(res), "bode.png", caption)
        cmp = compare(res, meas.u, meas.y)
        rep.figure(plots.compare(cmp, unit=y_unit or "").figure, "compare.png",
                   f"Measured output (mean of the periods) and the model's output simulated from the measured "
                   f"input over one period: fit {cmp['fit']:.1f} % = 100 (1 - ||y - yhat|| / ||y - mean y||).")
        summary["fit_percent"] = cmp["fit"]
    except (ValueError, NumericalError, np.linalg.LinAlgError):
        pass
    gap = summary["prediction_error_vs_noise_db"]

    rep.heading("The verdict's evidence")
    vlo, vhi = res.verdict_band
    ax = plots.normalized_residue(rows, res.normalized_residue, w0=model.w0, excited=res.verdict_lines)
    ax.set_title(f"excited lines: {100 * res.verdict_fraction:.1f} % above 0 dB "
                 f"(band {100 * vlo:.1f}-{100 * vhi:.1f} %); all lines: {100 * res.fraction_above_0db:.1f} %",
                 fontsize="medium")
    rep.figure(ax.figure, "normalized_residue.png",
               f"Normalised residue |e_l| / sqrt(var e_l) against frequency with the 0 dB line. On the "
               f"{res.verdict_lines.size} excited lines (marked) "
               f"{100 * res.verdict_fraction:.1f} % lie above 0 dB, where noise alone gives "
               f"{100 * vlo:.1f}-{100 * vhi:.1f} %; on all {rows.size} lines of the fit "
               f"{100 * res.fraction_above_0db:.1f} % (expected {100 * res.fraction_expected:.1f} %, band "
               f"{100 * lo:.1f}-{100 * hi:.1f} %). The verdict judges the {res.judged_lines.size} rows "
               "that read a line with signal, by the tests below. "
               + ("The fit shows no sign of modelling errors." if res.model_ok else
                  "The model is rejected: " + "; ".join(res.model_errors) + "."))
    residue_tests_section(rep, res)

    stability_section(rep, summary.get("stability_uncertainty"))
    rep.heading("The model")
    t = np.linspace(0.0, model.period, 400)
    ax = plots.frozen_poles_zeros(t, poles_est=frozen_poles(model, t), zeros_est=frozen_zeros(model, t),
                                  discrete=model.discrete)
    if model.is_lti:
        rep.figure(ax.figure, "frozen_poles_zeros.png",
                   "Poles (x) and zeros (o) of the LTI model, "
                   + ("in the z-plane (unitless) with the unit circle." if model.discrete else
                      "in the s-plane (rad/s), both axes on the same scale."))
    else:
        rep.figure(ax.figure, "frozen_poles_zeros.png",
                   "Frozen (instantaneous) poles and zeros of the estimate over one period, markers at "
                   "t = 0 " + ("(z-plane, unitless, with the unit circle)" if model.discrete else "(s-plane, rad/s)")
                   + ". They show how the system varies and say nothing about the stability of the "
                   "time-varying system.")
        coefficient_figure(rep, physical, u_unit=u_unit, y_unit=y_unit)
    gap_row = ["output residue against the noise", "-" if gap is None else f"{gap:+.1f} dB"]
    rep.heading("The fit")
    rep.table(["quantity", "value"], [
        ["file", f"{src} ({meas.format})"],
        ["periods x samples", f"{P} x {N}"],
        ["w0 (rad/s)", f"{model.w0:.6g}" + (f", ts = {model.ts:g} s" if model.discrete else "")],
        ["na, nb; harmonics ka, kb", f"{model.na}, {model.nb}; {summary['ka']}, {summary['kb']}"],
        ["lines of the fit", f"{rows.size} ({rows.min()} to {rows.max()})"],
        ["method, iterations, converged", f"{res.method}, {res.iterations}, {res.converged}"],
        ["normalised residues above 0 dB", f"{100 * res.fraction_above_0db:.1f} % (expected "
         f"{100 * res.fraction_expected:.1f} %, band {100 * lo:.1f}-{100 * hi:.1f} %)"],
        gap_row,
    ])
    rep.preformatted(res.summary())
    return rep


def _json_residue_tests(res):
    """The verdict's residue tests as plain values (an empty list without them)."""
    tests = res.residue_tests
    if tests is None:
        return []
    return [{"name": t.name, "n_rows": int(t.rows.size), "statistic": float(t.statistic),
             "p_value": float(t.p_value), "p_holm": float(t.p_holm), "rejects": bool(t.rejects)}
            for t in tests.tests]
