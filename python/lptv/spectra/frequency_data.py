"""Frequency data with its nonparametric noise model (METHOD.md section 4)."""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Optional

import numpy as np

from .. import _core
from .._validate import _array, as_float, as_int, as_optional, as_periods, check_finite

_periods_array = as_periods  # the name from_periods calls it by


def _line_vector(x, name, n, dtype):
    """One value per line 0..L (1-D, numeric, finite); n = None takes the length from x."""
    a = _array(x, name)
    if a.ndim != 1:
        raise ValueError(f"{name} must be 1-D, one value per line 0..L, got shape {a.shape}")
    if n is not None and a.size != n:
        raise ValueError(f"{name} must be 1-D with {n} lines like U, got shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"{name} must not be empty (one value per line 0..L)")
    if dtype is float and np.iscomplexobj(a):
        raise ValueError(f"{name} must be real (a variance), got complex values")
    a = a.astype(dtype)
    check_finite(a, name)
    return a


def _real_dc(X, name):
    scale = max(float(np.abs(X).max()), 1e-300)
    if abs(X[0].imag) > 1e-12 * scale:
        raise ValueError(f"{name}: line 0 (DC) must be real for a real signal, got {X[0]}")


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

    distortion = None
    """The :class:`lptv.DistortionResult` whose realisation this is (set by
    :meth:`lptv.DistortionResult.experiments`), else None."""
    realisation = None
    """Its index among that result's realisations, else None."""
    referred = None
    """How that result put the nonlinear distortion into these variances: 'output', 'input' or
    'none' (the noise alone), else None."""

    def __init__(self, U, Y, varU, varY, covYU=None, *, w0: float, ts: Optional[float] = None,
                 periods: int = 0):
        U = _line_vector(U, "U", None, complex)
        n = U.size
        Y = _line_vector(Y, "Y", n, complex)
        varU = _line_vector(varU, "varU", n, float)
        varY = _line_vector(varY, "varY", n, float)
        covYU = np.zeros(n, complex) if covYU is None else _line_vector(covYU, "covYU", n, complex)
        _real_dc(U, "U")
        _real_dc(Y, "Y")
        if np.any(varU < 0):
            raise ValueError("varU must be >= 0 (a variance)")
        if np.any(varY < 0):
            raise ValueError("varY must be >= 0 (a variance)")
        bad = np.flatnonzero(np.abs(covYU) ** 2 > varU * varY * (1 + 1e-12))
        if bad.size:
            raise ValueError(f"covYU: |covYU|^2 must not exceed varU * varY (a covariance), not so on line {bad[0]}")
        periods = as_int(periods, "periods")
        if periods == 1:
            raise ValueError("periods must be 0 (statistics from elsewhere) or >= 2 (the periods the "
                             "variances were estimated from), got 1")
        w0, ts = self._check(w0, ts)
        self._set(_core.FrequencyData(U, Y, varU, varY, covYU, periods), w0, ts)

    @staticmethod
    def _check(w0, ts):
        w0 = as_float(w0, "w0", minimum=0.0, open_min=True,
                      what="a finite positive angular frequency (rad/s)")
        ts = as_optional(ts, as_float, "ts", minimum=0.0, open_min=True, what="a positive sample period or None")
        return w0, ts

    def _set(self, cpp, w0, ts):
        w0, ts = self._check(w0, ts)
        self._cpp = cpp
        self.w0 = float(w0)
        self.ts = None if ts is None else float(ts)

    statistics = "given"
    """Where the (co)variances came from: 'periods' (the periods' sample statistics, section 4 of
    METHOD.md), 'record' (the whole record's bins between the lines, section 20) or 'given'."""

    @classmethod
    def from_periods(cls, u, y, *, w0: float, ts: Optional[float] = None,
                     statistics: str = "periods") -> "FrequencyData":
        """Spectra and noise statistics from P >= 2 steady-state periods.

        Parameters
        ----------
        u, y : array_like, shape (P, N)
            P consecutive periods of N samples of the input and the output.
        w0 : float
            Fundamental of the period (rad/s); line l is the frequency l * w0.
        ts : float, optional
            Sample period for a discrete-time model (N * ts * w0 = 2 pi).
        statistics : {'periods', 'record'}
            'periods' (default): each line's sample (co)variances over the periods (METHOD.md
            section 4). 'record': from the bins between the lines of the whole record's DFT
            (METHOD.md section 20), right also when the noise is the system's response to a
            disturbance that does not repeat (its leakage telescopes there as in the mean);
            the data then hold the noise's realisations (``noise_realisations``). The means
            are the same.

        Examples
        --------
        >>> import numpy as np, lptv
        >>> rng = np.random.default_rng(0)
        >>> u = rng.standard_normal((4, 64)); y = 2 * u + 0.1 * rng.standard_normal((4, 64))
        >>> d = lptv.FrequencyData.from_periods(u, y, w0=1.0, statistics="record")
        >>> d.statistics, d.noise_realisations[0].shape
        ('record', (3, 33))
        """
        if not isinstance(statistics, str) or statistics not in ("periods", "record"):
            raise ValueError(f"statistics must be 'periods' or 'record', got {statistics!r}")
        w0, ts = cls._check(w0, ts)
        u = _periods_array(u, "u")
        y = _periods_array(y, "y")
        if u.shape != y.shape:
            raise ValueError(f"u and y must have the same shape (P, N), got {u.shape} and {y.shape}")
        if u.shape[0] < 2:
            raise ValueError(f"u, y: at least 2 periods are needed for a noise model, got P = {u.shape[0]}")
        if ts is not None:
            n_expected = 2 * np.pi / (w0 * ts)
            if abs(n_expected - u.shape[1]) > 1e-6 * u.shape[1]:
                raise ValueError(f"u, y: {u.shape[1]} samples per period, but w0 = {w0:g} and ts = {ts:g} "
                                 f"give 2 pi / (w0 ts) = {n_expected:.6g}")
        if u.shape[1] < 2:
            raise ValueError("u, y: a period needs at least 2 samples")
        # NumPy's FFT (pocketfft, all periods in one call) and the statistics in the core: about
        # three times as fast as the core's own from_periods (Eigen's FFT, one period at a time).
        n = u.shape[1]
        Up = np.fft.rfft(u, axis=1)
        Up *= 1.0 / n
        Yp = np.fft.rfft(y, axis=1)
        Yp *= 1.0 / n
        obj = cls.__new__(cls)
        if statistics == "record":
            P = u.shape[0]
            Ur = np.fft.rfft(u.reshape(-1))
            Ur *= 1.0 / (P * n)
            Yr = np.fft.rfft(y.reshape(-1))
            Yr *= 1.0 / (P * n)
            obj._set(_core.FrequencyData.from_record_spectra(Up, Yp, Ur, Yr, n), w0, ts)
        else:
            obj._set(_core.FrequencyData.from_period_spectra(Up, Yp), w0, ts)
        obj.statistics = statistics
        obj._spectra = (Up, Yp)
        obj._record = (u, y)
        return obj

    def record_statistics(self) -> "FrequencyData":
        """These data with the (co)variances from the whole record's bins between the lines
        (``statistics='record'``, METHOD.md section 20); needs data made by :meth:`from_periods`."""
        if self.statistics == "record":
            return self
        rec = getattr(self, "_record", None)
        if rec is None:
            raise ValueError("the record's statistics need the periods: make the data with "
                             "FrequencyData.from_periods(u, y, ...)")
        return FrequencyData.from_periods(rec[0], rec[1], w0=self.w0, ts=self.ts, statistics="record")

    def with_realisations(self, noiseU, noiseY, *, like) -> "FrequencyData":
        """These data with noise realisations (P - 1, lines) on the lines and offsets of ``like``'s
        (a :class:`FrequencyData` with ``statistics='record'``); their sums of squares replace
        nothing: the (co)variances stay these data's."""
        cpp = _core.FrequencyData.with_realisations(self._cpp, np.ascontiguousarray(noiseU, complex),
                                                    np.ascontiguousarray(noiseY, complex), like._cpp)
        out = FrequencyData.__new__(FrequencyData)
        out._set(cpp, self.w0, self.ts)
        out.statistics = like.statistics
        return out

    @property
    def noise_realisations(self):
        """(noiseU, noiseY), each (P - 1, lines): realisations of the means' noise whose sums of
        squares are the (co)variances (``statistics='record'``), else None."""
        nu = np.asarray(self._cpp.noiseU)
        if nu.size == 0:
            return None
        return nu, np.asarray(self._cpp.noiseY)

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
        if w0 is not None and not np.isclose(as_float(w0, "w0"), u.w0):
            raise ValueError(f"w0={w0} disagrees with the data's w0={u.w0}")
        if ts is not None and u.ts is not None and not np.isclose(as_float(ts, "ts"), u.ts):
            raise ValueError(f"ts={ts} disagrees with the data's ts={u.ts}")
        return u
    if y is None:
        raise ValueError("y is missing: pass u and y of shape (P, N), or a FrequencyData")
    if w0 is None:
        raise ValueError("w0 is missing: the fundamental of the period (rad/s)")
    return FrequencyData.from_periods(u, y, w0=w0, ts=ts)


def experiments_of(items, w0, ts) -> list:
    """The data of several experiments of one system: ``items`` a list (or tuple) of
    :class:`FrequencyData` and/or ``(u, y)`` pairs of P_e x N_e period arrays (``w0``, ``ts`` as for
    one data set). Each experiment may have its own P and N; all must share the period (w0) and
    the time domain (continuous, or discrete with one sample period)."""
    if not isinstance(items, (list, tuple)):
        raise ValueError(f"experiments must be a list of FrequencyData or (u, y) pairs, got {type(items).__name__}")
    if len(items) == 0:
        raise ValueError("experiments: the list is empty (give one or more FrequencyData or (u, y) pairs)")
    datas = []
    for i, item in enumerate(items):
        if isinstance(item, FrequencyData):
            args = (item, None)
        elif isinstance(item, (list, tuple)) and len(item) == 2:
            args = tuple(item)
        else:
            raise ValueError(f"experiments[{i}] must be a FrequencyData or a (u, y) pair of period arrays, "
                             f"got {type(item).__name__}" + (f" of length {len(item)}"
                                                             if isinstance(item, (list, tuple)) else ""))
        try:
            datas.append(frequency_data_of(args[0], args[1], w0, ts))
        except ValueError as e:
            raise ValueError(f"experiments[{i}]: {e}") from None
    first = datas[0]
    for i, d in enumerate(datas[1:], start=1):
        if not np.isclose(d.w0, first.w0, rtol=1e-9, atol=0):
            raise ValueError(f"experiments disagree on the period: experiments[0] has w0 = {first.w0:.10g} rad/s, "
                             f"experiments[{i}] has w0 = {d.w0:.10g} rad/s (one model needs one period)")
        if (d.ts is None) != (first.ts is None):
            kind = lambda x: "continuous time (no ts)" if x.ts is None else f"discrete time (ts = {x.ts:g})"
            raise ValueError(f"experiments mix time domains: experiments[0] is {kind(first)}, "
                             f"experiments[{i}] is {kind(d)}")
        if d.ts is not None and not np.isclose(d.ts, first.ts, rtol=1e-9, atol=0):
            raise ValueError(f"experiments disagree on the sample period of the discrete-time model: "
                             f"experiments[0] has ts = {first.ts:g}, experiments[{i}] has ts = {d.ts:g}")
    refuse_repeated_experiments(datas)
    return datas


def refuse_repeated_experiments(datas) -> None:
    """A UserWarning when two experiments hold the same spectra (the same record given twice):
    fitted as two independent experiments, one measurement counts twice and every std shrinks by
    sqrt 2. Any data with ``U`` and ``Y`` arrays (one channel or several)."""
    seen = {}
    for i, d in enumerate(datas):
        U, Y = np.asarray(d.U), np.asarray(d.Y)
        key = (U.shape, Y.shape, U.tobytes(), Y.tobytes())
        if key in seen and np.any(U != 0):
            warnings.warn(f"experiments[{seen[key]}] and experiments[{i}] hold the same data (the same record "
                          "given twice?): fitted as two independent experiments, one measurement counts twice "
                          "and every std shrinks by sqrt 2; give each record once", UserWarning, stacklevel=4)
        seen.setdefault(key, i)


LINES_ALPHA = 0.01
"""The size of :func:`correlated_lines` over its two channels (Bonferroni)."""


@dataclass(frozen=True)
class LineCorrelation:
    """The test of :func:`correlated_lines`: for the input and the output, the lag-1 and lag-2
    sums of the periods' normalised deviations' inner products between lines, their chi-square
    statistic (4 degrees of freedom) and p-value; ``correlated`` when either p-value is below
    ``LINES_ALPHA / 2``."""

    correlated: bool
    statistic: tuple
    p_value: tuple
    pairs: int
    reason: str


def correlated_lines(d, alpha: float = LINES_ALPHA) -> LineCorrelation:
    """Whether the noise of neighbouring lines is correlated in the periods (METHOD.md section 20).

    Per channel X (input, output) and line l = 1 .. Lmax - 1, the deviations of the P periods'
    spectra from their mean, v_l in C^P, and c_l^(k) = <v_l, v_{l+k}> / (|v_l| |v_{l+k}|) for the
    lags k = 1, 2. Noise independent from line to line leaves the directions of the v_l
    independent and uniform in the (P - 1)-dimensional space of deviations, so
    S_k = sum_l c_l^(k) has mean 0 and E|S_k|^2 = n_k / (P - 1), the terms uncorrelated; then
    X^2 = 2 (P - 1) (|S_1|^2 / n_1 + |S_2|^2 / n_2) is about chi-square with 4 degrees of freedom.
    A disturbance whose response does not repeat leaks into every period's lines as a smooth
    term, and one filtered by a periodically time-varying system correlates the lines l and
    l +- k: both make the deviations of neighbouring lines alike.

    Parameters
    ----------
    d : FrequencyData
        Data made by :meth:`FrequencyData.from_periods` (the periods' spectra are needed).
    alpha : float
        The test's size over both channels.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(1)
    >>> u = rng.standard_normal((8, 256)); y = u + 0.1 * rng.standard_normal((8, 256))
    >>> lptv.correlated_lines(lptv.FrequencyData.from_periods(u, y, w0=1.0)).correlated
    False
    """
    alpha = as_float(alpha, "alpha", minimum=0.0, maximum=1.0, open_min=True, open_max=True,
                     what="a probability strictly between 0 and 1")
    spectra = getattr(d, "_spectra", None)
    if spectra is None:
        raise ValueError(f"d must be data made by FrequencyData.from_periods(u, y, ...) (the test reads the "
                         f"periods' spectra), got {type(d).__name__}")
    names = getattr(d, "_channel_names", ("the input", "the output"))
    return line_correlation(spectra, names, alpha)


def line_correlation(spectra, names, alpha: float = LINES_ALPHA) -> LineCorrelation:
    """:func:`correlated_lines` on the periods' spectra of each channel (a sequence of (P, lines)
    arrays) named by ``names``; Bonferroni over the channels."""
    P = spectra[0].shape[0]
    stat, pval, pairs = [], [], 0
    for X in spectra:
        V = X[:, 1:-1] - X[:, 1:-1].mean(0)
        norm = np.sqrt(np.einsum("pl,pl->l", V.real, V.real) + np.einsum("pl,pl->l", V.imag, V.imag))
        x2 = 0.0
        for k in (1, 2):
            na, nb = norm[:-k], norm[k:]
            ok = (na > 1e-300) & (nb > 1e-300)
            n = int(np.count_nonzero(ok))
            if n < 8:
                x2 = np.nan
                break
            dot = np.einsum("pl,pl->l", V[:, :-k], V[:, k:].conj())
            c = dot[ok] / (na[ok] * nb[ok])
            x2 += 2 * (P - 1) * abs(np.sum(c)) ** 2 / n
            pairs = max(pairs, n)
        stat.append(float(x2))
        # chi-square with 4 degrees of freedom: P(X > x) = exp(-x / 2) (1 + x / 2)
        pval.append(float(np.exp(-x2 / 2) * (1 + x2 / 2)) if np.isfinite(x2) else 1.0)
    m = len(spectra)
    hit = [i for i, p in enumerate(pval) if p < alpha / m]
    if hit:
        reason = ("the noise of neighbouring lines is correlated in " + " and ".join(names[i] for i in hit)
                  + " (p = " + ", ".join(f"{pval[i]:.2g}" for i in hit)
                  + "): a disturbance that passes through the system or does not repeat in the periods")
    else:
        reason = ("the noise of neighbouring lines is not correlated (p = "
                  + ", ".join(f"{p:.2g} in {n}" for p, n in zip(pval, names)) + ")")
    return LineCorrelation(bool(hit), tuple(stat), tuple(pval), pairs, reason)
