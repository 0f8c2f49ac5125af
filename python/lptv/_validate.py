"""Input checks shared by the Python layer: every message names its argument."""
from __future__ import annotations

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
    if isinstance(x, (bool, np.bool_)) or np.ndim(x) != 0:
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
        raise ValueError(f"{name} must be {kind}, got {v}")
    if v > maximum:
        raise ValueError(f"{name} must be at most {maximum}, got {v}")
    return v


def as_str(x, name, choices):
    if not isinstance(x, str) or x not in choices:
        opts = ", ".join(repr(c) for c in choices[:-1]) + f" or {choices[-1]!r}"
        raise ValueError(f"{name} must be {opts}, got {x!r}")
    return x


def as_positive_float(x, name):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be positive and finite, got {x!r}") from None
    if not (np.isfinite(v) and v > 0):
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
