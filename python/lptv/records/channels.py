"""Which arrays of a measurement file are the input, the output and the time, and what they say
about the sampling frequency (the helpers of :func:`lptv.read_measurements`).

- Channels by name: ``u=`` / ``y=`` (``--input`` / ``--output``) name a CSV column, an NPZ array
  or a MAT variable; by default ``u`` and ``y``. A name matches up to case and a trailing unit
  (``force`` finds ``force [N]`` and ``Force (N)``); several matches are listed, a wrong name
  lists what the file holds.
- The sampling frequency from the file: a time column or variable (``time=``, by default one
  named ``t`` or ``time``, optionally with its unit: ``time [s]``, ``t_ms``), checked uniform,
  or a stored scalar ``fs`` (Hz) or ``dt`` / ``Ts`` (s).
"""
from __future__ import annotations

import re
from typing import Dict, Optional, Sequence, Tuple

import numpy as np


class FileError(ValueError):
    """A problem with the input file or the options that the user can act on (a ValueError)."""


ROLES = {"u": ("input", "u=", "--input"), "y": ("output", "y=", "--output"), "time": ("time", "time=", "--time")}

_TIME = re.compile(r"^(t|time|timestamp)\s*(?:[\[(]\s*(s|sec|seconds|ms|us)\s*[\])]|[_ ](s|sec|ms|us))?$")
# A trailing unit: 'force [N]', 'force (N)'.
_UNIT_SUFFIX = re.compile(r"^(.*?)\s*(?:\[([^\[\]]*)\]|\(([^()]*)\))$")
_UNIT = {"s": 1.0, "sec": 1.0, "seconds": 1.0, "ms": 1e-3, "us": 1e-6, None: 1.0}
# Stored sampling variables (exact names): Hz, or seconds per sample.
FS_NAMES = ("fs", "Fs", "FS")
DT_NAMES = ("dt", "Ts", "ts", "DT", "TS")
# A time step may deviate from the mean step by this fraction (text files round the times).
STEP_TOLERANCE = 1e-3


def channel_name(x, role):
    """A channel name argument (None: the default), or FileError naming the argument."""
    word, kw, opt = ROLES[role]
    if x is None:
        return None
    if isinstance(x, (list, tuple)) and len(x) == 1 and role != "time":
        x = x[0]      # a list of one channel: the one-channel reader (several: several_channels)
    if role == "y" and isinstance(x, (list, tuple)) and len(x) > 1 and all(isinstance(v, str) for v in x):
        raise FileError(one_output_message(list(x), as_list=True))
    if not isinstance(x, str) or not x.strip():
        raise FileError(f"{kw} ({opt}) must name a channel of the file (a non-empty str), got {x!r}")
    return x.strip()


def one_output_message(names, as_list=False):
    """A comma name where one channel is read; ``as_list``: a list given to a reader of one pair
    (lptv.inspect)."""
    listed = ", ".join(repr(n) for n in names)
    if as_list:
        return (f"y= (--output) must name one output channel here, got {len(names)} ({listed}): lptv.inspect "
                f"reads one input and one output; inspect each pair (lptv inspect FILE --output "
                f"{','.join(names)} does it pair by pair)")
    return (f"y= (--output) names one output channel here, got {len(names)} in one name ({listed}): several "
            f"outputs are a list, y=[{listed}] (--output {','.join(names)} on the command line), read as "
            "(P, N, ny) arrays and fitted as one MimoModel")


def split_unit(name: str) -> Tuple[str, Optional[str]]:
    """('force', 'n') from 'Force [N]' or 'force (N)'; ('force', None) from 'force': the name
    without a trailing unit in brackets or parentheses, and the unit, both in lower case."""
    m = _UNIT_SUFFIX.match(name.strip())
    if not m or not m.group(1).strip():
        return name.strip().lower(), None
    return m.group(1).strip().lower(), (m.group(2) or m.group(3)).strip().lower()


def _same_channel(wanted: str, name: str) -> bool:
    """Equal up to case and a trailing unit that only one of them states (units that are both
    given must agree: 'force [kN]' is not 'force [N]')."""
    (a, ua), (b, ub) = split_unit(wanted), split_unit(name)
    return a == b and (ua is None or ub is None or ua == ub)


def find(wanted: str, available: Sequence[str], role: str, kind: str, shown) -> str:
    """The file's name for a wanted channel: exact, else the one name equal up to case and
    spaces, else the one equal up to case and a trailing unit (``force`` finds ``force [N]``
    or ``Force (N)``); FileError listing the candidates when several match, or the file's
    channels (``shown``, a str or a function giving one) when none does."""
    if wanted in available:
        return wanted
    key = wanted.strip().lower()
    near = [a for a in available if a.strip().lower() == key]
    if not near:
        near = [a for a in available if _same_channel(wanted, a)]
    if len(near) == 1:
        return near[0]
    if len(near) > 1:
        word, kw, opt = ROLES[role]
        raise FileError(f"{kind} '{wanted}' is ambiguous: the file has {', '.join(repr(n) for n in near)}; "
                        f"name one of them exactly with {opt} ({kw})")
    if role == "y" and "," in wanted:
        parts = [p.strip() for p in wanted.split(",") if p.strip()]
        if len(parts) > 1:
            raise FileError(one_output_message(parts))
    word, kw, opt = ROLES[role]
    shown = shown() if callable(shown) else shown
    if wanted == role:
        raise FileError(f"{kind} '{wanted}' is missing ({shown}); name the input and output channels with "
                        "--input NAME --output NAME (u=, y= of lptv.read_measurements)")
    raise FileError(f"{kind} '{wanted}', the {word} named by {opt} ({kw}), is missing ({shown})")


def distinct_channels(chosen, given, kind: str) -> None:
    """FileError when channels named for different roles, or twice for one role, are one
    channel of the file: ``chosen`` the file's names found, ``given`` the names as given, each
    a sequence of (role, name) pairs in the same order ('force' and 'Force [N]' find one column)."""
    seen = {}
    for (role, name), (_, asked) in zip(chosen, given):
        word, kw, opt = ROLES[role]
        if name in seen:
            role0, asked0 = seen[name]
            w0_, kw0, opt0 = ROLES[role0]
            how = f"'{asked0}' and '{asked}' name" if asked0 != asked else f"'{asked}' names"
            if role0 == role:
                raise FileError(f"{kw} ({opt}) names one {word} twice: {how} the {kind} '{name}'; name each "
                                "channel once")
            raise FileError(f"{kw0} ({opt0}) and {kw} ({opt}) name one {kind}: {how} '{name}', but the {w0_} "
                            f"and the {word} must be different channels of the file")
        seen[name] = (role, asked)


def time_unit(name: str) -> Optional[float]:
    """Seconds per unit of a column named like a time (t, time, time [s], t_ms ...), else None."""
    m = _TIME.match(name.strip().lower())
    if not m:
        return None
    return _UNIT[m.group(2) or m.group(3)]


def auto_time(available: Sequence[str], exclude=()) -> Optional[str]:
    """The first channel named like a time, not one of the exclude."""
    return next((a for a in available if a not in exclude and time_unit(a) is not None), None)


def fs_from_time(t, what: str, scale: float = 1.0, line_of=None) -> float:
    """The sampling frequency of a time vector (s per unit ``scale``), checked uniform: FileError
    naming the first sample whose step differs from the mean step by more than 0.1 %."""
    t = np.asarray(t, dtype=float).ravel() * scale
    if t.size < 2:
        raise FileError(f"{what} holds {t.size} sample(s); a time needs at least 2 to give the sampling frequency")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise FileError(f"{what} is NaN or inf at {_where(bad[0], line_of)}")
    d = np.diff(t)
    step = float(np.median(d))      # the record's step, whatever a few samples do
    if not step > 0:
        raise FileError(f"{what} does not increase (median step {step:.6g} s)")
    off = np.flatnonzero(np.abs(d - step) > STEP_TOLERANCE * step)
    if off.size:
        i = off[0] + 1
        raise FileError(f"{what} is not uniformly sampled: {_where(i, line_of)} is at {t[i]:.10g} s, "
                        f"{d[i - 1]:.6g} s after the previous one, where the record's step is {step:.6g} s "
                        f"(fs {1 / step:.6g} Hz); resample the record or give --fs")
    return _tidy((t.size - 1) / (t[-1] - t[0]))     # the mean step: rounding of the times averages out


def _where(i, line_of):
    return f"sample {i + 1}" + (f" (line {line_of[i]})" if line_of is not None else "")


def _tidy(fs):
    """fs rounded to 9 significant digits when that is a round number (times written as text)."""
    r = float(f"{fs:.9g}")
    return r if abs(r - fs) <= 1e-9 * fs else fs


def stored_fs(values: Dict[str, object]) -> Optional[Tuple[float, str]]:
    """(fs, 'variable NAME') from stored scalars fs / dt / Ts, checked positive and in agreement."""
    found = []
    for name in FS_NAMES + DT_NAMES:
        if name not in values:
            continue
        a = np.asarray(values[name])
        if a.dtype.kind not in "fiu" or a.size != 1 or not np.isfinite(a.item()) or a.item() <= 0:
            unit = "Hz" if name in FS_NAMES else "s"
            raise FileError(f"variable '{name}' must be a positive scalar ({unit}), the sampling "
                            f"{'frequency' if name in FS_NAMES else 'time'}; got {_describe(a)}")
        v = float(a.item())
        found.append((v if name in FS_NAMES else 1.0 / v, name))
    if not found:
        return None
    fs, name = found[0]
    for other, oname in found[1:]:
        if not np.isclose(other, fs, rtol=1e-6, atol=0):
            raise FileError(f"variables '{name}' and '{oname}' disagree: fs {fs:.10g} Hz against {other:.10g} Hz")
    return fs, f"variable '{name}'"


def _describe(a):
    if a.dtype.kind in "fiu" and a.size == 1:
        return repr(a.item())
    return f"an array of shape {a.shape} and dtype {a.dtype}" if a.size != 1 else f"dtype {a.dtype}"


def listing(shapes: Dict[str, Optional[tuple]]) -> str:
    """'the file has force (1 x 5000), disp (1 x 5000), fs (1 x 1)' from {name: shape or None}."""
    if not shapes:
        return "the file has none"
    parts = [k if s is None else f"{k} ({' x '.join(map(str, s)) or 'scalar'})" for k, s in shapes.items()]
    return "the file has " + ", ".join(parts)


# ------------------------------------------------------------------------- several channels

def several_channels(u, y) -> Optional[Tuple[Tuple[str, ...], Tuple[str, ...]]]:
    """(inputs, outputs) as tuples of names when ``u`` or ``y`` is a list or tuple of two or
    more names (several inputs or outputs, METHOD.md section 19), else None (one of each: the
    SISO reader's arguments, a list of one name included). FileError for an empty list, a name
    that is not a non-empty str, or a channel named twice."""
    lists = [isinstance(x, (list, tuple)) for x in (u, y)]
    if not any(isinstance(x, (list, tuple)) and len(x) > 1 for x in (u, y)):
        return None
    out = []
    seen = {}
    for x, role, is_list in zip((u, y), ("u", "y"), lists):
        word, kw, opt = ROLES[role]
        names = list(x) if is_list else [x if x is not None else role]
        if not names:
            raise FileError(f"{kw} ({opt}) must name at least one {word} channel, got an empty list")
        for n in names:
            if not isinstance(n, str) or not n.strip():
                raise FileError(f"{kw} ({opt}) must name channels of the file (non-empty str), got {n!r}")
            key = n.strip().lower()
            if key in seen:
                raise FileError(f"channel '{n.strip()}' is named twice ({seen[key]} and {opt} ({kw})): a "
                                "channel must be read once")
            seen[key] = f"{opt} ({kw})"
        out.append(tuple(n.strip() for n in names))
    return out[0], out[1]


def read_several(read_one, path, inputs, outputs, options: dict):
    """Several inputs and outputs: ``read_one`` (:func:`lptv.read_measurements`) on pairs of one
    input and one output, so that every channel is matched, split into periods, trimmed and
    checked as the SISO reader does; the channels stacked on a last axis: u (P, N, nu) and y
    (P, N, ny). The Measurements' ``input`` and ``output`` are the tuples of the file's names."""
    import dataclasses

    if options.get("realisations"):
        raise FileError("realisations=True reads one input and one output; several channels "
                        f"({len(inputs)} inputs, {len(outputs)} outputs) are read as periods only")
    options = {k: v for k, v in options.items() if k != "realisations"}
    reads = []
    for i in range(max(len(inputs), len(outputs))):
        reads.append(read_one(path, u=inputs[min(i, len(inputs) - 1)], y=outputs[min(i, len(outputs) - 1)],
                              **options))
    first = reads[0]
    for m in reads[1:]:
        if m.u.shape != first.u.shape or m.trimmed != first.trimmed:   # the same options on one file
            raise FileError(f"channels '{m.input}' and '{first.input}' differ in shape: "
                            f"{' x '.join(map(str, m.u.shape))} against {' x '.join(map(str, first.u.shape))}")
    names_u = tuple(reads[min(i, len(reads) - 1)].input for i in range(len(inputs)))
    names_y = tuple(reads[min(i, len(reads) - 1)].output for i in range(len(outputs)))
    distinct_channels([("u", n) for n in names_u] + [("y", n) for n in names_y],
                      [("u", n) for n in inputs] + [("y", n) for n in outputs], "channel")
    u = np.stack([reads[min(i, len(reads) - 1)].u for i in range(len(inputs))], axis=-1)
    y = np.stack([reads[min(i, len(reads) - 1)].y for i in range(len(outputs))], axis=-1)
    return dataclasses.replace(first, u=u, y=y, input=names_u, output=names_y)
