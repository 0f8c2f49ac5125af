"""What the commands share about their options.

Every bad option value ends in one line on stderr and exit status 2, never a usage block or a
traceback: argparse's own errors go through :class:`Parser`; a message of the library that names
a Python argument (``max_iter must be ...``) is put in the option's terms (``--max-iter must be
...``) by :func:`in_option_terms`; ranges of lines or grid values are bounded before they are
expanded; an output folder given with ``--out`` is checked before any work, so that a folder
that cannot be written is reported at once.
"""
from __future__ import annotations

import argparse
import contextlib
import errno
import os
import re
import signal
import tempfile
import threading
from pathlib import Path

import numpy as np

from lptv.records.measurements import FileError, read_measurements

INT_MAX = 2**31 - 1
"""The largest integer the core takes (a C int)."""
MAX_EXPANDED = 2**26
"""The most values a range option (``--lines 1-N``) may expand to: the largest grid of the core."""


MODEL_REJECTED = 3
"""The exit status of ``lptv identify FILE`` when the verdict finds model errors (MODEL ERRORS);
0 when it calls the model consistent with the data, :data:`NOT_DETERMINED` when the data cannot
decide, 2 for a file or options that cannot be used, 1 for a computation that failed."""
NOT_DETERMINED = 4
"""The exit status when the verdict cannot call the model consistent though it finds no error
(NOT DETERMINED: too little signal for the structure, or too few realisations to judge)."""


def verdict_status(res) -> int:
    """0 for a model the verdict calls consistent with the data, :data:`MODEL_REJECTED` when it
    finds model errors, :data:`NOT_DETERMINED` when the data do not determine the model."""
    if not res.model_ok:
        return MODEL_REJECTED
    return 0 if res.undetermined is None else NOT_DETERMINED


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``prog: error: message`` on stderr, exit status 2 (the usage
    block stays in ``--help``). A command's namespace also holds ``given_options``, the
    destinations of the options given on the command line (even at their default value), so that
    a route can refuse an option it would otherwise ignore (:func:`refuse_given`)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {' '.join(str(message).split())}\n")

    def parse_known_args(self, args=None, namespace=None):
        ns, rest = super().parse_known_args(args, namespace)
        if self._subparsers is None and args is not None:
            # the same words once more with every default suppressed: what remains was given
            saved = [(a, a.default) for a in self._actions if a.option_strings]
            try:
                for a, _ in saved:
                    a.default = argparse.SUPPRESS
                given = vars(super().parse_known_args(list(args), None)[0])
            except SystemExit:        # the first parse accepted these words: not reached
                given = {}
            finally:
                for a, d in saved:
                    a.default = d
            ns.given_options = frozenset(given)
        return ns, rest


def refuse_given(args, refused: dict, route: str):
    """A FileError for the first option of ``refused`` ({dest: reason}) given on the command line
    (:class:`Parser`'s ``given_options``): ``--method: --one-record ... (reason)``."""
    given = getattr(args, "given_options", frozenset())
    for dest, reason in refused.items():
        if dest in given:
            raise FileError(f"--{dest.replace('_', '-')} is not for {route}: {reason}")


def refuse_same_file(files) -> None:
    """FileError when one file is given twice to a fit of several experiments (its path spelled
    either way): fitted as two experiments, one measurement would count twice."""
    seen = {}
    for i, f in enumerate(files):
        key = os.path.realpath(f)
        if key in seen:
            raise FileError(f"{f} is given twice (files {seen[key] + 1} and {i + 1}): fitted as two experiments one "
                            "measurement would count twice and every std shrink by sqrt 2; give each record once")
        seen[key] = i


def integer(value, opt, minimum=0, maximum=INT_MAX):
    """An integer option's value within [minimum, maximum], or a FileError naming the option."""
    if value is None:
        return None
    if value < minimum:
        raise FileError(f"{opt} must be >= {minimum}, got {value}")
    if value > maximum:
        raise FileError(f"{opt} must be at most {maximum}, got {value}")
    return value


def bounded_range(lo: int, hi: int, opt: str, token: str, limit: int = MAX_EXPANDED):
    """range(lo, hi + 1) after checking that hi fits the core's int and that the range is not
    larger than ``limit`` values (a typo like 1-99999999999 would otherwise fill the memory)."""
    if hi > INT_MAX:
        raise FileError(f"{opt}: '{token}' goes beyond {INT_MAX}, the largest value the core takes")
    if hi - lo + 1 > limit:
        raise FileError(f"{opt}: '{token}' holds {hi - lo + 1} values; at most {limit} are accepted")
    return range(lo, hi + 1)


def output_folder(path):
    """Check, before any work, that the folder given with ``--out`` can be made and written, without
    leaving anything behind: OSError (its filename the folder) when a file stands there, or the
    nearest existing folder above it refuses a new entry."""
    if path is None:
        return None
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise FileExistsError(errno.EEXIST, "File exists", str(path))
    parent = p
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, "Not a directory", str(path))
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".lptv-probe-", dir=parent))
    except OSError as e:
        raise OSError(e.errno, e.strerror, str(path)) from None
    return path


def in_option_terms(message: str, names: dict) -> str:
    """A library message that starts with a Python argument's name (``max_iter must be``,
    ``lines: row 0 ...``), restated with the option (``--max-iter must be``)."""
    for name, opt in names.items():
        new = re.sub(rf"^{re.escape(name)}(?=[\s:])", opt, message)
        if new != message:
            return new
    return message


class Interrupted(KeyboardInterrupt):
    """SIGINT (Ctrl-C) or SIGTERM during a long command; ``status`` is the exit status a shell
    gives a process killed by that signal (128 + its number: 130, 143)."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum
        self.status = 128 + signum


@contextlib.contextmanager
def interruptible():
    """Turns the first SIGINT or SIGTERM in the block into :class:`Interrupted` (the command then
    stops cleanly: what is finished stays on disk) and ignores the next ones (a second Ctrl-C, or
    the same signal sent to the process group), so that the command's last line and exit status
    are its own. The previous handlers are restored after a block that was not interrupted; an
    interrupted command is ending, and keeps ignoring them until it exits."""
    signals = (signal.SIGINT, signal.SIGTERM)
    interrupted = []

    def handler(signum, frame):
        for s in signals:
            signal.signal(s, signal.SIG_IGN)
        interrupted.append(signum)
        raise Interrupted(signum)

    if threading.current_thread() is not threading.main_thread():
        yield   # signals reach the main thread only
        return
    old = {s: signal.signal(s, handler) for s in signals}
    try:
        yield
    finally:
        if not interrupted:
            for s, h in old.items():
                signal.signal(s, h)


# ------------------------------------------------------------------------------ what lptv identify's
# commands share (one file, a batch, --joint, select, montecarlo): the options' parsing

def parse_lines(text: str, opt: str = "--lines"):
    """'1-243', '1-100,120-150' or '10,20,30' -> the line numbers, in the order given;
    'excited' -> 'excited' (the lines the input excites, +-K for an LPTV model)."""
    if text.strip().lower() == "excited":
        return "excited"
    spans, total = [], 0
    for tok in text.split(","):
        m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", tok)
        if not m:
            raise FileError(f"{opt}: '{tok.strip()}' is not a line number or a range like 1-243")
        lo = int(m.group(1))
        hi = int(m.group(2)) if m.group(2) else lo
        if hi < lo:
            raise FileError(f"{opt}: '{tok.strip()}' is an empty range")
        r = bounded_range(lo, hi, opt, tok.strip(), MAX_EXPANDED - total)
        spans.append((r.start, r.stop - 1))
        total += len(r)
    # repeats by the ranges, sorted (a list of every line cost 36 bytes a line to check)
    ordered = sorted(spans)
    for (lo0, hi0), (lo1, _) in zip(ordered, ordered[1:]):
        if lo1 <= hi0:
            raise FileError(f"{opt}: line {lo1} is given twice")
    # as 64-bit integers, 8 bytes a line: the library names lines above the data's Nyquist line
    return np.concatenate([np.arange(lo, hi + 1, dtype=np.int64) for lo, hi in spans])


def parse_counts(text, opt):
    try:
        ks = [int(t) for t in text.split(",")]
    except ValueError:
        raise FileError(f"{opt}: '{text}' must be an integer or a comma list of integers, "
                        "one per coefficient") from None
    if any(k < 0 for k in ks):
        raise FileError(f"{opt}: harmonic counts must be >= 0, got '{text}'")
    return ks[0] if len(ks) == 1 else ks


def parse_known(text):
    if text is None:
        return None
    out = {}
    for tok in text.split(","):
        name, eq, value = tok.partition("=")
        name = name.strip()
        try:
            v = float(value)
        except ValueError:
            v = None
        if not eq or not name or v is None or not np.isfinite(v):
            raise FileError(f"--known: '{tok.strip()}' is not of the form name=number (e.g. a2=1.5)")
        if name in out:
            raise FileError(f"--known: {name} is given twice")
        out[name] = v
    return out


def positive(value, opt):
    if value is not None and not (np.isfinite(value) and value > 0):
        raise FileError(f"{opt} must be a positive number, got {value:g}")
    return value


def fundamental(args, meas):
    """w0 from --w0 / --period, the file, and (discrete time) --ts with the samples per period."""
    w0 = positive(args.w0, "--w0")
    if positive(args.period, "--period") is not None:
        w0 = 2 * np.pi / args.period
    given = "--w0" if args.w0 is not None else "--period"
    if meas.w0 is not None:
        if w0 is not None and not np.isclose(w0, meas.w0, rtol=1e-9, atol=0):
            raise FileError(f"{given} gives w0 = {w0:.10g} rad/s but the file says w0 = {meas.w0:.10g}")
        if w0 is None:
            w0, given = meas.w0, "the file's w0"
    if meas.fs is not None and w0 is None:
        w0 = 2 * np.pi * meas.fs / meas.u.shape[-1]
    if positive(args.ts, "--ts") is not None:
        n = meas.u.shape[-1]
        w0_ts = 2 * np.pi / (n * args.ts)
        if w0 is None:
            w0 = w0_ts
        elif not np.isclose(w0, w0_ts, rtol=1e-9, atol=0):
            # the library would accept it, with the lines mapped to the wrong frequencies
            raise FileError(f"{given} and --ts {args.ts:g} give {2 * np.pi / (w0 * args.ts):.6g} "
                            f"samples per period, but the record has {n}")
    if w0 is None:
        raise FileError("the period is unknown: give --w0 (rad/s) or --period (s)")
    return w0


OPTION_NAMES = {"na": "--na", "nb": "--nb", "ka": "--ka", "kb": "--kb", "max_iter": "--max-iter",
                "tol": "--tol", "lines": "--lines", "known": "--known", "method": "--method", "w0": "--w0",
                "ts": "--ts", "periods": "--periods", "covariance": "--covariance", "bootstrap": "--bootstrap", "noise": "--noise", "transient": "--transient",
                "disturbances": "--remove-disturbances"}
"""The arguments of lptv.identify and the options that set them, for the messages."""


def add_record_options(p, several: bool = False):
    """The options that say how a record is read and which of its lines are fitted, as every
    command that fits a file has them (``lptv identify``, ``lptv select``): the period (--w0 /
    --period), the sampling (--fs / --dt, --time), the channels, the periods kept (--periods,
    --trim, --skip-periods), --detrend, the model's time base (--discrete, --ts) and --lines;
    ``several``: --input / --output take comma lists (several channels)."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("--w0", type=float, help="fundamental of the period (rad/s)")
    g.add_argument("--period", type=float, metavar="T0", help="the period in seconds (w0 = 2 pi / T0)")
    s = p.add_mutually_exclusive_group()
    s.add_argument("--fs", type=float, metavar="HZ",
                   help="sampling frequency of the record (Hz); the model stays continuous-time. With the "
                        "period it gives the samples per period and splits a long record into whole periods")
    s.add_argument("--dt", type=float, metavar="S", help="sampling time of the record (s), 1 / fs")
    p.add_argument("--discrete", action="store_true",
                   help="identify a discrete-time model (in the shift z) with the sample period 1 / fs")
    p.add_argument("--ts", type=float, help="identify a DISCRETE-TIME model with this sample period (s); "
                   "to state how the record was sampled for a continuous-time model use --fs or --dt")
    p.add_argument("--input", metavar="NAME",
                   help="the input channel: a CSV column, NPZ array or MAT variable (default u)"
                        + ("; several as a comma list" if several else ""))
    p.add_argument("--output", metavar="NAME",
                   help="the output channel (default y)" + (
                       "; several as a comma list (--input f1,f2 --output x1,x2): the files are then "
                       "experiments of one system of several inputs and outputs" if several else "; one at a time"))
    p.add_argument("--time", metavar="NAME",
                   help="a time column or variable (s) giving fs, checked uniform (default: one named t or "
                        "time); without --fs, --dt and --periods the file's time or stored fs / dt / Ts is used")
    p.add_argument("--periods", type=int, metavar="P", help="number of periods in a CSV record (or a vector)")
    p.add_argument("--trim", action="store_true",
                   help="with --fs: drop the first samples of a long record to keep whole periods")
    p.add_argument("--skip-periods", type=int, default=0, metavar="K",
                   help="drop the first K periods (a start-up transient)")
    p.add_argument("--detrend", action="store_true",
                   help="take a linear drift out of each channel (the trend across the periods; each "
                   "period's shape is kept)")
    p.add_argument("--lines", help="lines of the fit, e.g. 1-243 or 1-100,120-150, or 'excited' (the lines "
                   "the input excites, +-K for an LPTV model); default: all usable. The verdict always "
                   "judges every row that reads a line with signal")
    return p


def sample_period(args, meas):
    """The model's sample period: --ts, or 1 / fs with --discrete (None: continuous time); with
    --discrete ``args.ts`` is set to it, as the commands' messages and summaries read it."""
    if args.discrete and args.ts is not None:
        raise FileError("--discrete takes the sample period from --fs / --dt; do not give --ts as well")
    if args.discrete and meas.fs is None:
        raise FileError("--discrete needs the sampling frequency --fs (or --dt)")
    if args.discrete:
        args.ts = 1.0 / meas.fs
    return args.ts


def read_options(args) -> dict:
    """The keyword arguments of lptv.read_measurements the options give (--periods, --fs / --dt,
    --period or --w0, --trim, --skip-periods, --input, --output, --time, --detrend)."""
    period = positive(args.period, "--period")
    if period is None and positive(args.w0, "--w0") is not None:
        period = 2 * np.pi / args.w0
    return dict(periods=args.periods, fs=args.fs, dt=args.dt, period=period, trim=args.trim,
                skip_periods=args.skip_periods, u=args.input, y=args.output, time=args.time,
                detrend=getattr(args, "detrend", False))


def read_record(src, args, realisations: bool = False):
    """The periods of one file as the options say (:func:`read_options`); with ``realisations``
    also M x P x N records of random-phase realisations."""
    return read_measurements(src, **read_options(args), realisations=realisations)


def count(n: int, word: str) -> str:
    """'1 input', '2 inputs', '1 period', '0 samples': a count with its noun in number."""
    return f"{n} {word}" + ("" if n == 1 else "s")


def dropped_note(meas):
    """'dropped at the start: 40 samples (--trim), 6 periods (--skip-periods)', naming only what
    was dropped; None when nothing was."""
    parts = ([f"{count(meas.trimmed, 'sample')} (--trim)"] if meas.trimmed else []) \
        + ([f"{count(meas.skipped, 'period')} (--skip-periods)"] if meas.skipped else [])
    return "dropped at the start: " + ", ".join(parts) if parts else None


def describe_record(meas) -> str:
    """', fs = 50 Hz from column 'time', input 'force', output 'disp'' (what the first line says)."""
    text = ""
    if meas.fs:
        text += f", fs = {meas.fs:g} Hz" + (f" from {meas.fs_source}" if meas.fs_source else "")
    if (meas.input, meas.output) != ("u", "y"):
        text += f", input '{meas.input}', output '{meas.output}'"
    return text
