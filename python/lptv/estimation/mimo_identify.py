"""lptv.identify for several inputs and outputs (METHOD.md section 19): the arguments, the rows,
the estimators of :mod:`lptv.estimation.mimo_fit`, the covariance with its small-sample factor, the
verdict; and :func:`mimo_crb`, the Cramer-Rao bound of a MIMO design."""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from .._validate import _array, as_float, as_int, as_lines, check_finite
from ..model.mimo import MimoModel
from ..spectra.frequency_data import refuse_repeated_experiments
from ..spectra.mimo_frequency_data import MimoFrequencyData, MimoStructure, as_entry_counts, as_order
from .mimo_fit import FitError, Transient, core_data, core_structure, expand, fisher, fit, residues, transient_orders
from ..judgement.mimo_result import MimoIdentificationResult, residue_tests

MIMO_METHODS = ("gtls", "wgtls", "sml")
AUTO_MIN_PERIODS = 4
"""noise='auto' moderates from this many periods (as for one input and output)."""
AUTO_MIN_PERIODS_RECORD = 8
"""noise='auto' on the record's statistics moderates from this many periods (as for one input and
output: at P = 4 the moderated fits' intervals on bench_process_noise_mimo.py's 2 x 2 rig covered
90.6 % (WGTLS) and 84.4 % (SML), the record's sample statistics 93.5 % and 89.7 %)."""


def _noise_route(datas, noise):
    """(route, why, the MimoModeratedNoise per experiment or None, the data) for noise='auto',
    'sample', 'moderated', 'full' or 'full-moderated' (METHOD.md sections 19 and 20): the
    statistics first (the whole record's when asked for, or when noise='auto' finds the periods'
    noise correlated between neighbouring lines), then the moderation."""
    full, lines = noise in ("full", "full-moderated"), ""
    if full:
        try:
            datas = [d.record_statistics() for d in datas]
        except ValueError as e:
            raise ValueError(f"noise='{noise}' takes the noise from the whole record: {e}") from None
        noise = "sample" if noise == "full" else "moderated"
    elif noise == "auto" and all(getattr(d, "_record", None) is not None for d in datas):
        from ..spectra.frequency_data import correlated_lines
        tests = [correlated_lines(d) for d in datas]
        full = any(t.correlated for t in tests)
        said = [(f"experiment {i}: " if len(datas) > 1 else "") + t.reason
                for i, t in enumerate(tests) if t.correlated == full]
        lines = "; ".join(said[:3]) + (" (the noise from the whole record)" if full else "")
        if full:
            datas = [d.record_statistics() for d in datas]
    route, why, mos = _moderation_route(datas, noise, full)
    if full:
        route = {"sample": "full", "moderated": "full-moderated"}[route]
    if lines:
        why = why + "; " + lines
    return route, why, mos, datas


def _moderation_route(datas, noise, full=False):
    """(route, why, mos) of the moderation for noise 'auto', 'sample' or 'moderated' (``full``: on
    the record's statistics)."""
    from ..spectra.moderation import smooth_noise
    from ..spectra.mimo_moderation import moderated_mimo_noise

    if noise == "sample":
        return "sample", "asked for", None
    if noise == "moderated":
        mos = [moderated_mimo_noise(d) for d in datas]
        if any(m.prior_dof <= 0 for m in mos):
            return "sample", ("the sample (co)variances: they cannot be moderated (too few lines with noise, "
                              "or not from periods)"), None
        return "moderated", "asked for", mos
    mos, why = [], []
    for e, d in enumerate(datas):
        if full and d.periods < AUTO_MIN_PERIODS_RECORD:
            return "sample", (f"the sample (co)variances: {d.periods} periods (on the record's noise the moderated "
                              f"route needs {AUTO_MIN_PERIODS_RECORD}: with fewer its intervals are too narrow)"), None
        if d.periods < AUTO_MIN_PERIODS:
            return "sample", (f"the sample (co)variances: {d.periods} periods (the moderated route needs "
                              f"{AUTO_MIN_PERIODS})"), None
        mo = moderated_mimo_noise(d)
        ok, reason = smooth_noise(mo)
        if not ok:
            return "sample", "the sample (co)variances: " + reason, None
        mos.append(mo)
        why.append(f"experiment {e}: {reason}" if len(datas) > 1 else reason)
    return "moderated", "moderated: " + "; ".join(why), mos


def noise_route_noisy(datas) -> bool:
    """Whether any experiment carries noise (co)variances."""
    return any(np.max(np.abs(d.C)) > 0 for d in datas)


def is_mimo(u, y) -> bool:
    """Whether identify's arguments are of several channels: 3-D arrays, MimoFrequencyData, or a
    list of experiments whose first is one of those."""
    if isinstance(u, MimoFrequencyData):
        return True
    if y is not None:
        return np.ndim(u) == 3 if not isinstance(u, (list, tuple)) or _regular(u) else False
    if isinstance(u, (list, tuple)) and u:
        first = u[0]
        if isinstance(first, MimoFrequencyData):
            return True
        if isinstance(first, (list, tuple)) and len(first) == 2:
            return _regular(first[0]) and np.ndim(first[0]) == 3
    return False


def _regular(x) -> bool:
    try:
        np.asarray(x, dtype=float)
        return True
    except (ValueError, TypeError):
        return False


def _experiments(u, y, w0, ts):
    if isinstance(u, MimoFrequencyData):
        return [u]
    if y is not None:
        return [MimoFrequencyData.from_periods(u, y, w0=_need_w0(w0), ts=ts)]
    if not isinstance(u, (list, tuple)) or not u:
        raise ValueError("u: give (P, N, nu) periods with y, or a non-empty list of experiments")
    if any(not isinstance(item, MimoFrequencyData) for item in u):
        _need_w0(w0)
    out = []
    for e, item in enumerate(u):
        if isinstance(item, MimoFrequencyData):
            out.append(item)
        elif isinstance(item, (list, tuple)) and len(item) == 2:
            try:
                out.append(MimoFrequencyData.from_periods(item[0], item[1], w0=_need_w0(w0), ts=ts))
            except ValueError as err:
                raise ValueError(f"experiments[{e}]: {err}") from None
        else:
            raise ValueError(f"u: experiment {e} must be a (u, y) pair of arrays (P, N, nu), (P, N, ny) or "
                             f"MimoFrequencyData, got {type(item).__name__}")
    ny, nu = out[0].n_outputs, out[0].n_inputs
    for e, d in enumerate(out):
        if (d.n_outputs, d.n_inputs) != (ny, nu):
            raise ValueError(f"experiments[{e}]: {d.n_inputs} inputs and {d.n_outputs} outputs, experiment 0 has "
                             f"{nu} and {ny}")
        if d.w0 != out[0].w0 or (d.ts or 0.0) != (out[0].ts or 0.0):
            raise ValueError(f"experiments[{e}]: w0 and ts must be those of experiment 0")
    refuse_repeated_experiments(out)
    return out


SILENT_ALPHA = 0.01
"""The size of :func:`silent_outputs`' test per output (Bonferroni over its rows)."""


def silent_outputs(datas, rows_list) -> list:
    """One sentence per output whose spectrum stands above its noise on none of the fitted rows:
    |Y_p,l|^2 / C_pp,l is F(2, 2(P-1)) where the output is noise alone, and no row beyond its
    1 - SILENT_ALPHA / n point (n rows) leaves no evidence that the output responds to the inputs
    (a dead sensor, a channel that is noise): its coefficients are then fitted to noise."""
    from .._dist import f_isf

    ny = datas[0].n_outputs
    z, dof = [], []
    for d, rows in zip(datas, rows_list):
        if d.periods < 2 or rows.size == 0:
            continue
        var = np.real(np.diagonal(d.C[rows], axis1=1, axis2=2))[:, :ny]
        with np.errstate(divide="ignore", invalid="ignore"):
            z.append(np.where(var > 0, np.abs(d.Y[rows]) ** 2 / var, np.inf))
        dof.append(np.full(rows.size, 2.0 * (d.periods - 1)))
    if not z:
        return []
    z, dof = np.concatenate(z), np.concatenate(dof)
    limit = f_isf(SILENT_ALPHA / z.shape[0], 2.0, dof)
    return [f"output {p} does not respond to the inputs: on none of the {z.shape[0]} fitted rows does its spectrum "
            f"stand above its noise (F(2, 2(P-1)) at {SILENT_ALPHA:g} over the rows); its coefficients are fitted "
            "to noise (a dead sensor, a channel not driven by these inputs?)"
            for p in range(ny) if not np.any(z[:, p] > limit)]


def _need_w0(w0):
    if w0 is None:
        raise ValueError("w0 must be given (the fundamental of the period in rad/s)")
    return w0


def _rows_of(d: MimoFrequencyData, lines, K: int, e: int):
    """The rows of experiment ``e``: by default and for 'excited' the lines K+1 .. Lmax-K (rows
    that read positive lines only), as for one channel; given lines from 1 up to Lmax-K, a row
    l <= K reading line 0 and the conjugates of lines 1..K-l (a real signal's spectrum)."""
    lo, hi = K + 1, d.max_line - K
    if lines is None:
        rows = np.arange(lo, hi + 1)
    elif isinstance(lines, str):
        if lines != "excited":
            raise ValueError(f"lines must be None, 'excited' or a sequence of integers, got {lines!r}")
        power = np.abs(d.U) ** 2
        noise = np.real(np.diagonal(d.C, axis1=1, axis2=2))[:, d.n_outputs:]
        exc = np.flatnonzero(np.any(power > 100 * noise, axis=1) & (np.arange(d.max_line + 1) > 0))
        rows = np.unique((exc[:, None] + np.arange(-K, K + 1)[None, :]).ravel())
        rows = rows[(rows >= lo) & (rows <= hi)]
    else:
        rows = np.unique(np.asarray(as_lines(lines, "lines"), dtype=int))
        bad = rows[(rows < 1) | (rows > hi)]
        if bad.size:
            raise ValueError(f"lines: line {int(bad[0])} (experiment {e}) is outside 1..{hi}: rows are lines >= 1 "
                             f"and every line a row reads (l - K .. l + K, K = {K}) must be measured, up to N/2")
    if rows.size == 0:
        raise ValueError(f"lines: experiment {e} has no row: it needs lines {lo}..{hi} (K = {K})")
    return rows


def _known_leading(known, na, ny):
    """known={'a<na>': M}: the mean of the leading matrix, ny x ny real and invertible (the only
    known entries built for several channels), or None."""
    if not known:
        return None
    if not isinstance(known, dict) or list(known) != [f"a{na}"]:
        raise ValueError(f"known: for several inputs or outputs only the mean of the leading matrix is built, as "
                         f"{{'a{na}': M}} with M real ny x ny; got {known!r}")
    M = _array(known[f"a{na}"], "known")
    if np.iscomplexobj(M) or M.shape != (ny, ny):
        raise ValueError(f"known: a{na} must be a real {ny} x {ny} matrix (the mean of A_{na}), got shape {M.shape}")
    M = M.astype(float)
    check_finite(M, "known")
    if np.linalg.cond(M) > 1e12:
        raise ValueError(f"known: a{na} must be invertible (condition number {np.linalg.cond(M):.3g})")
    return M


def identify_mimo(u, y=None, *, na, nb, ka=0, kb=0, w0=None, ts=None, lines=None, method="wgtls",
                  known=None, tol=1e-10, max_iter=50, covariance="analytic",
                  noise="auto", transient="auto") -> MimoIdentificationResult:
    """lptv.identify's route for several inputs or outputs (its docstring has the arguments)."""
    noises = ("auto", "sample", "moderated", "full", "full-moderated")
    if noise == "full-rows":
        raise ValueError("noise='full-rows' reads the rows on the record's realisations for one input and one "
                         "output only: use noise='full' for several channels")
    if not isinstance(noise, str) or noise not in noises:
        raise ValueError(f"noise must be one of {noises}, got {noise!r}")
    if not isinstance(method, str) or method not in MIMO_METHODS:
        raise ValueError(f"method must be one of {MIMO_METHODS} for several inputs or outputs, got {method!r}")
    if not isinstance(covariance, str) or covariance not in ("analytic", "none"):
        raise ValueError(f"covariance must be 'analytic' or 'none' for several inputs or outputs, got {covariance!r}")
    transient = as_transient(transient)
    na, nb = as_order(na, "na"), as_order(nb, "nb")
    tol = as_float(tol, "tol", minimum=0.0, open_min=True)
    max_iter = as_int(max_iter, "max_iter", minimum=1)
    datas = _experiments(u, y, w0, ts)
    route, choice, mos, datas = _noise_route(datas, noise)
    if route in ("moderated", "full-moderated"):
        datas = [m.data for m in mos]
    d0 = datas[0]
    ny, nu = d0.n_outputs, d0.n_inputs
    lead = _known_leading(known, na, ny)
    ka_r = as_entry_counts(ka, na, ny, ny, "ka")
    kb_r = as_entry_counts(kb, nb, ny, nu, "kb")
    st = MimoStructure(na, nb, ka_r, kb_r, ny, nu, d0.w0, d0.ts)
    if isinstance(lines, (list, tuple)) and len(datas) > 1 and len(lines) == len(datas) and all(
            v is None or isinstance(v, str) or np.ndim(v) == 1 for v in lines):
        per = list(lines)
    else:
        per = [lines] * len(datas)
    rows_list = [_rows_of(d, v, st.K, e) for e, (d, v) in enumerate(zip(datas, per))]
    # the record's transient term (METHOD.md section 20, eq. 20.5): fitted on the record's
    # statistics, where a disturbance that passes through the system was found or asked for
    if transient is True and transient_orders(st).size == 0:
        raise ValueError("transient: na = nb = 0 has no transient term (a static system's record holds none)")
    tr = Transient(st, len(datas)) if (transient is True or (transient == "auto" and route.startswith("full")
                                                              and transient_orders(st).size)) else None
    n_tr = 0 if tr is None else tr.n_parameters
    low = [int(r[r <= st.K][0]) for r in rows_list if np.any(r <= st.K)]
    if low and method == "sml" and noise_route_noisy(datas):
        raise ValueError(f"lines: line {low[0]} is a row l <= K = {st.K}, which reads line 0 and the conjugates of "
                         "lines 1..K-l, whose noise is not circular; method='sml' for several channels weighs the rows "
                         "by the circular complex likelihood, which such rows do not have: give rows from "
                         f"{st.K + 1}, or use method='wgtls' (its residue covariance and sandwich take them)")
    n_eq = sum(2 * r.size * ny for r in rows_list)
    if n_eq < st.free.size + n_tr:
        raise ValueError(f"lines: {n_eq // 2} complex residues cannot determine {st.free.size} free real parameters"
                         + (f" and the {n_tr} of the record's transient" if n_tr else ""))
    P = np.array([d.periods for d in datas])
    noisy = noise_route_noisy(datas)
    # the periods the (co)variances are worth: P, or 1 + dof / 2 of the moderated ones (the
    # median over the inner lines for the covariance's factor, each row's own for its tests)
    Pcov = P if mos is None else np.array([max(int(d.periods), int(round(1.0 + float(np.median(m.dof[1:-1])) / 2.0)))
                                           for d, m in zip(datas, mos)])
    if noisy and ny > 1 and P.min() <= ny:
        raise ValueError(f"u, y: P = {int(P.min())} periods give residue covariances of rank at most P - 1 < ny = "
                         f"{ny} (complex Wishart, METHOD.md section 19): several outputs need P > ny periods")
    if tr is None:
        data, cst = core_data(datas, rows_list), core_structure(st)
    else:
        data, cst = tr.data(datas, rows_list), tr.structure()
    warns = []
    try:
        xi, iters, converged, sv, noise_free, cost_sml, free_cov, res, Ce = fit(
            data, cst, method, tol=tol, max_iter=max_iter, covariance=covariance == "analytic")
    except FitError as err:
        raise ValueError(f"u, y: {err}") from None
    xi_core, t_coef = xi, None
    if tr is not None:
        xi, free_cov, t_coef = tr.reduce(xi, free_cov)
    if noisy:
        warns += silent_outputs(datas, rows_list)
    d = ny * ny
    if sv.size > d and sv[d] < 1.5 * sv[d - 1]:
        warns.append(f"the model is nearly unidentifiable: the generalised singular value {d + 1} is "
                     f"{sv[d] / sv[d - 1]:.3g} times value {d} (harmonic counts or orders too high, or a "
                     "common periodic left factor)")
    n_scalar = res.size
    if cost_sml is not None:
        cost = cost_sml / n_scalar
    elif noise_free:
        cost = 0.0
    else:
        q = np.real(np.einsum("rp,rp->r", res.conj(), np.linalg.solve(Ce, res[..., None])[..., 0]))
        cost = float(np.sum(q)) / n_scalar
    cov, factor = None, 1.0
    if free_cov is not None:
        Pmin = int(Pcov.min())
        # (P-1)/(P-3) for every ny, calibrated by Monte Carlo (METHOD.md section 19): the
        # (P-1)/(P-2-ny) of the Wishart argument over-covers at ny = 2 (97.7 % at P = 8)
        if Pmin >= 4:
            factor = (Pmin - 1.0) / (Pmin - 3.0)
        else:
            warns.append(f"the covariance is without its small-sample factor (P - 1) / (P - 3): P = {Pmin} "
                         "periods, at least 4 needed")
        cov = factor * expand(free_cov, st)
    for msg in warns:
        warnings.warn(msg, UserWarning, stacklevel=3)
    if lead is None:      # the normalised entries exactly (the core sets them through A_na,0^-1)
        fixed = np.setdiff1d(np.arange(xi.size), st.free)
        xi = xi.copy()
        xi[fixed] = np.round(xi[fixed])
    xi_fit = xi
    if tr is not None:
        xi_fit = xi_core.copy()
        xi_fit[tr.keep] = xi
    if lead is not None:
        # the model with A_na,0 = M is M times the one with A_na,0 = I (the same system)
        Kx = np.kron(lead, np.eye(st.n_row))
        xi = Kx @ xi
        cov = None if cov is None else Kx @ cov @ Kx.T
        res = res @ lead.T
        Ce = np.einsum("pi,rij,qj->rpq", lead, Ce, lead)
    a, b = st.coefficients(xi)
    model = MimoModel(a, b, w0=d0.w0, ts=d0.ts)
    if cov is not None:
        model.covariance, model.eta_names = cov, tuple(st.names)
    if mos is None:
        row_P = np.concatenate([np.full(r.size, p) for r, p in zip(rows_list, P)])
        Cv = Ce
    else:
        # the verdict divides by the moderated covariances with the prior's part at the
        # neighbours' mean itself (section 7, "The verdict's scale"), each row worth its line's dof
        row_P = np.concatenate([m.periods[r] for r, m in zip(rows_list, mos)])
        unbiased = [m.unbiased_data() for m in mos]
        _, Cv = residues(core_data(unbiased, rows_list) if tr is None else tr.data(unbiased, rows_list), cst, xi_fit)
        if lead is not None:
            Cv = np.einsum("pi,rij,qj->rpq", lead, Cv, lead)
    # rows l <= K read line 0 or a conjugate line: residues that are not circular, which the F
    # tests assume; they are fitted but not judged (as for one channel)
    row_lines = np.concatenate(rows_list)
    judged = np.flatnonzero(row_lines > st.K)
    tests = () if noise_free else tuple((int(judged[r]),) + t[1:] for t in residue_tests(res[judged], Cv[judged],
                                                                                      row_P[judged])
                                        for r in (t[0],))
    return MimoIdentificationResult(
        model=model, method=method, eta=xi, parameter_names=st.names, covariance=cov, converged=bool(converged),
        cost=float(cost), lines=np.concatenate(rows_list), experiment=np.concatenate(
            [np.full(r.size, e) for e, r in enumerate(rows_list)]), residue=res, residue_covariance=Ce,
        periods=tuple(int(p) for p in P), iterations=int(iters), singular_values=np.asarray(sv),
        n_free_parameters=int(st.free.size), noise_free=bool(noise_free), covariance_factor=float(factor),
        warnings=tuple(warns), tests=tests, noise=route, noise_choice=choice, moderation=tuple(mos or ()),
        transient=t_coef, transient_powers=None if tr is None else tuple(int(m) for m in tr.orders))


def as_transient(transient):
    """'auto', True or False (``transient=`` of :func:`lptv.identify`), else a ValueError."""
    if isinstance(transient, (bool, np.bool_)):
        return bool(transient)
    if isinstance(transient, str) and transient == "auto":
        return "auto"
    raise ValueError(f"transient must be 'auto', True or False, got {transient!r}")


@dataclass(frozen=True)
class MimoCramerRaoBound:
    """What :func:`mimo_crb` returns."""

    covariance: np.ndarray
    """The bound on the covariance of ``eta`` (zero rows and columns for the normalised entries)."""
    eta: np.ndarray
    """The true parameters, normalised to A_na,0 = I."""
    parameter_names: Tuple[str, ...]
    """The names of ``eta``'s entries (also as ``eta_names``)."""

    @property
    def eta_names(self) -> Tuple[str, ...]:
        """The names of ``eta``'s entries: the same tuple as ``parameter_names`` (the name
        :class:`lptv.CramerRaoBound` gives it; either works on either bound)."""
        return self.parameter_names

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))


def mimo_crb(model: MimoModel, inputs, *, noise, periods: int, lines=None, ka=None, kb=None) -> MimoCramerRaoBound:
    """Cramer-Rao bound of a MIMO design (METHOD.md eq. 19.15): F = sum_e 2 Re(J0^H C_E^-1 J0).

    Parameters
    ----------
    model : MimoModel
        The true system (continuous or discrete time); normalised here to A_na,0 = I.
    inputs : array_like, shape (E, L+1, nu) or (L+1, nu)
        The experiments' one-sided input spectra on lines 0..L (``fft(u)[l] / N`` per input).
    noise : array_like, shape (ny+nu,), (L+1, ny+nu) or (L+1, ny+nu, ny+nu)
        The (co)variance of ONE period's spectrum per channel (outputs first): white noise of
        standard deviation s with N samples per period gives ``s**2 / N``; a 3-D array is the full
        covariance per line.
    periods : int
        P: the means' covariance is ``noise / P``.
    lines : sequence of int, optional
        The rows (default K+1 .. L-K, as :func:`lptv.identify`).
    ka, kb :
        The structure (default: the model's own harmonic counts, one per order and column).

    Examples
    --------
    >>> import numpy as np, lptv
    >>> a = np.zeros((2, 2, 2)); a[1] = np.eye(2); a[0] = [[2.0, 0.5], [0.0, 3.0]]
    >>> m = lptv.MimoModel(a, np.ones((1, 2, 1)), w0=0.1)
    >>> U = lptv.multisine(range(1, 40), 128, seed=0).spectrum[:, None]
    >>> bound = lptv.mimo_crb(m, U, noise=[1e-6, 1e-6, 1e-8], periods=8)
    >>> bound.std.shape == bound.eta.shape
    True
    """
    if not isinstance(model, MimoModel):
        raise ValueError(f"model must be an lptv.MimoModel, got {type(model).__name__}")
    U = _array(inputs, "inputs")
    if U.ndim == 2:
        U = U[None]
    if U.ndim != 3 or U.shape[2] != model.n_inputs:
        raise ValueError(f"inputs must have shape (E, L+1, nu = {model.n_inputs}) or (L+1, nu), got {np.shape(inputs)}")
    U = U.astype(complex)
    check_finite(U, "inputs")
    periods = as_int(periods, "periods", minimum=1)
    ny, nu = model.n_outputs, model.n_inputs
    c = ny + nu
    Nz = _array(noise, "noise")
    L1 = U.shape[1]
    if Nz.ndim == 1 and Nz.shape == (c,):
        C = np.broadcast_to(np.diag(Nz.astype(complex)), (L1, c, c))
    elif Nz.ndim == 2 and Nz.shape == (L1, c):
        C = np.einsum("lc,cd->lcd", Nz.astype(complex), np.eye(c))
    elif Nz.ndim == 3 and Nz.shape == (L1, c, c):
        C = Nz.astype(complex)
    else:
        raise ValueError(f"noise must have shape ({c},), ({L1}, {c}) or ({L1}, {c}, {c}), got {Nz.shape}")
    check_finite(C, "noise")
    if np.any(np.real(np.diagonal(C, axis1=1, axis2=2)) < 0):
        raise ValueError("noise must hold non-negative variances, got a negative one")
    from ..simulation.fds import simulate

    ka = model.a.shape[3] // 2 if ka is None else ka
    kb = model.b.shape[3] // 2 if kb is None else kb
    st = MimoStructure(model.na, model.nb, as_entry_counts(ka, model.na, ny, ny, "ka"),
                       as_entry_counts(kb, model.nb, ny, nu, "kb"), ny, nu, model.w0, model.ts)
    A0 = np.real(model.a[model.na, :, :, model.a.shape[3] // 2])
    try:
        P0 = np.linalg.inv(A0)
    except np.linalg.LinAlgError:
        raise ValueError("model: the mean of its leading matrix A_na is singular (the normalisation A_na,0 = I "
                         "needs it invertible)") from None
    an = np.einsum("pj,njqk->npqk", P0, model.a)
    bn = np.einsum("pj,njrk->nprk", P0, model.b)
    xi = st.xi_of(an, bn)
    datas, rows_list = [], []
    for e in range(U.shape[0]):
        Y = np.asarray(simulate(model, U[e], lines_out=L1 - 1))
        Y = Y.reshape(L1, ny)
        d = MimoFrequencyData(U=U[e], Y=Y, C=np.array(C) / periods, periods=periods, w0=model.w0, ts=model.ts)
        datas.append(d)
        rows_list.append(_rows_of(d, lines, st.K, e))
        if rows_list[-1][0] <= st.K:
            raise ValueError(f"lines: line {int(rows_list[-1][0])} is a row l <= K = {st.K}, which reads line 0 and "
                             "conjugate lines, whose noise is not circular; the bound for several channels is that of "
                             f"the circular complex likelihood: give rows from {st.K + 1}")
    F = fisher(core_data(datas, rows_list), core_structure(st), xi)
    return MimoCramerRaoBound(covariance=expand(np.linalg.inv(F), st), eta=xi, parameter_names=st.names)
