"""Reading periodic measurements from files: CSV, NPZ and MATLAB (v4/v5/v7 and v7.3).

- CSV: a header row naming the columns (by default ``u`` and ``y``; other columns are ignored),
  one sample per row, the periods one after another.
- NPZ: arrays (by default ``u`` and ``y``) of shape (P, N) or one long vector each, optionally
  a scalar ``w0`` (rad/s).
- MATLAB ``.mat`` (v4/v5/v7 via scipy, v7.3 via h5py): variables as in NPZ, P x N or vectors.

The channels are named with ``u=`` / ``y=`` (``--input`` / ``--output``). A long record is split
into periods by ``periods`` or by the sampling frequency and the period; the sampling frequency
is given (``fs=`` / ``dt=``) or read from the file: a time column or variable (``t``, ``time``,
``time [s]`` ..., or ``time=``), checked uniform, or a stored scalar ``fs``, ``dt`` or ``Ts``
(:mod:`lptv.records.channels`).

Examples
--------
>>> import numpy as np, tempfile, os, lptv
>>> d = tempfile.mkdtemp(); path = os.path.join(d, "m.npz")
>>> np.savez(path, u=np.ones((2, 8)), y=np.zeros((2, 8)), w0=0.5)
>>> m = lptv.read_measurements(path)
>>> m.u.shape, m.w0, m.format
((2, 8), 0.5, 'NPZ')
"""
from __future__ import annotations

import contextvars

import csv
import io
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional, Tuple

import numpy as np

from .._validate import as_bool, as_float, as_int, as_optional, as_path, looks_transposed, not_regular
from .check import RecordCheck, RecordWarning, check_record, detrended  # noqa: F401 - lptv.records.measurements.*
from .budget import _bytes, _within_budget, memory_budget
from .channels import (DT_NAMES, FS_NAMES, FileError, auto_time, channel_name, distinct_channels, find,
                       fs_from_time, listing, read_several, several_channels, stored_fs, time_unit)

FORMATS = {".csv": "CSV", ".npz": "NPZ", ".mat": "MAT"}
_MATLAB_NUMERIC = {"double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                   "int64", "uint64"}
__all__ = ["FileError", "Measurements", "RecordCheck", "RecordWarning", "check_record", "memory_budget",
           "read_measurements", "samples_per_period"]


def _one_line(e):
    return " ".join(str(e).split()) or type(e).__name__


@dataclass(frozen=True)
class Measurements:
    """What a measurement file holds: P periods of N samples of u and y, shape (P, N); or, read
    with ``realisations=True`` from 3-D variables, M random-phase realisations of P periods
    each, shape (M, P, N) (see :attr:`realisations`)."""

    u: np.ndarray
    y: np.ndarray
    w0: Optional[float]
    """The fundamental (rad/s): the file's ``w0``, else ``2 pi / period`` when ``period`` was given."""
    format: str
    fs: Optional[float] = None
    """The sampling frequency (Hz) when it was given or read from the file; None otherwise."""
    trimmed: int = 0
    """Samples dropped at the start of a long record to keep whole periods (``trim=True``)."""
    skipped: int = 0
    """Whole periods dropped at the start (``skip_periods``)."""
    input: str = "u"
    """The file's name of the input channel (column, array or variable); several inputs: a tuple."""
    output: str = "y"
    """The file's name of the output channel; several outputs: a tuple."""
    fs_source: Optional[str] = None
    """Where fs came from: None when given (or unknown), else e.g. "column 'time'" or "variable 'fs'"."""

    @property
    def realisations(self) -> Optional[int]:
        """M for a record of realisations (``u`` of shape (M, P, N)), None for periods alone."""
        return int(self.u.shape[0]) if self.u.ndim == 3 else None


@dataclass
class _Raw:
    """What a reader found: the two channels as stored, the file's w0 and sampling frequency."""

    u: np.ndarray
    y: np.ndarray
    w0: Optional[float]
    found: Callable[[], Optional[Tuple[float, str]]]
    """(fs, where from) of the file itself, or None: computed when asked (an fs given overrides it)."""
    kind: str                    # "column" or "variable"
    names: Tuple[str, str]
    line_of: Optional[list] = None


# ------------------------------------------------------------------------------ reading

def read_measurements(path, periods: Optional[int] = None, *, fs: Optional[float] = None,
                      dt: Optional[float] = None, period: Optional[float] = None,
                      trim: bool = False, skip_periods: int = 0, u: Optional[str] = None,
                      y: Optional[str] = None, time: Optional[str] = None,
                      realisations: bool = False, detrend: bool = False) -> Measurements:
    """Read u, y (shape (P, N)) and an optional w0 from a CSV, NPZ or MATLAB file.

    Parameters
    ----------
    path : str or Path
    periods : int, optional
        How many periods a record stored as one long vector holds (CSV, vectors in NPZ/MAT).
    fs, dt : float, optional
        The sampling frequency in Hz, or the sampling time ``dt = 1 / fs`` in s (the name
        python-control uses). This is how the data were recorded; it does not make the model
        discrete. With the period (``period`` or the file's ``w0``) it gives the samples per
        period ``N = fs * period``, which must be an integer: a long record is then split into
        whole periods (``periods`` is not needed, and is checked if given), and a (P, N) array
        must have that N. Without ``fs``, ``dt`` and ``periods``, the file's own sampling
        frequency is used: its time column or variable (``time``), checked uniformly sampled,
        or a stored scalar ``fs`` (Hz), ``dt`` or ``Ts`` (s); ``Measurements.fs_source`` says which.
    period : float, optional
        The period in s (used with ``fs``/``dt``; else the file's ``w0`` gives it).
    trim : bool
        A long record that does not hold a whole number of periods has its first samples
        dropped (the record's end is the closest to steady state); without ``trim`` it is an
        error that says how many samples to drop.
    skip_periods : int
        Drop this many whole periods at the start (a start-up transient).
    u, y : str or list of str, optional
        The names of the input and output channels: CSV columns (matched up to case), NPZ
        arrays or MAT variables (default ``'u'`` and ``'y'``). Several inputs or outputs
        (METHOD.md section 19): a list of names, e.g. ``u=["f1", "f2"], y=["x1", "x2"]``; then
        ``u`` of the result has shape (P, N, nu) and ``y`` (P, N, ny), and ``input`` and
        ``output`` are tuples of the file's names (one name, or a list of one, stays 2-D).
    time : str, optional
        The name of a time column or variable in s (default: one named ``t`` or ``time``,
        also with a unit, ``time [s]``, ``t_ms``).
    realisations : bool
        Accept NPZ/MAT variables of shape (M, P, N): M >= 2 realisations (random-phase
        multisines of one amplitude spectrum, for :func:`lptv.distortion`), each of P periods
        (each realisation may also be one long vector, shape (M, samples), split as above).
        ``u`` and ``y`` of the result then have shape (M, P, N); ``skip_periods`` drops periods
        of every realisation. Without it such variables are refused, naming this option.
    detrend : bool
        Take a linear drift out of each channel (of each realisation): the least-squares trend
        across the periods with the mean period free (:func:`check_record` reports a drift), so
        that each period's shape is kept. Done after ``skip_periods``.

    Raises :class:`FileError` with a message naming the problem (not the file).

    Examples
    --------
    >>> import numpy as np, tempfile, os, lptv
    >>> d = tempfile.mkdtemp(); path = os.path.join(d, "long.npz")
    >>> np.savez(path, u=np.arange(1050.0), y=np.arange(1050.0))    # 10.5 periods of 100 samples
    >>> lptv.read_measurements(path, fs=100.0, period=1.0)
    Traceback (most recent call last):
    ...
    lptv.records.channels.FileError: variable 'u' has 1050 samples, 10.5 periods of 100 (fs 100 Hz x period 1 s): drop 50 samples to keep 10 whole periods (or trim=True / --trim)
    >>> m = lptv.read_measurements(path, fs=100.0, period=1.0, trim=True, skip_periods=1)
    >>> m.u.shape, m.trimmed, m.skipped
    ((9, 100), 50, 1)
    >>> t = np.arange(1000) / 100.0                                   # a time column at 100 Hz
    >>> np.savetxt(os.path.join(d, "r.csv"), np.c_[t, t, t], delimiter=",", header="time,force,disp",
    ...            comments="")
    >>> m = lptv.read_measurements(os.path.join(d, "r.csv"), u="force", y="disp", period=1.0)
    >>> m.u.shape, m.fs, m.fs_source, m.input
    ((10, 100), 100.0, "column 'time'", 'force')
    """
    several = several_channels(u, y)
    if several is not None:
        return read_several(read_measurements, path, *several, dict(
            periods=periods, fs=fs, dt=dt, period=period, trim=trim, skip_periods=skip_periods, time=time,
            realisations=realisations, detrend=detrend))
    path = Path(as_path(path))
    o = read_options(periods=periods, fs=fs, dt=dt, period=period, trim=trim, skip_periods=skip_periods,
                     u=u, y=y, time=time, detrend=detrend)
    periods, fs, dt, period, trim, skip_periods = (o[k] for k in ("periods", "fs", "dt", "period", "trim",
                                                                  "skip_periods"))
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
    fs = _sampling(fs, dt)
    if fmt == "CSV":
        raw = _read_csv(path, names)
    elif fmt == "NPZ":
        raw = _read_npz(path, names)
    else:
        raw, fmt = _read_mat(path, names)
    source = None
    found = raw.found() if fs is None and periods is None else None
    if found is not None:
        fs, source = found            # the file's own sampling frequency, when nothing overrides it
    split = _Split(periods, fs, period, trim, source)
    w0 = raw.w0
    if fs is not None and w0 is not None:
        if split.period is None:
            split.period = 2 * np.pi / w0
        elif not np.isclose(2 * np.pi / w0, split.period, rtol=1e-9, atol=0):
            raise FileError(f"the period {split.period:.10g} s disagrees with the file's w0 = {w0:.10g} "
                            f"rad/s (period {2 * np.pi / w0:.10g} s)")
    if raw.kind == "column":
        u_p, y_p = _csv_periods(raw, split)
    elif _is_realisations(raw):
        if not realisations:
            raise FileError(f"variable '{raw.names[0]}' has shape {_shape(np.asarray(raw.u))}: M realisations "
                            "x P periods x N samples, read by lptv identify FILE given alone (in Python: "
                            "lptv.read_measurements(..., realisations=True) and lptv.distortion)")
        u_p = _realisations(raw.names[0], raw.u, split, "u")
        y_p = _realisations(raw.names[1], raw.y, split, "y")
    else:
        u_p = _as_periods(raw.names[0], raw.u, split, "u")
        y_p = _as_periods(raw.names[1], raw.y, split, "y")
    if fs is not None and split.period is None and source is None:
        raise FileError("--fs needs the period: give --period (s) or --w0 (rad/s), or store w0 in the file")
    if u_p.shape != y_p.shape:
        raise FileError(f"u and y differ in shape: u is {_shape(u_p)} and y is {_shape(y_p)} "
                        + ("(realisations x periods x samples)" if u_p.ndim == 3 else "(periods x samples)"))
    if u_p.shape[-2] < 2:
        raise FileError("the record holds only 1 period" + (" per realisation" if u_p.ndim == 3 else "")
                        + "; the noise model needs at least 2")
    if skip_periods:
        P = u_p.shape[-2]
        if P - skip_periods < 2:
            left = (f"leaves {P - skip_periods} of the record's {P} periods" if skip_periods < P else
                    f"drops {'all' if skip_periods == P else 'more than all'} of the record's {P} periods")
            raise FileError(f"--skip-periods {skip_periods} {left}; the noise model needs at least 2 "
                            f"(--skip-periods {max(P - 2, 0)} at most)")
        u_p, y_p = u_p[..., skip_periods:, :], y_p[..., skip_periods:, :]
    if o["detrend"]:
        u_p, y_p = (np.stack([detrended(r) for r in x]) if x.ndim == 3 else detrended(x) for x in (u_p, y_p))
    if w0 is None and split.period is not None:
        w0 = 2 * np.pi / split.period      # the period given
    return Measurements(u=u_p, y=y_p, w0=w0, format=fmt, fs=fs, trimmed=split.trimmed, skipped=skip_periods,
                        input=raw.names[0], output=raw.names[1], fs_source=source)


_INPUT_ONLY = contextvars.ContextVar("lptv_read_input_only", default=False)
"""True inside :func:`read_input`: the output's place is the input's, not a second channel."""


def read_input(path, *, u=None, **options) -> "Measurements":
    """The input channel alone, read as :func:`read_measurements` reads a record (its ``y`` is
    its ``u``): a record for a model's prediction (``lptv simulate``) holds no output, and a
    time column is read this way too. :func:`read_measurements` refuses one channel in both roles."""
    token = _INPUT_ONLY.set(True)
    try:
        return read_measurements(path, u=u, y=u, **options)
    finally:
        _INPUT_ONLY.reset(token)


def read_options(**kw) -> dict:
    """The keyword arguments of :func:`read_measurements` (all but the path), checked and
    converted: FileError naming the first bad one (also for a name that is not one of them)."""
    known = ("periods", "fs", "dt", "period", "trim", "skip_periods", "u", "y", "time", "detrend")
    for k in kw:
        if k not in known:
            raise FileError(f"{k!r} is not an argument of lptv.read_measurements (one of {', '.join(known)})")
    o = dict(dict.fromkeys(known), trim=False, skip_periods=0, detrend=False)
    o.update(kw)
    return dict(
        periods=as_optional(o["periods"], _option, as_int, "--periods", minimum=1),
        fs=as_optional(o["fs"], _option, as_float, "--fs", minimum=0.0, open_min=True, what="a positive number"),
        dt=as_optional(o["dt"], _option, as_float, "--dt", minimum=0.0, open_min=True, what="a positive number"),
        period=as_optional(o["period"], _option, as_float, "--period", minimum=0.0, open_min=True,
                           what="a positive number"),
        trim=_option(o["trim"], as_bool, "--trim"), skip_periods=_option(o["skip_periods"], as_int, "--skip-periods"),
        detrend=_option(o["detrend"], as_bool, "--detrend"),
        u=channel_name(o["u"], "u"), y=channel_name(o["y"], "y"), time=channel_name(o["time"], "time"))


def _option(x, convert, name, **kw):
    """An argument through a _validate conversion, its ValueError as a FileError."""
    try:
        return convert(x, name, **kw)
    except ValueError as e:
        raise FileError(str(e)) from None


def _sampling(fs, dt):
    """The sampling frequency from fs (Hz) or dt (s), or None."""
    if fs is not None and dt is not None:
        raise FileError("give the sampling frequency --fs or the sampling time --dt, not both")
    for name, v in (("--fs", fs), ("--dt", dt)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise FileError(f"{name} must be a positive number, got {v!r}")
    return fs if dt is None else 1.0 / dt


def samples_per_period(fs: float, period: float, what: str = "fs x period") -> int:
    """``N = fs * period`` as an integer, or :class:`FileError` when it is not one.

    >>> from lptv.records.measurements import samples_per_period
    >>> samples_per_period(100.0, 10.0)
    1000
    """
    n = fs * period
    N = int(round(n))
    if N < 1 or abs(n - N) > 1e-6 * max(n, 1.0):
        raise FileError(f"{what} gives {n:.8g} samples per period, not a whole number: "
                        "check the sampling frequency and the period")
    return N


class _Split:
    """How a long record becomes periods: by the stated count, by fs and the period, or both."""

    def __init__(self, periods, fs, period, trim, source=None):
        self.periods, self.fs, self.period, self.trim = periods, fs, period, bool(trim)
        self.source = source
        self.trimmed = 0

    def desc(self):
        return f"fs {self.fs:g} Hz" + (f" from {self.source}" if self.source else "") + f" x period {self.period:g} s"

    def n(self):
        return None if self.fs is None or self.period is None else samples_per_period(
            self.fs, self.period, self.desc())

    def missing(self):
        """What to give when a vector cannot be split."""
        if self.fs is not None:
            return f"the period: --period (s) or --w0 (rad/s) with fs {self.fs:g} Hz from {self.source}, or --periods"
        return "--periods, the number of periods it holds (or --fs with the period)"

    def vector(self, what, v):
        N = self.n()
        if N is None:
            if self.periods is None:
                return None
            return _split_periods(what, v, self.periods)
        P, r = divmod(v.size, N)
        desc = self.desc()
        if P < 1:
            raise FileError(f"{what} has {v.size} samples, less than one period of {N} ({desc})")
        if self.periods is not None and v.size != self.periods * N:
            raise FileError(f"{what} has {v.size} samples = {v.size / N:.6g} periods of {N} ({desc}), "
                            f"but --periods says {self.periods} ({self.periods * N} samples)")
        if r:
            if not self.trim:
                raise FileError(f"{what} has {v.size} samples, {v.size / N:.6g} periods of {N} ({desc}): "
                                f"drop {r} samples to keep {P} whole periods (or trim=True / --trim)")
            self.trimmed = r
            v = v[r:]
        return v.reshape(P, N)

    def check_shape(self, name, a):
        N = self.n()
        if N is not None and a.shape[1] != N:
            raise FileError(f"variable '{name}' has {a.shape[1]} samples per period, but {self.desc()} gives "
                            f"{N}: the sampling frequency, the period or the record is wrong")
        return a


def _shape(a):
    return " x ".join(str(n) for n in a.shape)


_CSV_PARSED: dict = {}
"""The last CSV records parsed in this process, by path, names and content: `lptv identify FILE`
reads its file twice (the inspection, then the fit), and the parse is most of a read."""


def _read_csv(path, names):
    """_parse_csv, or a copy of its result for a file of the same bytes read before."""
    import dataclasses
    import hashlib

    size = path.stat().st_size
    if 4 * size > memory_budget() or size > 2**24:
        return _parse_csv(path, names)          # refused there, with the sizes; or not kept (16 MB of text)
    key = (str(path.resolve()), size, hashlib.blake2b(path.read_bytes(), digest_size=16).digest(),
           repr(names["u"]), repr(names["y"]), repr(names["time"]), bool(_INPUT_ONLY.get()))
    raw = _CSV_PARSED.get(key)
    if raw is None:
        raw = _parse_csv(path, names)
        _CSV_PARSED.clear()                     # one record kept: the one a command reads twice
        _CSV_PARSED[key] = raw
    return dataclasses.replace(raw, u=raw.u.copy(), y=raw.y.copy(),
                               line_of=None if raw.line_of is None else list(raw.line_of))


def _parse_csv(path, names):
    text = _csv_text(path)
    delimiter = _delimiter(text)
    rows = _Rows(text, delimiter)
    header = next((r for r in rows if any(c.strip() for c in r)), None)
    if header is None:
        raise FileError("the file is empty")
    if all(_is_number(c) for c in header):
        raise FileError("the first row must be a header naming the columns u and y; it holds numbers")
    heads = [c.strip() for c in header]
    shown = "the header has " + ", ".join(repr(c) for c in heads)
    cols = {}
    for role in ("u", "y"):
        name = find(names[role], heads, role, "column", shown)
        if sum(h.lower() == name.lower() for h in heads) > 1:
            raise FileError(f"column '{name}' appears {sum(h.lower() == name.lower() for h in heads)} times "
                            "in the header")
        cols[role] = heads.index(name)
    chosen = (heads[cols["u"]], heads[cols["y"]])
    if not _INPUT_ONLY.get():
        distinct_channels([("u", chosen[0]), ("y", chosen[1])], [("u", names["u"]), ("y", names["y"])], "column")
    t_name = find(names["time"], heads, "time", "column", shown) if names["time"] else auto_time(heads, chosen)
    if t_name is not None and t_name not in chosen:
        cols["time"] = heads.index(t_name)
    values = {k: [] for k in cols}
    line_of = []
    t_ok = True
    for row in rows:
        if not any(c.strip() for c in row):
            continue
        if len(row) != len(header):
            raise FileError(f"line {rows.line_num}: {len(row)} field(s), the header has {len(header)}"
                            + _field_hint(row, header, delimiter))
        for role, i in cols.items():
            cell = row[i].strip()
            try:
                values[role].append(_number(cell, delimiter))
            except ValueError:
                if role == "time" and not names["time"]:
                    t_ok = False     # a column named like a time that holds no numbers: not used
                    continue
                what = "is empty" if not cell else f"'{cell}' is not a number"
                raise FileError(f"line {rows.line_num}: column '{heads[i]}' {what}") from None
        line_of.append(rows.line_num)
    if not line_of:
        raise FileError("no data rows after the header")
    for role in ("u", "y"):
        v = np.array(values[role])
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise FileError(f"line {line_of[bad[0]]}: column '{heads[cols[role]]}' is NaN or inf")
    def found():
        if "time" not in cols or not t_ok:
            return None
        scale = time_unit(t_name) or 1.0
        return fs_from_time(values["time"], f"column '{t_name}'", scale, line_of), f"column '{t_name}'"

    return _Raw(np.array(values["u"]), np.array(values["y"]), None, found, "column", chosen, line_of)


def _csv_text(path):
    """A CSV file's text: UTF-8 (with or without a byte-order mark) or UTF-16 with its mark;
    UTF-16 without a mark, or bytes that are no text, named as such."""
    # a CSV's values take, once parsed, a few times their text (a Python float and its list slot)
    size = path.stat().st_size
    if 4 * size > memory_budget():
        raise FileError(f"the CSV file holds {_bytes(size)}, more than a quarter of lptv's memory budget of "
                        f"{_bytes(memory_budget())} (half the machine's memory, or LPTV_MEMORY_BUDGET): store "
                        "the record as NPZ or MAT (read without the text's overhead), or cut it")
    data = path.read_bytes()
    head = data[:4096]
    if head[:2] not in (b"\xff\xfe", b"\xfe\xff") and b"\x00" in head:
        # NUL bytes, which no UTF-8 text holds (though they decode): UTF-16 has one in every
        # other byte of ASCII text
        if head[1::2].count(0) > 0.4 * len(head[1::2]) or head[0::2].count(0) > 0.4 * len(head[0::2]):
            raise FileError("looks like UTF-16 text without a byte-order mark: save it as UTF-8 "
                            "(or UTF-16 with its byte-order mark)")
        raise FileError("not a text file (it holds NUL bytes; is it really CSV?)")
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        try:
            text = data.decode("utf-16")
        except UnicodeDecodeError:
            text = None
        if text is None or not text[1:].replace("\n", "").replace("\r", "").replace("\t", "").isprintable():
            raise FileError("not a text file (it starts with a UTF-16 byte-order mark, but what follows is "
                            "not UTF-16 text; is it really CSV?)")
        return text.lstrip("\ufeff")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise FileError("not a text file in UTF-8 or UTF-16 (is it really CSV?)") from None


class _Rows:
    """csv.reader over the text, its errors (a field over the csv module's limit, a NUL byte)
    as a FileError naming the line."""

    def __init__(self, text, delimiter):
        self._rows = csv.reader(io.StringIO(text), delimiter=delimiter)

    @property
    def line_num(self):
        return self._rows.line_num

    def __iter__(self):
        return self

    def __next__(self):
        try:
            return next(self._rows)
        except csv.Error as e:
            hint = (": a quote that is never closed, or not a CSV file" if "field larger" in str(e) else "")
            raise FileError(f"line {self._rows.line_num}: {_one_line(e)}{hint}") from None


def _csv_periods(raw, split):
    if split.periods is None and split.n() is None:
        if split.fs is not None:
            raise FileError(f"the period is needed to split the {raw.u.size} samples (fs {split.fs:g} Hz from "
                            f"{split.source}): give --period (s) or --w0 (rad/s), or --periods")
        raise FileError(f"--periods is required for a CSV record (how many periods its "
                        f"{raw.u.size} samples hold), or --fs with --period, or a time column")
    what_u, what_y = (f"column '{n}'" for n in raw.names)
    u = split.vector(what_u, raw.u)
    _not_transposed(what_u, u, raw.u, split)
    y = split.vector(what_y, raw.y)
    _not_transposed(what_y, y, raw.y, split)     # a constant input cannot tell: the output can
    return u, y


def _not_transposed(what, a, samples, split):
    """A record split into more periods than samples per period that does not repeat, while the
    other reading of the same numbers does: the counts are exchanged (or the array transposed)."""
    P, N = a.shape
    if P <= N:
        return
    if samples is None:      # a 2-D variable: the other reading is its transpose
        other, how = a.T, f"the array looks transposed: store it as {N} x {P} (periods x samples)"
    else:                     # a vector split into P periods: the other reading is N periods
        other = samples[split.trimmed:].reshape(N, P)
        how = (f"the record looks transposed (the counts exchanged): it repeats as {N} periods of {P} "
               "samples; --periods is the number of periods")
    if looks_transposed(a, other):
        raise FileError(f"{what} read as {P} periods of {N} samples does not repeat from period to period; {how}")


def _number(cell, delimiter):
    """A cell's value; with ';' or tabs between the columns a decimal comma is read too
    ('1,5' is 1.5, as the locales that write it separate their columns so)."""
    try:
        return float(cell)
    except ValueError:
        if delimiter != "," and cell.count(",") == 1 and "." not in cell:
            return float(cell.replace(",", "."))
        raise


def _field_hint(row, header, delimiter):
    """Why a row's field count may differ from the header's: decimal commas in a comma-separated
    file, another delimiter than the header's, or a missing or extra value."""
    if delimiter == "," and len(row) > len(header):
        return (" (decimal commas? '1,5' in a comma-separated file reads as two fields: export with a "
                "decimal point, or separate the columns with ';' or a tab)")
    if len(row) == 1 and len(header) > 1 and any(c in row[0] for c in ",;\t" if c != delimiter):
        return f" (the header is separated by {_DELIMITERS[delimiter]}, this row by another delimiter)"
    return " (a value missing or one too many: every row must have one value per column)"


_DELIMITERS = {",": "commas", ";": "semicolons", "\t": "tabs"}


def _delimiter(text):
    """Comma, semicolon (locales with a decimal comma) or tab, whichever the header uses."""
    first = next((ln for ln in text.splitlines() if ln.strip()), "")
    return next((c for c in ",;\t" if c in first), ",")


def _is_number(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def _split_periods(what, v, periods):
    if v.size % periods:
        raise FileError(f"{what} has {v.size} samples, not a whole number of periods "
                        f"({v.size} / {periods} = {v.size / periods:.6g})")
    return v.reshape(periods, -1)


def _is_realisations(raw) -> bool:
    """The input variable is 3-D: (M, P, N) realisations x periods x samples."""
    return np.ndim(raw.u) == 3


def _realisations(name, a, split, role):
    """(M, P, N) from a 3-D variable: each realisation read as a (P, N) record."""
    a = np.asarray(a)
    if a.shape[0] < 2:
        raise FileError(f"variable '{name}' holds {a.shape[0]} realisation; at least 2 are needed "
                        "to separate the nonlinear distortion from the noise")
    parts = [_as_periods(f"{name}[{m}]", a[m], split, role) for m in range(a.shape[0])]
    shapes = {p.shape for p in parts}
    if len(shapes) > 1:
        raise FileError(f"variable '{name}': its realisations differ in shape "
                        f"({', '.join(_shape(p) for p in parts[:3])}...)")
    return np.stack(parts)


def _as_periods(name, a, split, role):
    """A (P, N) float array from a file variable; vectors are split with --periods or fs."""
    periods = split.periods
    what = f"variable '{name}'"
    a = np.asarray(a)
    if a.dtype.kind == "c":
        raise FileError(f"{what} is complex; a measured time signal is real")
    if a.dtype.kind not in "fiu":
        raise FileError(f"{what} is not a numeric array (dtype {a.dtype})")
    if a.size == 0:
        raise FileError(f"{what} is empty")
    if a.ndim > 2:
        raise FileError(f"{what} has {a.ndim} dimensions ({_shape(a)}); expected periods x samples")
    a = a.astype(float)
    if a.ndim < 2 or 1 in a.shape:
        v = split.vector(what, a.ravel())
        if v is None:
            raise FileError(f"{what} is a vector of {a.size} samples: give {split.missing()}")
        if np.all(np.isfinite(v)):          # either channel: a constant input cannot tell
            _not_transposed(what, v, a.ravel(), split)
        a = v
    else:
        if np.all(np.isfinite(a)) and (periods is None or a.shape[0] == periods):
            _not_transposed(what, a, None, split)
        if periods is not None and a.shape[0] != periods:
            raise FileError(f"{what} holds {a.shape[0]} periods ({_shape(a)}) but --periods says {periods}")
        a = split.check_shape(name, a)
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        p, n = bad[0] + 1
        raise FileError(f"{what} is NaN or inf at period {p}, sample {n} (counting from 1)")
    return a


def _file_w0(a):
    if a is None:
        return None
    a = np.asarray(a)
    if a.dtype.kind not in "fiu" or a.size != 1 or not np.isfinite(a.item()) or a.item() <= 0:
        raise FileError("variable 'w0' must be a positive scalar (rad/s)")
    return float(a.item())


def _wanted(names, available, kind, shown):
    """The file's names of u, y and (if any) the time, and the sampling variables present."""
    u = find(names["u"], available, "u", kind, shown)
    y = find(names["y"], available, "y", kind, shown)
    if not _INPUT_ONLY.get():
        distinct_channels([("u", u), ("y", y)], [("u", names["u"]), ("y", names["y"])], kind)
    t = find(names["time"], available, "time", kind, shown) if names["time"] else auto_time(available, (u, y))
    extra = [n for n in FS_NAMES + DT_NAMES + ("w0",) if n in available and n not in (u, y)]
    return u, y, t, extra


def _raw_of(arrays, names, t):
    """_Raw from the loaded arrays of an NPZ or MAT file."""
    return _Raw(arrays[names[0]], arrays[names[1]], _file_w0(arrays.get("w0")),
                lambda: _file_fs(arrays, names, t), "variable", names)


def _file_fs(arrays, names, t):
    """(fs, where from) of stored fs / dt / Ts scalars and a time vector, checked to agree."""
    found = stored_fs({k: v for k, v in arrays.items() if k not in names})
    if t is not None:
        tv = np.asarray(arrays[t])
        n = np.asarray(arrays[names[0]]).size
        if tv.dtype.kind not in "fiu" or tv.size != n:
            if t in names or tv.size == 1:
                tv = None
            else:
                raise FileError(f"variable '{t}' (the time) must hold one number per sample ({n}), "
                                f"got {tv.size} of dtype {tv.dtype}")
        if tv is not None:
            fs_t = fs_from_time(tv, f"variable '{t}'", time_unit(t) or 1.0)
            if found is not None and not np.isclose(found[0], fs_t, rtol=1e-6, atol=0):
                raise FileError(f"{found[1]} says fs {found[0]:.10g} Hz but variable '{t}' is sampled at "
                                f"{fs_t:.10g} Hz")
            found = found or (fs_t, f"variable '{t}'")
    return found


def _npz_sizes(path, members):
    """{array name: number of values} from the headers of an NPZ's members, nothing else read."""
    import zipfile

    out = {}
    with zipfile.ZipFile(path) as z:
        for name in members:
            with z.open(name + ".npy") as f:
                version = np.lib.format.read_magic(f)
                shape = (np.lib.format.read_array_header_1_0(f) if version == (1, 0)
                         else np.lib.format.read_array_header_2_0(f))[0]
            out[name] = int(np.prod(shape, dtype=object))
    return out


def _read_npz(path, names):
    try:
        npz = np.load(path, allow_pickle=False)
    except Exception as e:  # zipfile, pickle and OS errors: all mean "not a readable NPZ"
        raise FileError(f"cannot read as NPZ: {_one_line(e)}") from None
    if not isinstance(npz, np.lib.npyio.NpzFile):
        raise FileError("holds a single array, not an NPZ archive with arrays u and y")
    with npz:
        try:
            files = list(npz.files)
            u, y, t, extra = _wanted(names, files, "array", lambda: listing({k: npz[k].shape for k in files}))
            wanted = {u, y, *extra, *([t] if t else [])}
            try:
                sizes = _npz_sizes(path, wanted)
            except (KeyError, ValueError, OSError):
                sizes = None            # not a plain .npy member: np.load's own error below
            if sizes is not None:
                _within_budget(sizes, "the NPZ file")
            arrays = {k: npz[k] for k in wanted}
        except FileError:
            raise
        except Exception as e:
            raise FileError(f"cannot read as NPZ: {_one_line(e)}") from None
    return _raw_of(arrays, (u, y), t)


def _read_mat(path, names):
    with open(path, "rb") as f:
        head = f.read(128)
    if head.startswith(b"MATLAB 7.3") or head.startswith(b"\x89HDF"):
        return _read_mat73(path, names), "MAT v7.3"
    import scipy.io

    try:
        declared = {name: int(np.prod(shape, dtype=object)) for name, shape, _ in scipy.io.whosmat(path)}
    except Exception:  # noqa: BLE001 - loadmat names the damage below
        declared = None
    if declared:
        _within_budget(declared, "the MATLAB file")
    try:
        d = scipy.io.loadmat(path, squeeze_me=False)
    except Exception as e:  # scipy raises a zoo of types for a damaged or foreign file
        raise FileError(f"cannot read as a MATLAB file: {_one_line(e)}") from None
    d = {k: v for k, v in d.items() if not k.startswith("__")}
    u, y, t, _ = _wanted(names, list(d), "variable", listing({k: np.shape(v) for k, v in d.items()}))
    return _raw_of(d, (u, y), t), "MAT v5"


def _read_mat73(path, names):
    try:
        import h5py
    except ImportError:
        raise FileError("reading MATLAB v7.3 files needs h5py (pip install h5py)") from None
    try:
        with h5py.File(path, "r") as f:
            avail = list(f.keys())
            # MATLAB's P x N is N x P in HDF5: the shapes as MATLAB shows them
            shown = listing({k: getattr(f[k], "shape", None) and f[k].shape[::-1] for k in avail})
            u, y, t, extra = _wanted(names, avail, "variable", shown)
            wanted = {u, y, *extra, *([t] if t else [])}
            _within_budget({k: int(np.prod(getattr(f[k], "shape", ()) or (1,), dtype=object)) for k in wanted},
                           "the MATLAB v7.3 file")
            arrays = {name: _h5_variable(f, name) for name in wanted}
    except FileError:
        raise
    except Exception as e:
        raise FileError(f"cannot read as a MATLAB v7.3 (HDF5) file: {_one_line(e)}") from None
    return _raw_of(arrays, (u, y), t)


def _h5_variable(f, name):
    import h5py

    obj = f[name]
    cls = obj.attrs.get("MATLAB_class")
    cls = cls.decode() if isinstance(cls, bytes) else cls
    if not isinstance(obj, h5py.Dataset) or (cls is not None and cls not in _MATLAB_NUMERIC):
        kind = f"a MATLAB {cls}" if cls else "an HDF5 group"
        raise FileError(f"variable '{name}' is {kind}, not a numeric array")
    if obj.attrs.get("MATLAB_empty", 0):
        raise FileError(f"variable '{name}' is empty")
    if obj.dtype.names:  # MATLAB stores complex arrays as a compound (real, imag)
        raise FileError(f"variable '{name}' is complex; a measured time signal is real")
    # MATLAB writes column-major arrays, so HDF5 sees the P x N variable as N x P.
    return np.asarray(obj[()]).T
