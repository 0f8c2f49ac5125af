"""The nonparametric harmonic transfer function from periodic data (METHOD.md section 11)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from .. import _core
from .._validate import as_float, as_lines, as_int, as_str
from .frequency_data import FrequencyData, frequency_data_of


def _lpm_data(u, y, w0, ts, degree, width):
    """Spectra and noise (co)variances of periodic lines 0..N/2 by the local polynomial method.

    The P periods form one record of P N samples; its DFT X_j = fft(x)[j] / (P N) has the
    periodic response on the bins j = P m only, where X_{P m} equals the period's line m. Around
    each such bin a polynomial in r (bins j + r, 0 < |r| <= width) is fitted by least squares to
    the non-periodic bins, which hold only the transient (smooth) and noise; its value at r = 0 is
    the transient on line m. The noise variance of one bin is the residual power over the residual
    degrees of freedom, and the corrected line carries it times 1 + h (h the leverage of r = 0).
    """
    src = FrequencyData.from_periods(u, y, w0=w0, ts=ts)  # validates shapes, w0, ts
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    P, N = u.shape
    degree = as_int(degree, "degree")
    width = P - 1 if width is None else as_int(width, "width", minimum=1)
    if width > P - 1:
        raise ValueError(f"width must be at most P - 1 = {P - 1} (the bins before the next periodic line), "
                         f"got {width}")
    n_fit = 2 * width
    if n_fit <= degree + 1:
        raise ValueError(f"degree {degree} needs more than {degree + 1} bins around each line; "
                         f"width {width} gives {n_fit}: use more periods or a lower degree")
    r = np.concatenate([np.arange(-width, 0), np.arange(1, width + 1)])
    A = np.vander(r / width, degree + 1, increasing=True)          # (2 width, degree + 1)
    pinv = np.linalg.pinv(A)                                         # (degree + 1, 2 width)
    h0 = float(np.linalg.inv(A.T @ A)[0, 0])
    lines = np.arange(N // 2 + 1)
    bins = (P * lines)[:, None] + r[None, :]                         # negative bins wrap: conj
    out = {}
    for name, x in (("U", u), ("Y", y)):
        X = np.fft.fft(x.reshape(-1)) / (P * N)
        nb = X[bins]                                                 # (lines, 2 width)
        c = nb @ pinv.T
        out[name] = X[P * lines] - c[:, 0]
        out["e" + name] = nb - c @ A.T
    dof = n_fit - (degree + 1)
    k = (1.0 + h0) / dof
    varU = k * np.sum(np.abs(out["eU"]) ** 2, axis=1)
    varY = k * np.sum(np.abs(out["eY"]) ** 2, axis=1)
    covYU = k * np.sum(out["eY"] * np.conj(out["eU"]), axis=1)
    U, Y = out["U"], out["Y"]
    U[0], Y[0], covYU[0] = U[0].real, Y[0].real, covYU[0].real
    data = FrequencyData(U, Y, varU, varY, covYU, w0=src.w0, ts=ts, periods=0)
    return data, dof


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
    method: str = "ratio"
    """'ratio' (means of steady-state periods) or 'lpm' (local polynomial method)."""
    leakage: Optional[np.ndarray] = None
    """Same shape as ``G``: the estimated size |sum| of what the other excited lines' branches put
    on the entry's output line, relative to U_l (METHOD.md section 11): the bias bound of the
    ratio there."""
    overlapped: Optional[np.ndarray] = None
    """Same shape as ``G``: the entry's ``leakage`` exceeds ``OVERLAP_LEVEL`` (0.3) of its standard
    deviation: the ratio
    Y_{l+k} / U_l there is biased by the neighbours' far branches by more than its noise. Compare
    a model with the unflagged entries only, or use several random-phase realisations
    (:func:`lptv.distortion`), which separate the branches."""

    @property
    def k(self) -> np.ndarray:
        """The branch indices -Kh..Kh (rows of ``G``)."""
        return np.arange(-self.branches, self.branches + 1)

    def significant(self, alpha: float = 1e-3) -> np.ndarray:
        """The branches that stand above the noise: p-value below ``alpha``."""
        alpha = as_float(alpha, "alpha", minimum=0.0, maximum=1.0, open_min=True, open_max=True)
        return self.k[self.p_value < alpha]

    def branch(self, k: int) -> np.ndarray:
        """G_k at the excited lines."""
        k = as_int(k, "k", minimum=-self.branches, maximum=self.branches)
        return self.G[self.branches + k]


def htf_estimate(u, y=None, *, w0: Optional[float] = None, ts: Optional[float] = None,
                 excited: Optional[Sequence[int]] = None, branches: int = 0, method: str = "ratio",
                 degree: int = 2, width: Optional[int] = None) -> HtfEstimate:
    """Estimate the harmonic transfer function's branches from steady-state periods, without a model.

    An LPTV system maps input line i to output lines i + k (METHOD.md section 11). When the
    excited lines are more than 2 Kh apart, the output line l + k near an excited line l holds
    only the branch G_k(w_l) U_l, so ``G_k(w_l) = Y_{l+k} / U_l`` from the mean spectra, with its
    variance from the periods (errors-in-variables: output noise, input noise and their
    covariance). Branches that stand above the noise show how many harmonics the time variation
    has. A time-varying denominator has branches at every |k|, decaying; the far ones of the
    neighbouring excited lines also reach line l + k and bias the ratio there. ``est.overlapped``
    flags the entries where a bound of that leakage (``est.leakage``, from the measured branches
    and their decay) exceeds 0.3 of the entry's standard deviation: compare a model's HTF
    (:func:`lptv.htf`) with the other entries only (on the paper's design 19 % of the entries up
    to branch 4 are flagged, 75 of the 80 biased by more than 3 std among them). Several
    random-phase realisations separate the branches instead (:func:`lptv.distortion`).

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
    method : {'ratio', 'lpm'}
        'ratio': the spectra are the means of the P periods, their variances those of the means.
        'lpm': the local polynomial method for records that are not in steady state (a start-up
        transient): the P periods are taken as one record of P N samples, whose DFT has the
        periodic response on every P-th bin only; the transient (and leakage) is smooth across
        bins, so a polynomial of ``degree`` fitted to the ``width`` bins on each side of each
        periodic line (none of them periodic lines) gives the transient on the line, which is
        subtracted, and the fit's residual gives the noise (co)variances (METHOD.md section 11).
    degree, width : int
        LPM only: the polynomial degree (default 2) and the bins on each side (default P - 1, all
        those before the next periodic line; 2 width must exceed degree + 1).

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
    from .._dist import gamma_sf

    method = as_str(method, "method", ("ratio", "lpm"))
    dof = None
    if method == "lpm":
        if y is None or isinstance(u, FrequencyData):
            raise ValueError("method='lpm' needs the periods u and y of shape (P, N), not a FrequencyData")
        if w0 is None:
            raise ValueError("w0 is missing: the fundamental of the period (rad/s)")
        data, dof = _lpm_data(u, y, w0, ts, degree, width)
    else:
        data = frequency_data_of(u, y, w0, ts)
    branches = as_int(branches, "branches", maximum=data.max_line)
    if excited is None:
        lines = [int(v) for v in _core.excited_lines(data._cpp)]
        if not lines:
            raise ValueError("u: no line stands above the input noise; pass excited= explicitly")
    else:
        lines = as_lines(excited, "excited", minimum=1, maximum=data.max_line)
    h = _core.htf_estimate(data._cpp, lines, branches)
    n = len(h.lines)
    stat = np.asarray(h.branch_statistic)
    P = data.periods
    # each |G_k|^2 / var G_k of a zero branch is F(2, 2 q) with q the variance's complex degrees
    # of freedom (P - 1 for the means of periods; the LPM fit's residual count minus its unknowns)
    q = dof if dof is not None else (P - 1 if P and P > 1 else 0)
    scale = q / (q - 1) if q > 1 else 1.0
    p = gamma_sf(stat / scale, n)
    lines = np.asarray(h.lines)
    G, std = np.asarray(h.G), np.sqrt(np.asarray(h.variance))
    leak = _leakage(G, std, lines, h.branches, np.abs(np.asarray(data.U)[lines]))
    return HtfEstimate(lines=lines, w=lines * data.w0, branches=h.branches, G=G, std=std, statistic=stat,
                       p_value=p, periods=np.shape(u)[0] if method == "lpm" else P, method=method,
                       leakage=leak, overlapped=leak > OVERLAP_LEVEL * std)


REACH = 32
OVERLAP_LEVEL = 0.3
"""An entry is flagged as overlapped when its leakage bound exceeds this many standard
deviations (the bound extrapolates from measured branches and falls short near a resonance)."""


def _leakage(G, std, lines, Kh, absU):
    """What the other excited lines' branches put on each entry's output line (relative to U_l).

    Neighbour l' reaches output line m = l + k through its branch d = m - l'. Where |d| <= Kh that
    branch is estimated at l' itself (counted where it stands 2 std above its noise); beyond, it is
    extrapolated from branch +-Kh by the branches' measured decay per line q, |G_{+-Kh}| /
    |G_{+-(Kh-1)}| at l' where both stand 2 std above the noise, else its median over the lines
    (a time-varying denominator's branches decay geometrically, METHOD.md section 3; near a
    resonance more slowly); with no decay measured anywhere, nothing beyond Kh is assumed. The neighbours' contributions are added in magnitude (their
    phases are those of the input's random phases): a bound of the bias, not an estimate of it."""
    n = lines.size
    leak = np.zeros_like(std)
    if n < 2:
        return leak
    sig = np.abs(G) > 2 * std
    q = {}   # per side: the decay per line at each line (its own where measured, else the median)
    if Kh >= 1:
        for sgn in (1, -1):
            a, b = Kh + sgn * Kh, Kh + sgn * (Kh - 1)
            both = sig[a] & sig[b]
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = np.where(both, np.abs(G[a]) / np.abs(G[b]), np.nan)
            med = float(np.nanmedian(ratio)) if np.sum(both) >= 3 else np.nan
            med = med if np.isfinite(med) and med < 1.0 else 0.0
            q[sgn] = np.where(np.isfinite(ratio) & (ratio < 1.0), ratio, med)
    absG = np.where(sig, np.abs(G), 0.0)                 # branches that stand above the noise
    idx = np.arange(n)
    # neighbours up to REACH excited lines away on each side (further ones are beyond any
    # measured decay's reach at the accuracy a bound needs, and the cost stays linear in n)
    for o in range(-min(REACH, n - 1), min(REACH, n - 1) + 1):
        if o == 0:
            continue
        i = idx[(idx + o >= 0) & (idx + o < n)]
        j = i + o
        for kk in range(2 * Kh + 1):
            d = lines[i] + (kk - Kh) - lines[j]             # branch d of neighbour j reaches entry i
            g = np.zeros(i.size)
            near = np.abs(d) <= Kh
            g[near] = absG[(d + Kh)[near], j[near]]
            if Kh >= 1:
                for sgn in (1, -1):
                    far = (np.sign(d) == sgn) & ~near
                    g[far] = absG[Kh + sgn * Kh, j[far]] * q[sgn][j[far]] ** (np.abs(d[far]) - Kh)
            leak[kk, i] += g * absU[j]
    with np.errstate(divide="ignore", invalid="ignore"):
        leak = np.where(absU[None, :] > 0, leak / absU[None, :], 0.0)
    return leak
