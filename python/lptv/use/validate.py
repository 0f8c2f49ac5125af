"""A saved model against a fresh record, the model fixed (METHOD.md section 21).

Periods of one input and output: the model's residues e_l = A Y - B U on the fresh record's
lines, judged against that record's own noise by the verdict's tests (``lptv.judgement.verdict``) with
the model fixed: no projection of a fit, the model's own estimation error counted instead
(Cov r = S + J C J^T, C its covariance), and a score test per coefficient: the change of its
parameters the fresh record asks for, against its noise and the model's covariance. Periods
of several channels: each line's output error against its noise (the tests of
:class:`lptv.MimoIdentificationResult`). One record: the residual of the prediction from rest,
tested as :func:`lptv.identify_record`'s verdict tests a fit's. The simulation fit in percent,
``100 (1 - ||y - y_hat|| / ||y - mean y||)``, as SITB's ``compare``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Optional, Tuple

import numpy as np

from .. import _core
from .._validate import _array, as_lines, check_finite
from ..model.mimo import MimoModel
from ..model.siso import Model
from ..judgement.verdict import ALPHA
from .predict import predict, sampling, whole_periods


@dataclass(frozen=True)
class CoefficientTest:
    """What the fresh record would change in one coefficient's parameters (a score test)."""

    name: str
    """The coefficient: 'a0' .. 'a<na>', 'b0' .. 'b<nb>'."""
    parameters: Tuple[str, ...]
    """Its real parameters, e.g. ('a0.re0', 'a0.re1', 'a0.im1')."""
    change: np.ndarray
    """The Gauss-Newton step from the model that the fresh record asks for, -F^-1 s on them."""
    std: np.ndarray
    """Its standard deviation when the model is right: sqrt(diag(kappa F^-1 + C))."""
    statistic: float
    """change^T (kappa F^-1 + C)^-1 change, chi-square with len(parameters) degrees of freedom."""
    p_value: float
    p_holm: float = float("nan")

    @property
    def rejects(self) -> bool:
        return self.p_holm <= ALPHA


@dataclass(frozen=True)
class ValidationResult:
    """:func:`validate`'s result: the model fixed against a fresh record."""

    model: object
    route: str
    """'periods', 'several channels' or 'one record'."""
    model_ok: bool
    """True when none of the tests rejects the model on the fresh record (Holm at ``ALPHA``)."""
    model_errors: Tuple[str, ...]
    fit_percent: np.ndarray
    """Per output: 100 (1 - ||y - y_hat|| / ||y - mean y||) over the record's samples."""
    y: np.ndarray
    """The measured output samples, (n,) or (n, ny)."""
    y_hat: np.ndarray
    """The model's prediction of them (periodic steady state; one record: from rest)."""
    lines: np.ndarray
    """The rows (lines) the residues are on."""
    residue: np.ndarray
    """e_l on ``lines`` (equation error A Y - B U; several channels and one record: the output error)."""
    normalized_residue: np.ndarray
    """|e_l| / sqrt(var e_l) (several channels: per output, shape (rows, ny))."""
    tests: Tuple = ()
    """The residue tests (:class:`lptv.judgement.verdict.ResidueTest`; several channels: (row, output, statistic,
    p-value) as :attr:`lptv.MimoIdentificationResult.tests`; one record: the record verdict)."""
    coefficient_tests: Tuple[CoefficientTest, ...] = ()
    noise: str = "sample"
    """The noise variances the tests divide by: 'sample' or 'moderated' (as the verdict chooses)."""
    notes: Tuple[str, ...] = field(default_factory=tuple)

    @property
    def verdict(self) -> str:
        if self.model_ok:
            fit = ", ".join(f"{f:.1f} %" for f in np.atleast_1d(self.fit_percent))
            return (f"the model is consistent with the fresh record: no test finds a model error (fit {fit})")
        return "MODEL ERRORS on the fresh record: " + "; ".join(self.model_errors)

    @property
    def changed(self) -> Tuple[CoefficientTest, ...]:
        """The coefficients whose parameters the fresh record would change (the rejecting score tests)."""
        return tuple(t for t in self.coefficient_tests if t.rejects)


def fit_percent(y, y_hat) -> np.ndarray:
    """100 (1 - ||y - y_hat|| / ||y - mean y||) per column; a ValueError for a constant y."""
    y, y_hat = np.atleast_2d(np.asarray(y).T).T, np.atleast_2d(np.asarray(y_hat).T).T
    den = np.linalg.norm(y - y.mean(axis=0), axis=0)
    if not np.all(den > 0):
        raise ValueError("y: a constant output has no fit in percent (||y - mean y|| = 0)")
    return 100.0 * (1.0 - np.linalg.norm(y - y_hat, axis=0) / den)


def _holm(p) -> np.ndarray:
    p = np.asarray(p, float)
    adj, run = np.empty(p.size), 0.0
    for rank, i in enumerate(np.argsort(p)):
        run = max(run, min(1.0, (p.size - rank) * p[i]))
        adj[i] = run
    return adj


def validate(model, u, y, *, fs: Optional[float] = None, lines=None, one_record: bool = False) -> ValidationResult:
    """The model, fixed, against a fresh record of its system.

    Parameters
    ----------
    model : lptv.Model or lptv.MimoModel
        E.g. read by :meth:`lptv.Model.load` from the model.json of ``lptv identify``.
    u, y : array_like
        Periods, shape (P, N) (several channels: (P, N, nu) and (P, N, ny)), starting at the
        start of a period of the model's coefficients; with ``one_record`` the samples of one
        record, shape (n,), from rest at its first sample.
    fs : float, optional
        Sampling frequency (Hz); needed with ``one_record`` for a continuous-time model, and
        checked against the model's samples per period when given.
    lines : sequence of int, optional
        The rows of the residues (default: every usable line, K+1 .. N/2 - K).

    Returns
    -------
    ValidationResult
        ``verdict``, ``model_ok``, ``fit_percent``, the residues and the tests.
    """
    cov = None
    if not isinstance(model, (Model, MimoModel)) and isinstance(getattr(model, "model", None), (Model, MimoModel)):
        # a fit's result: its model with the covariance of its parameters
        cov = (tuple(model.eta_names), model.covariance) if getattr(model, "covariance", None) is not None else None
        model = model.model
    if not isinstance(model, (Model, MimoModel)):
        raise ValueError(f"model must be an lptv.Model or lptv.MimoModel (or a fit's result), got "
                         f"{type(model).__name__}")
    if cov is None and getattr(model, "covariance", None) is not None:
        cov = (tuple(model.eta_names), model.covariance)
    if one_record:
        if isinstance(model, MimoModel):
            raise ValueError("one_record: a record that does not repeat is validated for one input and output")
        return _one_record(model, u, y, fs, lines)
    mimo = isinstance(model, MimoModel)
    u, y = (_periods(x, n, model.n_inputs if mimo and n == "u" else model.n_outputs if mimo else 0)
            for x, n in ((u, "u"), (y, "y")))
    if u.shape[:2] != y.shape[:2]:
        raise ValueError(f"u and y must hold the same periods and samples, got {u.shape} and {y.shape}")
    P, N = u.shape[:2]
    if P < 2:
        raise ValueError(f"u: {P} period(s): the record's noise needs P >= 2 periods (or one_record=True)")
    if model.discrete and N != model.samples_per_period:
        raise ValueError(f"u: {N} samples a period, but the discrete-time model has {model.samples_per_period}")
    if fs is not None:
        whole_periods(model, N, sampling(model, fs))
    return _mimo(model, u, y, lines, cov) if mimo else _siso(model, u, y, lines)


def _periods(x, name, channels):
    a = _array(x, name)
    if np.iscomplexobj(a):
        raise ValueError(f"{name} must be real samples, got complex values")
    a = a.astype(float)
    want = 3 if channels else 2
    if a.ndim != want:
        shape = f"(P, N, {channels})" if channels else "(P, N)"
        raise ValueError(f"{name} must have shape {shape}: P periods of N samples, got {a.shape}")
    if channels and a.shape[2] != channels:
        raise ValueError(f"{name} has {a.shape[2]} channels but the model has {channels}")
    check_finite(a, name)
    return a


def _rows(model, max_line, lines):
    K = max(model.ka, model.kb)
    if lines is None:
        rows = np.arange(K + 1, max_line - K + 1)
    else:
        rows = np.asarray(as_lines(lines, "lines"))
        bad = rows[(rows < K + 1) | (rows > max_line - K)]
        if bad.size:
            raise ValueError(f"lines: line {int(bad[0])} is outside the usable lines {K + 1} .. {max_line - K} "
                             f"of the record (K = {K})")
    if rows.size < 2:
        raise ValueError(f"the record has too few usable lines ({rows.size}) for the model's {K} harmonics")
    return rows


def _judged_noise(d):
    """The data the tests divide by and each line's degrees of freedom, as the verdict chooses
    (moderated when the noise spectrum is smooth, the sample (co)variances otherwise)."""
    from ..judgement import verdict
    from ..spectra.moderation import moderated_noise, smooth_noise

    P = int(d.periods)
    if verdict.MODERATE and P >= 2:
        mo = moderated_noise(d)
        if mo.prior_dof > 0 and smooth_noise(mo)[0]:
            return mo.unbiased_data(), np.asarray(mo.dof, float), "moderated"
    return d, np.full(d.max_line + 1, 2.0 * (P - 1)), "sample"


def _free_covariance(model, par, free):
    """The model's covariance on the parametrisation's free parameters (by name), or zeros."""
    names = list(par.eta_names)
    n = len(free)
    cov, have = getattr(model, "covariance", None), list(getattr(model, "eta_names", ()))
    if cov is None or not all(names[i] in have for i in free):
        return np.zeros((n, n)), False
    idx = [have.index(names[i]) for i in free]
    return np.asarray(cov)[np.ix_(idx, idx)], True


def _fitted_counts(model):
    """(ka, kb) per coefficient as the fit had them: from the covariance's parameter names, else
    the context's structure; None when neither says (the model's arrays then give them)."""
    names = list(getattr(model, "eta_names", ()) or ())
    if names:
        ka, kb = [0] * (model.na + 1), [0] * (model.nb + 1)
        for n in names:
            coef, _, part = n.partition(".")
            k = int(part[2:]) if part[:2] in ("re", "im") and part[2:].isdigit() else 0
            (ka if coef[0] == "a" else kb)[int(coef[1:])] = max(k, (ka if coef[0] == "a" else kb)[int(coef[1:])])
        return ka, kb
    ctx = getattr(model, "context", None)
    if ctx:
        s = ctx["structure"]
        return tuple(x if isinstance(x, list) else [x] * (n + 1) for x, n in ((s["ka"], model.na), (s["kb"], model.nb)))
    return None


def _parametrisation(model):
    """The fit's parametrisation (its harmonic counts per coefficient) when the model's arrays
    hold nothing beyond it, else the one the arrays' shape gives."""
    counts = _fitted_counts(model)
    if counts is not None:
        ka, kb = counts
        outside = False
        for c, ks in ((model.a, ka), (model.b, kb)):
            K = (c.shape[1] - 1) // 2
            for n, k in enumerate(ks):
                row = np.delete(c[n], np.arange(K - k, K + k + 1))
                outside |= bool(np.any(row != 0))
        if not outside:
            return _core.Parametrisation(model.na, model.nb, list(ka), list(kb), [], model.w0,
                                         model.ts if model.discrete else 0.0)
    return _core.Parametrisation(_core.Structure.of(model._cpp))


def _siso(model, u, y, lines):
    from ..spectra.frequency_data import FrequencyData
    from ..judgement.validation import normalized_residue
    from ..judgement.verdict import residue_tests

    d = FrequencyData.from_periods(u, y, w0=model.w0, ts=model.ts)
    rows = _rows(model, d.max_line, lines)
    par = _parametrisation(model)
    structure = par.structure
    theta = np.asarray(par.theta_from_model(model._cpp))
    e, var_e, r = normalized_residue(model, d, rows)
    free = [i for i in range(np.asarray(par.T).shape[1]) if i != par.norm_index]
    C, has_cov = _free_covariance(model, par, free)
    notes = () if has_cov else ("the model carries no covariance: its own estimation error is not counted",)
    ns = SimpleNamespace(experiments=(), data=d, noise_free=False, lines=rows, experiment=None, theta=theta,
                         moderation=(), noise="sample", method="fixed", residue=e, model=model, fixed_covariance=C)
    tests = residue_tests(ns, structure)
    if tests is None:
        raise ValueError("y: the fresh record carries no noise statistics to judge the model against")
    d_used, dof, route = _judged_noise(d)
    coef = _coefficient_tests(d_used, dof, par, theta, free, C, rows[tests.judged], max(model.ka, model.kb))
    p_all = [t.p_value for t in tests.tests] + [c.p_value for c in coef]
    adj = _holm(p_all)
    k = len(tests.tests)
    from dataclasses import replace

    res_tests = tuple(replace(t, p_holm=float(a)) for t, a in zip(tests.tests, adj[:k]))
    coef = tuple(replace(c, p_holm=float(a)) for c, a in zip(coef, adj[k:]))
    errors = [s for s in replace(tests, tests=res_tests).sentences()]
    for c in coef:
        if c.rejects:
            moved = ", ".join(f"{n} {v:+.3g} (std {s:.2g})" for n, v, s in zip(c.parameters, c.change, c.std))
            errors.append(f"the fresh record would change {c.name}: {moved} (chi-square {c.statistic:.3g} on "
                          f"{len(c.parameters)} degrees of freedom, p = {c.p_value:.2g}, Holm-adjusted "
                          f"{c.p_holm:.2g} < {ALPHA:g})")
    yv, y_hat = y.reshape(-1), predict(model, u.reshape(-1), fs=model.samples_per_period / model.period
                                       if model.discrete else u.shape[1] / model.period, initial="steady")
    return ValidationResult(model=model, route="periods", model_ok=not errors, model_errors=tuple(errors),
                            fit_percent=fit_percent(yv, y_hat), y=yv, y_hat=y_hat, lines=rows, residue=e,
                            normalized_residue=r, tests=res_tests, coefficient_tests=coef, noise=route, notes=notes)


def _coefficient_tests(d, dof, par, theta, free, C, rows, K):
    """Per coefficient: the Gauss-Newton step -F^-1 s of its parameters at the fixed model on the
    fresh record (s = J^T S^-1 r, F = J^T S^-1 J on the judged rows), referred to its covariance
    kappa F^-1 + C when the model is right (kappa the small-sample factor (nu - 2)/(nu - 4) of
    noise (co)variances with nu degrees of freedom, METHOD.md section 10, averaged over the rows)."""
    from .._dist import chi2_sf

    rows = [int(l) for l in rows]
    nu = np.array([dof[max(l - K, 1):l + K + 1].min() for l in rows])
    if len(rows) < 2 or np.any(nu <= 4):
        return ()
    like = _core.ExactLikelihood(d._cpp, par, rows)
    s = np.asarray(like.gradient(theta))[free] / 2.0
    F = np.asarray(like.fisher_information(theta))
    if F.shape != (len(free), len(free)):
        F = F[np.ix_(free, free)]
    try:
        Finv = np.linalg.inv(F)
    except np.linalg.LinAlgError:
        return ()
    kappa = float(np.mean((nu - 2.0) / (nu - 4.0)))
    step = -Finv @ s
    V = kappa * Finv + C
    names = [list(par.eta_names)[i] for i in free]
    out = []
    for coef in dict.fromkeys(n.split(".")[0] for n in names):
        idx = [j for j, n in enumerate(names) if n.split(".")[0] == coef]
        Vc = V[np.ix_(idx, idx)]
        try:
            stat = float(step[idx] @ np.linalg.solve(Vc, step[idx]))
        except np.linalg.LinAlgError:
            continue
        out.append(CoefficientTest(name=coef, parameters=tuple(names[j] for j in idx), change=step[idx],
                                   std=np.sqrt(np.diag(Vc)), statistic=stat,
                                   p_value=float(chi2_sf(stat, len(idx)))))
    return tuple(out)


def _parameter_jacobian(model, U, rows, names):
    """dYhat_l / d eta on ``rows`` for the parameters named as a MIMO fit names them ('a0[0,1].re1'),
    by central differences of the FDS (the output is linear in each coefficient's harmonic up to
    the model's inverse: a relative step of 1e-6 leaves 1e-12 of it)."""
    import re

    from ..simulation.fds import simulate

    a, b = model.a, model.b
    out = np.empty((rows.size, model.n_outputs, len(names)), complex)
    for i, name in enumerate(names):
        hit = re.fullmatch(r"([ab])(\d+)\[(\d+),(\d+)\]\.(re|im)(\d+)", name)
        if hit is None:
            raise ValueError(f"covariance: parameter name {name!r} is not of the form a0[p,q].re1")
        side, n, p, q, part, k = hit.groups()
        c = a if side == "a" else b
        Kc = (c.shape[-1] - 1) // 2
        n, p, q, k = int(n), int(p), int(q), int(k)
        if k > Kc or n >= c.shape[0]:
            raise ValueError(f"covariance: parameter {name!r} is not a coefficient of the model")
        h = 1e-6 * max(abs(c[n, p, q, Kc + k]), float(np.abs(c).max()) * 1e-3)
        step = np.zeros_like(c)
        unit = 1.0 if part == "re" else 1j
        step[n, p, q, Kc + k] += unit
        if k:
            step[n, p, q, Kc - k] += np.conj(unit)
        Ys = []
        for sgn in (1, -1):
            m = MimoModel(a + sgn * h * step, b, w0=model.w0, ts=model.ts) if side == "a" else \
                MimoModel(a, b + sgn * h * step, w0=model.w0, ts=model.ts)
            Ys.append(np.asarray(simulate(m, U, warn_unstable=False)).reshape(-1, model.n_outputs)[rows])
        out[:, :, i] = (Ys[0] - Ys[1]) / (2 * h)
    return out


def _mimo(model, u, y, lines, cov=None):
    from ..simulation.fds import htf, simulate
    from ..spectra.mimo_frequency_data import MimoFrequencyData
    from ..judgement.mimo_result import residue_tests

    d = MimoFrequencyData.from_periods(u, y, w0=model.w0, ts=model.ts)
    rows = _rows(model, d.max_line, lines)
    ny, nu = model.n_outputs, model.n_inputs
    Yhat = np.asarray(simulate(model, d.U, warn_unstable=False)).reshape(-1, ny)
    e = d.Y[rows] - Yhat[rows]
    Cyy, Cyu, Cuu = d.C[:, :ny, :ny], d.C[:, :ny, ny:], d.C[:, ny:, ny:]
    # the input noise through the model, lines independent and circular (METHOD.md section 21)
    K = max(model.ka, model.kb)
    if model.discrete:
        N = model.samples_per_period
        cols = np.arange(N)
        G = htf(model, 0)[rows]                           # (rows, ny, N, nu)
        vU = Cuu[np.minimum(cols, N - cols)]
        vU = np.where((cols > N // 2)[:, None, None], np.conj(vU), vU)
        diag = G[np.arange(rows.size), :, rows % N, :]
    else:
        W = 2 * K + 16
        cols = np.arange(-(int(rows.max()) + W), int(rows.max()) + W + 1)
        Lg = int(cols.max()) + 64
        G = htf(model, Lg, cols)[rows + Lg]               # (rows, ny, cols, nu)
        ok = np.abs(cols) <= d.max_line
        vU = np.zeros((cols.size, nu, nu), complex)
        vU[ok] = Cuu[np.abs(cols[ok])]
        vU[cols < 0] = np.conj(vU[cols < 0])
        diag = G[np.arange(rows.size), :, rows - cols[0], :]
    Cyu_r = Cyu[rows]
    Ce = (Cyy[rows] + np.einsum("rpjs,jst,rqjt->rpq", G, vU, G.conj())
          - np.einsum("rps,rqs->rpq", Cyu_r, diag.conj()) - np.einsum("rps,rqs->rpq", diag, Cyu_r.conj()))
    notes = ("the matrix model's own estimation error is not counted (model.json keeps no covariance for it; "
             "lptv.validate(result, u, y) with the fit's result counts it)",)
    if cov is not None:        # e = e0 - J delta: the model's own error (METHOD.md section 21)
        Jp = _parameter_jacobian(model, d.U, rows, cov[0])
        Ce = Ce + np.einsum("rpi,ij,rqj->rpq", Jp, np.asarray(cov[1]), Jp.conj())
        notes = ()
    tests = residue_tests(e, Ce, np.full(rows.size, d.periods))
    p = np.array([t[3] for t in tests])
    adj = _holm(p) if p.size else p
    errors = []
    for t, a in sorted(zip(tests, adj), key=lambda x: x[1]):
        if a > ALPHA or len(errors) >= 10:
            break
        who = "all outputs jointly" if t[1] < 0 else f"output {t[1]}"
        errors.append(f"{who}: the output error on line {int(rows[t[0]])} is too large for the noise "
                      f"(p = {t[3]:.2g}; Holm at {ALPHA:g} over {len(tests)} tests)")
    n = u.shape[0] * u.shape[1]
    y_hat = predict(model, u.reshape(n, nu), fs=u.shape[1] / model.period, initial="steady")
    yv = y.reshape(n, ny)
    diagC = np.real(np.diagonal(Ce, axis1=1, axis2=2))
    return ValidationResult(model=model, route="several channels", model_ok=not errors, model_errors=tuple(errors),
                            fit_percent=fit_percent(yv, y_hat), y=yv, y_hat=y_hat, lines=rows, residue=e,
                            normalized_residue=np.abs(e) / np.sqrt(diagC), tests=tests, noise="sample",
                            notes=notes)


def _one_record(model, u, y, fs, lines):
    from ..judgement.one_record_verdict import record_verdict

    fs = sampling(model, fs)
    u = np.asarray(_array(u, "u"), float).reshape(-1) if np.ndim(u) != 1 else np.asarray(_array(u, "u"), float)
    y = np.asarray(_array(y, "y"), float).reshape(-1) if np.ndim(y) != 1 else np.asarray(_array(y, "y"), float)
    if u.size != y.size:
        raise ValueError(f"u and y must have the same number of samples, got {u.size} and {y.size}")
    check_finite(y, "y")
    y_hat = predict(model, u, fs=fs, initial="rest")
    n = u.size
    L = whole_periods(model, n, fs)
    Ufull = np.fft.fft(u) / n
    E = np.fft.fft(y - y_hat) / n
    if lines is None:
        rows = np.arange(1, (n - 1) // 2 + 1)
    else:
        rows = np.asarray(as_lines(lines, "lines"))
        if rows.size and (rows.min() < 1 or rows.max() > (n - 1) // 2):
            raise ValueError(f"lines: the record's lines are 1 .. {(n - 1) // 2}")
    v = record_verdict(Ufull, E[rows], rows, L, max(model.ka, model.kb))
    if not np.isfinite(v.p_value):
        raise ValueError(f"u: {v.model_errors[0]}")
    errors = tuple(v.model_errors)
    return ValidationResult(model=model, route="one record", model_ok=not errors, model_errors=errors,
                            fit_percent=fit_percent(y, y_hat), y=y, y_hat=y_hat, lines=rows, residue=E[rows],
                            normalized_residue=np.abs(E[rows]) / np.sqrt(np.mean(np.abs(E[rows]) ** 2)),
                            tests=(v,), noise="residual")
