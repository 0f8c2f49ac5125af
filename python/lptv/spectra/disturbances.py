"""Disturbances that are not periodic in the record: sinusoids off the period's grid (METHOD.md
section 7, "Disturbances that are not periodic in the record").

The noise model of :meth:`lptv.FrequencyData.from_periods` takes everything that differs
between the periods as noise. A sinusoid whose frequency is not a line of the grid (mains hum
beside a multisine whose period is not a multiple of the mains period) changes phase from one
period to the next: its mean over the periods nearly cancels while its sample variance does
not, and by leakage it inflates the variances of dozens of lines around it. The fit then weighs
those lines by a variance its residues never reach, and the verdict finds residues "too small".
:func:`disturbances` finds such sinusoids in the deviations of the periods from their mean and
removes them; ``lptv.identify(u, y, ..., disturbances="remove")`` does it before the fit.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Tuple

import numpy as np

from .._validate import as_float, as_int, as_periods

ALPHA = 1e-3
"""Probability that noise alone puts one bin of a record above the detection threshold."""
HALF_WIDTH = 64
"""Half width (in bins of the record's grid) of the median that gives the local noise level."""
SEARCH_POINTS = 81
"""Frequencies tried within one bin either side of a peak before the parabolic refinement."""


@dataclass(frozen=True)
class Disturbance:
    """One sinusoid found in a signal: ``amplitude * cos(2 pi line n / N + phase)`` at sample n
    of the record (n = 0 at the first sample of the first period, N samples per period)."""

    signal: str
    """'u' (the input record) or 'y' (the output record)."""
    line: float
    """Its frequency in lines (cycles per period, not an integer: off the grid); times ``w0``
    it is in rad/s."""
    amplitude: float
    phase: float
    """Radians."""
    level: float
    """The peak bin's power over the local noise level: the detection statistic, compared with
    ln(M / alpha) (M the bins searched)."""


@dataclass(frozen=True)
class DisturbanceResult:
    """What :func:`disturbances` returns: the sinusoids found and the periods without them."""

    found: Tuple[Disturbance, ...]
    u: np.ndarray
    """The input periods (P, N) with the input's disturbances subtracted."""
    y: np.ndarray
    """The output periods with the output's disturbances subtracted."""
    threshold: float
    """The detection threshold for these records (METHOD.md section 7: ln(M / alpha), raised for
    the sampling error of the local noise level)."""
    spectra: dict = field(default_factory=dict, repr=False)
    """Per signal ('u', 'y'): (position in lines k / P, |R_k|^2, the local noise level lambda_k)
    of the deviation's spectrum before any removal, on the bins searched (what
    :func:`lptv.plots.disturbances` draws)."""

    def summary(self) -> str:
        """One line per disturbance, or a line saying there is none."""
        if not self.found:
            return f"no disturbance that is not periodic in the record (threshold {self.threshold:.1f})"
        return "\n".join(f"{d.signal}: a sinusoid at line {d.line:.3f}, amplitude {d.amplitude:.3g}, "
                         f"{d.level:.3g} times the local noise level (threshold {self.threshold:.1f})"
                         for d in self.found)


def _periods(x, name):
    a = as_periods(x, name)
    if a.shape[0] < 2:
        raise ValueError(f"{name}: at least 2 periods are needed, got P = {a.shape[0]}")
    if a.shape[1] < 4:
        raise ValueError(f"{name}: a period needs at least 4 samples, got {a.shape[1]}")
    return a


def _deviation(x, P, N):
    xp = x.reshape(P, N)
    return (xp - xp.mean(0)).reshape(-1)


def _local_level(p2, valid, half_width):
    """lambda_k: the median of |R_j|^2 over blocks of 2 H + 1 valid bins, over ln 2,
    interpolated between the blocks' centres."""
    idx = np.flatnonzero(valid)
    vals = p2[idx]
    B = 2 * half_width + 1
    nb = max(1, idx.size // B)
    edges = np.linspace(0, idx.size, nb + 1).astype(int)
    centres = np.array([idx[(a + b - 1) // 2] for a, b in zip(edges[:-1], edges[1:])], float)
    meds = np.array([np.median(vals[a:b]) for a, b in zip(edges[:-1], edges[1:])]) / np.log(2.0)
    return np.interp(np.arange(p2.size), centres, meds)


def _threshold(M, alpha, n_level):
    """t with P(max of M bins' |R|^2 / lambda_hat > t) = alpha: |R|^2 / lambda ~ Exp(1), and
    lambda_hat = lambda (1 + eps) from the median of n_level bins, eps about N(0, s^2) with
    s = 1 / (ln 2 sqrt(n_level)) (the median of Exp(1) has asymptotic variance 1 / n), so that
    P(|R|^2 / lambda_hat > t) = exp(-t + t^2 s^2 / 2) and t - t^2 s^2 / 2 = ln(M / alpha)."""
    L = float(np.log(max(M, 1) / alpha))
    s2 = 1.0 / (np.log(2.0) ** 2 * max(n_level, 1))
    disc = 1.0 - 2.0 * s2 * L
    return (1.0 - np.sqrt(disc)) / s2 if disc > 0 else 2.0 * L


def _fit_at(r, n, f, P, N):
    """Least squares of r on cos and sin at f (cycles per sample), as r sees them (minus their
    periodic means): (reduction of sum r^2, coefficients)."""
    w = 2.0 * np.pi * f * n
    X = np.stack([_deviation(np.cos(w), P, N), _deviation(np.sin(w), P, N)], axis=1)
    coef, *_ = np.linalg.lstsq(X, r, rcond=1e-10)
    return float(coef @ (X.T @ r)), coef


def _find(x, P, N, alpha, max_count, half_width, name):
    x = x.reshape(-1).copy()
    M_total = P * N
    n = np.arange(M_total, dtype=float)
    k = np.arange(M_total // 2 + 1)
    valid = (k % P != 0) & (k > 0) & (2 * k < M_total)
    M = int(valid.sum())
    threshold = _threshold(M, alpha, min(M, 2 * half_width + 1))
    found = []
    spectrum = None
    if M < 2 * half_width + 1:
        return x.reshape(P, N), found, threshold, spectrum
    for it in range(max(max_count, 1)):
        r = _deviation(x, P, N)
        p2 = np.abs(np.fft.rfft(r)) ** 2
        level = _local_level(p2, valid, half_width)
        if it == 0:
            spectrum = (k[valid] / P, p2[valid], level[valid])
        if it >= max_count:
            break
        ratio = np.where(valid & (level > 0), p2 / np.where(level > 0, level, 1.0), 0.0)
        k0 = int(np.argmax(ratio))
        if ratio[k0] <= threshold:
            break
        grid = (k0 + np.linspace(-1.0, 1.0, SEARCH_POINTS)) / M_total
        red = np.array([_fit_at(r, n, f, P, N)[0] for f in grid])
        i = int(np.argmax(red))
        f = grid[i]
        if 0 < i < grid.size - 1:       # a parabola through the best three
            y0, y1, y2 = red[i - 1], red[i], red[i + 1]
            den = y0 - 2 * y1 + y2
            if den < 0:
                f = grid[i] + 0.5 * (y0 - y2) / den * (grid[1] - grid[0])
        _, coef = _fit_at(r, n, f, P, N)
        w = 2.0 * np.pi * f * n
        x -= coef[0] * np.cos(w) + coef[1] * np.sin(w)
        found.append(Disturbance(signal=name, line=float(f * N), amplitude=float(np.hypot(*coef)),
                                 phase=float(np.arctan2(-coef[1], coef[0])), level=float(ratio[k0])))
    return x.reshape(P, N), found, threshold, spectrum


def disturbances(u, y, *, alpha: float = ALPHA, max_count: int = 8) -> DisturbanceResult:
    """Find and remove sinusoids that are not periodic in the record (off the period's grid).

    Per signal, the P periods' deviation from their mean is searched on the record's grid (the
    DFT of all P N samples, P bins per line): noise alone gives each bin an exponential power
    about a smooth level (a local median), and a bin whose power over that level exceeds
    ln(M / ``alpha``) (M bins searched) is a disturbance; its frequency, amplitude and phase are
    fitted by least squares and the whole sinusoid is subtracted, then the search repeats, up
    to ``max_count`` per signal (METHOD.md section 7). Components on the grid (periodic in the
    record) are signal and are left alone.

    Parameters
    ----------
    u, y : array_like, shape (P, N)
        P >= 2 periods of input and output, as for :func:`lptv.identify`.
    alpha : float
        Probability that noise alone gives a record a (false) disturbance, per signal.
    max_count : int
        At most this many disturbances per signal.

    Returns
    -------
    DisturbanceResult
        ``.found`` (the sinusoids, input's first), ``.u``, ``.y`` (the periods without them),
        ``.summary()``; :func:`lptv.plots.disturbances` draws what was searched.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> P, N = 8, 512
    >>> n = np.arange(P * N)
    >>> y = 0.01 * rng.standard_normal(P * N) + 0.05 * np.cos(2 * np.pi * 40.37 * n / N)
    >>> u = np.tile(np.cos(2 * np.pi * 3 * np.arange(N) / N), (P, 1))
    >>> out = lptv.disturbances(u, y.reshape(P, N))
    >>> [(d.signal, round(d.line, 2), round(d.amplitude, 3)) for d in out.found]
    [('y', 40.37, 0.05)]
    """
    u = _periods(u, "u")
    y = _periods(y, "y")
    if u.shape != y.shape:
        raise ValueError(f"u and y must have the same shape (P, N), got {u.shape} and {y.shape}")
    alpha = as_float(alpha, "alpha", minimum=0.0, open_min=True, maximum=0.5)
    max_count = as_int(max_count, "max_count", minimum=0)
    P, N = u.shape
    u2, fu, threshold, su = _find(u, P, N, alpha, max_count, HALF_WIDTH, "u")
    y2, fy, _, sy = _find(y, P, N, alpha, max_count, HALF_WIDTH, "y")
    spectra = {name: sp for name, sp in (("u", su), ("y", sy)) if sp is not None}
    return DisturbanceResult(found=tuple(fu + fy), u=u2, y=y2, threshold=threshold, spectra=spectra)
