"""The LPTV model (METHOD.md section 1)."""
from __future__ import annotations

import json
import os
from typing import Optional

import numpy as np

from . import _core
from ._validate import as_complex_2d, as_real_1d


class Model:
    """Linear periodically time-varying model

    ``sum_n a_n(t) d^n y/dt^n = sum_m b_m(t) d^m u/dt^m`` with
    ``a_n(t) = sum_k a[n, Ka + k] exp(j k w0 t)`` (likewise ``b``).

    Parameters
    ----------
    a : array_like, shape (na+1, 2Ka+1)
        Fourier coefficients of a_0(t) .. a_na(t); column ``Ka + k`` holds harmonic k.
        Real arrays of shape (na+1,) or (na+1, 1) are an LTI denominator, lowest power first.
    b : array_like, shape (nb+1, 2Kb+1)
        Likewise for the numerator.
    w0 : float
        Parameter fundamental in rad/s (T0 = 2 pi / w0).
    ts : float, optional
        Sample period of a discrete-time model (forward shift ``y[t+n]``); None or 0 for
        continuous time. In discrete time ``2 pi / (w0 ts)`` must be an integer N,
        the number of samples per period.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> a = np.array([[0.05, 1, 0.05], [0, 1, 0], [0, 1, 0]], dtype=complex)
    >>> m = lptv.Model(a, [[1.0], [1.0]], w0=1.0)
    >>> m.na, m.nb, m.ka, m.kb
    (2, 1, 1, 0)
    >>> m.a_at([0.0]).round(3)
    array([[1.1, 1. , 1. ]])
    """

    def __init__(self, a, b, w0: float, ts: Optional[float] = None):
        a = as_complex_2d(a, "a")
        b = as_complex_2d(b, "b")
        if ts is None:
            ts = 0.0
        self._cpp = _core.Model(a, b, float(w0), float(ts))

    @classmethod
    def _from_core(cls, cpp: "_core.Model") -> "Model":
        obj = cls.__new__(cls)
        obj._cpp = cpp
        return obj

    # -- properties --------------------------------------------------------------
    @property
    def a(self) -> np.ndarray:
        """Coefficients of a_n(t), shape (na+1, 2Ka+1), column Ka+k = harmonic k."""
        return np.array(self._cpp.a)

    @property
    def b(self) -> np.ndarray:
        """Coefficients of b_m(t), shape (nb+1, 2Kb+1)."""
        return np.array(self._cpp.b)

    na = property(lambda self: self._cpp.na, doc="Order of the output side.")
    nb = property(lambda self: self._cpp.nb, doc="Order of the input side.")
    ka = property(lambda self: self._cpp.ka, doc="Harmonic count of the a_n(t).")
    kb = property(lambda self: self._cpp.kb, doc="Harmonic count of the b_m(t).")
    w0 = property(lambda self: self._cpp.w0, doc="Parameter fundamental (rad/s).")

    @property
    def ts(self) -> Optional[float]:
        """Sample period, or None for continuous time."""
        return self._cpp.ts if self._cpp.ts > 0 else None

    @property
    def discrete(self) -> bool:
        return self._cpp.ts > 0

    @property
    def period(self) -> float:
        """Parameter period T0 = 2 pi / w0 in seconds."""
        return 2 * np.pi / self.w0

    @property
    def samples_per_period(self) -> int:
        """Discrete time: N = 2 pi / (w0 ts)."""
        return self._cpp.samples_per_period()

    @property
    def is_lti(self) -> bool:
        return self.ka == 0 and self.kb == 0

    # -- evaluation --------------------------------------------------------------
    def a_at(self, t) -> np.ndarray:
        """a_n(t) at times t: array (len(t), na+1)."""
        return self._cpp.a_at(as_real_1d(t, "t"))

    def b_at(self, t) -> np.ndarray:
        """b_m(t) at times t: array (len(t), nb+1)."""
        return self._cpp.b_at(as_real_1d(t, "t"))

    def frozen(self, t: float):
        """The frozen polynomials at time t: (num, den), highest power first (numpy.roots order)."""
        tt = np.array([float(t)])
        return self.b_at(tt)[0][::-1].copy(), self.a_at(tt)[0][::-1].copy()

    # -- persistence -------------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "format": "lptv.Model",
            "version": 1,
            "w0": self.w0,
            "ts": self.ts,
            "a_real": self.a.real.tolist(),
            "a_imag": self.a.imag.tolist(),
            "b_real": self.b.real.tolist(),
            "b_imag": self.b.imag.tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Model":
        if not isinstance(d, dict) or d.get("format") != "lptv.Model":
            raise ValueError("not an lptv.Model description (missing format: 'lptv.Model')")
        try:
            a = np.asarray(d["a_real"], float) + 1j * np.asarray(d["a_imag"], float)
            b = np.asarray(d["b_real"], float) + 1j * np.asarray(d["b_imag"], float)
            return cls(a, b, w0=d["w0"], ts=d.get("ts"))
        except KeyError as e:
            raise ValueError(f"lptv.Model description lacks the field {e.args[0]!r}") from None

    def save(self, path) -> None:
        """Write the model as JSON (readable by :meth:`Model.load`)."""
        with open(os.fspath(path), "w") as f:
            json.dump(self.to_dict(), f, indent=1)

    @classmethod
    def load(cls, path) -> "Model":
        """Read a model written by :meth:`Model.save`."""
        with open(os.fspath(path)) as f:
            try:
                d = json.load(f)
            except json.JSONDecodeError as e:
                raise ValueError(f"{path}: not valid JSON ({e})") from None
        return cls.from_dict(d)

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, Model)
            and self.w0 == other.w0
            and self.ts == other.ts
            and self.a.shape == other.a.shape
            and self.b.shape == other.b.shape
            and np.array_equal(self.a, other.a)
            and np.array_equal(self.b, other.b)
        )

    def __repr__(self) -> str:
        dom = "continuous" if not self.discrete else f"discrete, ts={self.ts:g}"
        return (f"lptv.Model(na={self.na}, nb={self.nb}, ka={self.ka}, kb={self.kb}, "
                f"w0={self.w0:g}, {dom})")
