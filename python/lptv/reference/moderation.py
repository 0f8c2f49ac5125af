"""METHOD.md section 7 ("The variances the tests divide by: moderated across lines") in plain
NumPy and SciPy: each line's sample noise (co)variances combined with its neighbours' by the local
empirical-Bayes rule of Smyth (2004, "Linear models and empirical Bayes methods for assessing
differential expression in microarray experiments", Stat. Appl. Genet. Mol. Biol. 3(1), art. 3).

The independent route :func:`lptv._core.moderated_noise` is tested against: SciPy's polygamma
and F quantile where the core has its own, NumPy's vector arithmetic over the lines. It was the
computation of :func:`lptv.moderated_noise` before the core had it. Nothing here calls the core's
computations (the :class:`lptv.FrequencyData` container holds the arrays).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_int

OUTLIER_RATE = 1e-3
"""A line whose sample variance exceeds its neighbours' by more than noise alone does with this
probability keeps its own variance (and is left out of its neighbours' prior)."""

MAX_PRIOR_DOF = 1e6
"""Cap on the prior degrees of freedom (noise that is exactly as smooth as its trend)."""


@dataclass(frozen=True)
class ModeratedNoise:
    """What :func:`moderated_noise` returns."""

    data: "object"
    """A :class:`lptv.FrequencyData` with the same spectra and periods, its variances moderated."""
    dof: np.ndarray
    """Per line 0..Lmax: the real degrees of freedom of the moderated variances (Satterthwaite:
    the line's own 2 (P - 1), the prior's d0, the neighbours' average); 2 (P - 1) for lines that
    kept their own variance, P - 1 for lines 0 and Lmax (possibly real lines)."""
    prior_dof: float
    """d0: the prior degrees of freedom (0: no moderation, ``MAX_PRIOR_DOF``: the noise is as
    smooth as its trend over the window)."""
    outliers: np.ndarray
    """Lines that kept their own sample variance (above their neighbours beyond noise)."""
    half_width: int
    """The neighbours: the lines within +-half_width of a line."""
    own_weight: np.ndarray = None
    """Per line: the weight d / (d + d0) of its own sample (co)variances (1 where kept)."""
    neighbour: np.ndarray = None
    """Per line: may serve as a neighbour (lines 1 .. Lmax - 1 that kept no own variance)."""
    source_varU: np.ndarray = None
    """The input's own sample variances (of the mean) the moderation started from."""
    source_varY: np.ndarray = None
    """The output's own sample variances (of the mean)."""

    def error_covariance(self, lines) -> np.ndarray:
        """Covariance of the relative sampling errors of the moderated variances on ``lines``
        (one channel): each line's sample variance is off by a relative error of variance
        2 / (2 (P - 1)), independently of the others, and a moderated variance mixes its own
        (weight w) with its neighbours' mean (1 - w): neighbouring lines share those errors.
        The prior's spread of the true variances is not an error shared between lines and is
        not in it."""
        lines = np.asarray(lines, int)
        L = self.data.max_line
        P = int(self.data.periods)
        if P < 2:
            return np.zeros((lines.size, lines.size))
        w = np.ones(L + 1) if self.own_weight is None else self.own_weight
        j = np.arange(L + 1)
        B = (np.abs(lines[:, None] - j[None, :]) <= self.half_width) & (j[None, :] != lines[:, None])
        if self.neighbour is not None:
            B &= self.neighbour[None, :]
        n = np.maximum(B.sum(axis=1), 1)
        M = B * ((1.0 - w[lines]) / n)[:, None]
        M[np.arange(lines.size), lines] = w[lines]
        return (2.0 / (2.0 * (P - 1))) * (M @ M.T)

    @property
    def periods(self) -> np.ndarray:
        """Per line: the number of periods the moderated variances are worth, 1 + dof / 2."""
        return 1.0 + self.dof / 2.0


def _trigamma_inverse(x: float) -> float:
    """y > 0 with trigamma(y) = x (Newton's iteration of Smyth 2004 on 1 / y)."""
    from scipy import special

    if x > 1e7:
        return 1.0 / np.sqrt(x)
    if x < 1e-6:
        return 1.0 / x
    y = 0.5 + 1.0 / x
    for _ in range(50):
        tri = float(special.polygamma(1, y))
        dif = tri * (1.0 - tri / x) / float(special.polygamma(2, y))
        y += dif
        if -dif / y < 1e-10:
            break
    return y


def _window_sums(x: np.ndarray, keep: np.ndarray, W: int):
    """Per position i: the sum of x[j] and the count over |j - i| <= W, j != i, keep[j]."""
    xs = np.where(keep, x, 0.0)
    cs = np.concatenate([[0.0], np.cumsum(xs)])
    cn = np.concatenate([[0], np.cumsum(keep)])
    i = np.arange(x.size)
    lo, hi = np.clip(i - W, 0, x.size), np.clip(i + W + 1, 0, x.size)
    s = cs[hi] - cs[lo] - xs
    n = cn[hi] - cn[lo] - keep
    return s, n


SHAPE_WIDTH = 2
"""The local log-quadratic trend that corrects the neighbours' mean for the spectrum's shape is
fitted over +-SHAPE_WIDTH * half_width lines."""


def _shape(z, ok, keep, W, var_log):
    """Per position i: (k_i, v_i), the factor that turns the arithmetic mean of the neighbours'
    variances (|j - i| <= W, j != i, keep[j]) into the trend's value at i, and the variance of
    log k_i. The trend: z_j = alpha + beta x + c x^2 (x = j - i) fitted by least squares to the
    log variances z over |x| <= SHAPE_WIDTH W (j != i, ok[j]); k_i = 1 / mean_j exp(beta x_j +
    c x_j^2 - q_j / 2), q_j the fitted shape's variance at x_j (var_log times the normal
    equations' inverse), which removes the fit's noise from the exponential's mean to first
    order. Near the first and last lines the window holds more lines on one side than on the
    other (at the first and last inner lines, on one side only) and the trend at i is
    extrapolated by one line there; its larger variance enters v. Fewer than 2 W points in the
    window, or a singular fit: k = 1, v = 0."""
    m = z.size
    S = SHAPE_WIDTH * W
    C = np.zeros((5, m))
    T = np.zeros((3, m))
    idx = np.arange(m)
    for x in range(-S, S + 1):
        if x == 0:
            continue
        j = idx + x
        inside = (j >= 0) & (j < m)
        jj = np.where(inside, j, 0)
        use = inside & ok[jj]
        zx = np.where(use, z[jj], 0.0)
        for p in range(5):
            C[p] += use * float(x) ** p
        for p in range(3):
            T[p] += zx * float(x) ** p
    # points on each side of i within the window (a one-sided fit would extrapolate to i)
    left = np.zeros(m, int)
    right = np.zeros(m, int)
    for x in range(1, S + 1):
        left[x:] += ok[:m - x]
        right[:m - x] += ok[x:]
    k, v = np.ones(m), np.zeros(m)
    for i in range(m):
        if left[i] + right[i] < 2 * W:
            continue
        A = np.array([[C[0, i], C[1, i], C[2, i]], [C[1, i], C[2, i], C[3, i]], [C[2, i], C[3, i], C[4, i]]])
        try:
            Ai = np.linalg.inv(A)
        except np.linalg.LinAlgError:
            continue
        if not np.all(np.isfinite(Ai)):
            continue
        theta = Ai @ T[:, i]
        V = var_log * Ai[1:, 1:]
        xs = np.array([x for x in range(-W, W + 1) if x != 0 and 0 <= i + x < m and keep[i + x]], float)
        if xs.size == 0:
            continue
        X = np.stack([xs, xs ** 2], 1)
        q = np.einsum("ja,ab,jb->j", X, V, X)
        e = np.exp(X @ theta[1:] - q / 2)
        k[i] = xs.size / e.sum()
        a = (e[:, None] * X).sum(0) / e.sum()
        v[i] = float(a @ V @ a)
    return k, v


def moderated_noise(data, half_width: int = 10) -> ModeratedNoise:
    """:func:`lptv.moderated_noise` (its arguments, result and method, METHOD.md section 7) in
    NumPy and SciPy: the independent route the core's is tested against.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.reference.moderation import moderated_noise
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal((4, 256)); y = 2 * u + 0.1 * rng.standard_normal((4, 256))
    >>> d = lptv.FrequencyData.from_periods(u, y, w0=1.0)
    >>> mod = moderated_noise(d)      # P = 4: each line's own variance has 6 dof
    >>> round(mod.prior_dof), round(float(np.median(mod.dof)))
    (43, 37)
    """
    from scipy import special, stats

    from ..spectra.frequency_data import FrequencyData

    if not isinstance(data, FrequencyData):
        raise ValueError(f"data must be an lptv.FrequencyData, got {type(data).__name__}")
    W = as_int(half_width, "half_width", minimum=1, maximum=10**6)
    P = int(data.periods)
    L = data.max_line
    vu, vy, c = np.asarray(data.varU, float), np.asarray(data.varY, float), np.asarray(data.covYU, complex)
    own = 2.0 * (P - 1) if P >= 2 else np.inf
    dof = np.full(L + 1, own)
    if P >= 2:
        dof[0] = dof[L] = P - 1.0

    def unchanged():
        return ModeratedNoise(data=data, dof=dof, prior_dof=0.0, outliers=np.zeros(0, int), half_width=W,
                              source_varU=vu, source_varY=vy)

    if P < 2 or L < 3 * W + 2:
        return unchanged()
    d = own
    inner = np.arange(1, L)
    mean_log = special.digamma(d / 2) - np.log(d / 2)      # E log(chi2_d / d)
    var_log = special.polygamma(1, d / 2)                 # Var log(chi2_d / d)
    channels = [v[inner] for v in (vu, vy) if np.count_nonzero(v[inner] > 0) >= 3 * W]
    if not channels:
        return unchanged()
    # Lines above their neighbours' mean by more than F(d, n d) (noise alone) allows keep their
    # own variance; the second pass leaves the first one's outliers out of the means.
    out = np.zeros(inner.size, bool)
    for _ in range(2):
        for v in channels:
            ok = (v > 0) & ~out
            s, n = _window_sums(v, ok, W)
            with np.errstate(invalid="ignore", divide="ignore"):
                m = s / n
            q = stats.f.isf(OUTLIER_RATE, d, np.maximum(n, 1) * d)
            out |= (n > 0) & (v > q * m)
    # d0 from the spread of the log variances about their local (leave-one-out) mean.
    r2 = []
    for v in channels:
        ok = (v > 0) & ~out
        z = np.where(ok, np.log(np.where(ok, v, 1.0)) - mean_log, 0.0)
        s, n = _window_sums(z, ok, W)
        use = ok & (n >= W)
        r = z[use] - s[use] / n[use]
        r2.append(r ** 2 / (1.0 + 1.0 / n[use]))
    r2 = np.concatenate(r2)
    if r2.size < 3 * W:
        return unchanged()
    excess = float(np.mean(r2)) - var_log
    d0 = MAX_PRIOR_DOF if excess <= 0 else min(2.0 * _trigamma_inverse(excess), MAX_PRIOR_DOF)
    # The prior scale: (d0 - 2) / d0 times the neighbours' mean (the mean of a scaled inverse
    # chi-square prior is d0 / (d0 - 2) times its scale).
    keep = ~out
    n = _window_sums(vu[inner], keep, W)[1]
    use = keep & (n > 0)
    scale = max(d0 - 2.0, 0.0) / d0
    w = d / (d + d0)
    # The neighbours' arithmetic mean, turned by each channel's shape factor into the trend's
    # value at the line (a log spectrum that slopes or bends within the window biases the mean).
    shape = []
    for v in (vu, vy):
        vi = v[inner]
        okv = (vi > 0) & keep
        if np.count_nonzero(okv) >= 3 * W:
            z = np.log(np.where(okv, vi, 1.0)) - mean_log
            shape.append(_shape(z, okv, keep, W, var_log))
        else:
            shape.append((np.ones(inner.size), np.zeros(inner.size)))
    (ku, vku), (ky, vky) = shape
    mu, my, mc = vu.copy(), vy.copy(), c.copy()
    for src, dst, kk in ((vu, mu, ku), (vy, my, ky)):
        s, _ = _window_sums(src[inner], keep, W)
        dst[inner[use]] = w * src[inner[use]] + (1 - w) * scale * kk[use] * s[use] / n[use]
    sr, _ = _window_sums(c[inner].real, keep, W)
    si, _ = _window_sums(c[inner].imag, keep, W)
    kc = np.sqrt(ku * ky)
    mc[inner[use]] = w * c[inner[use]] + (1 - w) * scale * kc[use] * (sr[use] + 1j * si[use]) / n[use]
    bad = np.abs(mc) ** 2 > mu * my
    mc[bad] *= np.sqrt(mu[bad] * my[bad]) / np.abs(mc[bad])
    # Satterthwaite: relative variance 2/d of the own part, 2/d0 + 2/(n d) + v of the prior's
    # (v the variance of the log shape factor).
    nn = n[use].astype(float)
    vk = np.maximum(vku, vky)[use]
    dof[inner[use]] = (d + d0) ** 2 / (d + d0 + d0 ** 2 * (1.0 / (nn * d) + vk / 2.0))
    own_weight = np.ones(L + 1)
    own_weight[inner[use]] = w
    neighbour = np.zeros(L + 1, bool)
    neighbour[inner[keep]] = True
    moderated = FrequencyData(data.U, data.Y, mu, my, mc, w0=data.w0, ts=data.ts, periods=P)
    return ModeratedNoise(data=moderated, dof=dof, prior_dof=float(d0), outliers=inner[out],
                          half_width=W, own_weight=own_weight, neighbour=neighbour, source_varU=vu,
                          source_varY=vy)


@dataclass(frozen=True)
class ModeratedCovariances:
    """What :func:`moderated_covariances` returns (the arrays of several channels)."""

    C: np.ndarray
    """The moderated covariance matrices of the means, shape (L+1, c, c)."""
    dof: np.ndarray
    prior_dof: float
    outliers: np.ndarray
    half_width: int
    own_weight: np.ndarray
    neighbour: np.ndarray


def moderated_covariances(C, periods: int, n_outputs: int, half_width: int = 10) -> ModeratedCovariances:
    """METHOD.md section 19, "Moderated noise for several channels", in NumPy and SciPy: the
    covariance matrices C (L+1, c, c) of c = ny + nu channels (outputs first) from P periods,
    each line's combined with its neighbours' mean by section 7's rule with one weight
    d / (d + d0) for the whole matrix (the conjugate inverse-Wishart prior); d0 from the log
    variances of every channel (inputs first, then outputs, as the single-channel pair (u, y)),
    a line outlying in any channel keeps its own matrix, and entry (p, q) of the neighbours'
    mean is scaled by sqrt(k_p k_q) (k the channels' shape factors). With c = 2,
    ``C = [[varY, covYU], [conj(covYU), varU]]`` this is :func:`moderated_noise`.

    Examples
    --------
    >>> import numpy as np
    >>> from lptv.reference.moderation import moderated_covariances
    >>> rng = np.random.default_rng(0)
    >>> z = rng.standard_normal((4, 200, 3)) + 1j * rng.standard_normal((4, 200, 3))
    >>> dz = z - z.mean(0)
    >>> C = np.einsum("plc,pld->lcd", dz, dz.conj()) / 12
    >>> mo = moderated_covariances(C, 4, 2)
    >>> mo.C.shape, bool(mo.prior_dof > 6)
    ((200, 3, 3), True)
    """
    from scipy import special, stats

    C = np.asarray(C, complex)
    W = as_int(half_width, "half_width", minimum=1, maximum=10**6)
    P = int(periods)
    L = C.shape[0] - 1
    c = C.shape[1]
    ny = int(n_outputs)
    order = list(range(ny, c)) + list(range(ny))          # inputs first, then outputs
    var = np.real(np.diagonal(C, axis1=1, axis2=2)).copy()
    own = 2.0 * (P - 1) if P >= 2 else np.inf
    dof = np.full(L + 1, own)
    if P >= 2:
        dof[0] = dof[L] = P - 1.0

    def unchanged():
        return ModeratedCovariances(C=C.copy(), dof=dof, prior_dof=0.0, outliers=np.zeros(0, int), half_width=W,
                                    own_weight=np.ones(L + 1), neighbour=np.zeros(L + 1, bool))

    if P < 2 or L < 3 * W + 2:
        return unchanged()
    d = own
    inner = np.arange(1, L)
    mean_log = special.digamma(d / 2) - np.log(d / 2)
    var_log = special.polygamma(1, d / 2)
    channels = [var[inner, q] for q in order if np.count_nonzero(var[inner, q] > 0) >= 3 * W]
    if not channels:
        return unchanged()
    out = np.zeros(inner.size, bool)
    for _ in range(2):
        for v in channels:
            ok = (v > 0) & ~out
            s, n = _window_sums(v, ok, W)
            with np.errstate(invalid="ignore", divide="ignore"):
                m = s / n
            q = stats.f.isf(OUTLIER_RATE, d, np.maximum(n, 1) * d)
            out |= (n > 0) & (v > q * m)
    r2 = []
    for v in channels:
        ok = (v > 0) & ~out
        z = np.where(ok, np.log(np.where(ok, v, 1.0)) - mean_log, 0.0)
        s, n = _window_sums(z, ok, W)
        use = ok & (n >= W)
        r = z[use] - s[use] / n[use]
        r2.append(r ** 2 / (1.0 + 1.0 / n[use]))
    r2 = np.concatenate(r2)
    if r2.size < 3 * W:
        return unchanged()
    excess = float(np.mean(r2)) - var_log
    d0 = MAX_PRIOR_DOF if excess <= 0 else min(2.0 * _trigamma_inverse(excess), MAX_PRIOR_DOF)
    keep = ~out
    n = _window_sums(np.ones(inner.size), keep, W)[1]
    use = keep & (n > 0)
    scale = max(d0 - 2.0, 0.0) / d0
    w = d / (d + d0)
    k = np.ones((inner.size, c))
    vk = np.zeros(inner.size)
    for q in range(c):
        vi = var[inner, q]
        okv = (vi > 0) & keep
        if np.count_nonzero(okv) >= 3 * W:
            z = np.log(np.where(okv, vi, 1.0)) - mean_log
            k[:, q], vq = _shape(z, okv, keep, W, var_log)
            vk = np.maximum(vk, vq)
    Cm = C.copy()
    sr = np.zeros((inner.size, c, c))
    si = np.zeros((inner.size, c, c))
    for p in range(c):
        for q in range(c):
            sr[:, p, q] = _window_sums(C[inner, p, q].real, keep, W)[0]
            si[:, p, q] = _window_sums(C[inner, p, q].imag, keep, W)[0]
    kk = np.sqrt(k[:, :, None] * k[:, None, :])
    mean = kk * (sr + 1j * si) / np.maximum(n, 1)[:, None, None]
    Cm[inner[use]] = w * C[inner[use]] + (1 - w) * scale * mean[use]
    nn = n[use].astype(float)
    dof[inner[use]] = (d + d0) ** 2 / (d + d0 + d0 ** 2 * (1.0 / (nn * d) + vk[use] / 2.0))
    own_weight = np.ones(L + 1)
    own_weight[inner[use]] = w
    neighbour = np.zeros(L + 1, bool)
    neighbour[inner[keep]] = True
    return ModeratedCovariances(C=Cm, dof=dof, prior_dof=float(d0), outliers=inner[out], half_width=W,
                                own_weight=own_weight, neighbour=neighbour)
