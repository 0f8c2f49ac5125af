"""The fit: coefficients over a period, the HTF branches, the Bode figure, the inspection."""
from __future__ import annotations

from typing import Optional

import numpy as np

from ._base import MARGINS, _axes, _db, _figure, _freq_axis, _log_x, _options, _series, _z_of  # noqa: F401


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
    from .._validate import as_float

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
    from ..simulation.fds import htf
    from ..model.siso import Model
    from ..spectra.htf_estimate import HtfEstimate
    from .._validate import as_bool, as_int

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
    from ..estimation.identify import IdentificationResult, excited_rows
    from .._validate import as_bool, as_float, as_int

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
        from ..judgement.parameters import freqresp_band

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
    from ..simulation.fds import simulate
    from ..judgement.parameters import perturbed_model

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


def _branch_bands(ax, res, lines, order, scale, level: float = 0.95):
    """The branches' 95 % magnitude bands at the excited lines (res.htf_band, METHOD.md section 22),
    shaded; nothing without a covariance."""
    if getattr(res, "covariance", None) is None or not hasattr(res, "htf_band"):
        return
    try:
        band = res.htf_band(lines=lines[lines > 0], branches=order, level=level)
    except (ValueError, np.linalg.LinAlgError):
        return
    mb = band.magnitude_band()
    for i, k in enumerate(band.branches):
        ax.fill_between(band.w * scale, _db(np.maximum(mb[i, :, 0], 1e-2 * np.abs(band.G[i]))), _db(mb[i, :, 1]),
                        color=_branch_color(int(k)), alpha=0.25, lw=0,
                        label=f"model {100 * level:g} % band" if i == 0 else None)


def _branches_panel(ax, res, sets, scale, n_points):
    """The model's HTF branches over the excited band and, where the record determines them, their
    nonparametric estimates (lptv.htf_estimate) with +-2 std."""
    from ..spectra.htf_estimate import htf_estimate

    model = res.model
    K = max(model.ka, model.kb)
    lines = np.concatenate([s[2] for s in sets])
    w_lo, w_hi = lines.min() * model.w0 / 1.2, lines.max() * model.w0 * 1.2
    if model.discrete:
        w_hi = min(w_hi, np.pi / model.ts)
    w = np.logspace(np.log10(w_lo), np.log10(w_hi), n_points)
    from ..judgement.uncertainty import _branches

    order = sorted(range(-K, K + 1), key=abs)
    curves = _branches(model, w, order)
    for k, G in zip(order, curves):
        ax.plot(w * scale, _db(G), "-", lw=1.2, color=_branch_color(k),
                label=f"G_{k:+d}" if k else "G_0")
    _branch_bands(ax, res, np.unique(lines), order, scale)
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
        # the note above the curves (a band of headroom) and the legend in the opposite corner,
        # so that neither hides the other or a curve (the legend's 'best' place does not avoid a
        # text; branches mostly fall with frequency)
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + 0.12 * (hi - lo))
        ax.text(0.98, 0.97, f"no nonparametric estimate: {reason}", transform=ax.transAxes, fontsize="small",
                color="0.3", ha="right", va="top")
    ax.set_ylabel("|G_k| (dB)")
    ax.legend(fontsize="small", ncol=min(2 * K + 2, 4), **({} if drawn else {"loc": "lower left"}))


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
    from ..records.inspection import Inspection
    from .._validate import as_bool

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
    from ..records.inspection import REPEAT_LIMIT

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
