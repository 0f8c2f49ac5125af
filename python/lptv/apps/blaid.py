"""``lptv identify FILE`` on a record of M random-phase realisations (arrays of shape (M, P, N)).

An LPTV system and a nonlinear one both put output power on lines the input does not excite;
realisations of one amplitude spectrum with independent random phases tell them apart
(METHOD.md section 16). The command

1. separates, per output line, the noise level (from the periods) from the stochastic nonlinear
   distortion (from the realisations) with :func:`lptv.distortion`, and says whether nonlinear
   distortion is detected;
2. identifies the best linear (time-periodic) approximation: the realisations are the
   experiments of one fit (:func:`lptv.identify` with a list), each output variance raised by
   the nonlinear level (:meth:`lptv.DistortionResult.experiments`), so that the parameter
   covariance and the verdict include the nonlinear distortion (``--covariance realisations``:
   the covariance from the realisations themselves, the jackknife of METHOD.md section 16, which
   also holds where the distortion is correlated across lines);
   The rows of the fit are, unless ``--lines`` says otherwise, the excited band: lines K+1 to the
   highest excited line + K;
3. writes ``model.json``, ``summary.json`` (with the distortion levels) and ``report.html``
   (the distortion figure: signal, noise and nonlinear levels per line, as FDIDENT draws them).

Example::

    python -c "import numpy as np, lptv; from lptv.examples import paper_model, noisy_periods
    m = paper_model(); u, y = [], []
    for r in range(6):
        ms = lptv.multisine(range(10, 241, 10), 2048, amplitudes=np.sqrt(2 / 24), seed=r)
        y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 2048)
        a, b = noisy_periods(ms.signal, y0 + 0.02 * y0 ** 3, 16, 50, 30, seed=100 + r)
        u.append(a); y.append(b)
    np.savez('rig.npz', u=np.array(u), y=np.array(y), w0=m.w0)"
    lptv identify rig.npz --na 2 --nb 1 --ka 3 --kb 3 --out rig-lptv
"""
from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import numpy as np

from lptv import NumericalError, distortion, identify, parameter_table, plots
from lptv.apps.options import verdict_status
from lptv.apps import units
from lptv.apps.report import Report, model_figures, parameter_section, write_fit
from lptv.judgement.parameters import format_parameter_table


def _fail(src, problem) -> int:
    print(f"lptv identify: error: {src}: {' '.join(str(problem).split())}", file=sys.stderr)
    return 2


def run(args, src, meas, *, w0, ts, lines, ka, kb, known) -> int:
    M, P, N = meas.u.shape
    noise = getattr(args, "noise", "auto")
    if noise in ("moderated", "full", "full-moderated"):
        return _fail(src, f"--noise {noise} is for records of periods, not M x P x N realisations (their "
                          "variances are the noise's and the nonlinear distortion's, per realisation)")
    covariance = getattr(args, "covariance", "analytic")
    if covariance == "bootstrap":
        return _fail(src, "--covariance bootstrap takes one record of periods, not M x P x N realisations "
                          "(their covariance includes the nonlinear distortion analytically, or from the "
                          "realisations with --covariance realisations)")
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            dist = distortion(meas.u, meas.y, w0=w0, ts=ts)
            if lines is None:
                # Default rows: the excited band, lines K+1 .. (highest excited line + K), where the
                # linear time-periodic response stands above the distortion; beyond it the output
                # holds only the nonlinear harmonics. (Measured on the paper's model with a cubic,
                # M = 6, P = 16: the band gives cost 1.02 and 37.5 % of the residues above 0 dB,
                # as predicted; all usable lines or only the excited lines +-K gave residues far
                # too small and a biased fit.)
                K = max(np.max(ka), np.max(kb))
                top = int(np.max(dist.excited)) + K
                lines = np.arange(K + 1, min(top, int(dist.lines[-1]) - K) + 1)
            per = lines if isinstance(lines, str) else [lines] * M
            referred = getattr(args, "referred", "auto")
            first_fit = None
            if referred == "auto":
                # the level on the outputs, unless the response depends on the phases (far HTF
                # branches): then the realisations with their noise alone and the jackknife,
                # the consistent fit there (METHOD.md section 16)
                referred = "none" if dist.depends_on_phases and M >= 4 else "output"
                first_fit = (f"the realisations' output powers differ up to {dist.output_spread:.3g} times"
                             if referred == "none" else None)
            if referred == "none":
                # the realisations with their noise alone; the jackknife over them brings the
                # distortion into the intervals (the analytic covariance would leave it out)
                exps = dist.experiments(referred="none")
                covariance = "realisations"
            else:
                exps = dist.experiments()
            if referred == "input" and dist.detected:
                # an actuator's distortion: referred to the input through a first, output-referred
                # fit; where that is refused (one common level above a weak realisation's output)
                # or its branches are unreliable, through a fit of the realisations' noise alone
                fit_args = dict(na=args.na, nb=args.nb, ka=ka, kb=kb, lines=per, method=args.method, known=known,
                                tol=args.tol, max_iter=args.max_iter)
                try:
                    exps = dist.experiments(referred="input", model=identify(exps, **fit_args))
                    first_fit = "an output-referred first fit"
                except ValueError as e:
                    plain = identify([(meas.u[i], meas.y[i]) for i in range(M)], w0=w0, ts=ts, **fit_args)
                    exps = dist.experiments(referred="input", model=plain)
                    why = re.sub(r"experiments?\[(\d+)\]|experiment (\d+)",
                                 lambda g: f"realisation {g.group(1) or g.group(2)}", " ".join(str(e).split()))
                    first_fit = ("a first fit of the realisations with their noise alone (the output-referred "
                                 f"one: {why[:160]}...)")
            res = identify(exps, na=args.na, nb=args.nb, ka=ka, kb=kb, lines=per, method=args.method,
                           known=known, tol=args.tol, max_iter=args.max_iter, covariance=covariance)
    except (ValueError, NumericalError) as e:
        # the realisations are the fit's experiments: name them as such
        return _fail(src, re.sub(r"experiments?\[(\d+)\]|experiment (\d+)",
                                 lambda g: f"realisation {g.group(1) or g.group(2)}", str(e)))
    said = set(res.warnings) | {res.unstable, res.stability_undecided}   # res.summary() prints these
    extra = list(dict.fromkeys(str(w.message) for w in caught if str(w.message) not in said))
    out = Path(args.out) if args.out else Path(Path(src).stem + "-lptv")
    print(f"lptv identify: {src} ({meas.format}, {M} realisations x {P} periods of {N} samples, "
          f"w0 = {w0:.6g} rad/s" + (f", discrete-time model with ts = {ts:g} s" if ts else
                                    ", continuous-time model") + f") -> {out}/")
    print(dist.summary())
    worth = ", ".join(str(e.periods) for e in exps)
    side = (f"referred to the input (a nonlinearity before the dynamics) through {first_fit or 'a first fit'}"
            if referred == "input" else "added to the output noise")
    if referred == "none":
        print("model: the best linear approximation, the realisations fitted together with their noise alone; "
              "its intervals from the jackknife over the realisations, which includes the nonlinear distortion "
              + ("(--referred none; --covariance is taken as realisations)"
                 if getattr(args, "referred", "auto") == "none" else
                 f"(--referred auto chose it: {first_fit}, a response that depends on the phases, where a level on the "
                 "outputs or referred to the input is no exact noise model; --referred output or input to "
                 "weigh the level instead)"))
    else:
        print("model: the best linear approximation, the realisations fitted together with the nonlinear "
              f"level {side} (their variances worth {worth} periods: the P shown below)"
              if dist.detected else "model: the realisations fitted together (no nonlinear level to add)")
    print(res.summary())
    for msg in extra:
        print(f"warning: {msg}")
    summary = _summary(args, src, meas, w0, ts, ka, kb, dist, res, extra, first_fit, referred)
    scale = units.parse_scale(getattr(args, "scale", None))
    try:
        physical = units.scaled(res, *scale) if scale else None
    except ValueError as e:
        return _fail(src, e)
    if physical is not None:
        print(units.physical_form(physical, meas)[0])
    summary["scale"] = None if scale is None else {"coefficient": scale[0], "value": scale[1]}
    summary["parameters_scaled"] = None if physical is None else units.physical_form(physical, meas)[1]
    failed = write_fit(out, res.model, summary, None if getattr(args, "no_report", False) else
                       lambda: _report(src, meas, dist, res, summary, known=known))
    return _fail(failed[0] or src, failed[1]) if failed else verdict_status(res)


def _levels(dist):
    """Mean signal, noise and nonlinear powers (dB) per kind of line, over the tested lines."""
    ok = np.isfinite(dist.p_value)
    out = {}
    for kind in ("excited", "sideband", "other"):
        sel = ok & (dist.kind == kind)
        if sel.any():
            out[kind] = {"lines": int(sel.sum()), **{
                name: float(10 * np.log10(max(float(np.mean(x[sel])), 1e-300)))
                for name, x in (("signal_db", dist.signal), ("noise_db", dist.noise),
                                ("nonlinear_db", dist.nonlinear))}}
    return out


def _dof_range(res):
    """The jackknife's degrees of freedom over the free parameters, as a phrase."""
    if res.covariance_dof is None or res.parameter_std is None:
        return "not formed"
    dof = res.covariance_dof[res.parameter_std > 0] if np.any(res.parameter_std > 0) else res.covariance_dof
    return f"{dof.min():.3g}-{dof.max():.3g} for {res.n_experiments} realisations"


def _res_covariance(args, res) -> str:
    """The covariance the fit reports: --covariance, or the jackknife with --referred none."""
    return "realisations" if res.covariance_dof is not None else getattr(args, "covariance", "analytic")


def _summary(args, src, meas, w0, ts, ka, kb, dist, res, extra, first_fit=None, referred="output"):
    M, P, N = meas.u.shape
    return {
        "file": str(src), "format": meas.format, "realisations": M, "periods": P, "samples_per_period": N,
        "w0": w0, "ts": ts, "na": res.model.na, "nb": res.model.nb, "ka": ka, "kb": kb, "method": res.method,
        "distortion": {"detected": dist.detected, "statistic": float(dist.statistic),
                       "p_value": float(dist.p_overall), "alpha": dist.alpha, "branches": int(dist.branches),
                       "levels": _levels(dist)},
        "n_lines": int(res.lines.size), "n_free_parameters": res.n_free_parameters,
        "iterations": res.iterations, "converged": res.converged, "cost": res.cost,
        "verdict": res.verdict, "model_ok": res.model_ok, "model_errors": list(res.model_errors),
        "parameters": parameter_table(res), "warnings": list(res.warnings) + extra,
        "covariance": _res_covariance(args, res),
        "referred": referred, "referred_option": getattr(args, "referred", "auto"),
        "first_fit": first_fit if referred == "input" else None,
        "covariance_dof": None if res.covariance_dof is None else [float(v) for v in res.covariance_dof],
    }


def _report(src, meas, dist, res, summary, known=None) -> Report:
    model = res.model
    M, P, N = meas.u.shape
    rep = Report(f"lptv identify: {Path(src).name} ({M} realisations)")
    rep.verdict(res.verdict, res.model_ok)
    rep.paragraph(
        f"{M} random-phase realisations of {P} periods of {N} samples in {src}. Per output line the "
        "noise level of a period mean (from the periods) and the stochastic nonlinear distortion (what "
        "varies from realisation to realisation beyond the system's linear time-periodic response, "
        "METHOD.md section 16) are separated: nonlinear distortion is "
        + ("DETECTED" if dist.detected else "not detected")
        + f" (z = {dist.statistic:.2f}, p = {dist.p_overall:.2g}, level {dist.alpha:g}).")
    ax = plots.distortion(dist)
    rep.figure(ax.figure, "distortion.png",
               "Output power per line (dB): the signal on the excited lines and their sidebands (within "
               f"+-{dist.branches} lines, the LPTV system's reach), the noise level of a period mean, and the "
               "stochastic nonlinear distortion where it is estimated above zero. A linear time-periodic "
               "system leaves the nonlinear level at the noise's scatter around zero.")
    lv = summary["distortion"]["levels"]
    rep.table(["lines", "count", "signal (dB)", "noise (dB)", "nonlinear (dB)"],
              [[k, v["lines"], f"{v['signal_db']:.1f}", f"{v['noise_db']:.1f}", f"{v['nonlinear_db']:.1f}"]
               for k, v in lv.items()])
    rep.paragraph(
        f"The model: na = {model.na}, nb = {model.nb}, {summary['ka']} harmonics on the a_n and "
        f"{summary['kb']} on the b_m ({res.n_free_parameters} free parameters), identified by "
        f"{res.method.upper()} from the {M} realisations fitted together ({res.lines.size} lines in all)"
        + ((", each input variance raised by the nonlinear level referred to the input through "
            + (summary.get("first_fit") or "a first fit")
            + " (a nonlinearity before the dynamics): the best linear time-periodic approximation."
            if summary.get("referred") == "input" else
            ", each with its noise alone (the weights), the nonlinear distortion in the intervals through the "
            "jackknife below: the best linear time-periodic approximation, consistent where the response "
            "depends on the phases"
            + (f" (chosen by --referred auto: the realisations' output powers differ up to "
               f"{dist.output_spread:.3g} times)." if summary.get("referred_option") == "auto" else ".")
            if summary.get("referred") == "none" else
            ", each output variance raised by the nonlinear level: the best linear time-periodic "
            "approximation, whose covariance includes the nonlinear distortion.")
           + ("" if summary.get("referred") == "none" else
              " Each realisation's raised variance is worth more periods than it has (the P of the summary "
              "below: the degrees of freedom of noise and level together, METHOD.md section 16).")
           if dist.detected else ".")
        + (" The parameter covariance is the jackknife over the realisations (each left out in turn), "
           "which holds whatever the distortion's correlation across lines, corrected for realisations "
           "of unequal information and scaled to the t quantile of its degrees of freedom ("
           + _dof_range(res) + ")." if summary.get("covariance") == "realisations" else ""))
    if res.lack_of_fit is not None:
        rep.figure(plots.lack_of_fit(res.lack_of_fit, w0=model.w0).figure, "lack_of_fit.png",
                   "The verdict's test: on each judged output line the model's prediction against the "
                   "regression of that line across the realisations (its F test's -log10 p; about 1 % of "
                   "the lines above the 1 % line when the model is the best linear approximation). The "
                   "decision is the permutation test of all lines together, in the title (METHOD.md "
                   "section 16).")
    rep.figure(plots.bode(res), "bode.png",
               "Each realisation's measured FRF Y/U on its excited lines (+-2 std from its periods) and the "
               "model's response with its 95 % band from the parameter covariance"
               + ("." if model.is_lti else
                  ": for a time-varying model the output the model predicts from each realisation's measured "
                  "input over that input (Y/U on a line holds every branch's share, not G_0 alone); below, "
                  "the model's HTF branches G_k with their nonparametric estimates where a realisation "
                  "separates them (lptv.htf_estimate; entries its neighbours' far branches overlap left out)."))
    # the parameters after the figures: a BLA's model is often large (34 parameters here, 100 rows
    # with their amplitudes and phases)
    scale = summary.get("scale")
    u_unit, y_unit = units.channel_unit(meas.input), units.channel_unit(meas.output)
    physical = parameter_section(rep, res, scale=(scale["coefficient"], scale["value"]) if scale else None,
                                 known=known, u_unit=u_unit, y_unit=y_unit)
    model_figures(rep, res, physical=physical, u_unit=u_unit, y_unit=y_unit)
    rep.preformatted(res.summary())
    return rep
