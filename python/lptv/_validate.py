"""Input checks shared by the Python layer: every message names its argument.

Every public function and constructor converts its arguments here, so that a wrong type, NaN or
inf, a wrong shape or size, a value out of range or beyond the core's C int gives a ValueError
whose message names the argument and says what was wrong (never a TypeError from deep inside
NumPy, an OverflowError, a silent truncation of 2.5 to 2, or a number wrapped around in 32 bits).
ValueError is used for wrong types too, consistently, as the layer always has.
"""
from __future__ import annotations

import json
import sys
import os
import stat
from typing import Optional

import numpy as np


def _array(x, name):
    try:
        arr = np.asarray(x)
    except Exception as e:  # ragged lists etc.
        raise ValueError(f"{name} must be array-like: {e}") from None
    # kinds b, i, u, f, c: booleans and numbers (not timedelta, datetime, strings, objects)
    if arr.dtype.kind not in "biufc":
        raise ValueError(f"{name} must be numeric, got dtype {arr.dtype}")
    return arr


INT_MAX = 2**31 - 1  # the core indexes lines and samples with C int


def as_int(x, name, minimum=0, maximum=INT_MAX):
    """A whole number in [minimum, maximum], or a ValueError naming the argument."""
    if isinstance(x, (bool, np.bool_, str, bytes)) or np.ndim(x) != 0:
        raise ValueError(f"{name} must be an integer, got {x!r}")
    try:
        v = float(x) if not isinstance(x, (int, np.integer)) else x
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an integer, got {x!r}") from None
    if isinstance(v, float) and (not np.isfinite(v) or v != np.floor(v)):
        raise ValueError(f"{name} must be an integer, got {x!r}")
    v = int(v)
    if v < minimum:
        kind = {0: "a non-negative integer", 1: "a positive integer"}.get(minimum, f"an integer >= {minimum}")
        raise ValueError(f"{name} must be {kind}, got {_shown(v)}")
    if v > maximum:
        raise ValueError(f"{name} must be at most {maximum}, got {_shown(v)}")
    return v


def _shown(v: int) -> str:
    """An integer as a user typed it, or in short scientific form beyond 20 digits (1e300)."""
    return str(v) if abs(v) < 10**20 else f"{float(v):.6g}"


def as_str(x, name, choices):
    if not isinstance(x, str) or x not in choices:
        opts = ", ".join(repr(c) for c in choices[:-1]) + f" or {choices[-1]!r}"
        raise ValueError(f"{name} must be {opts}, got {x!r}")
    return x


def as_positive_float(x, name):
    v = as_float(x, name, what="positive and finite")
    if not v > 0:
        raise ValueError(f"{name} must be positive and finite, got {x!r}")
    return v


def check_finite(arr, name):
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise ValueError(f"{name} contains NaN or inf (first at index {tuple(int(i) for i in bad)})")


def as_complex_2d(x, name):
    arr = _array(x, name)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise ValueError(f"{name} must be 2-D (order+1, 2K+1), got shape {arr.shape}")
    if arr.shape[0] < 1:
        raise ValueError(f"{name} must have at least one row, got shape {arr.shape}")
    if arr.shape[1] % 2 != 1:
        raise ValueError(f"{name} must have an odd number of columns 2K+1, got shape {arr.shape}")
    arr = arr.astype(complex)
    check_finite(arr, name)
    return np.ascontiguousarray(arr)


def as_real_1d(x, name, min_len=0):
    arr = _array(x, name)
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} must be real, got complex values")
    arr = np.atleast_1d(arr).astype(float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {arr.shape}")
    if arr.size < min_len:
        raise ValueError(f"{name} must have at least {min_len} entries, got {arr.size}")
    check_finite(arr, name)
    return arr


def as_spectrum(x, name):
    """One-sided spectra: (L+1,) or (L+1, ncols) complex; returns (2-D array, was_1d)."""
    arr = _array(x, name)
    was_1d = arr.ndim == 1
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise ValueError(f"{name} must be 1-D (lines) or 2-D (lines, inputs), got shape {arr.shape}")
    if arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    arr = arr.astype(complex)
    check_finite(arr, name)
    return arr, was_1d


def _is_real_number(x) -> bool:
    # a one-element array counts as its number (w0 read from a .mat file is 1 x 1)
    return (isinstance(x, (int, float, np.integer, np.floating))
            or (isinstance(x, np.ndarray) and x.size == 1 and x.dtype.kind in "iuf")) \
        and not isinstance(x, (bool, np.bool_))


def as_float(x, name, *, minimum=None, maximum=None, open_min=False, open_max=False,
             finite=True, what=None):
    """A real number (float), optionally within [minimum, maximum] (open ends on request), or a
    ValueError naming the argument: strings, None, complex, bools and sequences are refused."""
    custom = what is not None
    if what is None:
        what = "a finite real number" if finite else "a real number (not NaN)"
    if not _is_real_number(x):
        raise ValueError(f"{name} must be {what}, got {x!r}")
    v = float(x.reshape(-1)[0]) if isinstance(x, np.ndarray) else float(x)
    if np.isnan(v) or (finite and not np.isfinite(v)):
        raise ValueError(f"{name} must be {what}, got {x!r}")
    lo_bad = minimum is not None and (v < minimum or (open_min and v == minimum))
    hi_bad = maximum is not None and (v > maximum or (open_max and v == maximum))
    if (lo_bad or hi_bad) and custom:
        raise ValueError(f"{name} must be {what}, got {x!r}")
    if lo_bad or hi_bad:
        if minimum is not None and maximum is not None:
            rng = f"in {'(' if open_min else '['}{minimum:g}, {maximum:g}{')' if open_max else ']'}"
        elif minimum is not None:
            rng = f"{'>' if open_min else '>='} {minimum:g}"
        else:
            rng = f"{'<' if open_max else '<='} {maximum:g}"
        raise ValueError(f"{name} must be {rng}, got {x!r}")
    return v


def as_optional(x, convert, *args, **kwargs):
    """None stays None; anything else goes through ``convert(x, *args, **kwargs)``."""
    return None if x is None else convert(x, *args, **kwargs)


def as_bool(x, name):
    """True or False (also NumPy's bool and the integers 0 and 1); strings, NaN and the rest are
    refused rather than judged by their truth value ('no' is true)."""
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)) and x in (0, 1):
        return bool(x)
    raise ValueError(f"{name} must be True or False, got {x!r}")


def as_path(x, name="path"):
    """A file path (str or os.PathLike) as a str."""
    if not isinstance(x, (str, os.PathLike)):
        raise ValueError(f"{name} must be a file path (str or os.PathLike), got {type(x).__name__}")
    p = os.fspath(x)
    if not isinstance(p, str) or not p:
        raise ValueError(f"{name} must be a non-empty file path, got {x!r}")
    return p


def not_regular(path) -> Optional[str]:
    """Why ``path`` is not a file to read, if it exists and is not a regular file (a FIFO, a
    socket, a device, a folder), else None: opening a FIFO with no writer waits for ever, and a
    device may never end."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return None                    # missing or unreadable: the open's own error says which
    if stat.S_ISREG(mode):
        return None
    kind = ("a folder" if stat.S_ISDIR(mode) else "a FIFO (named pipe)" if stat.S_ISFIFO(mode)
            else "a socket" if stat.S_ISSOCK(mode) else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
            else "not a regular file")
    return f"is {kind}, not a regular file"


def load_json(path, name="path"):
    """The JSON document in a file; a file that is not JSON text (binary data, another format) or
    not a regular file (a FIFO, a device) is a ValueError naming the file, and a missing file the
    usual OSError (FileNotFoundError)."""
    p = as_path(path, name)
    why = not_regular(p)
    if why:
        raise ValueError(f"{p}: {why}")
    with open(p, "rb") as f:
        raw = f.read()
    try:
        return json.loads(raw.decode("utf-8-sig"), parse_int=_json_int)
    except UnicodeDecodeError:
        raise ValueError(f"{p}: not a JSON file (binary data that is not UTF-8 text)") from None
    except json.JSONDecodeError as e:
        raise ValueError(f"{p}: not valid JSON ({e})") from None
    except RecursionError:
        raise ValueError(f"{p}: JSON nested deeper than any lptv file ({sys.getrecursionlimit()} levels or "
                         "more): not a file lptv wrote") from None
    except ValueError as e:      # _json_int's, and Python's limit on the digits of an integer
        raise ValueError(f"{p}: {e}") from None


JSON_INT_DIGITS = 40
"""The most digits an integer of a JSON file lptv reads may have (a count, a version, a 128-bit seed)."""


def _json_int(text):
    digits = len(text.lstrip("-"))
    if digits > JSON_INT_DIGITS:
        raise ValueError(f"an integer of {digits} digits (at most {JSON_INT_DIGITS}): not a value lptv wrote")
    return int(text)


def as_seed(seed, name="seed"):
    """A numpy Generator from None, a non-negative integer (or a sequence of them), a SeedSequence,
    a BitGenerator or a Generator."""
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, (bool, np.bool_, float, np.floating, complex, str, bytes)):
        raise ValueError(f"{name} must be None, a non-negative integer or a numpy Generator, got {seed!r}")
    try:
        return np.random.default_rng(seed)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} must be None, a non-negative integer or a numpy Generator, got {seed!r} "
                         f"({e})") from None


def as_int_list(x, name, minimum=0, maximum=INT_MAX):
    """A 1-D sequence of whole numbers, each in [minimum, maximum], as a list of int.

    A ``range``, an integer NumPy array or a list of integers is checked as a whole (its
    bounds), not entry by entry; anything else, and any out-of-range entry, goes through :func:`as_int` per entry,
    which names what is wrong."""
    if isinstance(x, range):
        if len(x) == 0 or (min(x[0], x[-1]) >= minimum and max(x[0], x[-1]) <= maximum):
            return list(x)
    else:
        arr = x
        # The types of a list's entries at C speed (a generator over the entries cost 0.1 ms per
        # call at 500 lines): plain ints are checked by their bounds; bools (which NumPy would
        # take as integers) go the long way.
        types = set(map(type, x)) if isinstance(x, (list, tuple)) and len(x) > 8 else None
        if types is not None and types == {int}:
            if min(x) >= minimum and max(x) <= maximum:
                return list(x)
        elif types is not None and bool not in types and np.bool_ not in types:
            try:
                arr = np.asarray(x)   # a list of Python or NumPy integers: dtype int64
            except (TypeError, ValueError, OverflowError):
                arr = x
        if isinstance(arr, np.ndarray) and arr.ndim == 1 and arr.dtype.kind in "iu":
            if arr.size == 0 or (int(arr.min()) >= minimum and int(arr.max()) <= maximum):
                return arr.tolist()
    if isinstance(x, (str, bytes)) or np.ndim(x) != 1:
        shape = "a string" if isinstance(x, (str, bytes)) else f"shape {np.shape(x)}"
        raise ValueError(f"{name} must be a 1-D sequence of integers, got {shape}")
    try:
        items = list(x)
    except TypeError:
        raise ValueError(f"{name} must be a 1-D sequence of integers, got {x!r}") from None
    out = []
    for v in items:
        try:
            out.append(as_int(v, name, minimum=minimum, maximum=maximum))
        except ValueError as e:
            raise ValueError(f"{e} (an entry of {name})") from None
    return out


def as_lines(x, name="lines", minimum=0, maximum=INT_MAX):
    """A non-empty 1-D sequence of line numbers (whole, non-negative, within the core's int)."""
    if isinstance(x, (int, np.integer)):
        raise ValueError(f"{name} must be a sequence of line numbers, got the single integer {x!r}")
    rows = as_int_list(x, name, minimum=minimum, maximum=maximum)
    if not rows:
        raise ValueError(f"{name} must be a non-empty 1-D sequence of integers")
    return rows


def as_counts(k, n, name):
    """Harmonic counts: one integer for all n+1 coefficients, or one per coefficient."""
    if np.ndim(k) == 0 and not isinstance(k, (str, bytes)):
        return [as_int(k, name)] * (n + 1)
    ks = as_int_list(k, name)
    if len(ks) != n + 1:
        raise ValueError(f"{name} must give one harmonic count per coefficient ({n + 1}), got {len(ks)}")
    return ks


def spread(x):
    """Mean variance over the rows (periods) over the power of the mean row: small for a periodic
    signal cut at its period, about 1 or more for anything else (inf for a zero mean row)."""
    mean_power = float(np.mean(x.mean(axis=0) ** 2))
    if x.shape[0] < 2:
        return np.inf
    return float(x.var(axis=0, ddof=1).mean() / mean_power) if mean_power > 0 else np.inf


def looks_transposed(x, swapped) -> bool:
    """More periods than samples per period, no repetition from period to period, while the
    swapped reading (the same samples as ``swapped``) repeats: a record given as samples x
    periods, or split with the counts exchanged."""
    P, N = x.shape
    if P <= N or swapped.shape[0] < 2:
        return False
    # the swapped reading repeats as a periodic input does (check_record's limit), the given one
    # does not, by a factor of 100: noise or a signal that is not periodic is never "transposed"
    s_given, s_swapped = spread(x), spread(swapped)
    return s_given > 0.1 and s_swapped < 0.1 and s_swapped < 0.01 * s_given


def as_periods(x, name):
    """P periods of N samples, shape (P, N), real and finite; a record that looks transposed is
    refused with a message saying so."""
    arr = _array(x, name)
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} must be a real time signal, got complex values")
    if arr.ndim != 2:
        raise ValueError(f"{name} must have shape (P, N): P periods of N samples, got shape {arr.shape}")
    check_finite(arr, name)
    arr = np.ascontiguousarray(arr, dtype=float)
    if looks_transposed(arr, arr.T):
        P, N = arr.shape
        raise ValueError(f"{name} looks transposed: {P} periods of {N} samples do not repeat, but its "
                         f"{N} columns do; pass the record as (P, N) = periods x samples ({name}.T)")
    return arr
