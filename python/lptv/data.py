"""Frequency data with its nonparametric noise model (METHOD.md section 4)."""
from __future__ import annotations

from typing import Optional

import numpy as np

from . import _core
from ._validate import as_int, check_finite


def _periods_array(x, name):
    try:
        arr = np.asarray(x)
    except Exception as e:
        raise ValueError(f"{name} must be array-like: {e}") from None
    if arr.dtype == object or not np.issubdtype(arr.dtype, np.number):
        raise ValueError(f"{name} must be numeric, got dtype {arr.dtype}")
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} must be a real time signal, got complex values")
    if arr.ndim != 2:
        raise ValueError(f"{name} must have shape (P, N): P periods of N samples, got shape {arr.shape}")
    check_finite(arr, name)
    return np.ascontiguousarray(arr, dtype=float)


class FrequencyData:
    """Mean input/output spectra on lines 0..Lmax with the variances of the means.

    ``varU``, ``varY`` are the variances of the mean spectra and ``covYU = E{dY conj(dU)}``
    their covariance, per line (Pintelon & Schoukens 2001, eq. 2-31). Build it from periods
    with :meth:`from_periods`, or from spectra and variances you already have.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal((4, 64)); y = 2 * u + 0.1 * rng.standard_normal((4, 64))
    >>> d = lptv.FrequencyData.from_periods(u, y, w0=1.0)
    >>> d.periods, d.max_line
    (4, 32)
    """

    def __init__(self, U, Y, varU, varY, covYU=None, *, w0: float, ts: Optional[float] = None,
                 periods: int = 0):
        U = np.asarray(U, dtype=complex).ravel()
        n = U.size
        def vec(x, name, dtype):
            a = np.asarray(x)
            if a.dtype == object or not np.issubdtype(a.dtype, np.number):
                raise ValueError(f"{name} must be numeric, got dtype {a.dtype}")
            if a.ndim != 1 or a.size != n:
                raise ValueError(f"{name} must be 1-D with {n} lines like U, got shape {a.shape}")
            if dtype is float and np.iscomplexobj(a):
                raise ValueError(f"{name} must be real (a variance), got complex values")
            a = a.astype(dtype)
            check_finite(a, name)
            return a
        Y = vec(Y, "Y", complex)
        varU = vec(varU, "varU", float)
        varY = vec(varY, "varY", float)
        covYU = np.zeros(n, complex) if covYU is None else vec(covYU, "covYU", complex)
        check_finite(U, "U")
        if np.any(varU < 0):
            raise ValueError("varU must be >= 0 (a variance)")
        if np.any(varY < 0):
            raise ValueError("varY must be >= 0 (a variance)")
        periods = as_int(periods, "periods")  # 0: the variances came from elsewhere
        self._set(_core.FrequencyData(U, Y, varU, varY, covYU, periods), w0, ts)

    def _set(self, cpp, w0, ts):
        if w0 is None or not np.isfinite(w0) or w0 <= 0:
            raise ValueError(f"w0 must be a finite positive angular frequency (rad/s), got {w0!r}")
        if ts is not None and (not np.isfinite(ts) or ts <= 0):
            raise ValueError(f"ts must be a positive sample period or None, got {ts!r}")
        self._cpp = cpp
        self.w0 = float(w0)
        self.ts = None if ts is None else float(ts)

    @classmethod
    def from_periods(cls, u, y, *, w0: float, ts: Optional[float] = None) -> "FrequencyData":
        """Spectra and noise statistics from P >= 2 steady-state periods.

        Parameters
        ----------
        u, y : array_like, shape (P, N)
            P consecutive periods of N samples of the input and the output.
        w0 : float
            Fundamental of the period (rad/s); line l is the frequency l * w0.
        ts : float, optional
            Sample period for a discrete-time model (N * ts * w0 = 2 pi).
        """
        u = _periods_array(u, "u")
        y = _periods_array(y, "y")
        if u.shape != y.shape:
            raise ValueError(f"u and y must have the same shape (P, N), got {u.shape} and {y.shape}")
        if u.shape[0] < 2:
            raise ValueError(f"u, y: at least 2 periods are needed for a noise model, got P = {u.shape[0]}")
        if ts is not None and w0 is not None and np.isfinite(ts) and np.isfinite(w0) and ts > 0 and w0 > 0:
            n_expected = 2 * np.pi / (w0 * ts)
            if abs(n_expected - u.shape[1]) > 1e-6 * u.shape[1]:
                raise ValueError(f"u, y: {u.shape[1]} samples per period, but w0 = {w0:g} and ts = {ts:g} "
                                 f"give 2 pi / (w0 ts) = {n_expected:.6g}")
        obj = cls.__new__(cls)
        obj._set(_core.FrequencyData.from_periods(u, y), w0, ts)
        return obj

    U = property(lambda self: np.asarray(self._cpp.U), doc="Mean input spectrum, lines 0..Lmax.")
    Y = property(lambda self: np.asarray(self._cpp.Y), doc="Mean output spectrum.")
    varU = property(lambda self: np.asarray(self._cpp.varU), doc="Variance of the mean of U.")
    varY = property(lambda self: np.asarray(self._cpp.varY), doc="Variance of the mean of Y.")
    covYU = property(lambda self: np.asarray(self._cpp.covYU), doc="E{dY conj(dU)} of the means.")
    periods = property(lambda self: self._cpp.periods, doc="P (0 if the statistics came from elsewhere).")

    @property
    def max_line(self) -> int:
        return self.U.size - 1

    def __repr__(self):
        return f"lptv.FrequencyData(lines 0..{self.max_line}, periods={self.periods}, w0={self.w0:g})"


def frequency_data_of(u, y, w0, ts) -> "FrequencyData":
    """The data of a call that takes either periods ``u, y`` (with ``w0``, ``ts``) or a
    :class:`FrequencyData` as ``u``; ``w0``/``ts`` given with a FrequencyData must agree with it."""
    if isinstance(u, FrequencyData):
        if y is not None:
            raise ValueError("y must be omitted when u is a FrequencyData")
        if w0 is not None and not np.isclose(w0, u.w0):
            raise ValueError(f"w0={w0} disagrees with the data's w0={u.w0}")
        if ts is not None and u.ts is not None and not np.isclose(ts, u.ts):
            raise ValueError(f"ts={ts} disagrees with the data's ts={u.ts}")
        return u
    if y is None:
        raise ValueError("y is missing: pass u and y of shape (P, N), or a FrequencyData")
    if w0 is None:
        raise ValueError("w0 is missing: the fundamental of the period (rad/s)")
    return FrequencyData.from_periods(u, y, w0=w0, ts=ts)
