"""``report.html`` of ``lptv identify FILES --input f1,f2 --output x1,x2``: the verdict, the
parameters with their standard deviations, each output's normalised residue over the lines of
the fit, the estimate's Floquet multipliers and its frozen poles. Built from the public API
only (:class:`lptv.judgement.mimo_result.MimoIdentificationResult`, :func:`lptv.floquet`,
:func:`lptv.frozen_poles`)."""
from __future__ import annotations

import numpy as np

from lptv.apps.report import Report


def physical_table(physical, u_units, y_units):
    """The rows of :meth:`lptv.MimoIdentificationResult.parameters` of the scaled parameters."""
    from lptv.judgement.mimo_result import parameter_rows

    name = physical.scale[0]
    fixed = frozenset(n for n in physical.eta_names if n.startswith(f"{name}[") and n.endswith(".re0"))
    return parameter_rows(physical.eta_names, physical.eta, physical.covariance, 0.95, fixed)


def normalised_residues(res) -> np.ndarray:
    """|e_{l,p}|^2 / C_{e,l}[p, p] per row and output, shape (rows, ny): each output's normalised
    residue, F(2, 2(P-1))-distributed for a right model with noise (co)variances from P periods
    (METHOD.md eq. 19.14); 1 (0 dB) is its mean for known variances."""
    e = np.asarray(res.residue)
    C = np.asarray(res.residue_covariance)
    var = np.real(np.diagonal(C, axis1=1, axis2=2))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(e) ** 2 / var


def predicted_outputs(model, u, y):
    """One period of each output: the mean of the periods of ``y`` (P, N, ny) and the model's
    steady-state output simulated from the mean of ``u`` (P, N, nu) (:func:`lptv.simulate`), both
    (N, ny), and each output's fit in percent, 100 (1 - ||y - yhat|| / ||y - mean y||)."""
    import lptv

    u_mean, y_mean = np.mean(u, axis=0), np.mean(y, axis=0)
    n = u_mean.shape[0]
    U = np.fft.rfft(u_mean, axis=0) / n
    Y = np.asarray(lptv.simulate(model, U, lines_out=U.shape[0] - 1, warn_unstable=False)).reshape(U.shape[0], -1)
    y_hat = np.fft.irfft(n * Y, n, axis=0)
    err = np.linalg.norm(y_mean - y_hat, axis=0)
    spread = np.linalg.norm(y_mean - y_mean.mean(axis=0), axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        fit = 100.0 * (1.0 - err / spread)
    return y_mean, y_hat, fit


def build(res, *, files, inputs, outputs, w0, stability, physical=None, experiments=None) -> Report:
    """The report of a fit of several channels (``stability``: mimoid.stability_of's dict;
    ``physical``: the parameters of ``--scale``, :func:`lptv.apps.units.scaled_mimo`;
    ``experiments``: the (u, y) periods of each file, for the measured and predicted outputs)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import lptv
    from lptv.apps import units

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
    if getattr(res, "transient", None) is not None:
        rep.paragraph(res.transient_note[0].upper() + res.transient_note[1:] + ": a disturbance that passes through "
                      "the system leaves the record's boundary states in every row, a term the rows then do not "
                      "share as noise.")
    u_units = [units.channel_unit(n) for n in inputs]
    y_units = [units.channel_unit(n) for n in outputs]
    rep.heading("Parameters")
    rep.table(["parameter", "estimate", "std", "95 % interval", "unit"],
              _parameter_rows(res.parameters(0.95), units.mimo_coefficient_units(model, u_units, y_units)))
    if physical is not None:
        name, value = physical.scale
        rep.paragraph(f"In physical form (--scale {name}={value:g}): the equation multiplied from the left so that "
                      f"the mean of {name} is {value:g} times the identity (the same system; the covariance carried "
                      "by the exact Jacobian of that map).")
        rep.table(["parameter", "value", "std", "95 % interval", "unit"],
                  _parameter_rows(physical_table(physical, u_units, y_units),
                                  units.mimo_coefficient_units(physical.model, u_units, y_units, physical.scale),
                                  fixed="(by --scale)"))

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
        ax.set_ylabel(residue_label(outputs[p]))
    axes[-1, 0].set_xlabel("frequency of the row (rad/s)")
    fig.tight_layout()
    rep.heading("Residues")
    worth = ", what the moderated noise is worth" if route in ("moderated", "full-moderated") else ""
    rep.figure(fig, "residues.png",
               "Each output's normalised residue |e_p|^2 / C_e[p, p] on the rows of the fit (all experiments), "
               "in dB relative to its own noise (the residue e_p is in the unit of output p's equation, C_e[p, p] in "
               "its square: the ratio has no unit): about 0 dB (its mean) where the model is right; the dashed "
               "line is the 99 % point of "
               f"F(2, 2(P-1)) for one row (P = {P}{worth}); the verdict judges every row above line K (rows l <= K "
               "read line 0 and conjugate lines) of every output and all outputs jointly with Holm's correction, "
               "not by this line.")
    plt.close(fig)

    if experiments:
        _outputs_section(rep, res, files, outputs, w0, experiments, plt)

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
    rep.heading("The fit")
    rep.preformatted(res.summary(units=units.mimo_coefficient_units(model, u_units, y_units)))
    return rep


def _outputs_section(rep, res, files, outputs, w0, experiments, plt):
    """The measured and predicted outputs of each experiment over one period, each output in its
    own unit (its name's)."""
    from lptv import NumericalError

    ny = res.model.n_outputs
    E = len(experiments)
    fig, axes = plt.subplots(ny, E, figsize=(4.2 * E + 1.5, 1.9 * ny + 0.8), squeeze=False, sharex=True)
    fits = []
    try:
        for e, (u, y) in enumerate(experiments):
            y_mean, y_hat, fit = predicted_outputs(res.model, u, y)
            fits.append(fit)
            t = np.arange(y_mean.shape[0]) * (2 * np.pi / w0) / y_mean.shape[0]
            for p in range(ny):
                ax = axes[p, e]
                ax.plot(t, y_mean[:, p], color="C0", lw=1.0, label="measured (mean of the periods)")
                ax.plot(t, y_hat[:, p], color="C3", lw=0.9, ls="--", label="model, from the measured input")
                ax.set_title(f"{files[e]}: fit {fit[p]:.1f} %", fontsize=8)
                if e == 0:
                    ax.set_ylabel(outputs[p])
            axes[-1, e].set_xlabel("time over one period (s)")
        axes[0, 0].legend(fontsize=7, loc="best")
        fig.tight_layout()
    except (ValueError, NumericalError, np.linalg.LinAlgError):
        plt.close(fig)
        return
    rep.heading("The model against the data")
    rep.figure(fig, "outputs.png",
               "Each output (rows, in its own unit) of each experiment (columns) over one period: the mean of the "
               "measured periods and the model's steady-state output simulated from the measured input "
               "(lptv.simulate); fit = 100 (1 - ||y - yhat|| / ||y - mean y||) per output: "
               + "; ".join(f"{files[e]}: " + ", ".join(f"{outputs[p]} {f[p]:.1f} %" for p in range(ny))
                           for e, f in enumerate(fits)) + ".")
    plt.close(fig)


def residue_label(output: str) -> str:
    """The residue axis of one output: its name (with the unit it states, 'x1 [mm]') and that the
    quantity is in dB relative to its noise (a ratio without unit)."""
    return f"{output}: |e|^2 / C_e (dB)"


def _parameter_rows(rows, unit_of, fixed="(normalised)"):
    out = []
    for r in rows:
        unit = unit_of.get(r["name"].split(".")[0], "")
        if r["kind"] == "normalised":
            out.append([r["name"], f"{r['value']:.7g}", fixed, "", unit])
        elif r["std"] is None:
            out.append([r["name"], f"{r['value']:.7g}", "-", "-", unit])
        else:
            out.append([r["name"], f"{r['value']:.7g}", f"{r['std']:.4g}", f"[{r['low']:.6g}, {r['high']:.6g}]", unit])
    return out
