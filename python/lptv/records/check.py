"""Checks of a record of periods before it is fitted: a start-up transient, a drift, periods cut
at the wrong length (:func:`check_record`), and the drift's removal (:func:`detrended`; the
``detrend`` option of :func:`lptv.read_measurements`). Importable from :mod:`lptv.records.measurements`
as well, where they were first."""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Tuple

import numpy as np

from .._validate import as_bool, as_float


class RecordWarning(UserWarning):
    """The record does not look like steady-state periods (a transient, or the wrong period)."""


@dataclass(frozen=True)
class RecordCheck:
    """What :func:`check_record` found in P periods of u and y."""

    transient_ratio: float
    """Power of (first period - mean of the others) over what the noise explains (about 1
    in steady state; inf where the others are noise-free and the first differs); nan for P < 3."""
    transient_threshold: float
    """The ratio above which the first period is reported as a transient."""
    input_spread: float
    """Mean variance of the input over the periods relative to the power of its mean period: small
    (the input noise-to-signal ratio) for a periodic input cut at its period, about 1 or more for
    a record cut at the wrong length."""
    messages: Tuple[str, ...]

    @property
    def ok(self) -> bool:
        return not self.messages


def _transient_ratio(x):
    P, N = x.shape
    rest = x[1:]
    d = x[0] - rest.mean(axis=0)
    s2 = rest.var(axis=0, ddof=1).mean()
    num = float(np.mean(d ** 2))
    if s2 <= 0:
        return np.inf if num > 1e-24 * max(float(np.mean(x ** 2)), 1e-300) else 1.0
    return num / (s2 * (1.0 + 1.0 / (P - 1)))


DRIFT_T = 8.0
"""A drift is reported when its slope stands this many standard errors from zero ..."""
DRIFT_FRACTION = 0.25
"""... and explains at least this share of the periods' deviations from their mean."""


def _drift(x):
    """(slope per period, its t statistic, the share of the deviations it explains) of a linear
    trend through the record x (P, N): x[p, n] = m[n] + beta (p + n / N) + noise, m free, so that
    the deviations from the mean period are beta (p - (P - 1) / 2) + noise, whatever m is."""
    P, N = x.shape
    dev = x - x.mean(axis=0)
    c = np.arange(P) - (P - 1) / 2.0
    scc = N * float(c @ c)
    beta = float(c @ dev.sum(axis=1)) / scc
    total = float(np.sum(dev ** 2))
    explained = beta ** 2 * scc
    dof = N * (P - 1) - 1
    if dof < 1 or total <= 0:
        return beta, 0.0, 0.0
    s2 = max(total - explained, 1e-300 * total) / dof
    return beta, abs(beta) / np.sqrt(s2 / scc), explained / total


def detrended(x, beta=None):
    """x (P, N) without its linear trend across the periods (:func:`_drift`'s beta), each
    period's shape and the mean level kept."""
    x = np.asarray(x, dtype=float)
    P, N = x.shape
    if beta is None:
        beta = _drift(x)[0]
    t = np.arange(P)[:, None] + np.arange(N)[None, :] / N
    return x - beta * (t - t.mean())


def check_record(u, y, *, warn: bool = True, spread_limit: float = 0.1) -> RecordCheck:
    """Look for a start-up transient, a drift and for periods cut at the wrong length.

    The transient check compares the first period with the mean of the others, relative to the
    noise the other periods show: ``r = mean((x_1 - mean_{p>1} x_p)^2) / (s^2 (1 + 1/(P-1)))``
    with ``s^2`` the sample variance over periods 2..P, for the input and the output (the larger
    is reported). In steady state r is about 1 with standard deviation about
    ``sqrt(2 / N + 2 / (N (P - 2)))`` (white noise); a first period above 1 + 6 such deviations (and
    above 1.5) is reported with the advice to drop it (``skip_periods=1`` / ``--skip-periods 1``).
    It needs P >= 3.

    The drift check fits a linear trend through each channel across the periods (the mean period
    free): a slope more than ``DRIFT_T`` = 8 standard errors from zero that explains more than
    ``DRIFT_FRACTION`` = 25 % of the periods' deviations from their mean is reported as a drift,
    with the advice to detrend (``detrend=True`` of :func:`read_measurements`, ``--detrend``);
    the first period is then judged a transient only if it still differs once the drift is out.

    The period check: a periodic input (a generator's multisine) cut at its period repeats up to
    its noise; ``input_spread`` (the mean variance over the periods over the power of the mean
    period) above ``spread_limit`` says the record is not cut into its periods (wrong count,
    period or sampling frequency).

    Parameters
    ----------
    u, y : array_like, shape (P, N)
    warn : bool
        Also issue each message as a :class:`RecordWarning`.
    spread_limit : float

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> x = np.tile(np.sin(2 * np.pi * np.arange(100) / 100), (6, 1))
    >>> y = x + 0.01 * rng.standard_normal(x.shape)
    >>> y[0] += 0.2 * np.exp(-np.arange(100) / 10)              # a decaying start-up transient
    >>> c = lptv.check_record(x, y, warn=False)
    >>> c.ok, c.transient_ratio > 10
    (False, True)
    >>> "skip_periods=1" in c.messages[0]
    True
    """
    from .._validate import as_periods as _periods_array

    warn = as_bool(warn, "warn")
    spread_limit = as_float(spread_limit, "spread_limit", minimum=0.0, open_min=True)
    u, y = _periods_array(u, "u"), _periods_array(y, "y")
    if u.shape != y.shape:
        raise ValueError(f"u and y must have the same shape (P, N), got {u.shape} and {y.shape}")
    P, N = u.shape
    msgs = []
    ratio, limit = np.nan, np.nan
    if P >= 3:
        ratio = max(_transient_ratio(u), _transient_ratio(y))
        limit = max(1.0 + 6.0 * np.sqrt(2.0 / N + 2.0 / (N * (P - 2))), 1.5)
        drifts = {}
        for name, x in (("input", u), ("output", y)):
            beta, t, share = _drift(x)
            if t > DRIFT_T and share > DRIFT_FRACTION:
                drifts[name] = (beta, t, share, x)
        transient = ratio > limit
        if drifts:
            # what is left of the first period's difference once the drift is gone
            left = max(_transient_ratio(detrended(x, beta)) if name in drifts else _transient_ratio(x)
                       for name, x, beta in (("input", u, drifts.get("input", (0,))[0]),
                                             ("output", y, drifts.get("output", (0,))[0])))
            transient = left > limit
            if transient:   # a transient as well: the drift must show without the first period
                drifts = {k: v for k, v in drifts.items()
                          if P >= 4 and _drift(v[3][1:])[1] > DRIFT_T and _drift(v[3][1:])[2] > DRIFT_FRACTION}
        for name, (beta, t, share, _) in drifts.items():
            msgs.append(f"the {name} drifts through the record: a linear trend of {beta:.3g} per period "
                        f"({t:.0f} times its standard error, {100 * share:.0f} % of the periods' deviations from "
                        "their mean), a drift rather than a start-up transient; remove it with detrend=True "
                        "(--detrend), which takes the trend out and keeps each period's shape, or find its cause "
                        "(an offset that creeps, a temperature)")
        if transient:
            msgs.append(f"the first period differs from the mean of the others by {ratio:.3g} times what "
                        f"the noise explains (steady state: about 1): a start-up transient? Drop it with "
                        f"skip_periods=1 (--skip-periods 1)")
    mean_power = float(np.mean(u.mean(axis=0) ** 2))
    spread = float(u.var(axis=0, ddof=1).mean() / mean_power) if mean_power > 0 else np.inf
    if spread > spread_limit:
        msgs.append(f"the input's periods differ by {100 * spread:.3g} % of its power: the record is not "
                    f"{P} periods of {N} samples of a periodic input (check the number of periods, the "
                    "period and the sampling frequency fs / --fs)")
    if warn:
        for m in msgs:
            warnings.warn(m, RecordWarning, stacklevel=2)
    return RecordCheck(float(ratio), float(limit), spread, tuple(msgs))
