"""``report.html`` of ``lptv identify FILES --input f1,f2 --output x1,x2``: the verdict, the
parameters with their standard deviations, each output's normalised residue over the lines of
the fit, the estimate's Floquet multipliers and its frozen poles. Built from the public API
only (:class:`lptv.judgement.mimo_result.MimoIdentificationResult`, :func:`lptv.floquet`,
:func:`lptv.frozen_poles`)."""
from __future__ import annotations

import numpy as np

from lptv.apps.report import Report


def normalised_residues(res) -> np.ndarray:
    """|e_{l,p}|^2 / C_{e,l}[p, p] per row and output, shape (rows, ny): each output's normalised
    residue, F(2, 2(P-1))-distributed for a right model with noise (co)variances from P periods
    (METHOD.md eq. 19.14); 1 (0 dB) is its mean for known variances."""
    e = np.asarray(res.residue)
    C = np.asarray(res.residue_covariance)
    var = np.real(np.diagonal(C, axis1=1, axis2=2))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(e) ** 2 / var


def build(res, *, files, inputs, outputs, w0, stability) -> Report:
    """The report of a fit of several channels (``stability``: mimoid.stability_of's dict)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import lptv

    model = res.model
    rep = Report("lptv identify: a model of several inputs and outputs")
    ok = res.model_ok
    rep.verdict(res.verdict, bool(ok))
    rep.paragraph(f"{len(files)} experiment{'s' if len(files) > 1 else ''} ({', '.join(map(str, files))}); "
                  f"inputs {', '.join(inputs)}; outputs {', '.join(outputs)}; w0 = {w0:.6g} rad/s; "
                  f"method {res.method.upper()}, converged {res.converged}, {res.lines.size} rows, "
                  f"{res.n_free_parameters} free parameters, normalised so that the mean of the leading "
                  "matrix A_na is the identity (METHOD.md section 19).")
    route = getattr(res, "noise", "sample")
    choice = getattr(res, "noise_choice", "")
    rep.paragraph(f"Noise (co)variances: {route} (asked for)." if choice in ("", "asked for") else
                  f"Noise (co)variances (noise='auto'): {choice}.")
    std = res.parameter_std
    rows = []
    for i, name in enumerate(res.parameter_names):
        s = "-" if std is None else ("(normalised)" if std[i] == 0 else f"{std[i]:.4g}")
        rows.append([name, f"{res.eta[i]:.7g}", s])
    rep.heading("Parameters")
    rep.table(["parameter", "estimate", "std"], rows)

    # each output's normalised residue over the rows, against its single-row 99 % point
    z = normalised_residues(res)
    ny = z.shape[1]
    P = min(res.periods) if len(res.periods) else 0
    if getattr(res, "noise", "sample") == "moderated" and res.moderation:
        # the periods the moderated (co)variances are worth (their median over the inner lines)
        P = int(round(min(float(np.median(m.periods[1:-1])) for m in res.moderation)))
    fig, axes = plt.subplots(ny, 1, figsize=(7.5, 1.9 * ny + 0.6), sharex=True, squeeze=False)
    w = np.asarray(res.lines) * w0
    for p in range(ny):
        ax = axes[p, 0]
        ax.plot(w, 10 * np.log10(np.maximum(z[:, p], 1e-30)), ".", ms=3, color="C0")
        ax.axhline(0.0, color="0.5", lw=0.8)
        if P >= 2:
            from scipy.special import fdtri
            ax.axhline(10 * np.log10(fdtri(2, 2 * (P - 1), 0.99)), color="C3", lw=0.8, ls="--")
        ax.set_ylabel(f"{outputs[p]} (dB)")
    axes[-1, 0].set_xlabel("frequency of the row (rad/s)")
    fig.tight_layout()
    rep.heading("Residues")
    rep.figure(fig, "residues.png",
               "Each output's normalised residue |e_p|^2 / C_e[p, p] on the rows of the fit (all experiments), "
               "in dB: about 0 dB (its mean) where the model is right; the dashed line is the 99 % point of "
               f"F(2, 2(P-1)) for one row (P = {P}{', what the moderated noise is worth' if route in ('moderated', 'full-moderated') else ''}); the verdict judges every row of every output and all "
               "outputs jointly with Holm's correction, not by this line.")
    plt.close(fig)

    rep.heading("Stability")
    rep.paragraph("The estimate is " + stability["text"] + ".")
    mult = stability.get("multipliers")
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(8.5, 3.6))
    th = np.linspace(0, 2 * np.pi, 200)
    ax1.plot(np.cos(th), np.sin(th), color="0.6", lw=0.8)
    if mult:
        m = np.array([complex(a, b) for a, b in mult])
        ax1.plot(m.real, m.imag, "x", color="C3")
    ax1.set_aspect("equal")
    ax1.set_xlabel("Re")
    ax1.set_ylabel("Im")
    ax1.set_title("Floquet multipliers", fontsize=10)
    t = np.linspace(0, model.period, 60, endpoint=False)
    poles = np.asarray(lptv.frozen_poles(model, t))
    fin = np.isfinite(poles)
    ax2.plot(poles.real[fin], poles.imag[fin], ".", ms=2, color="C0")
    if fin.any() and not model.discrete:       # the imaginary axis in view: how far left the poles are
        lo = min(float(poles.real[fin].min()), 0.0)
        hi = max(float(poles.real[fin].max()), 0.0)
        pad = 0.1 * max(hi - lo, 1e-12)
        ax2.set_xlim(lo - pad, hi + pad)
        ax2.axvline(0.0, color="0.6", lw=0.8)
    elif model.discrete:
        ax2.plot(np.cos(th), np.sin(th), color="0.6", lw=0.8)
        ax2.set_aspect("equal")
    ax2.ticklabel_format(useOffset=False)
    ax2.locator_params(axis="x", nbins=5)
    ax2.set_xlabel("Re")
    ax2.set_title("frozen poles over one period", fontsize=10)
    fig.tight_layout()
    rep.figure(fig, "stability.png",
               "Left: the Floquet multipliers of the estimate (inside the unit circle: stable). Right: its "
               "frozen poles (the roots of det sum_n A_n(t) s^n, " + ("z-plane" if model.discrete else "s-plane, rad/s")
               + ") at 60 instants of the period; they show how the system varies and say nothing about "
               "the stability of the time-varying system.")
    plt.close(fig)
    return rep
