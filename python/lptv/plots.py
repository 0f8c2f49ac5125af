"""Figures of the method (the paper's Figs. 2-6).

Every function takes an optional matplotlib ``ax`` and returns it. Without ``ax`` a new
:class:`matplotlib.figure.Figure` is made (not through pyplot, so no global state is touched
and nothing is shown); ``ax.figure`` gives it. Nothing here calls ``plt.show()`` or changes
matplotlib's settings.
"""
from __future__ import annotations

from typing import Optional

import numpy as np


# Margins of a new figure in inches: room for the tick labels and the axis label on the left,
# the x label below and a title above. Fixed margins instead of matplotlib's constrained layout,
# which measures every text of every axes before drawing (it was half of the identify report's
# figure time); every figure here keeps its texts within these margins.
MARGINS = dict(left=0.85, right=0.2, bottom=0.55, top=0.42, hspace=0.55, wspace=0.75)


def _figure(figsize=(6.4, 4.0), rows: int = 1, cols: int = 1, *, sharex=False, width_ratios=None,
            height_ratios=None, **margins):
    """A new figure (not through pyplot) and its ``rows`` x ``cols`` axes (a 2-D array), with the
    fixed :data:`MARGINS` (in inches; keywords override them)."""
    from matplotlib.figure import Figure

    m = {**MARGINS, **margins}
    w, h = figsize
    fig = Figure(figsize=figsize)
    # hspace / wspace are fractions of the mean axes' height / width
    ax_h = (h - m["bottom"] - m["top"] - (rows - 1) * m["hspace"]) / rows
    ax_w = (w - m["left"] - m["right"] - (cols - 1) * m["wspace"]) / cols
    fig.subplots_adjust(left=m["left"] / w, right=1 - m["right"] / w, bottom=m["bottom"] / h,
                        top=1 - m["top"] / h, hspace=m["hspace"] / max(ax_h, 0.1),
                        wspace=m["wspace"] / max(ax_w, 0.1))
    axes = fig.subplots(rows, cols, sharex=sharex, squeeze=False, width_ratios=width_ratios,
                        height_ratios=height_ratios)
    for ax in axes.flat:      # at most 6 ticks a side: each tick is a text to lay out and draw
        ax.locator_params(nbins=5)
    return fig, axes


def _axes(ax, figsize=(6.4, 4.0)):
    if ax is not None:
        return ax
    return _figure(figsize)[1][0, 0]


def _log_x(ax):
    """A logarithmic frequency axis with ticks at 1, 2, 5 times the powers of ten, labelled in
    plain numbers (0.5, 1, 2, 5, 10, ...) rather than in powers of ten, and no minor ticks (each
    tick is a text to lay out and a grid line to draw)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    ax.set_xscale("log")
    ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.grid(True, which="major", alpha=0.3)


def _z_of(level: float) -> float:
    """The two-sided standard normal quantile of a confidence level (the standard library's:
    scipy.stats costs half a second to import)."""
    from statistics import NormalDist

    return NormalDist().inv_cdf(0.5 + level / 2.0)


def _series(x, name, n=None, ndim=1):
    """A numeric array of the given dimension (and length n along its first axis) to plot; NaN
    and inf are allowed (a pole at infinity, a line without data)."""
    from ._validate import _array

    a = _array(x, name)
    if a.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-D, got shape {a.shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} must have one value per line or time ({n}), got {a.shape[0]}")
    return a


def _options(w0=None, hz=False):
    from ._validate import as_bool, as_float

    as_bool(hz, "hz")
    if w0 is not None and w0 != 0:
        as_float(w0, "w0", minimum=0.0, open_min=True, what="a finite positive angular frequency (rad/s)")


def _freq_axis(lines, w0, hz):
    """x values and label of a frequency axis: line * w0 in rad/s (or Hz), else the line number."""
    _options(w0, hz)
    lines = _series(lines, "lines")
    if not w0:
        return lines, "line (multiple of the fundamental)"
    if hz:
        return lines * w0 / (2 * np.pi), "frequency (Hz)"
    return lines * w0, "angular frequency (rad/s)"


def _db(x):
    x = np.abs(np.asarray(x))
    with np.errstate(divide="ignore"):
        return 20 * np.log10(np.where(x > 0, x, np.nan))


def output_spectrum(lines, Y_fds, Y_time=None, *, w0=None, ax=None, labels=("FDS", "CVODE"), hz=False):
    """Output spectrum of the FDS, the time integration and their difference in dB (paper Fig. 2).

    Parameters
    ----------
    lines : array of int
    Y_fds, Y_time : complex arrays on ``lines``
    w0 : float, optional
        Plot against angular frequency l * w0 (rad/s) instead of the line number.
    hz : bool
        With ``w0``: the frequency axis in Hz instead of rad/s.
    """
    x, xlabel = _freq_axis(lines, w0, hz)
    _series(Y_fds, "Y_fds", x.size)
    if Y_time is not None:
        _series(Y_time, "Y_time", x.size)
    ax = _axes(ax)
    if Y_time is not None:
        ax.plot(x, _db(Y_time), "o", ms=4.5, mfc="none", mew=0.8, color="C1", label=labels[1])
    ax.plot(x, _db(Y_fds), ".", ms=3, color="C0", zorder=3, label=labels[0])
    if Y_time is not None:
        ax.plot(x, _db(np.asarray(Y_fds) - np.asarray(Y_time)), ".", ms=2, color="C3",
                label=f"|{labels[0]} - {labels[1]}|")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("amplitude (dB)")
    ax.grid(True, alpha=0.3)
    handles, names = ax.get_legend_handles_labels()
    order = sorted(range(len(names)), key=lambda i: names[i] != labels[0])
    ax.legend([handles[i] for i in order], [names[i] for i in order])
    return ax


def frozen_poles_zeros(t, poles_true=None, zeros_true=None, poles_est=None, zeros_est=None, *,
                       ax=None, zoom_on_poles=False, discrete=False, equal_aspect=None):
    """Frozen (instantaneous) poles and zeros over a period, true and estimated (paper Figs. 3, 5).

    Continuous time: the s-plane, both axes in rad/s. ``discrete=True``: the z-plane (unitless),
    with the unit circle. ``equal_aspect`` draws both axes on the same scale (so a damping ratio
    reads off as an angle); by default it is on unless the curves are far wider than tall (the
    paper's Fig. 3), and always on in the z-plane.
    """
    from ._validate import as_bool

    t = _series(t, "t")
    for name, arr in (("poles_true", poles_true), ("zeros_true", zeros_true), ("poles_est", poles_est),
                      ("zeros_est", zeros_est)):
        if arr is not None:
            _series(np.atleast_2d(arr) if np.ndim(arr) < 2 else arr, name, t.size, ndim=2)
    discrete = as_bool(discrete, "discrete")
    zoom_on_poles = as_bool(zoom_on_poles, "zoom_on_poles")
    ax = _axes(ax)
    style = {"true": dict(lw=2.0, alpha=0.5), "est": dict(lw=1.0, ls="--")}
    drawn = []
    def curves(arr, marker, color, label, kind):
        if arr is None:
            return
        arr = np.atleast_2d(np.asarray(arr))
        drawn.append(arr[np.isfinite(arr)])
        for j in range(arr.shape[1]):
            ax.plot(arr[:, j].real, arr[:, j].imag, color=color, **style[kind])
            ax.plot(arr[0, j].real, arr[0, j].imag, marker, color=color, ms=7, mfc="none", mew=1.2)
        # the legend shows what is drawn: the curve (time-varying roots) and the marker at t = 0
        if arr.size == 0:
            return
        with np.errstate(invalid="ignore"):
            moving = arr.shape[0] > 1 and bool(np.any(np.abs(np.ptp(arr, axis=0)) > 1e-9 * (1 + np.abs(arr[0]))))
        ax.plot([], [], marker=marker, color=color, ms=7, mfc="none", mew=1.2, label=label,
                **(style[kind] if moving else dict(ls="none")))
    curves(poles_true, "x", "C0", "poles, true", "true")
    curves(poles_est, "x", "C3", "poles, estimated", "est")
    if not zoom_on_poles:
        curves(zeros_true, "o", "C2", "zeros, true", "true")
        curves(zeros_est, "o", "C1", "zeros, estimated", "est")
    if discrete:
        th = np.linspace(0, 2 * np.pi, 361)
        ax.plot(np.cos(th), np.sin(th), color="0.5", lw=0.8, label="unit circle")
        ax.set_xlabel("real part (z-plane, unitless)")
        ax.set_ylabel("imaginary part (z-plane, unitless)")
    else:
        ax.set_xlabel("real part (rad/s)")
        ax.set_ylabel("imaginary part (rad/s)")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.axvline(0.0, color="0.6", lw=0.6)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    if zoom_on_poles and poles_true is not None:
        pt = np.asarray(poles_true)
        pt = pt[np.isfinite(pt)]
        sel = pt[pt.imag >= 0] if np.any(pt.imag >= 0) else pt
        pad = 0.15 * max(np.ptp(sel.real), np.ptp(sel.imag), 1e-3)
        ax.set_xlim(sel.real.min() - pad, sel.real.max() + pad)
        ax.set_ylim(sel.imag.min() - pad, sel.imag.max() + pad)
    elif equal_aspect is None:
        pts = np.concatenate(drawn) if drawn else np.zeros(0)
        wide = pts.size and np.ptp(pts.real) > 8 * max(np.ptp(pts.imag), 1e-12) and np.ptp(pts.imag) > 0
        equal_aspect = discrete or not wide
    if zoom_on_poles and equal_aspect is None:
        equal_aspect = True
    if equal_aspect:
        # with the zoom's fixed limits the box adapts; otherwise the limits do
        ax.set_aspect("equal", adjustable="box" if zoom_on_poles else "datalim")
    return ax


def prediction_error(lines, noise_std, error, *, w0=None, ax=None, mean_noise_std=None, hz=False):
    """Output-noise standard deviation against |true - predicted output| per line (paper Fig. 4);
    against frequency l * w0 in rad/s (or Hz with ``hz``) when ``w0`` is given."""
    x, xlabel = _freq_axis(lines, w0, hz)
    _series(noise_std, "noise_std", x.size)
    _series(error, "error", x.size)
    ax = _axes(ax)
    ax.plot(x, _db(noise_std), "-", color="C0", label="output noise std (one period)")
    if mean_noise_std is not None:
        ax.plot(x, _db(mean_noise_std), "-", color="C0", alpha=0.4, label="std of the mean of P periods")
    ax.plot(x, _db(error), ".", ms=3, color="C3", label="|true - predicted output|")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("amplitude (dB)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def normalized_residue(lines, r, *, w0=None, ax=None, fraction=None, expected=None, hz=False,
                       excited=None):
    """Normalised residue |e_l| / sqrt(var e_l) per line in dB with the 0 dB line (paper Fig. 6);
    against frequency l * w0 in rad/s (or Hz with ``hz``) when ``w0`` is given. ``excited``: the
    lines to mark (those the verdict judges), drawn on top in another colour."""
    x, xlabel = _freq_axis(lines, w0, hz)
    _series(r, "r", x.size)
    ax = _axes(ax)
    if excited is None:
        ax.plot(x, _db(r), ".", ms=4, color="C0")
    else:
        on = np.isin(np.asarray(lines), np.asarray(excited))
        ax.plot(x[~on], _db(np.asarray(r)[~on]), ".", ms=3, color="0.6", label="other lines of the fit")
        ax.plot(x[on], _db(np.asarray(r)[on]), "o", ms=4, color="C0", zorder=3,
                label="excited lines")
        ax.legend(fontsize="small")
    ax.axhline(0.0, color="k", lw=1)
    title = []
    if fraction is not None:
        title.append(f"{100 * fraction:.1f} % above 0 dB")
    if expected is not None:
        title.append(f"expected {100 * expected:.1f} %")
    if title:
        ax.set_title(", ".join(title))
    ax.set_xlabel(xlabel)
    ax.set_ylabel("normalised residue (dB)")
    ax.grid(True, alpha=0.3)
    return ax


def lack_of_fit(lof, *, w0: Optional[float] = None, hz: bool = False, ax=None):
    """Where a model of the best linear approximation departs from the per-line regression
    across the realisations (a :class:`lptv.LackOfFit`, ``res.lack_of_fit``): each judged line's
    -log10 of its F test's p-value, the 5 % and 1 % lines of one line's test, the three worst
    lines marked. The verdict itself is the permutation test of all lines together (in the
    title); single lines above the 1 % line are expected in about 1 % of the lines.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import noisy_periods, paper_model
    >>> m = paper_model()
    >>> u, y = [], []
    >>> for r in range(6):
    ...     ms = lptv.multisine(range(10, 241, 10), 2048, amplitudes=np.sqrt(2 / 24), seed=r)
    ...     y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 2048)
    ...     a, b = noisy_periods(ms.signal, y0 + 0.02 * y0 ** 3, 4, 50, 30, seed=100 + r)
    ...     u.append(a); y.append(b)
    >>> d = lptv.distortion(np.array(u), np.array(y), w0=m.w0)
    >>> res = lptv.identify(d.experiments(), na=2, nb=1, ka=3, kb=3, lines=[range(1, 244)] * 6, method="sml")
    >>> ax = lptv.plots.lack_of_fit(res.lack_of_fit, w0=m.w0)
    >>> ax.get_ylabel()
    '-log10 p of the line'
    """
    from .distortion import LackOfFit
    from ._validate import as_bool, as_positive_float

    if not isinstance(lof, LackOfFit):
        raise ValueError(f"lof must be an lptv.LackOfFit (res.lack_of_fit or d.lack_of_fit(model)), "
                         f"got {type(lof).__name__}")
    hz = as_bool(hz, "hz")
    if w0 is not None:
        w0 = as_positive_float(w0, "w0")
    ax = _axes(ax)
    x = lof.lines * (1.0 if w0 is None else w0 / (2 * np.pi if hz else 1.0))
    y = -np.log10(np.clip(lof.p_lines, 1e-300, 1.0))
    ax.plot(x, y, ".", ms=4, color="C0", label="per line: F(2 q, 2 (M - q)) test")
    for level, style in ((0.05, ":"), (0.01, "--")):
        ax.axhline(-np.log10(level), color="0.4", ls=style, lw=1, label=f"one line at {100 * level:g} %")
    worst = np.argsort(lof.p_lines, kind="stable")[:3]
    for i in worst:
        ax.annotate(str(int(lof.lines[i])), (x[i], y[i]), textcoords="offset points", xytext=(3, 3),
                    fontsize="x-small")
    ax.set_xlabel("line" if w0 is None else ("frequency (Hz)" if hz else "angular frequency (rad/s)"))
    ax.set_ylabel("-log10 p of the line")
    ax.set_title(f"lack of fit against the {lof.realisations} realisations: z = {lof.statistic:.2f},\n"
                 f"permutation p = {lof.p_value:.2g} ({'rejected' if lof.rejects else 'not rejected'} at "
                 f"{100 * lof.alpha:g} %)", fontsize="medium")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    return ax


def distortion(d, *, hz: bool = False, ax=None):
    """Signal, noise and nonlinear distortion levels per output line in dB (FDIDENT's picture of
    a nonlinear measurement): the output power on the excited lines and their sidebands, the
    noise of a period mean, and the stochastic nonlinear distortion (a
    :class:`lptv.DistortionResult`).

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import noisy_periods, paper_model
    >>> m = paper_model()
    >>> u, y = [], []
    >>> for r in range(6):
    ...     ms = lptv.multisine(range(10, 241, 10), 2048, seed=r)
    ...     y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 2048)
    ...     a, b = noisy_periods(ms.signal, y0 + 0.05 * y0 ** 3, 4, 50, 30, seed=100 + r)
    ...     u.append(a); y.append(b)
    >>> ax = lptv.plots.distortion(lptv.distortion(np.array(u), np.array(y), w0=m.w0))
    >>> ax.get_ylabel()
    'power (dB)'
    """
    from .distortion import DistortionResult
    from ._validate import as_bool

    if not isinstance(d, DistortionResult):
        raise ValueError(f"d must be an lptv.DistortionResult, got {type(d).__name__}")
    hz = as_bool(hz, "hz")
    ax = _axes(ax)
    x = d.w / (2 * np.pi) if hz else d.w
    ok = np.isfinite(d.p_value)
    for kind, style, label in (("excited", dict(marker="o", ms=4, color="C0"), "output, excited lines"),
                               ("sideband", dict(marker=".", ms=3, color="C2"),
                                f"output, sidebands (+-{d.branches})")):
        sel = d.kind == kind
        ax.plot(x[sel], _db(np.sqrt(d.signal[sel])), ls="none", label=label, **style)
    ax.plot(x[ok], _db(np.sqrt(d.noise[ok])), color="0.5", lw=1, label="noise (from the periods)")
    nl = np.where(ok & (d.nonlinear > 0), d.nonlinear, np.nan)
    ax.plot(x, _db(np.sqrt(nl)), "x", ms=3, color="C3", label="nonlinear distortion (from the realisations)")
    ax.set_xlabel("frequency (Hz)" if hz else "angular frequency (rad/s)")
    ax.set_ylabel("power (dB)")
    ax.set_title(f"{d.realisations} realisations x {d.periods} periods: nonlinear distortion "
                 f"{'detected' if d.detected else 'not detected'} (p = {d.p_overall:.2g})", fontsize="medium")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    return ax


def moderated_noise(mod, *, hz: bool = False, ax=None):
    """The noise variances of a period mean per line, each line's own sample variance against the
    moderated one (a :class:`lptv.ModeratedNoise`): output and input, in dB, with the lines that
    kept their own (above their neighbours beyond noise) marked.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal((4, 256)); y = 2 * u + 0.1 * rng.standard_normal((4, 256))
    >>> mod = lptv.moderated_noise(lptv.FrequencyData.from_periods(u, y, w0=1.0))
    >>> ax = lptv.plots.moderated_noise(mod)
    >>> ax.get_ylabel()
    'noise variance of the mean (dB)'
    """
    from .moderation import ModeratedNoise
    from ._validate import as_bool

    if not isinstance(mod, ModeratedNoise):
        raise ValueError(f"mod must be an lptv.ModeratedNoise (from lptv.moderated_noise), got {type(mod).__name__}")
    hz = as_bool(hz, "hz")
    ax = _axes(ax)
    d = mod.data
    L = d.max_line
    lines = np.arange(1, L)
    own_u, own_y = np.asarray(mod.source_varU), np.asarray(mod.source_varY)
    x, label = _freq_axis(lines, d.w0, hz)
    for own, moderated, color, name in ((own_y, d.varY, "C0", "output"), (own_u, d.varU, "C1", "input")):
        if not np.any(np.asarray(moderated)[lines] > 0):
            continue
        ax.plot(x, 10 * np.log10(np.maximum(own[lines], 1e-300)), ".", ms=3, color=color, alpha=0.5,
                label=f"{name}: each line's own")
        ax.plot(x, 10 * np.log10(np.maximum(np.asarray(moderated)[lines], 1e-300)), "-", lw=1.2, color=color,
                label=f"{name}: moderated")
    if mod.outliers.size:
        xo, _ = _freq_axis(mod.outliers, d.w0, hz)
        ax.plot(xo, 10 * np.log10(np.maximum(own_y[mod.outliers], 1e-300)), "o", mfc="none", color="C3",
                label="kept their own (above their neighbours)")
    ax.set_xlabel(label)
    ax.set_ylabel("noise variance of the mean (dB)")
    dof = float(np.median(mod.dof[lines]))
    ax.set_title(f"P = {d.periods}: own {2 * (d.periods - 1)} dof per line, moderated about {dof:.0f} "
                 f"(d0 = {mod.prior_dof:.3g})", fontsize="medium")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    return ax


def disturbances(result, *, w0: float = None, hz: bool = False, fig=None):
    """What :func:`lptv.disturbances` searched: per signal (input, output), the power of the
    periods' deviation from their mean on the record's grid (P bins per line) against its local
    noise level and the detection threshold, with the sinusoids found marked.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> P, N = 8, 512
    >>> n = np.arange(P * N)
    >>> y = (0.01 * rng.standard_normal(P * N) + 0.05 * np.cos(2 * np.pi * 40.37 * n / N)).reshape(P, N)
    >>> u = np.tile(np.cos(2 * np.pi * 3 * np.arange(N) / N), (P, 1)) + 0.01 * rng.standard_normal((P, N))
    >>> fig = lptv.plots.disturbances(lptv.disturbances(u, y))
    >>> [ax.get_title() for ax in fig.axes]
    ['input: nothing found', 'output: 1 sinusoid off the grid']
    """
    from .disturbances import DisturbanceResult
    from ._validate import as_bool, as_float

    if not isinstance(result, DisturbanceResult):
        raise ValueError(f"result must be an lptv.DisturbanceResult (from lptv.disturbances), got {type(result).__name__}")
    hz = as_bool(hz, "hz")
    if w0 is not None:
        w0 = as_float(w0, "w0", minimum=0.0, open_min=True)
    if not result.spectra:
        raise ValueError("result holds no spectra: the records were too short to search")
    n = len(result.spectra)
    if fig is None:
        fig, axes = _figure((6.4, 2.6 * n), n, 1, hspace=0.85)
    else:
        axes = fig.subplots(n, 1, squeeze=False)
    axes = axes[:, 0]
    names = {"u": "input", "y": "output"}
    for ax, (sig, (pos, p2, level)) in zip(axes, result.spectra.items()):
        x, label = (pos, "line (cycles per period)") if w0 is None else _freq_axis(pos, w0, hz)
        ax.plot(x, 10 * np.log10(np.maximum(p2, 1e-300)), ".", ms=2, color="C0", alpha=0.5,
                label="deviation from the periodic mean")
        ax.plot(x, 10 * np.log10(np.maximum(level, 1e-300)), "-", lw=1, color="C2", label="local noise level")
        ax.plot(x, 10 * np.log10(np.maximum(level * result.threshold, 1e-300)), "--", lw=1, color="C3",
                label="detection threshold")
        mine = [d for d in result.found if d.signal == sig]
        for d in mine:
            xd = d.line if w0 is None else _freq_axis(np.array([d.line]), w0, hz)[0][0]
            ax.axvline(xd, color="C3", lw=0.8, alpha=0.6)
        ax.set_title(f"{names[sig]}: " + (f"{len(mine)} sinusoid{'s' if len(mine) > 1 else ''} off the grid"
                                           if mine else "nothing found"))
        ax.set_xlabel(label)
        ax.set_ylabel("power (dB)")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize="small", loc="upper right")
    return fig


def residue_tests(res, *, fig=None):
    """The verdict's residue tests (:attr:`lptv.IdentificationResult.residue_tests`) as horizontal
    bars, each on its own statistic against its own threshold, under the short names of
    :func:`residue_test_label` (the reports' tables use them too): the sums of normal scores (z,
    standard normal without a model error; two-sided over all rows with signal, one-sided per
    group of rows at one distance d from the excited lines) in the upper panel, the score tests of
    one more harmonic per coefficient (an F statistic with its own degrees of freedom) in the
    lower one. A test's threshold is where its statistic reaches the level Holm's method gives
    it, alpha / (number of tests not yet rejected before it) (overall size ``alpha``, 1 %); it
    rejects (red) when it and every test with a smaller p-value reach theirs.

    Returns the figure.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import system_measurements
    >>> d = system_measurements("third_order", seed=1, periods=8)
    >>> res = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], lines=d["lines"])
    >>> fig = lptv.plots.residue_tests(res)
    >>> [ax.get_xlabel().split(":")[0] for ax in fig.axes]
    ['z', 'F of the score test for one more harmonic on the coefficient']
    """
    tests = getattr(res, "residue_tests", None)
    if tests is None:
        raise ValueError("res: the fit has no residue tests (no noise in the data, or no data kept)")
    thresholds = residue_test_thresholds(tests)
    groups = [[i for i, t in enumerate(tests.tests) if t.kind != "score"],
              [i for i, t in enumerate(tests.tests) if t.kind == "score"]]
    groups = [g for g in groups if g]
    # horizontal bars, one row per test: the names read in full and each threshold marks its own row
    heights = [len(g) + 0.6 for g in groups]
    if fig is None:
        fig, axes = _figure((6.4, 1.35 + 0.3 * sum(heights) + 0.55 * (len(groups) - 1)), len(groups), 1,
                            left=1.95, top=0.5, bottom=0.5, hspace=0.55, height_ratios=heights)
    else:
        axes = fig.subplots(len(groups), 1, squeeze=False, height_ratios=heights)
    for ax, idx in zip(axes[:, 0], groups):
        score = tests.tests[idx[0]].kind == "score"
        y = np.arange(len(idx))[::-1]
        stat = np.array([tests.tests[i].statistic for i in idx])
        ax.barh(y, stat, height=0.6, color=["C3" if tests.tests[i].rejects else "C0" for i in idx])
        for yi, i in zip(y, idx):
            for thr in thresholds[i]:
                if thr is not None:
                    ax.vlines(thr, yi - 0.42, yi + 0.42, color="k", ls="--", lw=1.2)
        ax.set_yticks(y, [f"{residue_test_label(tests.tests[i])} ({tests.tests[i].rows.size} rows)" for i in idx],
                      fontsize="small")
        ax.set_ylim(-0.6, len(idx) - 0.4)
        marks = [v for i in idx for v in thresholds[i] if v is not None]
        if score:
            ax.set_xlabel("F of the score test for one more harmonic on the coefficient", fontsize="small")
            top = max(float(np.max(stat)), max(marks))
            if top > 30 * max(marks):      # a rejected structure's F of 10^5 would hide the thresholds
                from matplotlib.ticker import FuncFormatter

                ax.set_xscale("log")
                ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
                ax.set_xlim(0.5 * min(float(np.min(stat[stat > 0], initial=1.0)), min(marks)), 2 * top)
            else:
                ax.set_xlim(0, 1.1 * top)
        else:
            ax.set_xlabel("z: sum of the rows' normal scores over its std (N(0, 1) without a model error)",
                          fontsize="small")
            lo = min(0.0, float(np.min(stat)), min(marks))
            hi = max(0.0, float(np.max(stat)), max(marks))
            pad = 0.08 * (hi - lo)
            ax.set_xlim(lo - pad, hi + pad)
            ax.axvline(0.0, color="k", lw=0.8)
        ax.grid(True, axis="x", alpha=0.3)
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fig.legend(handles=[Line2D([], [], color="k", ls="--", lw=1.1,
                               label=f"each test's threshold (Holm, overall {100 * tests.alpha:g} %)"),
                        Patch(color="C0", label="not rejected"), Patch(color="C3", label="rejects")],
               # a constrained layout (a figure passed in) makes room above the axes for it
               loc="outside upper center" if type(fig.get_layout_engine()).__name__ == "ConstrainedLayoutEngine"
               else "upper center", ncol=3, fontsize="small", frameon=False, borderaxespad=0.2)
    return fig


def residue_test_label(test) -> str:
    """The short name of a residue test (a :class:`lptv.verdict.ResidueTest`) that the reports'
    table and :func:`residue_tests` share: 'all rows' (every row with signal), 'd = 3' (the rows 3
    lines from the nearest excited line), 'a0: +1 harmonic' (the score test of one more harmonic
    on a_0)."""
    import re

    if test.kind == "score":
        m = re.search(r"on (\w+)$", test.name)
        return f"{m.group(1) if m else test.name}: +1 harmonic"
    if test.name == "rows with signal":
        return "all rows"
    m = re.match(r"rows (\d+) lines? from", test.name)
    return f"d = {m.group(1)}" if m else test.name


def residue_test_thresholds(tests):
    """Per test of a :class:`lptv.verdict.ResidueTests`, its thresholds ``(lower, upper)`` on its own
    statistic (None where a side is not tested): the values at which its p-value reaches the level
    Holm's step-down method gives it, alpha / (k - r) for the test of rank r (0 for the smallest
    p-value) among k. A z test (a sum of normal scores): one-sided per offset group (upper), two-sided over all
    rows with signal; a score test: the F(2, nu) quantile, nu recovered from the test's F value and
    p-value (the F(2, nu) tail is (1 + 2 F / nu)^(-nu / 2), monotone in nu; nu infinite is the
    chi-squared limit exp(-F))."""
    from statistics import NormalDist

    k = len(tests.tests)
    ranks = np.argsort(np.argsort([t.p_value for t in tests.tests], kind="stable"), kind="stable")
    out = []
    for t, r in zip(tests.tests, ranks):
        q = tests.alpha / (k - r)
        if t.kind == "score":
            nu = _f2_dof(t.statistic, t.p_value)
            out.append((None, -np.log(q) if nu is None else nu / 2 * (q ** (-2 / nu) - 1)))
        elif t.name == "rows with signal":
            zq = NormalDist().inv_cdf(1 - q / 2)
            out.append((-zq, zq))
        else:
            out.append((None, NormalDist().inv_cdf(1 - q)))
    return out


def _f2_dof(F: float, p: float):
    """nu with P(F(2, nu) > F) = p; None for the chi-squared limit (p at or below exp(-F))."""
    if not (F > 0 and 0 < p < 1) or np.log(p) <= -F * (1 - 1e-12):
        return None
    g = lambda nu: -nu / 2 * np.log1p(2 * F / nu) - np.log(p)     # decreasing in nu
    lo, hi = 1e-6, 1.0
    while g(hi) > 0:
        hi *= 2
        if hi > 1e12:
            return None
    for _ in range(200):
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if g(mid) > 0 else (lo, mid)
        if hi / lo < 1 + 1e-13:
            break
    return float(np.sqrt(lo * hi))


def coefficients(t, true=None, est=None, *, names=None, ax=None, ylabel="coefficient value"):
    """Coefficient trajectories a_n(t) / b_m(t) over time, true (wide, pale) and estimated (dashed).

    One colour per coefficient; the legend names the coefficients by colour and, when both are
    drawn, the line styles of true and estimated.
    """
    from matplotlib.lines import Line2D

    t = _series(t, "t")
    drawn = [(_series(arr, lab if lab == "true" else "est", t.size, ndim=2), lab)
             for arr, lab in ((true, "true"), (est, "estimated")) if arr is not None]
    ax = _axes(ax)
    styles = {"true": dict(ls="-", lw=3.0, alpha=0.35), "estimated": dict(ls="--", lw=1.2)}
    n = max((arr.shape[1] for arr, _ in drawn), default=0)
    label = [names[j] if names else f"c{j}" for j in range(n)]
    if len(drawn) == 1:  # one kind: plain lines, as the legend shows them
        styles[drawn[0][1]] = dict(ls="-", lw=1.6)
    for arr, lab in drawn:
        for j in range(arr.shape[1]):
            ax.plot(t, arr[:, j], color=f"C{j % 10}", **styles[lab])
    handles = [Line2D([], [], color=f"C{j % 10}", lw=1.6, label=label[j]) for j in range(n)]
    if len(drawn) > 1:
        handles += [Line2D([], [], color="0.3", label=lab, **styles[lab]) for _, lab in drawn]
    elif drawn:
        ax.set_title(f"{drawn[0][1]} coefficients over one period")
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    if handles:
        ax.legend(handles=handles, fontsize="small", ncol=2 if n > 4 else 1)
    return ax


def coefficient_bands(t, values, std=None, *, names, units=None, level: float = 0.95, fig=None,
                      title: Optional[str] = None):
    """One panel per coefficient over time (``values``, shape (len(t), n)), each on its own axis
    with its ``level`` band ``+- z std`` (``std`` of the same shape, or None): coefficients of very
    different sizes (a stiffness of 40 and a mass of 1) each show their own time variation.
    ``units``: a unit per coefficient for its axis label (or None).

    Returns the figure.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> t = np.linspace(0, 5, 50)
    >>> v = np.column_stack([40 + 12 * np.cos(2 * np.pi * t / 5), np.full(50, 0.8)])
    >>> fig = lptv.plots.coefficient_bands(t, v, 0.01 * np.ones((50, 2)), names=["a0", "a1"])
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['a0', 'a1']
    """
    from ._validate import as_float

    t = _series(t, "t")
    values = _series(values, "values", t.size, ndim=2)
    n = values.shape[1]
    if std is not None:
        std = _series(std, "std", t.size, ndim=2)
        if std.shape != values.shape:
            raise ValueError(f"std must have the shape of values {values.shape}, got {std.shape}")
    names = [str(v) for v in names]
    if len(names) != n:
        raise ValueError(f"names must name each of the {n} coefficients, got {len(names)}")
    units = [None] * n if units is None else list(units)
    if len(units) != n:
        raise ValueError(f"units must have one entry per coefficient ({n}), got {len(units)}")
    level = as_float(level, "level", minimum=0.0, maximum=1.0, open_min=True, open_max=True)
    z = _z_of(level)
    cols = 1 if n == 1 else 2
    rows = -(-n // cols)
    if fig is None:
        fig, axes = _figure((6.4, 0.95 + 1.75 * rows), rows, cols, sharex=True, hspace=0.3, wspace=1.05)
    else:
        axes = fig.subplots(rows, cols, sharex=True, squeeze=False)
    for j in range(rows * cols):
        ax = axes.flat[j]
        if j >= n:
            ax.set_visible(False)
            continue
        color = f"C{j % 10}"
        if std is not None:
            ax.fill_between(t, values[:, j] - z * std[:, j], values[:, j] + z * std[:, j], color=color,
                            alpha=0.25, lw=0)
        ax.plot(t, values[:, j], "-", color=color, lw=1.4)
        ax.set_ylabel(names[j] + (f" ({units[j]})" if units[j] else ""))
        ax.grid(True, alpha=0.3)
        # a constant coefficient: a few significant digits of range around it, not rounding noise
        lo, hi = ax.get_ylim()
        mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        floor = 1e-3 * max(abs(mid), 1e-300)
        if half < floor:
            ax.set_ylim(mid - floor, mid + floor)
        ax.ticklabel_format(axis="y", useOffset=False)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    if rows > 1 and n % cols:     # the last row's empty slot: the x label on the panel above it
        axes[-2, -1].xaxis.set_tick_params(labelbottom=True)
        axes[-2, -1].set_xlabel("time (s)")
    band = f" ({100 * level:g} % band)" if std is not None else ""
    fig.suptitle((title or "coefficients over one period") + band, fontsize="medium",
                 y=1 - 0.12 / fig.get_figheight())
    return fig


def model_fit(lines, Y, Y_model, noise_std=None, *, w0=None, ax=None, hz=False):
    """Measured output spectrum, the model's output, their difference and the noise level (dB),
    against frequency l * w0 in rad/s (or Hz with ``hz``) when ``w0`` is given. The model is drawn
    as open circles under the measured points, so the data stay visible."""
    x, xlabel = _freq_axis(lines, w0, hz)
    Y, Y_model = _series(Y, "Y", x.size), _series(Y_model, "Y_model", x.size)
    if noise_std is not None:
        _series(noise_std, "noise_std", x.size)
    ax = _axes(ax)
    if noise_std is not None:
        ax.plot(x, _db(noise_std), "-", color="0.55", lw=1.0, label="noise std of the mean output")
    ax.plot(x, _db(Y - Y_model), ".", ms=2.5, color="C3", alpha=0.7, label="difference |Y - Y_model|")
    ax.plot(x, _db(Y_model), "o", ms=5, mfc="none", mew=0.8, color="C1",
            label="model output from the measured input")
    ax.plot(x, _db(Y), ".", ms=3, color="C0", zorder=3, label="measured output |Y| (mean of the periods)")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("amplitude (dB)")
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    ax.legend(handles[::-1], labels[::-1], fontsize="small")
    return ax


def htf_branches(est, model=None, *, hz: bool = False, ax=None, guard: int = 60):
    """The nonparametric HTF branches |G_k| in dB against frequency with +-2 standard deviations
    (a :class:`lptv.HtfEstimate`), and, given a model, its branches on top (lines through the same
    frequencies). Branches whose p-value says they stand above the noise are drawn solid, the
    others faint; entries that the far branches of neighbouring excited lines overlap
    (``est.overlapped``: the ratio there is biased by more than a fraction of its noise) are
    crosses, and a model should be compared on the other entries only.

    Parameters
    ----------
    est : lptv.HtfEstimate
    model : lptv.Model, optional
        Its HTF (:func:`lptv.htf`) at the excited lines, continuous time on lines -L..L with
        ``guard`` lines beyond the highest branch.
    hz : bool
        Frequency axis in Hz instead of rad/s.
    """
    from .fds import htf
    from .model import Model
    from .nonparametric import HtfEstimate
    from ._validate import as_bool, as_int

    if not isinstance(est, HtfEstimate):
        raise ValueError(f"est must be an lptv.HtfEstimate, got {type(est).__name__}")
    if model is not None and not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model or None, got {type(model).__name__}")
    hz = as_bool(hz, "hz")
    guard = as_int(guard, "guard")
    ax = _axes(ax)
    x = est.w / (2 * np.pi) if hz else est.w
    sig = set(est.significant().tolist())
    G_model = None
    if model is not None:
        lines = [int(l) for l in est.lines]
        if model.discrete:
            N = model.samples_per_period
            G = htf(model, 0, lines)
            G_model = np.array([[G[(l + k) % N, c] for c, l in enumerate(lines)] for k in est.k])
        else:
            L = max(lines) + est.branches + guard
            G = htf(model, L, lines)
            G_model = np.array([[G[l + k + L, c] for c, l in enumerate(lines)] for k in est.k])
    # Where the band reaches zero its lower edge is drawn at a floor 20 dB under the data.
    floor = 10 ** ((np.nanmin(_db(est.G)) - 20) / 20)
    for i, k in enumerate(est.k):
        color = f"C{i % 10}"
        alpha = 1.0 if k in sig else 0.35
        mag = np.abs(est.G[i])
        lo = _db(np.maximum(mag - 2 * est.std[i], floor))
        hi = _db(mag + 2 * est.std[i])
        ax.fill_between(x, lo, hi, color=color, alpha=0.15 * alpha, lw=0)
        over = est.overlapped[i] if est.overlapped is not None else np.zeros(mag.size, bool)
        ax.plot(x[~over], _db(mag[~over]), "o", ms=3.5, color=color, alpha=alpha,
                label=f"G_{k:+d} (data)" if k else "G_0 (data)")
        if over.any():
            ax.plot(x[over], _db(mag[over]), "x", ms=4.5, color=color, alpha=alpha)
        if G_model is not None:
            ax.plot(x, _db(G_model[i]), "-", lw=1.0, color=color, alpha=alpha)
    if est.overlapped is not None and est.overlapped.any():
        ax.plot([], [], "x", color="0.3", label="overlapped by neighbours' branches (biased)")
    if G_model is not None:
        ax.plot([], [], "-", color="0.3", lw=1.0, label="model")
    _log_x(ax)
    ax.set_xlabel("frequency (Hz)" if hz else "angular frequency (rad/s)")
    ax.set_ylabel("|G_k| (dB)")
    ax.set_title(f"HTF branches from {est.periods} periods (shaded: +-2 std; faint: within the noise)",
                 fontsize="medium")
    ax.legend(fontsize=7, ncol=2)
    return ax


def bode(res, *, hz: bool = False, level: float = 0.95, n_points: int = 400, fig=None):
    """Bode plot of an identification against the measured ``Y / U`` on the excited lines (with
    +-2 standard deviations from the periods' noise, input and output). Log-frequency axis in
    rad/s (or Hz). For a fit of several experiments, each experiment's measured ratio on its own
    excited lines, with its own marker.

    LTI model: its frequency response with the ``level`` band from the parameter covariance
    (magnitude on top, phase below), the curve the measured points should follow.

    LPTV model: the measured ratio on line l holds every branch's share,
    ``Y_l / U_l = sum_k G_k(w_{l-k}) U_{l-k} / U_l``, so it is compared with what the model
    predicts from the measured input on the same lines (``simulate(model, U)[l] / U_l``, its
    ``level`` band from the parameter covariance, first order), not with the branch G_0. A
    third panel draws the model's branches |G_k(w)|, k = -K..K, and, where the record determines
    them (excited lines more than 2K apart: :func:`lptv.htf_estimate`; entries overlapped by
    neighbouring lines' far branches left out), their nonparametric estimates with +-2 std.

    Returns the figure.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model([[6.0, 40.0, 6.0], [0, 0.8, 0], [0, 1.0, 0]], [[1.0]], w0=2 * np.pi / 5)
    >>> ms = lptv.multisine(range(1, 31), 1000, seed=0)
    >>> y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 1000)
    >>> rng = np.random.default_rng(1)
    >>> u = ms.periods(8) + 1e-3 * rng.standard_normal((8, 1000))
    >>> y = np.tile(y1, (8, 1)) + 1e-5 * rng.standard_normal((8, 1000))
    >>> res = lptv.identify(u, y, na=2, nb=0, ka=[1, 0, 0], kb=0, w0=m.w0)
    >>> fig = lptv.plots.bode(res)
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['|Y/U| (dB)', 'phase of Y/U (deg)', '|G_k| (dB)']
    """
    from .identify import IdentificationResult, excited_rows
    from ._validate import as_bool, as_float, as_int

    if not isinstance(res, IdentificationResult):
        raise ValueError(f"res must be an lptv.IdentificationResult, got {type(res).__name__}")
    if res.data is None and not res.experiments:
        raise ValueError("res must carry its data (res.data is None)")
    hz = as_bool(hz, "hz")
    level = as_float(level, "level", minimum=0.0, maximum=1.0, open_min=True, open_max=True)
    n_points = as_int(n_points, "n_points", minimum=2, maximum=100_000)
    model = res.model
    lti = model.is_lti
    if fig is None:
        fig, axes = _figure((6.4, 5.6 if lti else 7.8), 2 if lti else 3, 1, sharex=True, hspace=0.3)
    else:
        axes = fig.subplots(2 if lti else 3, 1, sharex=True, squeeze=False)
    ax_m, ax_p = axes[0, 0], axes[1, 0]

    def excited_only(d, rows):
        # Y/U is read only where the input is excited: the verdict's rows also hold the +-K
        # sidebands of an LPTV model, where U is noise and Y/U means nothing.
        try:
            keep = rows[np.isin(rows, excited_rows(d, 0))]
        except ValueError:
            return rows
        return keep if keep.size else rows

    if res.data is not None:
        sets = [("measured Y/U (+-2 std)", res.data, excited_only(res.data, np.asarray(res.verdict_lines)))]
    else:  # several experiments: each one's measured ratio on its own excited lines
        mask, exp = res.verdict_mask, np.asarray(res.experiment)
        sets = [(f"experiment {e} Y/U (+-2 std)", d, excited_only(d, res.lines[mask & (exp == e)]))
                for e, d in enumerate(res.experiments)]
        sets = [s for s in sets if s[2].size]
    scale = 1 / (2 * np.pi) if hz else 1.0
    z = _z_of(level)
    markers = "osD^v<>"
    shown = []
    curve = None
    if lti:
        from .parameters import freqresp_band

        w_all = np.concatenate([s[2] for s in sets]) * model.w0
        wmax = np.pi / model.ts if model.discrete else w_all.max() * 1.5
        w = np.logspace(np.log10(w_all.min() / 1.5), np.log10(min(wmax, w_all.max() * 1.5)), n_points)
        H, s_abs, s_ph = freqresp_band(res, w)
        ph_model = np.degrees(np.unwrap(np.angle(H)))
        x = w * scale
        if s_abs is not None:
            ax_m.fill_between(x, _db(np.maximum(np.abs(H) - z * s_abs, 1e-300)), _db(np.abs(H) + z * s_abs),
                              color="C1", alpha=0.3, lw=0, label=f"model {100 * level:g} % band")
            ax_p.fill_between(x, ph_model - np.degrees(z * s_ph), ph_model + np.degrees(z * s_ph),
                              color="C1", alpha=0.3, lw=0)
        ax_m.plot(x, _db(H), "-", color="C1", lw=1.2, label="model")
        ax_p.plot(x, ph_model, "-", color="C1", lw=1.2)
        shown.append(_db(H))
        curve = (w, ph_model)
    for i, (label, d, rows) in enumerate(sets):
        color = "C0" if i == 0 else f"C{i + 1}"  # C1 is the model's
        rows = np.sort(rows)
        U, Y = d.U[rows], d.Y[rows]
        G = Y / U
        sG = _ratio_std(d, rows, G)
        xl = rows * model.w0 * scale
        if lti:
            ref_ph = np.interp(rows * model.w0, *curve)
        else:
            Gp, sp_abs, sp_ph = _predicted_ratio(res, d, rows)
            ph_p = np.degrees(np.unwrap(np.angle(Gp)))
            pred = "model's prediction from the measured input" + (f" ({100 * level:g} % band)"
                                                                  if sp_abs is not None else "")
            pred_label = pred if i == 0 else None
            if sp_abs is not None:
                ax_m.fill_between(xl, _db(np.maximum(np.abs(Gp) - z * sp_abs, 1e-300)),
                                  _db(np.abs(Gp) + z * sp_abs), color="C1", alpha=0.3, lw=0)
                ax_p.fill_between(xl, ph_p - np.degrees(z * sp_ph), ph_p + np.degrees(z * sp_ph),
                                  color="C1", alpha=0.3, lw=0)
            ax_m.plot(xl, _db(Gp), "-", color="C1", lw=1.0, marker=".", ms=4, label=pred_label)
            ax_p.plot(xl, ph_p, "-", color="C1", lw=1.0, marker=".", ms=4)
            shown.append(_db(Gp))
            ref_ph = ph_p
        ax_m.errorbar(xl, _db(G),
                      yerr=[_db(np.abs(G)) - _db(np.maximum(np.abs(G) - 2 * sG, 1e-300 + 0 * sG)),
                            _db(np.abs(G) + 2 * sG) - _db(G)],
                      fmt=markers[i % len(markers)], ms=3.5, mfc="none", color=color, elinewidth=0.8,
                      label=label, zorder=3)
        # the measured phase on the model's branch of the phase
        ph_meas = np.degrees(np.angle(G))
        ph_meas = ph_meas + 360 * np.round((ref_ph - ph_meas) / 360)
        ax_p.errorbar(xl, ph_meas, yerr=2 * np.degrees(np.minimum(sG / np.abs(G), np.pi)),
                      fmt=markers[i % len(markers)], ms=3.5, mfc="none", color=color, elinewidth=0.8, zorder=3)
        shown.append(_db(G))
    # The view follows the points and the model: an error bar reaching |G| = 0 (a line where the
    # noise is as large as the response) would otherwise stretch the axis to -6000 dB.
    shown = np.concatenate(shown)
    shown = shown[np.isfinite(shown)]
    if shown.size:
        span = max(float(shown.max() - shown.min()), 1.0)
        ax_m.set_ylim(shown.min() - 0.15 * span - 3.0, shown.max() + 0.15 * span + 3.0)
    for ax in axes[:, 0]:
        _log_x(ax)
    ax_m.set_ylabel("|Y/U| (dB)")
    ax_p.set_ylabel("phase of Y/U (deg)")
    axes[-1, 0].set_xlabel("frequency (Hz)" if hz else "angular frequency (rad/s)")
    if len(sets) < 3:
        ax_m.legend(fontsize="small")
    else:   # many experiments: one entry for their points (the containers keep their own labels)
        handles, labels = ax_m.get_legend_handles_labels()
        keep = [i for i, lab in enumerate(labels) if not lab.startswith("experiment ")]
        first = labels.index(sets[0][0])
        ax_m.legend([handles[i] for i in keep] + [handles[first]],
                    [labels[i] for i in keep] + [f"each of the {len(sets)} experiments' Y/U (+-2 std), "
                                                 "a marker each"], fontsize="small")
    if lti:
        ax_m.set_title("Bode plot: the measured Y/U and the identified model", fontsize="medium")
    else:
        ax_m.set_title("Y/U on the excited lines: measured, and predicted by the model", fontsize="medium")
        _branches_panel(axes[2, 0], res, sets, scale, min(n_points, 80))
    return fig


def _ratio_std(d, rows, G):
    """Standard deviation of the measured ratio Y/U on ``rows`` from the periods' noise on input
    and output and their covariance (first order)."""
    varG = (d.varY[rows] + np.abs(G) ** 2 * d.varU[rows]
            - 2 * np.real(np.conj(G) * d.covYU[rows])) / np.abs(d.U[rows]) ** 2
    return np.sqrt(np.maximum(varG, 0.0))


def _predicted_ratio(res, d, rows):
    """The model's output from the measured input over that input, Y_model,l / U_l on ``rows``,
    with the standard deviations of its magnitude and phase (rad) from the parameter covariance
    (central differences of the simulated output over the parameters, first order); the stds are
    None without a covariance."""
    from .fds import simulate
    from .parameters import perturbed_model

    model = res.model
    U = d.U[rows]
    Yp = np.asarray(simulate(model, d.U, warn_unstable=False))[rows]
    cov = res.covariance
    if cov is None:
        return Yp / U, None, None
    eta = np.asarray(res.eta, float)
    J_abs = np.zeros((rows.size, eta.size))
    J_ph = np.zeros((rows.size, eta.size))
    for i, name in enumerate(res.eta_names):
        if not cov[i, i] > 0:
            continue
        h = 1e-6 * max(abs(eta[i]), 1e-3)
        Ypp, Ypm = (np.asarray(simulate(perturbed_model(model, name, s * h), d.U, warn_unstable=False))[rows]
                    for s in (1, -1))
        dY = (Ypp - Ypm) / (2 * h)
        J_abs[:, i] = np.real(dY * np.conj(Yp)) / np.maximum(np.abs(Yp), 1e-300)
        J_ph[:, i] = np.imag(dY / np.where(Yp == 0, 1, Yp))
    s_abs = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", J_abs, cov, J_abs), 0.0))
    s_ph = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", J_ph, cov, J_ph), 0.0))
    return Yp / U, s_abs / np.abs(U), s_ph


def _branch_color(k: int) -> str:
    return "0.15" if k == 0 else f"C{(2 * abs(k) + (k < 0)) % 10}"


def _branches_panel(ax, res, sets, scale, n_points):
    """The model's HTF branches over the excited band and, where the record determines them, their
    nonparametric estimates (lptv.htf_estimate) with +-2 std."""
    from .nonparametric import htf_estimate

    model = res.model
    K = max(model.ka, model.kb)
    lines = np.concatenate([s[2] for s in sets])
    w_lo, w_hi = lines.min() * model.w0 / 1.2, lines.max() * model.w0 * 1.2
    if model.discrete:
        w_hi = min(w_hi, np.pi / model.ts)
    w = np.logspace(np.log10(w_lo), np.log10(w_hi), n_points)
    order = sorted(range(-K, K + 1), key=abs)
    for k in order:
        ax.plot(w * scale, _db(model.freqresp(w, branch=k)), "-", lw=1.2, color=_branch_color(k),
                label=f"G_{k:+d}" if k else "G_0")
    why = []
    drawn = False
    for i, (_, d, rows) in enumerate(sets):
        try:
            est = htf_estimate(d, excited=np.sort(rows), branches=K)
        except ValueError as e:
            why.append(str(e))
            continue
        over = est.overlapped if est.overlapped is not None else np.zeros(est.G.shape, bool)
        for j, k in enumerate(est.k):
            keep = ~over[j]
            if not keep.any():
                continue
            mag, sd = np.abs(est.G[j][keep]), est.std[j][keep]
            ax.errorbar(est.w[keep] * scale, _db(mag),
                        yerr=[_db(mag) - _db(np.maximum(mag - 2 * sd, mag * 1e-3)), _db(mag + 2 * sd) - _db(mag)],
                        fmt="osD^v<>"[i % 7], ms=3.5, mfc="none", color=_branch_color(int(k)), elinewidth=0.8,
                        ls="none")
            drawn = True
    if drawn:
        ax.errorbar([], [], yerr=[], fmt="o", ms=3.5, mfc="none", color="0.3", ls="none",
                    label="from the data, +-2 std")
        ax.set_title("HTF branches: the model's, and where the record separates them, the data's",
                     fontsize="medium")
    else:
        ax.set_title("HTF branches of the model (the record does not separate them)", fontsize="medium")
        reason = ("excited lines closer than 2K + 1 apart" if any("apart" in m or "close" in m for m in why)
                  else "no entry of the data free of its neighbours' branches")
        ax.text(0.02, 0.04, f"no nonparametric estimate: {reason}", transform=ax.transAxes, fontsize="small",
                color="0.3")
    ax.set_ylabel("|G_k| (dB)")
    ax.legend(fontsize="small", ncol=min(2 * K + 2, 4))


def compare(cmp, *, ax=None, unit: str = ""):
    """Measured against simulated output over one period (a :func:`lptv.compare` result)."""
    if not isinstance(cmp, dict) or not {"t", "y", "y_model", "fit"} <= set(cmp):
        raise ValueError(f"cmp must be the dict lptv.compare returns (keys t, y, y_model, fit), got "
                         f"{type(cmp).__name__}")
    ax = _axes(ax)
    ax.plot(cmp["t"], cmp["y"], "-", color="C0", lw=1.0, label="measured (mean of the periods)")
    ax.plot(cmp["t"], cmp["y_model"], "--", color="C1", lw=1.2, label=f"model, fit {cmp['fit']:.1f} %")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("output" + (f" ({unit})" if unit else ""))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def inspection(insp, *, hz: bool = False, fig=None):
    """What :func:`lptv.inspect` found: the input's repeat residue r(L) against the lag with the
    period marked, and the output's spectrum of the mean period by class of line (excited,
    sidebands, odd and even detection lines, elsewhere) over its noise level.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> k = np.arange(2000)
    >>> u = np.cos(2 * np.pi * 3 * k / 200) + np.cos(2 * np.pi * 7 * k / 200)
    >>> fig = lptv.plots.inspection(lptv.inspect(u=u, y=0.5 * u + 0.01 * np.sin(k), fs=100.0))
    >>> fig.axes[0].get_title()
    'the input repeats every 2.00 s (200 samples)'
    """
    from .inspection import Inspection
    from ._validate import as_bool

    if not isinstance(insp, Inspection):
        raise ValueError(f"insp must be an lptv.Inspection (from lptv.inspect), got {type(insp).__name__}")
    hz = as_bool(hz, "hz")
    rows = 2 if insp.repeats else 1
    axes = (_figure((6.4, 6.4 if insp.repeats else 3.2), rows, 1, hspace=0.85)[1] if fig is None
            else fig.subplots(rows, 1, squeeze=False))[:, 0]
    fig = axes[0].figure
    ax = axes[0]
    lag = insp.lags[1:]
    x = lag / insp.fs if insp.fs else lag
    ax.semilogy(x, np.maximum(insp.repeat[1:], 1e-12), lw=0.8, color="C0", label="input: r(L)")
    from .inspection import REPEAT_LIMIT

    ax.axhline(REPEAT_LIMIT, color="C3", ls="--", lw=1, label=f"limit of a period ({REPEAT_LIMIT:g})")
    if insp.repeats:
        L = insp.input_period_samples
        for m in range(1, insp.max_period_samples // L + 1):
            ax.axvline(m * L / insp.fs if insp.fs else m * L, color="C2", lw=0.8, alpha=0.6)
        ax.set_title(f"the input repeats every {insp.seconds(L)}", fontsize="medium")
    else:
        ax.set_title(f"the input does not repeat up to {insp.seconds(insp.max_period_samples)}", fontsize="medium")
    ax.set_xlabel("lag L (s)" if insp.fs else "lag L (samples)")
    ax.set_ylabel("r(L): share of the power not repeated")
    ax.legend(fontsize="small", loc="lower right")
    ax.grid(True, alpha=0.3)
    if not insp.repeats:
        return fig
    ax = axes[1]
    lines = insp.spectrum_lines
    w0 = insp.w0
    xs = (lambda ls: _freq_axis(ls, w0, hz)[0]) if w0 else (lambda ls: np.asarray(ls))
    label = _freq_axis(lines, w0, hz)[1] if w0 else "line (cycles per period)"
    p = 10 * np.log10(np.maximum(np.abs(insp.Y) ** 2, 1e-300))
    ax.plot(xs(lines), 10 * np.log10(np.maximum(insp.noise_y, 1e-300)), "-", color="k", lw=0.8,
            label="output noise (mean of the periods)")
    ax.plot(xs(lines), 10 * np.log10(np.maximum(insp.noise_y * insp.threshold, 1e-300)), "--", color="k",
            lw=0.6, label="line test threshold")
    groups = [("excited", insp.lines, "C0", "o")] + [
        (c.name, c.lines, color, mk) for c, color, mk in
        zip(insp.classes, ("C1", "C3", "C2", "0.6"), ("s", "v", "^", "."))]
    for name, ls, color, mk in groups:
        if ls.size:
            ax.plot(xs(ls), p[ls - 1], mk, ms=3.5 if mk != "." else 2.5, color=color, ls="none",
                    label=f"{name} ({ls.size})")
    ax.set_xlabel(label)
    ax.set_ylabel("output power (dB)")
    ax.set_title(f"output of the mean of {insp.periods - insp.transient_periods} periods by class of line",
                 fontsize="medium")
    ax.legend(fontsize="small", ncol=2)
    ax.grid(True, alpha=0.3)
    return fig
