"""The LPTV model (METHOD.md section 1)."""
from __future__ import annotations

import json
import os
from typing import Optional

import numpy as np

from .. import _core
from .._validate import as_complex_2d, as_float, as_int, as_path, as_real_1d, load_json

FORMAT_VERSION = 1
"""The version of the JSON description :meth:`Model.to_dict` writes and :meth:`Model.from_dict` reads."""
_FIELDS = ("format", "version", "w0", "ts", "a_real", "a_imag", "b_real", "b_imag", "eta_names", "covariance",
           "context")


def _w0(w0):
    return as_float(w0, "w0", minimum=0.0, open_min=True, what="a finite positive angular frequency (rad/s)")


def _ts(ts):
    if ts is None:
        return 0.0
    return as_float(ts, "ts", minimum=0.0, what="finite and >= 0 (0 or None for continuous time)")


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

    covariance = None
    """Covariance of the estimated real parameters (``eta_names``), set by :func:`lptv.identify`
    for WGTLS and SML and kept by :meth:`save` / :meth:`load`; None otherwise."""
    eta_names = ()
    """Names of the parameters the covariance is about, e.g. 'a0.re1' (Re of harmonic 1 of a_0)."""
    context = None
    """What the model was fitted to (channels and units, sampling, period, structure, estimator,
    noise route), set by ``lptv identify`` and kept by :meth:`save` / :meth:`load` for ``lptv
    validate`` and ``lptv simulate`` (:mod:`lptv.use.modelfile`); None otherwise."""

    def __init__(self, a, b, w0: float, ts: Optional[float] = None):
        a = as_complex_2d(a, "a")
        b = as_complex_2d(b, "b")
        self._cpp = _core.Model(a, b, _w0(w0), _ts(ts))

    @classmethod
    def from_tf(cls, num, den, *, w0: float = 1.0, ts: Optional[float] = None) -> "Model":
        """An LTI model from numerator and denominator in descending powers, as scipy.signal and
        MATLAB write them: ``num = [b_nb, ..., b_0]``, ``den = [a_na, ..., a_0]`` (for a discrete
        model, powers of the forward shift z). ``w0`` is the fundamental of the line grid the model
        will be simulated on (any positive value for an LTI system).

        Examples
        --------
        >>> import lptv
        >>> m = lptv.Model.from_tf([1.0], [1.0, 4.0, 100.0])      # 1 / (s^2 + 4 s + 100)
        >>> m.a[:, 0].real.tolist(), m.b[:, 0].real.tolist()
        ([100.0, 4.0, 1.0], [1.0])
        >>> m.to_tf()
        (array([1.]), array([  1.,   4., 100.]))
        """
        num = as_real_1d(num, "num")
        den = as_real_1d(den, "den")
        for name, v in (("num", num), ("den", den)):
            if v.size == 0 or v[0] == 0:
                raise ValueError(f"{name} must be a non-empty coefficient list, highest power first, "
                                 f"with a non-zero leading coefficient, got {v.tolist()}")
        return cls(den[::-1].reshape(-1, 1), num[::-1].reshape(-1, 1), w0=w0, ts=ts)

    def _check_t(self, t):
        if t is None:
            if not self.is_lti:
                raise ValueError("t: this model is time-varying; give the time t (s) of the frozen system")
            return 0.0
        return as_float(t, "t", what="a finite time (s)")

    def to_tf(self, t: Optional[float] = None):
        """``(num, den)`` in descending powers (scipy.signal / MATLAB order) of the LTI model, or of
        the frozen system at time ``t`` (s) of an LPTV model (:meth:`frozen`); real arrays.

        A frozen system is the LTI system with the coefficients held at their values at t; it is
        not the periodic system's response (use :meth:`freqresp` for that).
        """
        num, den = self.frozen(self._check_t(t))
        return np.real(num).copy(), np.real(den).copy()

    def to_lti(self, t: Optional[float] = None):
        """A :class:`scipy.signal.lti` (continuous) or :class:`scipy.signal.dlti` (discrete, ``dt =
        ts``) of the LTI model or of the frozen system at time ``t``.

        Examples
        --------
        >>> import numpy as np, lptv
        >>> m = lptv.Model.from_tf([1.0], [1.0, 4.0, 100.0])
        >>> w, H = m.to_lti().freqresp([10.0])
        >>> bool(np.allclose(H, m.freqresp([10.0]), rtol=1e-14))
        True
        """
        import scipy.signal

        num, den = self.to_tf(t)
        if self.discrete:
            return scipy.signal.dlti(num, den, dt=self.ts)
        return scipy.signal.lti(num, den)

    def to_scipy(self):
        """The LTI model as a :class:`scipy.signal.lti` (continuous) or :class:`scipy.signal.dlti`
        (``dt = ts``); an LPTV model is refused with the reason (a ValueError).

        Examples
        --------
        >>> import numpy as np, lptv
        >>> m = lptv.Model.from_tf([2.0], [1.0, 3.0])
        >>> w, H = m.to_scipy().freqresp([1.0])
        >>> bool(np.isclose(H[0], 2 / (1j + 3), rtol=1e-14))
        True
        """
        from ..use.export import to_scipy

        return to_scipy(self)

    def to_control(self, t: Optional[float] = None):
        """A python-control ``TransferFunction`` (``control.tf``; ``dt = ts`` in discrete time) of the
        LTI model or of the frozen system at time ``t``; an LPTV model without ``t`` is refused with
        the reason (a ValueError). Needs the optional extra ``pip install 'lptv[control]'``."""
        if t is None:
            from ..use.export import refuse_lptv

            refuse_lptv(self, "to_control")
        try:
            import control
        except ImportError:
            raise ImportError("Model.to_control needs python-control: pip install 'lptv[control]'") from None
        num, den = self.to_tf(t)
        return control.tf(num, den, self.ts) if self.discrete else control.tf(num, den)

    def freqresp(self, w, *, branch: int = 0, harmonics: Optional[int] = None) -> np.ndarray:
        """Frequency response at angular frequencies ``w`` (rad/s).

        For an LTI model ``B(s) / A(s)`` at ``s = j w`` (``z = exp(j w ts)`` in discrete time). For
        an LPTV model the harmonic transfer function's branch ``G_branch(w)``: an input exp(j w t)
        gives the output ``sum_k G_k(w) exp(j (w + k w0) t)``; ``branch=0`` is the time-averaged
        transfer function. It is computed by harmonic balance on ``2 harmonics + 1`` output
        harmonics (default ``max(32, 8 (Ka + Kb))``), converged for a stable, well-behaved model.

        Examples
        --------
        >>> import numpy as np, lptv
        >>> m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2)
        >>> bool(np.isclose(m.freqresp([2.0])[0], 1 / (2j + 2)))
        True
        """
        w = as_real_1d(w, "w")
        branch = as_int(branch, "branch", minimum=-2**31 + 1)
        if harmonics is not None:
            harmonics = as_int(harmonics, "harmonics", minimum=1, maximum=4096)
        if self.is_lti:
            if branch:
                return np.zeros(w.size, complex)
            x = np.exp(1j * w * self.ts) if self.discrete else 1j * w
            num, den = self.to_tf()
            return np.polyval(num, x) / np.polyval(den, x)
        return self._branches(w, [branch], harmonics)[0]

    def _branches(self, w, branches, harmonics=None) -> np.ndarray:
        """G_k(w) of an LPTV model for each k of ``branches`` (checked integers), shape
        (len(branches), w.size): one harmonic balance per frequency serves every branch, the
        balances of all frequencies solved as one stack (LAPACK's gesv on each matrix)."""
        L = max(32, 8 * (self.ka + self.kb)) if harmonics is None else int(harmonics)
        for branch in branches:
            if abs(branch) > L:
                raise ValueError(f"branch {branch} is beyond the {L} harmonics of the balance")
        w = np.asarray(w, float)
        M = 2 * L + 1
        block = max(1, 2**22 // (M * M))     # frequencies per stack: about 64 MB of matrices
        if w.size > block:
            return np.concatenate([self._branches(w[i:i + block], branches, L)
                                   for i in range(0, w.size, block)], axis=1)
        a, b, Ka, Kb = self.a, self.b, self.ka, self.kb
        ks = np.arange(-L, L + 1)
        if w.size == 0:
            return np.empty((len(branches), 0), complex)
        arg = w[:, None] + ks[None, :] * self.w0
        x = np.exp(1j * arg * self.ts) if self.discrete else 1j * arg
        A = np.zeros((w.size, M, M), complex)
        for n in range(self.na + 1):
            pw = x ** n
            for h in range(-Ka, Ka + 1):
                c = a[n, Ka + h]
                if c == 0:
                    continue
                # row k, column j = k - h: a_{n,h} x_j^n
                idx = np.arange(max(0, h), min(M, M + h))
                A[:, idx, idx - h] += c * pw[:, idx - h]
        rhs = np.zeros((w.size, M), complex)
        x0 = np.exp(1j * w * self.ts) if self.discrete else 1j * w
        for m in range(self.nb + 1):
            for h in range(-Kb, Kb + 1):
                rhs[:, L + h] += b[m, Kb + h] * x0 ** m
        X = np.linalg.solve(A, rhs[..., None])[..., 0]
        return np.stack([X[:, L + int(k)] for k in branches])

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
        if isinstance(t, (str, bytes)) or np.size(t) != 1:
            raise ValueError(f"t must be one time (s), got {t!r}: use a_at / b_at for many times")
        tt = as_real_1d(np.reshape(t, 1) if isinstance(t, np.ndarray) else t, "t")
        return self.b_at(tt)[0][::-1].copy(), self.a_at(tt)[0][::-1].copy()

    # -- persistence -------------------------------------------------------------
    def to_dict(self) -> dict:
        d = self._to_dict()
        if self.covariance is not None:
            d["eta_names"] = list(self.eta_names)
            d["covariance"] = np.asarray(self.covariance).tolist()
        if self.context is not None:
            d["context"] = dict(self.context)
        return d

    def _to_dict(self) -> dict:
        return {
            "format": "lptv.Model",
            "version": FORMAT_VERSION,
            "w0": self.w0,
            "ts": self.ts,
            "a_real": self.a.real.tolist(),
            "a_imag": self.a.imag.tolist(),
            "b_real": self.b.real.tolist(),
            "b_imag": self.b.imag.tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Model":
        """The model a :meth:`to_dict` description holds; every field is checked (its type, shape,
        finiteness, the format and version), and a wrong one is a ValueError naming it."""
        if not isinstance(d, dict) or d.get("format") != "lptv.Model":
            hint = " (an lptv.MimoModel description: read it with lptv.MimoModel.load)" \
                if isinstance(d, dict) and d.get("format") == "lptv.MimoModel" else ""
            raise ValueError(f"not an lptv.Model description (missing format: 'lptv.Model'){hint}")
        unknown = [k for k in d if k not in _FIELDS]
        if unknown:
            raise ValueError(f"lptv.Model description: unknown field {unknown[0]!r} (fields: {', '.join(_FIELDS)})")
        for key in ("w0", "a_real", "a_imag", "b_real", "b_imag", "version"):
            if key not in d:
                raise ValueError(f"lptv.Model description lacks the field {key!r}")
        v = d["version"]
        if isinstance(v, bool) or not isinstance(v, int) or v != FORMAT_VERSION:
            raise ValueError(f"lptv.Model description: version must be {FORMAT_VERSION} (the only version this "
                             f"lptv reads), got {v!r}")
        w0 = _w0(d["w0"])
        ts = _ts(d.get("ts"))

        def coef(key):
            _no_bool(d[key], f"lptv.Model description: {key}")
            try:
                arr = np.array(d[key], dtype=float)
            except (TypeError, ValueError):
                raise ValueError(f"lptv.Model description: {key} must be a 2-D list of numbers, "
                                 f"got {_short(d[key])}") from None
            if arr.ndim != 2 or arr.size == 0:
                raise ValueError(f"lptv.Model description: {key} must be a non-empty 2-D list of numbers, "
                                 f"got shape {arr.shape}")
            return arr

        parts = {k: coef(k) for k in ("a_real", "a_imag", "b_real", "b_imag")}
        for side in "ab":
            re_, im = parts[f"{side}_real"], parts[f"{side}_imag"]
            if re_.shape != im.shape:
                raise ValueError(f"lptv.Model description: {side}_imag must have the shape of {side}_real "
                                 f"{re_.shape}, got {im.shape}")
        try:
            m = cls(parts["a_real"] + 1j * parts["a_imag"], parts["b_real"] + 1j * parts["b_imag"], w0=w0, ts=ts)
        except ValueError as e:
            raise ValueError(f"lptv.Model description: {e}") from None
        try:
            check_leading(m)
        except ValueError as e:
            raise ValueError(f"lptv.Model description: a_real, a_imag: {e}") from None
        if d.get("covariance") is not None:
            m.eta_names, m.covariance = read_covariance(d, "lptv.Model description")
        if "context" in d:
            from ..use.modelfile import check_context

            try:
                m.context = check_context(d["context"], m)
            except ValueError as e:
                raise ValueError(f"lptv.Model description: {e}") from None
        return m

    def save(self, path) -> None:
        """Write the model as JSON (readable by :meth:`Model.load`)."""
        from ..atomic import atomic_open

        with atomic_open(as_path(path)) as f:     # whole or not at all
            json.dump(self.to_dict(), f, indent=1)

    @classmethod
    def load(cls, path) -> "Model":
        """Read a model written by :meth:`Model.save`. A file that is not such a description (not
        JSON, binary, another version, a field of the wrong type or shape) is a ValueError naming
        the file and the problem; a missing file is FileNotFoundError."""
        d = load_json(path)
        try:
            return cls.from_dict(d)
        except ValueError as e:
            raise ValueError(f"{os.fspath(path)}: {e}") from None

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


def _no_bool(x, where):
    """Refuse true/false anywhere in a nested list of a description's numbers: NumPy would read
    them as 1 and 0 without a word."""
    stack = [(x, "")]
    while stack:
        v, at = stack.pop()
        if isinstance(v, bool):
            raise ValueError(f"{where}{at} holds {str(v).lower()}, not a number")
        if isinstance(v, (list, tuple)):
            stack.extend(reversed([(e, f"{at}[{i}]") for i, e in enumerate(v)]))   # the first one first


# A symmetric covariance's entries agree to the last bits; its diagonal (the variances) is >= 0.
_SYMMETRY_RTOL = 1e-9


def read_covariance(d: dict, what: str):
    """(eta_names, covariance) of a description's ``eta_names`` and ``covariance`` keys, each
    checked: a list of names, a square finite matrix of their size, a covariance."""
    cov, names = d.get("covariance"), d.get("eta_names", ())
    if not isinstance(names, (list, tuple)) or not all(isinstance(n, str) for n in names):
        raise ValueError(f"{what}: eta_names must be a list of parameter names, got {_short(names)}")
    _no_bool(cov, f"{what}: covariance")
    try:
        cov = np.array(cov, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: covariance must be a square list of numbers, got {_short(cov)}") from None
    if cov.shape != (len(names), len(names)):
        raise ValueError(f"{what}: covariance of shape {cov.shape} does not match its {len(names)} eta_names")
    if not np.all(np.isfinite(cov)):
        raise ValueError(f"{what}: covariance contains NaN or inf")
    check_covariance(cov, names, what)
    return tuple(names), cov


def check_covariance(cov: np.ndarray, names, what: str = "lptv.Model description") -> None:
    """A saved covariance must be a covariance: no negative variance, symmetric up to rounding."""
    diag = np.diag(cov)
    if np.any(diag < 0):
        i = int(np.argmax(diag < 0))
        raise ValueError(f"{what}: covariance has the negative variance {diag[i]:.6g} on its "
                         f"diagonal (entry {i}, {names[i]}): not a covariance")
    scale = float(np.max(np.abs(cov))) if cov.size else 0.0
    gap = np.abs(cov - cov.T)
    if cov.size and float(gap.max()) > _SYMMETRY_RTOL * scale:
        i, j = np.unravel_index(int(np.argmax(gap)), gap.shape)
        raise ValueError(f"{what}: covariance is not symmetric: entry [{i}][{j}] = "
                         f"{cov[i, j]:.6g} but [{j}][{i}] = {cov[j, i]:.6g}")


def check_leading(model) -> None:
    """The leading coefficient a_na(t) must not vanish within the period: the equation cannot be
    solved for the highest derivative (the highest shift) where it does. Continuous time: on a grid
    of 256 points per harmonic (a_na(t) is a trigonometric polynomial of degree Ka), a sign change
    of its real part with a small imaginary part, or a value below 1e-12 of its largest; discrete
    time: at each of the N samples, a value below 1e-14 of the largest (the thresholds of the
    core's monodromy)."""
    na = model.na
    if model.discrete:
        N = model.samples_per_period
        t = np.arange(N) * model.ts
        v = model.a_at(t)[:, na]
        vmax = np.max(np.abs(v))
        bad = np.flatnonzero(np.abs(v) <= 1e-14 * vmax)
        if bad.size:
            raise ValueError(f"the leading coefficient a_{na}[k] vanishes at sample k = {bad[0]} of the period; "
                             f"the recursion cannot be solved for y[k + {na}] there")
        return
    n = 256 * (model.ka + 1) + 1
    t = np.linspace(0.0, model.period, n)
    v = model.a_at(t)[:, na]
    vmax = np.max(np.abs(v))
    small = np.abs(v) <= 1e-12 * vmax
    re = v.real
    flips = (np.signbit(re[1:]) != np.signbit(re[:-1])) & (np.abs(v.imag[1:]) <= 1e-6 * vmax)
    if small.any() or flips.any():
        i = int(np.argmax(small)) if small.any() else None
        k = int(np.argmax(flips)) if flips.any() else None
        if i is None or (k is not None and k < i):
            tz = t[k] + (t[k + 1] - t[k]) * re[k] / (re[k] - re[k + 1])
        else:
            tz = t[i]
        raise ValueError(f"the leading coefficient a_{na}(t) vanishes near t = {tz:.6g} s (period "
                         f"{model.period:.6g} s): the equation cannot be solved for the highest derivative there")


def _short(x) -> str:
    r = repr(x)
    return r if len(r) <= 60 else r[:57] + "..."
