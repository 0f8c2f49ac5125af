"""Input checks shared by the Python layer: every message names its argument."""
from __future__ import annotations

import numpy as np


def _array(x, name):
    try:
        arr = np.asarray(x)
    except Exception as e:  # ragged lists etc.
        raise ValueError(f"{name} must be array-like: {e}") from None
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        raise ValueError(f"{name} must be numeric, got dtype {arr.dtype}")
    return arr


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
