"""Reading periodic measurements from files: CSV, NPZ and MATLAB (v4/v5/v7 and v7.3).

- CSV: a header row naming the columns ``u`` and ``y`` (other columns are ignored), one sample
  per row, the periods one after another; ``periods`` says how many the record holds.
- NPZ: arrays ``u`` and ``y`` of shape (P, N), optionally a scalar ``w0`` (rad/s).
- MATLAB ``.mat`` (v4/v5/v7 via scipy, v7.3 via h5py): variables ``u`` and ``y`` of size P x N,
  optionally a scalar ``w0``. In NPZ and MAT files, vectors are accepted with ``periods``.

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

import csv
import io
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

FORMATS = {".csv": "CSV", ".npz": "NPZ", ".mat": "MAT"}
_MATLAB_NUMERIC = {"double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                   "int64", "uint64"}


def _one_line(e):
    return " ".join(str(e).split()) or type(e).__name__


class FileError(Exception):
    """A problem with the input file or the options that the user can act on."""


@dataclass(frozen=True)
class Measurements:
    """What a measurement file holds: P periods of N samples of u and y."""

    u: np.ndarray
    y: np.ndarray
    w0: Optional[float]
    format: str


# ------------------------------------------------------------------------------ reading

def read_measurements(path, periods: Optional[int] = None) -> Measurements:
    """Read u, y (shape (P, N)) and an optional w0 from a CSV, NPZ or MATLAB file.

    Raises :class:`FileError` with a message naming the problem (not the file).
    """
    path = Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise FileError(f"unknown file type '{path.suffix}' (expected .csv, .npz or .mat)")
    if not path.exists():
        raise FileError("no such file")
    if path.is_dir():
        raise FileError("is a directory, not a measurement file")
    if periods is not None and periods < 1:
        raise FileError(f"--periods must be a positive integer, got {periods}")
    if fmt == "CSV":
        u, y, w0 = _read_csv(path, periods)
    elif fmt == "NPZ":
        u, y, w0 = _read_npz(path, periods)
    else:
        u, y, w0, fmt = _read_mat(path, periods)
    if u.shape != y.shape:
        raise FileError(f"u and y differ in shape: u is {_shape(u)} and y is {_shape(y)} (periods x samples)")
    if u.shape[0] < 2:
        raise FileError("the record holds only 1 period; the noise model needs at least 2")
    return Measurements(u=u, y=y, w0=w0, format=fmt)


def _shape(a):
    return " x ".join(str(n) for n in a.shape)


def _read_csv(path, periods):
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise FileError("not a text file (is it really CSV?)") from None
    rows = csv.reader(io.StringIO(text), delimiter=_delimiter(text))
    header = next((r for r in rows if any(c.strip() for c in r)), None)
    if header is None:
        raise FileError("the file is empty")
    names = [c.strip().lower() for c in header]
    if all(_is_number(c) for c in header):
        raise FileError("the first row must be a header naming the columns u and y; it holds numbers")
    cols = {}
    for name in ("u", "y"):
        if names.count(name) > 1:
            raise FileError(f"column '{name}' appears {names.count(name)} times in the header")
        if name not in names:
            found = ", ".join(repr(c.strip()) for c in header)
            raise FileError(f"column '{name}' is missing (the header has {found})")
        cols[name] = names.index(name)
    values = {"u": [], "y": []}
    line_of = []
    need = max(cols.values()) + 1
    for row in rows:
        if not any(c.strip() for c in row):
            continue
        if len(row) < need:
            raise FileError(f"line {rows.line_num}: {len(row)} field(s), the header has {len(header)}")
        for name, i in cols.items():
            cell = row[i].strip()
            try:
                values[name].append(float(cell))
            except ValueError:
                what = "is empty" if not cell else f"'{cell}' is not a number"
                raise FileError(f"line {rows.line_num}: column '{name}' {what}") from None
        line_of.append(rows.line_num)
    if not line_of:
        raise FileError("no data rows after the header")
    for name in ("u", "y"):
        v = np.array(values[name])
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise FileError(f"line {line_of[bad[0]]}: column '{name}' is NaN or inf")
    if periods is None:
        raise FileError(f"--periods is required for a CSV record (how many periods its "
                        f"{len(line_of)} samples hold)")
    return (_split_periods("column 'u'", np.array(values["u"]), periods),
            _split_periods("column 'y'", np.array(values["y"]), periods), None)


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


def _as_periods(name, a, periods):
    """A (P, N) float array from a file variable; vectors are split with --periods."""
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
        if periods is None:
            raise FileError(f"{what} is a vector of {a.size} samples: give --periods, "
                            "the number of periods it holds")
        a = _split_periods(what, a.ravel(), periods)
    elif periods is not None and a.shape[0] != periods:
        raise FileError(f"{what} holds {a.shape[0]} periods ({_shape(a)}) but --periods says {periods}")
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


def _read_npz(path, periods):
    try:
        npz = np.load(path, allow_pickle=False)
    except Exception as e:  # zipfile, pickle and OS errors: all mean "not a readable NPZ"
        raise FileError(f"cannot read as NPZ: {_one_line(e)}") from None
    if not isinstance(npz, np.lib.npyio.NpzFile):
        raise FileError("holds a single array, not an NPZ archive with arrays u and y")
    with npz:
        try:
            arrays = {k: npz[k] for k in ("u", "y", "w0") if k in npz.files}
        except Exception as e:
            raise FileError(f"cannot read as NPZ: {_one_line(e)}") from None
    return _u_y_w0(arrays, npz.files, periods, "array")


def _read_mat(path, periods):
    with open(path, "rb") as f:
        head = f.read(128)
    if head.startswith(b"MATLAB 7.3") or head.startswith(b"\x89HDF"):
        return (*_read_mat73(path, periods), "MAT v7.3")
    import scipy.io

    try:
        d = scipy.io.loadmat(path, squeeze_me=False)
    except Exception as e:  # scipy raises a zoo of types for a damaged or foreign file
        raise FileError(f"cannot read as a MATLAB file: {_one_line(e)}") from None
    names = [k for k in d if not k.startswith("__")]
    return (*_u_y_w0(d, names, periods, "variable"), "MAT v5")


def _read_mat73(path, periods):
    try:
        import h5py
    except ImportError:
        raise FileError("reading MATLAB v7.3 files needs h5py (pip install h5py)") from None
    try:
        with h5py.File(path, "r") as f:
            names = list(f.keys())
            arrays = {name: _h5_variable(f, name) for name in ("u", "y", "w0") if name in f}
    except FileError:
        raise
    except Exception as e:
        raise FileError(f"cannot read as a MATLAB v7.3 (HDF5) file: {_one_line(e)}") from None
    return _u_y_w0(arrays, names, periods, "variable")


def _u_y_w0(arrays, names, periods, kind):
    """u and y as (P, N) periods and the optional w0 from what a file holds."""
    for name in ("u", "y"):
        if name not in arrays:
            raise FileError(f"{kind} '{name}' is missing (the file has {', '.join(names) or 'none'})")
    return (_as_periods("u", arrays["u"], periods), _as_periods("y", arrays["y"], periods),
            _file_w0(arrays.get("w0")))


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
