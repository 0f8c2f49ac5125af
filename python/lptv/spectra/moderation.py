"""Noise variances moderated across neighbouring lines (METHOD.md section 7, "Moderated noise").

From P periods each line's sample (co)variances carry only 2 (P - 1) real degrees of freedom (6
at P = 4): a statistic that divides by them is heavy-tailed, and a test built on it must give
away most of its power to stay calibrated. Noise spectra are usually smooth across a few lines,
so the neighbours of a line know its variance too. :func:`moderated_noise` combines each line's
own sample (co)variances with those of its neighbours by the empirical-Bayes rule of Smyth (2004,
"Linear models and empirical Bayes methods for assessing differential expression in microarray
experiments", Stat. Appl. Genet. Mol. Biol. 3(1), art. 3), made local in frequency: the prior of
a line's variance is a scaled inverse chi-square around the mean of its neighbours, with prior
degrees of freedom d0 estimated from the spread of the log sample variances about their local
trend. Smooth noise gives d0 large (the neighbours decide), rough noise small (each line keeps its
own); a line far above its neighbours (a narrowband disturbance) keeps its own variance.

The computation runs in the compiled core (``_core.moderated_noise``, ``lptv::moderated_noise``
in C++, with its own polygamma functions and F quantile); its NumPy and SciPy twin is
:mod:`lptv.reference.moderation`. The argument checks and the wrapping are here.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._validate import as_int

OUTLIER_RATE = _core.MODERATION_OUTLIER_RATE
"""A line whose sample variance exceeds its neighbours' by more than noise alone does with this
probability keeps its own variance (and is left out of its neighbours' prior)."""

MAX_PRIOR_DOF = _core.MODERATION_MAX_PRIOR_DOF
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
    source_covYU: np.ndarray = None
    """The own sample cross-covariances E{dY conj(dU)} (of the mean)."""
    _core: object = field(default=None, repr=False, compare=False)

    def unbiased_data(self):
        """``data`` with the prior's part at the neighbours' mean itself: w C_own + (1 - w) C_mean
        per line, where ``data`` has w C_own + (1 - w) (d0 - 2)/d0 C_mean (Smyth's scale, right
        for 1 / sigma^2 when the true variances scatter like the prior). Unbiased for a flat noise
        spectrum, and on average for a scattered one; what the verdict divides by (METHOD.md
        section 7, "The verdict's scale"). ``data`` itself when nothing was moderated.

        Examples
        --------
        >>> import numpy as np, lptv
        >>> rng = np.random.default_rng(0)
        >>> u = rng.standard_normal((4, 512)); y = rng.standard_normal((4, 512))
        >>> mo = lptv.moderated_noise(lptv.FrequencyData.from_periods(u, y, w0=1.0))
        >>> mo.unbiased_data().varY.shape == mo.data.varY.shape
        True
        """
        from .frequency_data import FrequencyData

        m, d0 = self.data, self.prior_dof
        if not d0 > 2 or self.own_weight is None or self.source_covYU is None:
            return m
        f = d0 / (d0 - 2.0)
        w = np.asarray(self.own_weight, float)

        def fix(mod, own):
            mod, own = np.asarray(mod), np.asarray(own)
            return w * own + (mod - w * own) * f

        return FrequencyData(m.U, m.Y, fix(m.varU, self.source_varU), fix(m.varY, self.source_varY),
                             fix(m.covYU, self.source_covYU), w0=m.w0, ts=m.ts, periods=m.periods)

    def error_covariance(self, lines) -> np.ndarray:
        """Covariance of the relative sampling errors of the moderated variances on ``lines``
        (one channel): each line's sample variance is off by a relative error of variance
        2 / (2 (P - 1)), independently of the others, and a moderated variance mixes its own
        (weight w) with its neighbours' mean (1 - w): neighbouring lines share those errors.
        The prior's spread of the true variances is not an error shared between lines and is
        not in it."""
        lines = np.asarray(lines, int)
        if self._core is None:      # built by hand, not by moderated_noise
            from ..reference.moderation import ModeratedNoise as _Reference

            return _Reference.error_covariance(self, lines)
        if lines.ndim != 1:
            raise ValueError(f"lines must be a 1-d array of line numbers, got shape {lines.shape}")
        return np.asarray(self._core.error_covariance(lines.tolist()))

    @property
    def periods(self) -> np.ndarray:
        """Per line: the number of periods the moderated variances are worth, 1 + dof / 2."""
        return 1.0 + self.dof / 2.0


def moderated_noise(data, half_width: int = 10) -> ModeratedNoise:
    """The noise (co)variances of ``data`` moderated across neighbouring lines.

    Per line l (1 .. Lmax - 1) the moderated covariance matrix of the mean input and output is
    (d C_l + d0 C0_l) / (d + d0): C_l the line's sample (co)variances (d = 2 (P - 1) real degrees
    of freedom), C0_l the prior scale, (d0 - 2) / d0 times the mean of C over the lines within
    +-``half_width`` of l (l itself and outlying lines excluded), d0 estimated from the spread of
    log varU and log varY about their local means (Smyth 2004's moment estimator, made local).
    Lines 0 and Lmax, and lines far above their neighbours, keep their own (co)variances.

    Parameters
    ----------
    data : lptv.FrequencyData or lptv.MimoFrequencyData
        Spectra and noise statistics from P >= 2 periods. For several channels the whole
        covariance matrix of the outputs and inputs on a line is moderated with one weight
        (METHOD.md section 19, "Moderated noise for several channels"), d0 from every channel's
        variances, and a :class:`lptv.mimo_moderation.MimoModeratedNoise` is returned.
    half_width : int
        The neighbours of a line: the lines within +-half_width (default 10). Wider windows
        moderate more but follow a changing noise spectrum less closely (the estimated d0 then
        drops: the rule stays calibrated and moderates less).

    Returns
    -------
    ModeratedNoise
        With ``prior_dof`` 0 and the data unchanged when it cannot be formed (fewer than
        ``3 half_width`` lines with noise, statistics not from periods).

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal((4, 256)); y = 2 * u + 0.1 * rng.standard_normal((4, 256))
    >>> d = lptv.FrequencyData.from_periods(u, y, w0=1.0)
    >>> mod = lptv.moderated_noise(d)      # P = 4: each line's own variance has 6 dof
    >>> round(mod.prior_dof), round(float(np.median(mod.dof)))
    (43, 37)
    """
    from .frequency_data import FrequencyData
    from .mimo_frequency_data import MimoFrequencyData

    if isinstance(data, MimoFrequencyData):
        from .mimo_moderation import moderated_mimo_noise

        return moderated_mimo_noise(data, half_width)
    if not isinstance(data, FrequencyData):
        raise ValueError(f"data must be an lptv.FrequencyData or lptv.MimoFrequencyData, got {type(data).__name__}")
    W = as_int(half_width, "half_width", minimum=1, maximum=10**6)
    core = _core.moderated_noise(data._cpp, W)
    vu, vy = data.varU, data.varY
    dof = np.array(core.dof, dtype=float)
    if not core.moderated:
        return ModeratedNoise(data=data, dof=dof, prior_dof=0.0, outliers=np.zeros(0, int), half_width=W,
                              source_varU=vu, source_varY=vy, source_covYU=data.covYU, _core=core)
    moderated = FrequencyData.__new__(FrequencyData)
    moderated._set(core.data, data.w0, data.ts)
    return ModeratedNoise(data=moderated, dof=dof, prior_dof=float(core.prior_dof),
                          outliers=np.asarray(core.outliers, int).reshape(-1), half_width=W,
                          own_weight=np.array(core.own_weight, dtype=float),
                          neighbour=np.array(core.neighbour, dtype=bool), source_varU=vu, source_varY=vy,
                          source_covYU=data.covYU, _core=core)


SMOOTH_MAX_OUTLIERS = 0.10
"""The smoothness check (:func:`smooth_noise`) fails when more than this share of the lines keep
their own variance (outlying above their neighbours)."""


SMOOTH_LAG_SIGMAS = 2.5
"""The smoothness check fails when the correlation of neighbouring lines' log-variance residuals
exceeds this many of its standard errors 1 / sqrt(n) (n pairs of lines)."""


def _window_sum(a, kernel):
    """Per i: sum over x of a[i + x] kernel[x + S] for x = -S..S (kernel of length 2 S + 1, its
    middle entry ignored), a[j] = 0 outside 0..len(a) - 1."""
    k = kernel.copy()
    k[k.size // 2] = 0.0
    if a.size < k.size:     # np.convolve's 'same' takes the longer input's length
        pad = k.size
        return np.convolve(np.concatenate([np.zeros(pad), a, np.zeros(pad)]), k[::-1], mode="same")[pad:pad + a.size]
    return np.convolve(a, k[::-1], mode="same")


def _trend_residuals(v, keep, W):
    """Per line of ``v`` (variances of lines 1..Lmax-1): log v minus the value at the line of the
    least-squares quadratic in the offset x fitted to the other lines' log v over |x| <= 2 W
    (lines not kept and non-positive left out); NaN where fewer than W lines lie on either side."""
    m = v.size
    ok = keep & (v > 0)
    z = np.where(ok, np.log(np.where(ok, v, 1.0)), 0.0)
    S = 2 * W
    # the window sums over the offsets x = -S..S (x = 0 left out) as correlations with the
    # kernels x^q: sum_x ok[i + x] x^q and sum_x z[i + x] x^q, lines outside 0..m-1 absent
    x = np.arange(-S, S + 1, dtype=float) / S     # offsets scaled to -1..1 (the fit's value at 0 unchanged)
    okf = ok.astype(float)
    C = np.stack([_window_sum(okf, x ** q) for q in range(5)])
    T = np.stack([_window_sum(z, x ** q) for q in range(3)])
    left = _window_sum(okf, (x < 0).astype(float))
    right = _window_sum(okf, (x > 0).astype(float))
    good = ok & (left >= W) & (right >= W)
    r = np.full(m, np.nan)
    if good.any():
        # the first unknown of the 3 x 3 normal equations (Hankel in the moments C), by Cramer's
        # rule on the scaled offsets (entries of one size)
        c0, c1, c2, c3, c4 = C[:, good]
        t0, t1, t2 = T[:, good]
        m00, m01, m02 = c2 * c4 - c3 * c3, c1 * c4 - c2 * c3, c1 * c3 - c2 * c2
        det = c0 * m00 - c1 * m01 + c2 * m02
        # a window with the points of fewer than three offsets (half_width 1) fits no quadratic
        fits = det > 1e-10 * c0 * c2 * c4
        alpha = (t0 * m00 - c1 * (t1 * c4 - c3 * t2) + c2 * (t1 * c3 - c2 * t2)) / np.where(fits, det, 1.0)
        r[good] = np.where(fits, z[good] - alpha, np.nan)
    return r


def _lag_correlation(mo: ModeratedNoise):
    """The largest over the input and output of the correlation of neighbouring lines' residuals
    about the local log-quadratic trend, and its count of pairs (the smallest)."""
    W = int(mo.half_width)
    inner_n = int(np.size(mo.dof)) - 2
    keep = np.ones(inner_n, bool)
    if np.size(mo.outliers):
        keep[np.asarray(mo.outliers, int) - 1] = False
    worst, pairs = -1.0, 0
    channels = mo.channel_variances if hasattr(mo, "channel_variances") else (mo.source_varU, mo.source_varY)
    # one channel's moderation in the core fitted the same trends for its shape factors
    core = getattr(mo, "_core", None)
    fitted = ((np.asarray(core.trend_residual_u), np.asarray(core.trend_residual_y))
              if core is not None and hasattr(core, "trend_residual_u") else (None, None))
    for c, v in enumerate(channels):
        if v is None:
            continue
        v = np.asarray(v, float)[1:-1]
        if np.count_nonzero(v > 0) < 3 * W:
            continue
        r = fitted[c] if c < 2 and fitted[c] is not None and fitted[c].size == v.size else _trend_residuals(v, keep, W)
        a, b = r[:-1], r[1:]
        ok = np.isfinite(a) & np.isfinite(b)
        if ok.sum() < 3 * W:
            continue
        a, b = a[ok] - a[ok].mean(), b[ok] - b[ok].mean()
        c = float(a @ b / np.sqrt((a @ a) * (b @ b))) if (a @ a) > 0 and (b @ b) > 0 else 0.0
        if c > worst:
            worst, pairs = c, int(ok.sum())
    return worst, pairs


def smooth_noise(mo: ModeratedNoise):
    """The smoothness check of ``identify(..., noise='auto')`` (METHOD.md section 7, "The
    default noise route"): (passed, the sentence saying why).

    The noise spectrum counts as smooth across lines when the prior degrees of freedom d0 that
    :func:`moderated_noise` estimated from the spread of the log variances about their local
    trend are at least the lines' own d = 2 (P - 1) (the neighbours then know a line's
    variance at least as well as its own periods do), at most ``SMOOTH_MAX_OUTLIERS`` of the
    lines kept their own variance (a spectrum of many narrow peaks is not smooth), and the
    residuals of neighbouring lines' log variances about their local quadratic trend (over
    +-2 half_width lines, the line itself left out) do not correlate beyond
    ``SMOOTH_LAG_SIGMAS`` standard errors, in the input or the output (in any channel of several; a spectrum of bumps a few
    lines wide, which the trend cannot follow and the moderation would smear, is not smooth;
    for scatter about a smooth trend the residuals of neighbours are independent).

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.spectra.moderation import smooth_noise
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal((4, 512)); y = rng.standard_normal((4, 512))
    >>> ok, why = smooth_noise(lptv.moderated_noise(lptv.FrequencyData.from_periods(u, y, w0=1.0)))
    >>> ok
    True
    """
    from .mimo_moderation import MimoModeratedNoise

    if not isinstance(mo, (ModeratedNoise, MimoModeratedNoise)):
        raise ValueError(f"mo must be an lptv.ModeratedNoise (or the MimoModeratedNoise of several channels), "
                         f"got {type(mo).__name__}")
    P = int(mo.data.periods)
    d = 2.0 * (P - 1)
    d0 = float(mo.prior_dof)
    inner = max(int(np.size(mo.dof)) - 2, 1)
    share = np.size(mo.outliers) / inner
    if d0 <= 0:
        return False, "the noise variances cannot be moderated (too few lines with noise, or not from periods)"
    if d0 < d:
        return False, (f"the noise spectrum is not smooth across lines (prior degrees of freedom d0 = {d0:.3g} "
                       f"< the lines' own {d:.3g})")
    if share > SMOOTH_MAX_OUTLIERS:
        return False, (f"the noise spectrum is not smooth across lines ({np.size(mo.outliers)} of {inner} lines "
                       f"stand out above their neighbours)")
    corr, pairs = _lag_correlation(mo)
    limit = SMOOTH_LAG_SIGMAS / np.sqrt(max(pairs, 1))
    if pairs and corr > limit:
        return False, (f"the noise spectrum is not smooth across lines (neighbouring lines' variances about "
                       f"their trend correlate by {corr:.2f} > {limit:.2f}: bumps a few lines wide)")
    return True, (f"the noise spectrum is smooth across lines (prior degrees of freedom d0 = {d0:.3g} >= {d:.3g}; "
                  f"{np.size(mo.outliers)} of {inner} lines outlying; neighbouring lines' variances about "
                  f"their trend correlate by {corr:.2f} <= {limit:.2f})")
