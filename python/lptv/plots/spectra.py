"""Spectra, residues, poles and the nonlinear and disturbance figures."""
from __future__ import annotations

from typing import Optional

import numpy as np

from ._base import MARGINS, _axes, _db, _figure, _freq_axis, _log_x, _options, _series, _z_of  # noqa: F401


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
    from .._validate import as_bool

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
    from ..spectra.distortion import LackOfFit
    from .._validate import as_bool, as_positive_float

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
    from ..spectra.distortion import DistortionResult
    from .._validate import as_bool

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
    from ..spectra.moderation import ModeratedNoise
    from .._validate import as_bool

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
    from ..spectra.disturbances import DisturbanceResult
    from .._validate import as_bool, as_float

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
