"""The memory budget of a measurement file: the most bytes its arrays may take once read, checked
against what the file's headers declare before any sample is read."""
from __future__ import annotations

import os

import numpy as np

from .channels import FileError


def memory_budget() -> int:
    """The most bytes a measurement file's arrays may take once read (as float64): the
    environment variable ``LPTV_MEMORY_BUDGET`` (bytes, or with a suffix K, M, G, T: powers of
    1024), else half of this machine's physical memory. A file whose headers declare more (an
    NPZ's array headers, a MAT file's variable list, an HDF5 dataset's shape, a CSV's size) is
    refused before any of it is read, with the sizes; the allocator is never the one to say no."""
    text = os.environ.get("LPTV_MEMORY_BUDGET", "").strip()
    if text:
        scale = {"K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}
        unit = text[-1].upper()
        try:
            value = float(text[:-1]) * scale[unit] if unit in scale else float(text)
        except ValueError:
            raise FileError(f"LPTV_MEMORY_BUDGET must be a number of bytes (e.g. 4G), got {text!r}") from None
        if not (np.isfinite(value) and value > 0):
            raise FileError(f"LPTV_MEMORY_BUDGET must be positive, got {text!r}")
        return int(value)
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // 2
    except (ValueError, OSError, AttributeError):     # no sysconf: 8 GiB
        return 8 << 30


def _bytes(n) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} bytes"


def _within_budget(declared, what):
    """declared: {name: number of values}; FileError when they exceed the budget as float64."""
    total = 8 * sum(int(v) for v in declared.values())
    budget = memory_budget()
    if total > budget:
        big = max(declared, key=lambda k: declared[k])
        raise FileError(f"{what} declares {_bytes(total)} of samples ({big!r}: {int(declared[big])} values), "
                        f"more than lptv's memory budget of {_bytes(budget)} (half the machine's memory, or "
                        "LPTV_MEMORY_BUDGET): nothing was read; cut the record, or raise the budget")
