"""The matrix LPTV model: several inputs and outputs (METHOD.md section 19)."""
from __future__ import annotations

import json
import os
from typing import Optional

import numpy as np

from .. import _core
from .._validate import _array, as_path, as_real_1d, check_finite, load_json
from .siso import Model, _no_bool, _short, _ts, _w0, read_covariance

FORMAT_VERSION = 1
"""The version of the JSON description :meth:`MimoModel.to_dict` writes and :meth:`MimoModel.from_dict` reads."""
_FIELDS = ("format", "version", "n_outputs", "n_inputs", "w0", "ts", "a_real", "a_imag", "b_real", "b_imag",
           "eta_names", "covariance", "context")


def _as_coefficients(x, name, rows=None):
    """(order+1, ny, ncols, 2K+1) complex; a real 3-D array (order+1, ny, ncols) is constant (K = 0)."""
    arr = _array(x, name)
    if arr.ndim == 3:
        arr = arr[..., None]
    if arr.ndim != 4:
        raise ValueError(f"{name} must be 4-D (order+1, n_outputs, columns, 2K+1), or 3-D for constant "
                         f"coefficients, got shape {arr.shape}")
    if min(arr.shape) < 1:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    if arr.shape[3] % 2 != 1:
        raise ValueError(f"{name} must have an odd number 2K+1 of harmonics on its last axis, got shape {arr.shape}")
    if rows is not None and arr.shape[1] != rows:
        raise ValueError(f"{name} must have n_outputs = {rows} rows per matrix (axis 1), got shape {arr.shape}")
    arr = arr.astype(complex)
    check_finite(arr, name)
    return np.ascontiguousarray(arr)


def _highest(c, axis_drop):
    """Per entry: the highest index along the dropped axis with a nonzero coefficient (-1: none)."""
    nz = c != 0
    if axis_drop == "order":
        idx = np.arange(c.shape[0])[:, None, None, None]
        return np.max(np.where(nz, idx, -1), axis=(0, 3))
    K = (c.shape[3] - 1) // 2
    idx = np.abs(np.arange(-K, K + 1))[None, None, None, :]
    return np.max(np.where(nz, idx, -1), axis=(0, 3))


class MimoModel:
    """Linear periodically time-varying model with several inputs and outputs

    ``sum_n A_n(t) d^n y/dt^n = sum_m B_m(t) d^m u/dt^m`` (METHOD.md eq. 19.1), y with
    ``n_outputs`` (ny) and u with ``n_inputs`` (nu) channels, every entry of A_n(t) (ny x ny)
    and B_m(t) (ny x nu) a Fourier series in w0 with its own harmonic count:
    ``[A_n(t)]_pq = sum_k a[n, p, q, Ka + k] exp(j k w0 t)``.

    Parameters
    ----------
    a : array_like, shape (na+1, ny, ny, 2Ka+1)
        Fourier coefficients of the entries of A_0(t) .. A_na(t); an entry with fewer harmonics
        or a lower order holds zeros. A real array (na+1, ny, ny) is a constant (LTI) A.
    b : array_like, shape (nb+1, ny, nu, 2Kb+1)
        Likewise for B_0(t) .. B_nb(t) (or (nb+1, ny, nu) constant).
    w0 : float
        Parameter fundamental in rad/s.
    ts : float, optional
        Sample period of a discrete-time model (forward shift); None or 0 for continuous time.

    Examples
    --------
    Two masses coupled by a spring k_c(t) = 2 (1 + 0.3 cos t), one force on each:

    >>> import numpy as np, lptv
    >>> kc = np.array([0.3, 2.0, 0.3])                      # harmonics -1, 0, 1 of k_c(t)
    >>> S = np.array([[1.0, -1.0], [-1.0, 1.0]])
    >>> K = S[:, :, None] * kc + np.diag([5.0, 3.0])[:, :, None] * [0, 1, 0]
    >>> m = lptv.MimoModel.mechanical(np.eye(2), 0.2 * np.eye(2), K, np.eye(2), w0=1.0)
    >>> m.n_outputs, m.n_inputs, m.na, m.ka
    (2, 2, 2, 1)
    >>> m.ka_entries.tolist()                             # A's entries' own harmonic counts
    [[1, 1], [1, 1]]
    """

    def __init__(self, a, b, w0: float, ts: Optional[float] = None):
        a = _as_coefficients(a, "a")
        if a.shape[1] != a.shape[2]:
            raise ValueError(f"a must hold square ny x ny matrices (axes 1 and 2), got shape {a.shape}")
        b = _as_coefficients(b, "b", rows=a.shape[1])
        ny, nu = a.shape[1], b.shape[2]
        self._cpp = _core.MimoModel(a.reshape(-1, a.shape[3]), b.reshape(-1, b.shape[3]), ny, nu,
                                    _w0(w0), _ts(ts))

    @classmethod
    def mechanical(cls, M, C, K, B, *, w0: float, ts: Optional[float] = None) -> "MimoModel":
        """``M y'' + C y' + K y = B u``: na = 2, A_2 = M, A_1 = C, A_0 = K, B_0 = B. Each matrix
        is constant (ny x ny, B ny x nu) or periodic, with its harmonics on a last axis
        (ny x ny x (2K+1), column K + k holding harmonic k)."""
        mats = [np.asarray(_array(x, name), dtype=complex) for x, name in ((K, "K"), (C, "C"), (M, "M"), (B, "B"))]
        for i, name in enumerate("KCMB"):
            if mats[i].ndim == 2:
                mats[i] = mats[i][:, :, None]
            if mats[i].ndim != 3 or mats[i].shape[2] % 2 != 1:
                raise ValueError(f"{name} must be a matrix, or a matrix with 2K+1 harmonics on a last axis, "
                                 f"got shape {np.shape(mats[i])}")
        Ka = max((x.shape[2] - 1) // 2 for x in mats[:3])
        ny = mats[2].shape[0]
        a = np.zeros((3, ny, ny, 2 * Ka + 1), complex)
        for n, x in enumerate(mats[:3]):
            if x.shape[:2] != (ny, ny):
                raise ValueError(f"{'KCM'[n]} must be {ny} x {ny} (as M), got {x.shape[:2]}")
            k = (x.shape[2] - 1) // 2
            a[n, :, :, Ka - k:Ka + k + 1] = x
        return cls(a, mats[3][None], w0=w0, ts=ts)

    @classmethod
    def from_siso(cls, model: Model) -> "MimoModel":
        """The SISO model as a 1 x 1 matrix model."""
        if not isinstance(model, Model):
            raise ValueError(f"model must be an lptv.Model, got {type(model).__name__}")
        return cls(model.a[:, None, None, :], model.b[:, None, None, :], w0=model.w0, ts=model.ts)

    def to_siso(self) -> Model:
        """The 1 x 1 model as an :class:`lptv.Model` (ValueError for more channels)."""
        if self.n_outputs != 1 or self.n_inputs != 1:
            raise ValueError(f"to_siso: the model has {self.n_outputs} outputs and {self.n_inputs} inputs, not 1 and 1")
        return Model(self.a[:, 0, 0, :], self.b[:, 0, 0, :], w0=self.w0, ts=self.ts)

    @classmethod
    def _from_core(cls, cpp) -> "MimoModel":
        obj = cls.__new__(cls)
        obj._cpp = cpp
        return obj

    # -- properties --------------------------------------------------------------
    n_outputs = property(lambda self: self._cpp.n_outputs, doc="Number of outputs ny.")
    n_inputs = property(lambda self: self._cpp.n_inputs, doc="Number of inputs nu.")
    na = property(lambda self: self._cpp.na, doc="Order of the output side (the highest over the entries).")
    nb = property(lambda self: self._cpp.nb, doc="Order of the input side.")
    ka = property(lambda self: self._cpp.ka, doc="Harmonic count of the A_n(t) (the highest over the entries).")
    kb = property(lambda self: self._cpp.kb, doc="Harmonic count of the B_m(t).")
    w0 = property(lambda self: self._cpp.w0, doc="Parameter fundamental (rad/s).")

    @property
    def a(self) -> np.ndarray:
        """Coefficients, shape (na+1, ny, ny, 2Ka+1): a[n, p, q, Ka + k] = harmonic k of [A_n(t)]_pq."""
        c = np.array(self._cpp.a)
        return c.reshape(self.na + 1, self.n_outputs, self.n_outputs, c.shape[1])

    @property
    def b(self) -> np.ndarray:
        """Coefficients, shape (nb+1, ny, nu, 2Kb+1): b[m, p, r, Kb + k] = harmonic k of [B_m(t)]_pr."""
        c = np.array(self._cpp.b)
        return c.reshape(self.nb + 1, self.n_outputs, self.n_inputs, c.shape[1])

    @property
    def ka_entries(self) -> np.ndarray:
        """Each entry's own harmonic count (ny, ny): the highest |k| with a nonzero coefficient in
        any A_n (-1 for an entry that is zero at every order)."""
        return _highest(self.a, "harmonic")

    @property
    def kb_entries(self) -> np.ndarray:
        """Each entry's own harmonic count in B (ny, nu)."""
        return _highest(self.b, "harmonic")

    @property
    def na_entries(self) -> np.ndarray:
        """Each entry's own order in A (ny, ny): the highest n with a nonzero coefficient (-1: none)."""
        return _highest(self.a, "order")

    @property
    def nb_entries(self) -> np.ndarray:
        """Each entry's own order in B (ny, nu)."""
        return _highest(self.b, "order")

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
        """A_n(t) at times t: real array (len(t), na+1, ny, ny)."""
        v = self._cpp.a_at(as_real_1d(t, "t"))
        return v.reshape(-1, self.na + 1, self.n_outputs, self.n_outputs)

    def b_at(self, t) -> np.ndarray:
        """B_m(t) at times t: real array (len(t), nb+1, ny, nu)."""
        v = self._cpp.b_at(as_real_1d(t, "t"))
        return v.reshape(-1, self.nb + 1, self.n_outputs, self.n_inputs)

    context = None
    """What the model was fitted to, as :attr:`lptv.Model.context` (:mod:`lptv.use.modelfile`)."""
    covariance = None
    """Covariance of the estimated real parameters (``eta_names``, as
    :attr:`lptv.MimoIdentificationResult.parameter_names`), set by :func:`lptv.identify` and kept
    by :meth:`save` (``lptv.validate`` then counts the model's own estimation error)."""
    eta_names = ()

    # -- persistence -------------------------------------------------------------
    def to_dict(self) -> dict:
        d = {
            "format": "lptv.MimoModel",
            "version": FORMAT_VERSION,
            "n_outputs": self.n_outputs,
            "n_inputs": self.n_inputs,
            "w0": self.w0,
            "ts": self.ts,
            "a_real": self.a.real.tolist(),
            "a_imag": self.a.imag.tolist(),
            "b_real": self.b.real.tolist(),
            "b_imag": self.b.imag.tolist(),
        }
        if self.covariance is not None:
            d["eta_names"] = list(self.eta_names)
            d["covariance"] = np.asarray(self.covariance).tolist()
        if self.context is not None:
            d["context"] = dict(self.context)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "MimoModel":
        """The model a :meth:`to_dict` description holds; every field is checked, and a wrong one
        is a ValueError naming it."""
        what = "lptv.MimoModel description"
        if not isinstance(d, dict) or d.get("format") != "lptv.MimoModel":
            hint = " (an lptv.Model description: read it with lptv.Model.load)" \
                if isinstance(d, dict) and d.get("format") == "lptv.Model" else ""
            raise ValueError(f"not an lptv.MimoModel description (missing format: 'lptv.MimoModel'){hint}")
        unknown = [k for k in d if k not in _FIELDS]
        if unknown:
            raise ValueError(f"{what}: unknown field {unknown[0]!r} (fields: {', '.join(_FIELDS)})")
        for key in ("version", "n_outputs", "n_inputs", "w0", "a_real", "a_imag", "b_real", "b_imag"):
            if key not in d:
                raise ValueError(f"{what} lacks the field {key!r}")
        v = d["version"]
        if isinstance(v, bool) or not isinstance(v, int) or v != FORMAT_VERSION:
            raise ValueError(f"{what}: version must be {FORMAT_VERSION} (the only version this lptv reads), got {v!r}")
        dims = {}
        for key in ("n_outputs", "n_inputs"):
            x = d[key]
            if isinstance(x, bool) or not isinstance(x, int) or x < 1:
                raise ValueError(f"{what}: {key} must be a positive integer, got {_short(x)}")
            dims[key] = x
        w0 = _w0(d["w0"])
        ts = _ts(d.get("ts"))

        def coef(key, shape_mid):
            _no_bool(d[key], f"{what}: {key}")
            try:
                arr = np.array(d[key], dtype=float)
            except (TypeError, ValueError):
                raise ValueError(f"{what}: {key} must be a 4-D list of numbers, got {_short(d[key])}") from None
            if arr.ndim != 4 or arr.size == 0 or arr.shape[1:3] != shape_mid:
                raise ValueError(f"{what}: {key} must be a 4-D list of shape (order+1, {shape_mid[0]}, "
                                 f"{shape_mid[1]}, 2K+1), got shape {arr.shape}")
            return arr

        ny, nu = dims["n_outputs"], dims["n_inputs"]
        parts = {k: coef(k, (ny, ny) if k[0] == "a" else (ny, nu)) for k in ("a_real", "a_imag", "b_real", "b_imag")}
        for side in "ab":
            if parts[f"{side}_real"].shape != parts[f"{side}_imag"].shape:
                raise ValueError(f"{what}: {side}_imag must have the shape of {side}_real "
                                 f"{parts[f'{side}_real'].shape}, got {parts[f'{side}_imag'].shape}")
        try:
            m = cls(parts["a_real"] + 1j * parts["a_imag"], parts["b_real"] + 1j * parts["b_imag"], w0=w0, ts=ts)
            if d.get("covariance") is not None:
                names, cov = read_covariance(d, what)
                bad = [n for n in names if not _mimo_name(n, m)]
                if bad:
                    raise ValueError(f"{what}: eta_names: {bad[0]!r} is not a coefficient entry of this model "
                                     "(names like 'a0[0,1].re1')")
                m.eta_names, m.covariance = names, cov
            if "context" in d:
                from ..use.modelfile import check_context

                m.context = check_context(d["context"], m)
        except ValueError as e:
            raise ValueError(f"{what}: {e}") from None
        return m

    def save(self, path) -> None:
        """Write the model as JSON (readable by :meth:`MimoModel.load`), with its covariance
        when it has one."""
        from ..atomic import atomic_open

        with atomic_open(as_path(path)) as f:
            json.dump(self.to_dict(), f, indent=1)

    @classmethod
    def load(cls, path) -> "MimoModel":
        """Read a model written by :meth:`MimoModel.save`; a file that is not such a description is a
        ValueError naming the file and the problem."""
        d = load_json(path)
        try:
            return cls.from_dict(d)
        except ValueError as e:
            raise ValueError(f"{os.fspath(path)}: {e}") from None

    def __eq__(self, other) -> bool:
        return (isinstance(other, MimoModel) and self.w0 == other.w0 and self.ts == other.ts
                and self.a.shape == other.a.shape and self.b.shape == other.b.shape
                and np.array_equal(self.a, other.a) and np.array_equal(self.b, other.b))

    def __repr__(self) -> str:
        dom = "continuous" if not self.discrete else f"discrete, ts={self.ts:g}"
        return (f"lptv.MimoModel(n_outputs={self.n_outputs}, n_inputs={self.n_inputs}, na={self.na}, "
                f"nb={self.nb}, ka={self.ka}, kb={self.kb}, w0={self.w0:g}, {dom})")


def _mimo_name(name: str, m: "MimoModel") -> bool:
    """Whether ``name`` ('a0[0,1].re1') names a coefficient entry's harmonic of ``m``."""
    import re

    hit = re.fullmatch(r"([ab])(\d+)\[(\d+),(\d+)\]\.(re|im)(\d+)", name)
    if hit is None:
        return False
    side, n, p, q, part, k = hit.groups()
    n, p, q, k = int(n), int(p), int(q), int(k)
    order, cols, K = (m.na, m.n_outputs, m.ka) if side == "a" else (m.nb, m.n_inputs, m.kb)
    return n <= order and p < m.n_outputs and q < cols and k <= K and not (part == "im" and k == 0)
