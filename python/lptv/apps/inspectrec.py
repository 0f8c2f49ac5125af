"""``lptv inspect FILE``: what a record holds before a model is fitted, and the command to fit one.

Prints :meth:`lptv.Inspection.summary` (sampling, period, periods, transient, excitation, the
output between the excited lines, the suggested ``lptv identify`` command) and writes
``report.html`` (with the figure of :func:`lptv.plots.inspection`) and ``summary.json`` into
``--out`` (default ``<file stem>-inspect/``). Exit status 0 when the record was inspected (a
record that does not repeat included: the summary says so and names the one-record route),
2 for a file or options that cannot be read.

The same diagnosis names the cause of an error of ``lptv identify FILE`` (:func:`setup_problem`,
:func:`failure_cause`): a period or a sampling frequency that contradicts the record, a record
that does not repeat, an output that does not repeat with the input.

Example::

    lptv inspect rig.csv --input force --output displacement
    lptv inspect loop.csv --input force --output displacement --reference reference   (under feedback)
    lptv inspect exp0.csv --input f1,f2 --output x1,x2     (several channels: lptv.apps.inspectmimo)
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np

from lptv import inspect, plots
from lptv.apps.options import in_option_terms, output_folder
from lptv.apps.report import PLOTS_EXTRA, Report, write_json
from lptv.records.measurements import FileError

OPTION_NAMES = {"fs": "--fs", "dt": "--dt", "reach": "--reach"}

_HELP = """\
Looks at a record before any model is fitted: the sampling frequency (--fs / --dt, else the
file's time column or stored fs, checked uniform), the period (the shortest lag at which the
input repeats; the output's, when it repeats only every few of the input's periods), the whole
periods and the samples left over, the start-up transient, the excited lines and their
signal-to-noise ratios, and the output's power on the other lines: sidebands of the excited
lines (time variation), odd and even detection lines (nonlinear distortion), elsewhere (noise or
a disturbance). Ends with the lptv identify command the record asks for. Writes report.html
(with a figure) and summary.json into --out."""


def add_parser(sub):
    p = sub.add_parser("inspect", help="look at a measurement file: period, transient, excited lines",
                       description=_HELP, formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog="examples:\n"
                              "  lptv inspect rig.csv --input force --output displacement\n"
                              "  lptv inspect record.npz --fs 100\n"
                              "  lptv inspect rig.csv --input force --output displacement --reach 3")
    p.add_argument("file", metavar="FILE", help="measurements: .csv, .npz or .mat (as for lptv identify)")
    p.add_argument("--input", metavar="NAME", help="the input channel (default u; matched up to case and a unit); "
                   "several as a comma list (each inspected with the first output)")
    p.add_argument("--output", metavar="NAME", help="the output channel (default y); several as a comma list")
    p.add_argument("--time", metavar="NAME", help="a time column or variable (default: one named t, time, time [s] ...)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--fs", type=float, help="sampling frequency in Hz (default: the file's)")
    g.add_argument("--dt", type=float, help="sampling time in s")
    p.add_argument("--reference", metavar="NAME",
                   help="read the period where this column repeats (the loop's external periodic reference of a "
                        "record under feedback, where the input also holds the loop's response to the disturbance)")
    p.add_argument("--reach", type=int, metavar="K",
                   help="count sidebands up to +-K lines from an excited line (default: the room the design leaves)")
    p.add_argument("--out", help="output folder (default: <file stem>-inspect/)")
    return p


def _fail(name, problem) -> int:
    text = " ".join(str(problem).split()) or type(problem).__name__
    print(f"lptv inspect: error: {name}: {in_option_terms(text, OPTION_NAMES)}", file=sys.stderr)
    return 2


def run(args) -> int:
    src = args.file
    try:
        output_folder(args.out)
    except OSError as e:
        return _fail(e.filename or args.out, e.strerror or e)
    if any(v is not None and "," in v for v in (args.input, args.output)):
        if args.reference:
            return _fail("--reference", "the period read from a reference column is built for one input and one "
                                        "output; give --period to lptv identify for several channels")
        from lptv.apps import inspectmimo
        return inspectmimo.run(args, summary, report, _fail)
    try:
        insp = inspect(src, u=args.input, y=args.output, time=args.time, fs=args.fs, dt=args.dt, reach=args.reach,
                       reference=args.reference)
    except ValueError as e:
        if args.reference and str(e).startswith("reference"):
            return _fail(f"--reference {args.reference}", str(e).partition(": ")[2] or e)
        return _fail(src, e)
    print(insp.summary())
    out = Path(args.out) if args.out else Path(Path(src).stem + "-inspect")
    try:
        out.mkdir(parents=True, exist_ok=True)
        write_json(out / "summary.json", summary(insp))
        report(insp).write(out)
    except OSError as e:
        return _fail(e.filename or out, e.strerror or e)
    except ImportError:
        print(f"lptv inspect: {PLOTS_EXTRA}", file=sys.stderr)
        return 0
    print(f"wrote {out / 'report.html'}, {out / 'summary.json'}")
    return 0


def summary(insp) -> dict:
    """The findings as plain values (summary.json)."""
    return {
        "file": insp.source, "format": insp.format, "input": insp.input, "output": insp.output,
        "reference": insp.reference, "input_repeat_ratio": None if insp.reference is None else insp.input_repeat_ratio,
        "samples": insp.samples, "fs": insp.fs, "fs_source": insp.fs_source, "file_fs": insp.file_fs,
        "repeats": insp.repeats, "input_period_samples": insp.input_period_samples,
        "period_samples": insp.period_samples, "input_period_exact_samples": insp.input_period_exact, "period": insp.period,
        "w0": insp.w0, "repeat_ratio": insp.repeat_ratio, "output_repeats": insp.output_repeats,
        "periods": insp.periods, "leftover_samples": insp.leftover, "transient_periods": insp.transient_periods,
        "transient_ratios": insp.transient_ratios.tolist(), "transient_limit": insp.transient_limit,
        "excited_lines": insp.lines.tolist(), "spacing": insp.spacing, "weak_input_lines": insp.weak_input_lines.tolist(),
        "input_snr_db": insp.input_snr_db.tolist(), "output_snr_db": insp.output_snr_db.tolist(),
        "reach": insp.reach, "time_variation_reach": insp.time_variation_reach,
        "classes": {c.name: {"lines": int(c.lines.size), "above_noise": c.above.tolist(),
                             "excess_db": c.excess_db, "strongest_db": c.level_db} for c in insp.classes},
        "notes": list(insp.notes), "swapped": insp.swapped, "command": insp.command,
    }


def report(insp) -> Report:
    rep = Report(f"lptv inspect: {Path(insp.source).name}")
    rep.paragraph("What the record holds before any model is fitted, from its samples alone "
                  "(METHOD.md section 18 gives the criteria).")
    rep.preformatted(insp.summary())
    fig = plots.inspection(insp)
    caption = ("Top: the input's repeat residue r(L), the share of its power that the record shifted by L "
               "samples does not reproduce (0: repeats exactly; about 1: unrelated), with the limit a period "
               "must meet; the period found and its multiples are marked.")
    if insp.repeats:
        caption += (" Bottom: the output spectrum of the mean of the steady periods, each line marked by its "
                    "class, over the noise level of that mean and the line test's threshold (noise alone "
                    f"crosses it on any of the {insp.spectrum_lines.size} lines with a chance of 1 %).")
    rep.figure(fig, "inspection.png", caption)
    return rep


# ------------------------------------------------------------------------------ lptv identify's diagnosis

def period_option(args):
    """How the options state the period: ('--period 4', seconds) or ('--w0 1.2', seconds), or None."""
    if args.period is not None and args.period > 0:
        return f"--period {args.period:g}", float(args.period)
    if args.w0 is not None and args.w0 > 0:
        return f"--w0 {args.w0:g}", 2 * np.pi / float(args.w0)
    return None


def diagnose(src, args):
    """:func:`lptv.inspect` on the file as the options name its channels and fs; None when the
    file cannot be read that way (the reader's own error then stands). With ``--reference NAME``
    (lptv identify) the period is read where the reference repeats, not the input: under
    feedback the input holds the loop's response to its disturbance (METHOD.md section 20)."""
    reference = getattr(args, "reference", None)
    try:
        return inspect(src, u=args.input, y=args.output, time=args.time, fs=args.fs, dt=args.dt, reference=reference)
    except (ValueError, OSError) as e:
        if reference and "reference" in str(e):
            raise FileError(f"--reference {reference}: {' '.join(str(e).split())}") from None
        return None


def setup_problem(insp, args, samples_per_period=None):
    """The first contradiction between the options and the record, as a one-line message, or None:
    an fs that contradicts the file's time; a period (given, or the split's samples per period)
    that is not the one the record repeats at (nor a multiple); a record that does not repeat."""
    if insp is None:
        return None
    given_fs = f"--fs {args.fs:g}" if args.fs is not None else (f"--dt {args.dt:g}" if args.dt is not None else None)
    if given_fs and insp.file_fs is not None and not np.isclose(insp.fs, insp.file_fs, rtol=1e-6, atol=0):
        return (f"{given_fs} contradicts the file's {insp.file_fs_source} ({insp.file_fs:.10g} Hz): leave "
                f"{given_fs.split()[0]} out, or name the time's unit (time [ms])")
    if not insp.repeats:
        return not_repeating(insp)
    if samples_per_period is None:
        return None
    if insp.agrees_with(samples_per_period):
        return None
    return wrong_period(insp, args, samples_per_period)


def transient_note(insp, samples_per_period, skipped: int, model_ok: bool):
    """What ``lptv identify`` says when the periods it fits still hold the start-up transient that
    :func:`lptv.inspect` finds (``insp.transient_periods`` more than the ``skipped`` ones): a
    rejection is then the transient's (its spectrum is smooth and lies on every line, the rows
    next to the excited lines too), a pass still biased. None when no transient is left."""
    if insp is None or not insp.repeats or insp.period_samples != samples_per_period \
            or insp.transient_periods <= skipped:
        return None
    K = insp.transient_periods
    kept = f"with {skipped} dropped, " if skipped else ""
    if model_ok:
        return (f"the record's first {K} periods hold a start-up transient (lptv inspect): {kept}what is left "
                f"of it biases the parameters though the verdict finds no error; --skip-periods {K} drops it")
    return (f"the verdict sees the start-up transient: the record's first {K} periods hold one (lptv inspect), "
            f"{kept}left in the fitted periods it lies on every line, the rows next to the excited lines too; "
            f"--skip-periods {K} drops it")


def not_repeating(insp) -> str:
    return (f"the record does not repeat at any period up to {insp.seconds(insp.max_period_samples, 'half the record')}"
            f": the input's best lag leaves {100 * min(insp.repeat_ratio, 9.99):.3g} % of its power unexplained; it "
            "is not a record of periods: identify it as one record with its transient (--one-record; "
            "lptv.identify_record in Python)")


def wrong_period(insp, args, samples_per_period) -> str:
    N = insp.period_samples
    found = f"the input repeats every {insp.seconds(insp.input_period_samples)}"
    if N != insp.input_period_samples:
        found += f" and the output every {insp.seconds(N)}"
    opt = period_option(args)
    by_count = f"use --periods {insp.periods}" + (f" after dropping the first {insp.leftover} samples"
                                                   if insp.leftover else "")
    fix = f"use --period {N / insp.fs:.12g}" if insp.fs is not None else by_count
    if opt is not None:
        said = f"not every {opt[1]:g} s ({opt[0]}"
        said += f", {samples_per_period:g} samples)" if insp.fs is not None else ")"
        if insp.fs is not None and not insp.fs_given and insp.fs_source:
            said += f" at the {insp.fs:g} Hz of the file's {insp.fs_source}"
        elif insp.fs is not None:
            fix += f", or correct --fs ({N:g} samples in {opt[1]:g} s is {N / opt[1]:.6g} Hz)"
    elif args.periods is not None:
        said, fix = f"not every {samples_per_period:g} samples (--periods {args.periods})", by_count
    elif insp.stored_period is not None:
        said = f"not every {samples_per_period:g} samples (the file's periods x samples arrays)"
        fix = "store the record as one long vector, or as periods of that length"
    else:
        said = f"not every {insp.seconds(samples_per_period)} (the file's w0 or fs)"
    return f"{found}, {said}: {fix}"


def output_period_note(insp, samples_per_period):
    """A warning when the record is cut at the input's period (or a multiple) that the output
    does not repeat at: its period is a multiple of the input's (the system's period)."""
    if insp is None or not insp.repeats or not insp.agrees_with(samples_per_period) \
            or insp.output_agrees_with(samples_per_period):
        return None
    fix = f"--period {insp.period:.12g}" if insp.period is not None else f"periods of {insp.period_samples} samples"
    return (f"the output repeats only every {insp.seconds(insp.period_samples)}, every "
            f"{insp.period_samples // insp.input_period_samples} of the input's periods: the system's period is "
            f"probably that one ({fix})")


def period_multiple_note(insp, args, samples_per_period, model_ok: bool = True):
    """A warning when the record is cut into periods that hold several of the ones input and output
    repeat at (``--period 8`` on a record repeating every 4 s, or a wrong ``--fs`` on a file
    without a time): the fit then reads the system's harmonics as multiples of a lower w0, and a
    time-varying model with a harmonic count for the true period misses them (MODEL ERRORS).
    None when the periods are the record's own."""
    if insp is None or not insp.repeats or not insp.output_agrees_with(samples_per_period):
        return None
    own = insp.input_period_exact * (insp.period_samples // insp.input_period_samples)
    m = int(round(samples_per_period / own))
    if m < 2:
        return None
    opt = period_option(args)
    lead = "the verdict's model errors may be the period's: " if not model_ok else ""
    found = f"input and output repeat every {insp.seconds(insp.period_samples)}"
    true = f"{insp.period:.6g} s" if insp.period is not None else f"{insp.period_samples:g} samples"
    if opt is not None and insp.file_fs is not None:
        said = f"{opt[0]} holds {m} of the record's periods ({found} at the {insp.fs:g} Hz of the file's " \
               f"{insp.file_fs_source})"
        fix = f"use --period {insp.period:.12g}"
    elif opt is not None and insp.fs is not None:
        fs = insp.fs
        said = (f"{opt[0]} at --fs {fs:g} is {samples_per_period:g} samples, {m} of the record's periods "
                f"({found} at that fs)")
        fix = (f"use --period {insp.period:.12g} at this fs, or correct --fs ({insp.period_samples:g} samples in "
               f"{opt[1]:g} s is {insp.period_samples / opt[1]:.6g} Hz)")
    elif getattr(args, "periods", None) is not None:
        said = f"--periods {args.periods} cuts the record into periods of {m} of its own ({found})"
        fix = f"use --periods {insp.periods}"
    else:
        said = f"each period of the file holds {m} of the record's periods ({found})"
        fix = f"store periods of {insp.period_samples:g} samples"
    return (f"{lead}{said}: the system's period is probably {true}, and at the fit's period a time-varying "
            f"model needs {m} times the harmonics for the same variation ({fix}; keep the fit's period only if "
            "the system's own period is that long)")


def failure_cause(insp, args, samples_per_period=None):
    """The likely cause of a failure of the fit on a record cut into periods (a refusal of the
    data diagnostics: no input or output variation above the noise), or None: the record's
    own problem when it has one, an output that does not repeat with the input."""
    problem = setup_problem(insp, args, samples_per_period)
    if problem or insp is None or not insp.repeats:
        return problem
    if not insp.output_repeats:
        return (f"the output does not repeat with the input (every {insp.seconds(insp.period_samples)}): "
                f"{100 * min(insp.output_repeat_ratio, 9.99):.3g} % of its power does not repeat; it shows no "
                "periodic response above its noise (a dead or unconnected output channel, the wrong output, or "
                "a response far below the noise)")
    return None


def read_failure_cause(diag, args, error):
    """A reader's error with the record's own diagnosis where that names the cause: an fs or a
    period (in s) that contradicts the record replaces it; for a record split by --periods or
    stored as periods x samples arrays, where the reader's count is itself the news, the cause
    is added to it."""
    text = str(error)
    if diag is None or args.no_period_check:
        return text
    fs = args.fs if args.fs is not None else (1 / args.dt if args.dt else None)
    if fs is None and args.periods is None:
        fs = diag.file_fs
    period = period_option(args)
    n, by_count = None, False
    if fs and period:
        n = fs * period[1]
    elif args.periods:
        n, by_count = diag.samples / args.periods, True
    cause = setup_problem(diag, args, n)
    split = re.search(r"whole|drop \d+ samples|samples per period|less than one period|period is needed|"
                      r"--periods is required|needs the period|: give ", text)
    if cause is None:
        if n is None and diag.repeats and split:
            hint = f"--period {diag.period:.12g}" if diag.period is not None else f"--periods {diag.periods}"
            return f"{text}; the input repeats every {diag.seconds(diag.period_samples)}: {hint}"
        return text
    if cause.startswith(("--fs", "--dt")):
        return cause
    if not diag.repeats:
        # a reader's count on arrays stored the other way round, or on a record too short, stands
        return cause if split and diag.stored_period is None else text
    if by_count or diag.stored_period is not None:
        return f"{text}; {cause}"
    return cause
