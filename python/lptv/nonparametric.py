"""The nonparametric harmonic transfer function from periodic data (METHOD.md section 11)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from . import _core
from ._validate import as_int
from .data import frequency_data_of


@dataclass(frozen=True)
class HtfEstimate:
    """What :func:`htf_estimate` returns: branches G_k(w_l), k = -Kh..Kh, at the excited lines."""

    lines: np.ndarray
    """The excited lines l."""
    w: np.ndarray
    """Their angular frequencies l w0 (rad/s)."""
    branches: int
    """Kh."""
    G: np.ndarray
    """(2 Kh + 1, lines): row Kh + k is G_k(w_l) = Y_{l+k} / U_l."""
    std: np.ndarray
    """Standard deviation of each entry of ``G`` from the periods (noise on input and output)."""
    statistic: np.ndarray
    """Per branch: sum over the lines of |G_k|^2 / var G_k under G_k = 0."""
    p_value: np.ndarray
    """Per branch: probability of a statistic this large if the branch were zero."""
    periods: int

    @property
    def k(self) -> np.ndarray:
        """The branch indices -Kh..Kh (rows of ``G``)."""
        return np.arange(-self.branches, self.branches + 1)

    def significant(self, alpha: float = 1e-3) -> np.ndarray:
        """The branches that stand above the noise: p-value below ``alpha``."""
        return self.k[self.p_value < alpha]

    def branch(self, k: int) -> np.ndarray:
        """G_k at the excited lines."""
        k = as_int(k, "k", minimum=-self.branches, maximum=self.branches)
        return self.G[self.branches + k]


def htf_estimate(u, y=None, *, w0: Optional[float] = None, ts: Optional[float] = None,
                 excited: Optional[Sequence[int]] = None, branches: int = 0) -> HtfEstimate:
    """Estimate the harmonic transfer function's branches from steady-state periods, without a model.

    An LPTV system maps input line i to output lines i + k (METHOD.md section 11). When the
    excited lines are more than 2 Kh apart, the output line l + k near an excited line l holds
    only the branch G_k(w_l) U_l, so ``G_k(w_l) = Y_{l+k} / U_l`` from the mean spectra, with its
    variance from the periods (errors-in-variables: output noise, input noise and their
    covariance). Branches that stand above the noise show how many harmonics the time variation
    has; the model's HTF (:func:`lptv.htf`) must fall within their uncertainty.

    Parameters
    ----------
    u, y : array_like, shape (P, N)
        P >= 2 steady-state periods, or a :class:`lptv.FrequencyData` as ``u`` (no ``y``).
    w0, ts : float
        The period's fundamental (rad/s) and, for discrete time, the sample time.
    excited : sequence of int, optional
        The excited lines. Default: the lines whose input power exceeds 100 times its noise
        variance (every nonzero line for a noise-free input).
    branches : int
        Kh: branches k = -Kh..Kh are estimated. The excited lines must be more than 2 Kh apart and
        above Kh (a ``ValueError`` says which lines are too close).

    Notes
    -----
    ``p_value`` treats each term |G_k|^2 / var G_k of a zero branch as F(2, 2(P-1))-distributed
    (variances from P periods) and their sum over n lines as a Gamma(n) variable scaled by the
    F's mean (P-1)/(P-2): exact for known variances, an approximation for sample variances.
    A time-varying denominator gives branches beyond any Kh (decaying with |k|): output line l + k
    also holds the far branches of the neighbouring excited lines, which bias the estimate where
    they stand above the noise. Excite lines far enough apart for those to be negligible. Records
    that are not in steady state (a start-up transient) bias the plain ratio too; drop the first
    periods.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model([[1.0], [1.0]], [[0.25, 1.0, 0.25]], w0=0.1)   # (1 + 0.5 cos(w0 t)) u, then 1/(s+1)
    >>> ms = lptv.multisine(range(10, 100, 10), 512, seed=0)
    >>> y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 512)
    >>> rng = np.random.default_rng(1)
    >>> u = ms.periods(8) + 1e-4 * rng.standard_normal((8, 512))
    >>> y = np.tile(y1, (8, 1)) + 1e-4 * rng.standard_normal((8, 512))
    >>> est = lptv.htf_estimate(u, y, w0=0.1, branches=2)
    >>> est.significant().tolist()        # the modulation reaches one line each side
    [-1, 0, 1]
    """
    from scipy import stats

    data = frequency_data_of(u, y, w0, ts)
    branches = as_int(branches, "branches", maximum=data.max_line)
    if excited is None:
        lines = [int(v) for v in _core.excited_lines(data._cpp)]
        if not lines:
            raise ValueError("u: no line stands above the input noise; pass excited= explicitly")
    else:
        try:
            lines = [as_int(v, "excited", minimum=1, maximum=data.max_line) for v in excited]
        except TypeError:
            raise ValueError(f"excited must be a sequence of integers, got {excited!r}") from None
    h = _core.htf_estimate(data._cpp, lines, branches)
    n = len(h.lines)
    stat = np.asarray(h.branch_statistic)
    P = data.periods
    scale = (P - 1) / (P - 2) if P and P > 2 else 1.0
    p = stats.gamma.sf(stat / scale, n)
    lines = np.asarray(h.lines)
    return HtfEstimate(lines=lines, w=lines * data.w0, branches=h.branches, G=np.asarray(h.G),
                       std=np.sqrt(np.asarray(h.variance)), statistic=stat, p_value=p, periods=P)
