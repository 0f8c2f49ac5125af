"""What a record holds before any model is fitted: :func:`lptv.inspect`.

From the input and output samples alone (NumPy and SciPy only): the sampling frequency (given,
or the file's time column or stored fs, checked uniform), the period (the shortest lag at which
the input repeats, METHOD.md section 18), the whole periods and the samples left over, the
start-up transient, the excited lines with their signal-to-noise ratios, and the output's power
on the other lines sorted into what it means: sidebands of the excited lines (time variation),
odd and even detection lines (nonlinear distortion), elsewhere (noise or a disturbance). It ends
with the ``lptv identify`` command the record asks for. ``lptv identify FILE`` runs the same
diagnosis to name the cause of a record's error (a wrong period or fs, a record that does not
repeat).
"""
from __future__ import annotations

import math
import shlex
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Tuple

import numpy as np

from .._validate import _array, as_float, as_int, as_path, not_regular
from .channels import FileError
from .scan import (ALPHA, NOISE_HALF_WINDOW, REPEAT_LIMIT, SIGMAS, WHOLE, LineClass,  # noqa: F401
                         _classify, _detrended, _drift, _output_multiple, _pooled, _residue_at, _spectra,
                         _threshold, _transient, find_period, repeat_residue)
from .scan import TRANSIENT_LEFT, TransientSkip, transient_skip

__all__ = ["Inspection", "LineClass", "inspect"]

OUTPUT_REPEAT_LIMIT = 0.5
"""The output repeats with the input when its repeat residue is below this (its repeating part
holds more power than its noise)."""
SWAPPED_DB = 10.0
"""The input's median SNR on the excited lines this far below the output's asks whether input and
output are swapped: an excitation is measured where it is made, mostly the cleaner of the two,
while the output carries the system's filtering (:attr:`Inspection.swapped`)."""
WEAK_INPUT_DB = 40.0
"""Input lines above the noise but this far below the median excited line are not counted as
excitation (an actuator's distortion, leakage), only reported."""


@dataclass(frozen=True)
class Inspection:
    """What :func:`inspect` found in a record (see :meth:`summary`)."""

    source: str
    format: str
    input: str
    output: str
    samples: int
    fs: Optional[float]
    """The sampling frequency used (Hz): given, else the file's; None when unknown."""
    fs_source: Optional[str]
    """Where fs came from: None when given (or unknown), else e.g. "column 'time [s]'"."""
    file_fs: Optional[float]
    """The file's own sampling frequency (time column or stored fs), whether used or not."""
    file_fs_source: Optional[str]
    fs_given: bool
    lags: np.ndarray
    """The lags searched (samples), 0 .. half the record."""
    repeat: np.ndarray
    """The input's repeat residue r(L) at each lag (0: repeats exactly; about 1: unrelated)."""
    repeats: bool
    """The input repeats (and so the record can be cut into periods)."""
    input_period_samples: Optional[int]
    """The shortest lag at which the input repeats (samples)."""
    input_period_exact: Optional[float]
    """The input's period refined between samples: whole when the generator and the sampling
    share a clock."""
    period_samples: Optional[int]
    """The period of input and output together (samples): the input's, or a multiple where the
    output repeats only every few of the input's periods."""
    repeat_ratio: float
    """r at the input's period: the share of the input's power that does not repeat (its noise)."""
    output_repeats: bool
    output_repeat_ratio: float
    periods: int
    """Whole periods in the record."""
    leftover: int
    """Samples before the first whole period (the record's end is kept: it is the closest to
    steady state)."""
    transient_ratios: np.ndarray
    """Per leading period, its difference from the steady periods over what the noise explains
    (the larger of input and output; about 1 in steady state)."""
    transient_limit: float
    transient_periods: int
    """Leading periods to drop (--skip-periods): those that differ from the steady ones, and more
    until what is left of the transient in the mean of the kept periods is below
    :data:`TRANSIENT_LEFT` of that mean's noise power (:attr:`transient`)."""
    transient: TransientSkip
    """How ``transient_periods`` was counted: the periods seen, the decay, what is left."""
    lines: np.ndarray
    """The excited lines (of the period's grid)."""
    spacing: int
    """The greatest common divisor of the excited lines: detection lines are its multiples."""
    weak_input_lines: np.ndarray
    input_snr_db: np.ndarray
    """|U_l|^2 over the noise variance of the mean of the periods, per excited line (dB)."""
    output_snr_db: np.ndarray
    reach: int
    """Sidebands counted up to +-reach lines from an excited line."""
    classes: Tuple[LineClass, ...]
    time_variation_reach: int
    """The largest distance d <= reach, contiguous from 1, at which an unexcited line stands above
    the noise: the harmonics K a model needs, at least."""
    threshold: float
    """The line test's threshold on |X_l|^2 / var(X_l) (the mean of the periods)."""
    spectrum_lines: np.ndarray
    U: np.ndarray
    """The mean period's input spectrum on spectrum_lines (DFT / N)."""
    Y: np.ndarray
    noise_u: np.ndarray
    """The noise variance of U on spectrum_lines (pooled over neighbouring lines)."""
    noise_y: np.ndarray
    stored_period: Optional[int]
    """Samples per row of a (P, N) array in the file, None for a long record."""
    notes: Tuple[str, ...]
    reference: Optional[str] = None
    """The channel the period was read from when it is not the input (``reference=``): the
    loop's external periodic excitation of a record taken under feedback."""
    input_repeat_ratio: float = math.nan
    """With a reference: r of the input at the reference's period (under feedback the share of
    its power that is the loop's response to the disturbance, plus its noise)."""

    # ------------------------------------------------------------------ derived

    @property
    def max_period_samples(self) -> int:
        return int(self.lags[-1]) if self.lags.size else 0

    @property
    def period(self) -> Optional[float]:
        """The period in s (None without fs or without a period)."""
        if self.period_samples is None or self.fs is None:
            return None
        return self.period_samples / self.fs

    @property
    def w0(self) -> Optional[float]:
        return None if self.period is None else 2 * np.pi / self.period

    def agrees_with(self, samples_per_period: float) -> bool:
        """Whether a record cut into periods of ``samples_per_period`` samples is cut at the input's
        period or a multiple of it, to the sampling's resolution (half a sample)."""
        if self.input_period_exact is None:
            return False
        m = max(1, round(samples_per_period / self.input_period_exact))
        return abs(samples_per_period - m * self.input_period_exact) <= 0.5

    def output_agrees_with(self, samples_per_period: float) -> bool:
        """... and at a multiple of the output's period (:attr:`period_samples`) too."""
        if not self.agrees_with(samples_per_period):
            return False
        m = self.period_samples // self.input_period_samples
        return round(samples_per_period / self.input_period_exact) % m == 0

    def seconds(self, samples: float, more: str = "") -> str:
        """'5.000 s (1000 samples)' at 200 Hz (as many decimals as the sampling resolves), or
        '1000 samples' without fs; ``more`` is added inside the parentheses."""
        if self.fs is None:
            return f"{samples:g} samples" + (f" ({more})" if more else "")
        decimals = max(0, math.ceil(math.log10(self.fs) - 1e-9))
        return f"{samples / self.fs:.{decimals}f} s ({samples:g} samples" + (f", {more}" if more else "") + ")"

    @property
    def sidebands_visible(self) -> bool:
        """The excitation leaves unexcited lines within +-reach of its excited lines inside its
        band, where time variation would show (a full multisine leaves none)."""
        if not self.lines.size:
            return False
        lo, hi = self.lines.min(), self.lines.max()
        for c in self.classes:
            inside = c.lines[(c.lines > lo) & (c.lines < hi)]
            pos = np.searchsorted(self.lines, inside)
            dist = np.minimum(np.abs(inside - self.lines[np.clip(pos - 1, 0, self.lines.size - 1)]),
                              np.abs(self.lines[np.clip(pos, 0, self.lines.size - 1)] - inside))
            if np.any(dist <= self.reach):
                return True
        return self.time_variation_reach > 0

    @property
    def swapped(self) -> Optional[str]:
        """A sentence asking whether input and output are swapped, when the input's median SNR on
        the excited lines is :data:`SWAPPED_DB` or more below the output's; else None."""
        if not self.lines.size:
            return None
        si, so = float(np.median(self.input_snr_db)), float(np.median(self.output_snr_db))
        if not (np.isfinite(si) and np.isfinite(so)) or si > so - SWAPPED_DB:
            return None
        return (f"the input '{self.input}' is the noisier channel: its median SNR on the excited lines is "
                f"{si:.0f} dB against the output's {so:.0f} dB; an excitation is mostly measured cleaner than "
                f"the response: are input and output swapped? (--input '{self.output}' --output "
                f"'{self.input}' if so)")

    def line_class(self, name: str) -> LineClass:
        return next(c for c in self.classes if c.name == name)

    @property
    def command(self) -> Optional[str]:
        """The ``lptv identify`` command this record asks for (None when it does not repeat);
        NA, NB stand for the model's orders (``lptv select`` chooses them)."""
        if not self.repeats:
            return None
        cmd = ["lptv", "identify", shlex.quote(self.source)]
        if self.input != "u":
            cmd += ["--input", shlex.quote(self.input)]
        if self.output != "y":
            cmd += ["--output", shlex.quote(self.output)]
        if self.reference is not None and self.format != "arrays":
            cmd += ["--reference", shlex.quote(self.reference)]
        if self.fs is not None:
            if self.fs_given:
                cmd += ["--fs", f"{self.fs:.12g}"]
            cmd += ["--period", f"{self.period_samples / self.fs:.12g}"]
        elif self.stored_period != self.period_samples:
            cmd += ["--periods", str(self.periods)]
        if self.leftover:
            cmd += ["--trim"]
        if self.transient_periods:
            cmd += ["--skip-periods", str(self.transient_periods)]
        k = str(self.time_variation_reach) if self.sidebands_visible else "K"
        cmd += ["--lines", "excited", "--na", "NA", "--nb", "NB", "--ka", k, "--kb", k]
        return " ".join(cmd)

    # ------------------------------------------------------------------ text

    def summary(self) -> str:
        """What the record holds, one finding a line, ending with the suggested command."""
        out = [f"lptv inspect: {self.source} ({self.format}, {self.samples} samples; input '{self.input}', "
               f"output '{self.output}'" + (f", reference '{self.reference}'" if self.reference else "") + ")"]
        if self.fs is None:
            out.append("sampling:    fs unknown (no time column or stored fs; give --fs): periods in samples")
        else:
            src = "given" if self.fs_given else f"from {self.fs_source}" + (
                ", uniform" if "column" in (self.fs_source or "") or "'t" in (self.fs_source or "") else "")
            out.append(f"sampling:    fs = {self.fs:g} Hz ({src})")
        what = f"the reference '{self.reference}'" if self.reference else "the input"
        if not self.repeats:
            out.append(f"period:      none: {what} does not repeat at any lag up to "
                       f"{self.seconds(self.max_period_samples, 'half the record')}"
                       f"; the best lag leaves {100 * min(self.repeat_ratio, 9.99):.3g} % of its power unexplained")
            out.append("route:       not a periodic record: identify it as one record with its transient, "
                       f"lptv identify {shlex.quote(self.source)} --one-record --period T ... "
                       "(lptv.identify_record(u, y, na=..., nb=..., w0=2 pi / T, ts=1 / fs) in Python; "
                       "T the system's period, known from the set-up)")
            out += [f"note:        {n}" for n in self.notes]
            return "\n".join(out)
        N, L = self.period_samples, self.input_period_samples
        out.append(f"period:      {what} repeats every {self.seconds(L)}; "
                   f"{100 * self.repeat_ratio:.2g} % of its power does not repeat (its noise)")
        if self.reference:
            out.append(f"             the input: {100 * min(self.input_repeat_ratio, 9.99):.2g} % of its power does not "
                       "repeat at that period (under feedback: the loop's response to its disturbance, and its noise)")
        if N != L:
            out.append(f"             the output repeats only every {N // L} of them: period {self.seconds(N)}")
        elif not self.output_repeats:
            out.append(f"             the output does not repeat with it ({100 * min(self.output_repeat_ratio, 9.99):.3g} "
                       "% of its power does not repeat): no response above the noise, or not a periodic one")
        out.append(f"periods:     {self.periods} whole periods, {self.leftover} samples left over at the start"
                   + (" (--trim drops them)" if self.leftover else ""))
        if self.transient_ratios.size:
            first = float(self.transient_ratios[0])
            tr = self.transient
            if self.transient_periods:
                seen = ("the first period differs" if tr.seen == 1 else f"the first {tr.seen} periods differ")
                more = ("" if tr.periods == tr.seen else
                        f"; it decays by {-10 * math.log10(tr.decay):.3g} dB a period, and {tr.periods} dropped leave "
                        f"{tr.left:.2g} of the kept periods' noise power in their mean (at most {TRANSIENT_LEFT:g}: "
                        "no bias)")
                out.append(f"transient:   {seen} from the steady ones (the first by {first:.3g} times what the "
                           f"noise explains, limit {self.transient_limit:.3g}){more}: drop {self.transient_periods} "
                           f"(--skip-periods {self.transient_periods})")
            else:
                out.append(f"transient:   none seen (first period {first:.3g} times the noise, limit "
                           f"{self.transient_limit:.3g})")
        else:
            out.append("transient:   not judged (fewer than 3 periods)")
        if self.lines.size:
            out.append(f"excitation:  {self.lines.size} lines, {_describe_lines(self.lines, self.spacing)}; "
                       f"SNR of the mean period on them: input {_range_db(self.input_snr_db)}, output "
                       f"{_range_db(self.output_snr_db)}")
        else:
            out.append("excitation:  no input line above the noise")
        if self.weak_input_lines.size:
            out.append(f"             {self.weak_input_lines.size} weaker input lines ({WEAK_INPUT_DB:g} dB or more "
                       f"below the excitation), not counted: {_compress(self.weak_input_lines)}")
        out.append(f"unexcited:   the output on the other lines (line test at {10 * np.log10(self.threshold):.1f} dB "
                   "over the noise):")
        for c in self.classes:
            out.append(f"  {_CLASS_TITLE[c.name](self.reach):<26} {c.above.size} of {c.lines.size} lines above the noise"
                       + (f", strongest {c.level_db:+.1f} dB from the excited lines' output" if c.present else "")
                       + f": {self._meaning(c)}")
        out += [f"note:        {n}" for n in self.notes + ((self.swapped,) if self.swapped else ())]
        out.append("suggested:   " + self.command)
        out.append("             (NA, NB: the orders of the model"
                   + ("" if self.sidebands_visible else ", K: its harmonics, which this excitation cannot show")
                   + "; lptv select chooses them; add --discrete for a discrete-time model)")
        return "\n".join(out)

    def _meaning(self, c: LineClass) -> str:
        if c.name == "sidebands":
            k = self.time_variation_reach
            if k:
                far = " or farther" if k == self.reach else ""
                span = f"{k} line" + ("" if k == 1 else "s")
                if c.present:
                    return (f"the system varies in time: sidebands reach +-{span}{far} (harmonics K >= {k}; or "
                            "nonlinear distortion there)")
                # the lines up to k from the excited ones that stand above the noise are detection lines
                return (f"none here, but the detection lines up to {span}{' or more' if far else ''} from the "
                        f"excited ones stand above the noise: time variation (harmonics K >= {k}), or nonlinear "
                        "distortion on those lines")
            if not self.sidebands_visible:
                return ("no unexcited line between the excited ones: time variation, if any, hides under them "
                        "(the fit's verdict or lptv.htf_estimate tells)")
            where = "" if c.lines.size else " on the detection lines next to the excited ones"
            return f"no sign of time variation{where} (an LTI model may do: --ka 0 --kb 0)"
        if c.name in ("odd detection", "even detection"):
            kind = c.name.split()[0]
            if not c.lines.size:
                return "none in this design"
            if self.spacing < 3:
                # excited lines next to each other leave no line to sidebands alone
                return (f"{kind} nonlinear distortion or time variation: this design puts both on the same lines "
                        "(excited lines on multiples of 2K + 1 tell them apart, lptv.excitation_lines)"
                        if c.present else f"no sign of {kind} nonlinear distortion or time variation")
            return (f"{kind} nonlinear distortion (or time variation reaching beyond +-{self.reach})" if c.present
                    else "no sign of " + kind + " nonlinear distortion")
        if not c.present:
            return "noise alone"
        side = self.line_class("sidebands").present or self.time_variation_reach > 0
        return ("a disturbance, the excitation's harmonics beyond its band"
                + (f", or sidebands beyond +-{self.reach}" if side else "")
                + " (--remove-disturbances removes sinusoids off the period's grid)")


_CLASS_TITLE = {
    "sidebands": lambda K: f"sidebands (+-1..{K}):" if K > 1 else "sidebands (+-1):",
    "odd detection": lambda K: "odd detection lines:",
    "even detection": lambda K: "even detection lines:",
    "elsewhere": lambda K: "elsewhere:",
}


def _range_db(v):
    if not v.size:
        return "-"
    return f"{np.min(v):.0f} to {np.max(v):.0f} dB (median {np.median(v):.0f})"


def _compress(lines, head=8):
    """'5-95 every 10, 100' style: runs of a constant step written once."""
    lines = [int(x) for x in lines]
    parts, i = [], 0
    while i < len(lines):
        j = i
        if i + 1 < len(lines):
            step = lines[i + 1] - lines[i]
            while j + 1 < len(lines) and lines[j + 1] - lines[j] == step:
                j += 1
        if j - i >= 2:
            parts.append(f"{lines[i]}-{lines[j]}" + (f" every {step}" if step > 1 else ""))
            i = j + 1
        else:
            parts.append(str(lines[i]))
            i += 1
    if len(parts) > head:
        parts = parts[:head] + ["..."]
    return ", ".join(parts)


def _describe_lines(lines, s):
    j = lines // s
    what = f"{_compress(lines)}"
    if s > 1:
        what += f" (multiples of {s}"
        if np.all(j % 2 == 1):
            missing = np.setdiff1d(np.arange(j[0], j[-1] + 1, 2), j)
            what += ", odd ones" + (f", {missing.size} left out as odd detection lines" if missing.size else "")
        what += ")"
    elif np.all(lines % 2 == 1):
        missing = np.setdiff1d(np.arange(lines[0], lines[-1] + 1, 2), lines)
        what += " (odd lines" + (f", {missing.size} left out as odd detection lines" if missing.size else "") + ")"
    return what


# ------------------------------------------------------------------------------ reading

def _raw_record(path, u, y, time, fs_given):
    """Input, output (1-D), names, format, (file fs, where), stored period of a file."""
    from .measurements import FORMATS, _read_csv, _read_mat, _read_npz, read_options

    o = read_options(u=u, y=y, time=time)
    names = {"u": o["u"] or "u", "y": o["y"] or "y", "time": o["time"]}
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise FileError(f"unknown file type '{path.suffix}' (expected .csv, .npz or .mat)")
    if not path.exists():
        raise FileError("no such file")
    if path.is_dir():
        raise FileError("is a directory, not a measurement file")
    why = not_regular(path)
    if why:
        raise FileError(why)          # a FIFO would hang the read for ever
    if fmt == "CSV":
        raw = _read_csv(path, names)
    elif fmt == "NPZ":
        raw = _read_npz(path, names)
    else:
        raw, fmt = _read_mat(path, names)
    try:
        found = raw.found()
    except FileError:
        if not fs_given:
            raise
        found = None               # a time the given fs overrides
    a = [np.asarray(raw.u), np.asarray(raw.y)]
    for name, v in zip(raw.names, a):
        if v.ndim == 3:
            raise FileError(f"variable '{name}' holds M x P x N realisations: inspect one of them (a record of "
                            "periods); lptv.distortion separates their noise and distortion")
        if v.dtype.kind not in "fiu":
            raise FileError(f"{raw.kind} '{name}' is not numeric (dtype {v.dtype})")
    stored = a[0].shape[1] if a[0].ndim == 2 and min(a[0].shape) > 1 else None
    return (a[0].astype(float).ravel(), a[1].astype(float).ravel(), raw.names, fmt, found, stored, raw.kind)


def inspect(path=None, *, u=None, y=None, time=None, fs: Optional[float] = None, dt: Optional[float] = None,
            reach: Optional[int] = None, reference=None) -> Inspection:
    """Look at a record before fitting a model: its sampling, period, periods, transient,
    excitation and the output's power between the excited lines.

    Parameters
    ----------
    path : str or Path, optional
        A measurement file (CSV, NPZ, MAT, as :func:`lptv.read_measurements` reads). Without it
        ``u`` and ``y`` are the samples themselves.
    u, y : str or array_like
        With ``path``: the names of the input and output channels (default ``'u'`` and ``'y'``;
        matched up to case and a trailing unit, ``force`` finds ``force [N]``). Without it:
        the input and output samples, one long record each (or (P, N) arrays, read row after row).
    time : str, optional
        The name of a time column or variable (default: one named like ``t``, ``time [s]``).
    fs, dt : float, optional
        The sampling frequency (Hz) or time (s); default the file's (its time, or a stored
        ``fs`` / ``dt`` / ``Ts``). Without any, periods are in samples.
    reach : int, optional
        Sidebands are counted up to +-reach lines from an excited line (default: what the
        excitation's grid leaves between its lines, (s - 1) // 2 for excited lines on multiples
        of s, at least 1).
    reference : str or array_like, optional
        Read the period where this channel repeats instead of the input (with ``path`` its
        name, else its samples): the loop's external periodic excitation of a record taken under
        feedback, where the input also holds the loop's response to the disturbance, which does
        not repeat and can make the input's repeat residue lowest at a multiple of the period
        (METHOD.md section 20). The rest (excitation, transient, lines) is judged on the input.

    Returns
    -------
    Inspection
        ``.summary()`` says what was found, ``.command`` the ``lptv identify`` command to run;
        ``lptv.plots.inspection`` draws it.

    Raises :class:`lptv.channels.FileError` (a ValueError) for a file that cannot be read and
    for a constant (dead) input.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> N, P = 250, 6                                          # 250 samples a period, 6 periods
    >>> k = np.arange(N * P)
    >>> u = sum(np.cos(2 * np.pi * l * k / N + l) for l in (3, 9, 15, 21)) + 0.01 * rng.standard_normal(k.size)
    >>> y = np.convolve(u, [0.5, 0.3, 0.2])[:k.size] + 0.01 * rng.standard_normal(k.size)
    >>> r = lptv.inspect(u=u[100:], y=y[100:], fs=50.0)        # a record that starts mid-period
    >>> r.period_samples, r.period, r.periods, r.leftover, r.lines.tolist()
    (250, 5.0, 5, 150, [3, 9, 15, 21])
    >>> r.command
    'lptv identify arrays --fs 50 --period 5 --trim --lines excited --na NA --nb NB --ka 0 --kb 0'
    """
    fs_in = None
    if fs is not None and dt is not None:
        raise FileError("give the sampling frequency fs or the sampling time dt, not both")
    if fs is not None:
        fs_in = as_float(fs, "fs", minimum=0.0, open_min=True)
    elif dt is not None:
        fs_in = 1.0 / as_float(dt, "dt", minimum=0.0, open_min=True)
    if fs_in is not None and not FS_RANGE[0] <= fs_in <= FS_RANGE[1]:
        raise ValueError(f"{'fs' if fs is not None else 'dt'}: a sampling frequency of {fs_in:g} Hz is outside "
                         f"{FS_RANGE[0]:g} .. {FS_RANGE[1]:g} Hz, where the periods' times and frequencies (w0 = "
                         "2 pi fs / N) would lose their precision or overflow: give it in other units")
    if reach is not None:
        reach = as_int(reach, "reach", minimum=1, maximum=10**6)
    if path is not None:
        p = Path(as_path(path))
        uu, yy, names, fmt, found, stored, kind = _raw_record(p, u, y, time, fs_in is not None)
        source, what = str(path), f"{kind} '{names[0]}'"
        if reference is not None:
            if not isinstance(reference, str):
                raise ValueError(f"reference must be the name of a channel of the file, got {type(reference).__name__}")
            try:
                rr, _, rnames, *_ = _raw_record(p, reference, y, time, fs_in is not None)
            except FileError as e:
                raise FileError(f"reference: {e}") from None
            ref_name = rnames[0]
    else:
        for name, v in (("u", u), ("y", y)):
            if v is None:
                raise ValueError(f"{name} is missing: give a file (path), or the samples u and y")
        uu, yy = (_array(v, name) for v, name in ((u, "u"), (y, "y")))
        for name, v in (("u", uu), ("y", yy)):
            if v.dtype.kind == "c" or v.ndim > 2:
                raise ValueError(f"{name} must be a real record (1-D, or periods x samples), got "
                                 f"{'complex values' if v.dtype.kind == 'c' else f'shape {v.shape}'}")
        uu, yy = uu.astype(float), yy.astype(float)
        stored = uu.shape[1] if uu.ndim == 2 and min(uu.shape) > 1 else None
        uu, yy = uu.ravel(), yy.ravel()
        if uu.size != yy.size:
            raise ValueError(f"u and y must have as many samples, got {uu.size} and {yy.size}")
        names, fmt, found, source, what = ("u", "y"), "arrays", None, "arrays", "the input"
        if reference is not None:
            rr = _array(reference, "reference")
            if rr.dtype.kind == "c" or rr.ndim > 2:
                raise ValueError("reference must be a real record (1-D, or periods x samples), got "
                                 f"{'complex values' if rr.dtype.kind == 'c' else f'shape {rr.shape}'}")
            rr = rr.astype(float).ravel()
            if rr.size != uu.size:
                raise ValueError(f"reference must have as many samples as u, got {rr.size} and {uu.size}")
            ref_name = "reference"
    if reference is None:
        rr, ref_name = uu, None
    for name, v in zip(names, (uu, yy)):
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise FileError(f"{name} contains NaN or inf (sample {bad[0] + 1})")
    if uu.size < 8:
        raise FileError(f"the record holds {uu.size} samples: too few to look for a period")
    if np.ptp(uu) == 0:
        raise FileError(f"{what} (the input) is constant: a dead or disconnected input channel; nothing excites "
                        "the system")
    if ref_name is not None:
        bad = np.flatnonzero(~np.isfinite(rr))
        if bad.size:
            raise FileError(f"the reference '{ref_name}' contains NaN or inf (sample {bad[0] + 1})")
        if np.ptp(rr) == 0:
            raise FileError(f"the reference '{ref_name}' is constant: it cannot show the period")
    file_fs, file_src = found if found is not None else (None, None)
    fs_used, fs_src = (fs_in, None) if fs_in is not None else (file_fs, file_src)
    n = uu.size
    # scale-free: each channel by a power of two (exact) to a largest value between 1/2 and 1,
    # the reported spectra and noise in the record's own units again at the end
    (uu, su), (yy, sy) = (_unit(v, name) for v, name in zip((uu, yy), names))
    rr = uu if ref_name is None else _unit(rr, f"the reference '{ref_name}'")[0]
    L, Lf, r = find_period(rr)
    lags = np.arange(r.size)
    notes = []
    if fs_in is not None and file_fs is not None and not np.isclose(fs_in, file_fs, rtol=1e-6, atol=0):
        notes.append(f"the fs given ({fs_in:g} Hz) contradicts the file's {file_src} ({file_fs:g} Hz)")
    if np.ptp(yy) == 0:
        notes.append(f"the output '{names[1]}' is constant: a dead output channel (or a sensor stuck at one value)")
    common = dict(source=source, format=fmt, input=names[0], output=names[1], samples=n, fs=fs_used,
                  fs_source=fs_src, file_fs=file_fs, file_fs_source=file_src, fs_given=fs_in is not None,
                  lags=lags, repeat=r, stored_period=stored, reference=ref_name)
    if L is None:
        lo = np.flatnonzero(r[1:] >= 1.0)
        rr = float(np.min(r[lo[0] + 1:])) if lo.size and lo[0] + 1 < r.size else float(np.min(r[1:])) if r.size > 1 else 1.0
        return Inspection(**common, repeats=False, input_period_samples=None, input_period_exact=None, period_samples=None,
                          repeat_ratio=rr, output_repeats=False, output_repeat_ratio=np.nan, periods=0, leftover=0,
                          transient_ratios=np.zeros(0), transient_limit=np.nan, transient_periods=0,
                          transient=TransientSkip(0, 0, math.nan, 0.0, True),
                          lines=np.zeros(0, int), spacing=0, weak_input_lines=np.zeros(0, int),
                          input_snr_db=np.zeros(0), output_snr_db=np.zeros(0), reach=0, classes=(),
                          time_variation_reach=0, threshold=np.nan, spectrum_lines=np.zeros(0, int),
                          U=np.zeros(0, complex), Y=np.zeros(0, complex), noise_u=np.zeros(0), noise_y=np.zeros(0),
                          notes=tuple(notes))
    # the output: with the input, or every m of its periods (judged past the first quarter)
    P_u = n // L
    left_u = n - P_u * L
    m, r_y = _output_multiple(yy, L, Lf, left_u, left_u + L * (P_u // 4)) if np.ptp(yy) > 0 else (1, 1.0)
    N = int(round(m * Lf))
    P = n // N
    left = n - P * N
    if abs(Lf - L) > WHOLE:
        notes.append(f"the period is about {Lf:.2f} samples, not a whole number: the generator's clock and the "
                     "sampling's are not synchronised, and the periods' spectra leak (resample, or synchronise them)")
    if stored is not None and stored != N and not (stored % N == 0):
        notes.append(f"the file's arrays hold periods of {stored} samples, but the record repeats every {N}: "
                     "store it as one long record (or as periods of the right length)")
    us, ys = uu[left:].reshape(P, N), yy[left:].reshape(P, N)
    drifts = [_drift(xs) for xs in (us, ys)]
    for name, drift, scale in zip(names, drifts, (su, sy)):
        if drift is not None:
            notes.append(f"'{name}' drifts by {drift[0] / scale:.3g} per period ({drift[1]:.0f} standard errors): a trend the "
                         "periods do not share; take it out (--detrend), or the spectra's lowest lines carry it "
                         "(it is taken out here)")
    if drifts[0] is not None:
        us = _detrended(uu[left:]).reshape(P, N)
    if drifts[1] is not None:
        ys = _detrended(yy[left:]).reshape(P, N)
    if P >= 3:
        n_ref = max(2, (P + 1) // 2)
        ratios = np.maximum(_transient(us, n_ref), _transient(ys, n_ref))
        limit = max(1.0 + SIGMAS * math.sqrt(2.0 / N + 2.0 / (N * (n_ref - 1))), 1.5)
        tr = transient_skip(ratios, limit, P, n_ref)
    else:
        ratios, limit, tr = np.zeros(0), np.nan, TransientSkip(0, 0, math.nan, 0.0, True)
    skip = tr.periods
    if not tr.enough:
        notes.append(f"the start-up transient lasts too long for this record: dropping {skip} of its {P} periods "
                     f"still leaves {tr.left:.2g} times the noise power of the kept periods' mean in it (at most "
                     f"{TRANSIENT_LEFT:g} leaves no bias): record more periods, or identify it as one record "
                     "with its transient (--one-record)")
    Ps = P - skip
    lines, U, varU = _spectra(us[skip:])
    _, Y, varY = _spectra(ys[skip:])
    nu, dof = _pooled(varU, Ps)
    ny, _ = _pooled(varY, Ps)
    t = _threshold(lines.size, dof)
    with np.errstate(divide="ignore", invalid="ignore"):
        zu = np.where(nu > 0, np.abs(U) ** 2 / (nu / Ps), np.where(np.abs(U) > 0, np.inf, 0.0))
        zy = np.where(ny > 0, np.abs(Y) ** 2 / (ny / Ps), np.where(np.abs(Y) > 0, np.inf, 0.0))
    # a noise-free record: lines above the rounding of the largest one
    zu = np.where(np.abs(U) ** 2 <= 1e-20 * np.max(np.abs(U) ** 2), 0.0, zu)
    zy = np.where(np.abs(Y) ** 2 <= 1e-20 * max(np.max(np.abs(Y) ** 2), 1e-300), 0.0, zy)
    det = lines[zu > t]
    if det.size:
        pw = np.abs(U[det - 1]) ** 2
        strong = pw >= np.median(pw) * 10 ** (-WEAK_INPUT_DB / 10)
        excited, weak = det[strong], det[~strong]
    else:
        excited, weak = det, det
    if excited.size:
        s = int(np.gcd.reduce(excited))
        K = reach if reach is not None else max(1, (s - 1) // 2)
        y_exc = float(np.mean(np.abs(Y[excited - 1]) ** 2))
        classes, k_tv = _classify(lines, excited, weak, s, K, zy, np.abs(Y) ** 2, ny / Ps, y_exc, t)
    else:
        s, K, classes, k_tv = 0, reach or 1, (), 0
    with np.errstate(divide="ignore"):
        snr_u = 10 * np.log10(zu[excited - 1]) if excited.size else np.zeros(0)
        snr_y = 10 * np.log10(zy[excited - 1]) if excited.size else np.zeros(0)
    return Inspection(**common, repeats=True, input_period_samples=L, input_period_exact=Lf, period_samples=N,
                      repeat_ratio=_residue_at(rr, L),
                      input_repeat_ratio=_residue_at(uu, L) if ref_name is not None else math.nan,
                      output_repeats=bool(r_y <= OUTPUT_REPEAT_LIMIT),
                      output_repeat_ratio=float(r_y), periods=P, leftover=left, transient_ratios=ratios,
                      transient_limit=float(limit), transient_periods=skip, transient=tr, lines=excited, spacing=s,
                      weak_input_lines=weak, input_snr_db=snr_u, output_snr_db=snr_y, reach=K, classes=classes,
                      time_variation_reach=k_tv, threshold=t, spectrum_lines=lines, U=U / su, Y=Y / sy,
                      noise_u=nu / Ps / su ** 2, noise_y=ny / Ps / sy ** 2, notes=tuple(notes))


FS_RANGE = (1e-100, 1e100)
"""The sampling frequencies (Hz) :func:`inspect` takes."""
AMPLITUDE_RANGE = (1e-150, 1e150)
"""The largest |value| of a channel :func:`inspect` takes: its squares (the noise's variances)
stay within double precision's range."""


def _unit(x, name):
    """(x scaled by a power of two to a largest |value| in [1/2, 1), the scale); FileError for a
    channel whose largest |value| is outside AMPLITUDE_RANGE (0 is left as it is)."""
    top = float(np.max(np.abs(x)))
    if top == 0.0:
        return x, 1.0
    if not AMPLITUDE_RANGE[0] <= top <= AMPLITUDE_RANGE[1]:
        raise FileError(f"{name} reaches |{top:.3g}|: outside {AMPLITUDE_RANGE[0]:g} .. {AMPLITUDE_RANGE[1]:g}, where "
                        "the squares of its values (the noise's variances) leave double precision's range: "
                        "rescale the record (give it in other units)")
    scale = math.ldexp(1.0, -math.frexp(top)[1])
    return x * scale, scale
