"""Choosing the structure: orders and harmonic count from the data (METHOD.md section 13)."""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Optional, Tuple

import numpy as np

from .._validate import as_int, as_positive_float, as_str
from .executors import describe_executor, one_blas_thread, require, run_tasks
from ..spectra.frequency_data import FrequencyData, frequency_data_of
from ..estimation.identify import IdentificationResult, _rows, excited_rows, identify
from ..spectra.htf_estimate import HtfEstimate, htf_estimate

CRITERIA = ("mdl", "aic")
# Columns of the ranked table, in order.
COLUMNS = ("rank", "na", "nb", "k", "n_free_parameters", "method", "V", "aic", "mdl", "verdict", "model_ok",
           "residue_ok", "fraction_above_0db", "converged", "nearly_unidentifiable", "V_wgtls", "error",
           "model_errors", "warnings")
# The verdict column's words: lptv.identify's verdict of the candidate (IdentificationResult.verdict).
VERDICTS = ("consistent", "MODEL ERRORS", "NOT DETERMINED", "failed")
# The HTF guide estimates at most this many branches each side.
MAX_GUIDE_BRANCHES = 10


@dataclass(frozen=True, eq=False)
class SelectionResult:
    """What :func:`select` returns: the ranked candidates and the chosen structure."""

    rows: Tuple[dict, ...] = field(repr=False)
    """One dict per candidate (keys ``COLUMNS``), best first: sorted by (the verdict finds no
    model error, refined by SML, the criterion, the number of parameters); failed fits last.
    ``verdict`` is the verdict :func:`lptv.identify` gives the candidate's fit ('consistent',
    'MODEL ERRORS', 'NOT DETERMINED'), ``model_errors`` its reasons."""
    choice: Tuple[int, int, int]
    """(na, nb, k) of the first row."""
    result: IdentificationResult = field(repr=False)
    """The chosen structure's fit (SML when refined, else WGTLS), with its covariance."""
    criterion: str
    lines: np.ndarray = field(repr=False)
    """The rows of every fit (the default ones of the largest k in the grid)."""
    correction: float
    """c = (P-1)/(P-2): the penalties are multiplied by it (noise variances from P periods)."""
    choice_ok: bool
    """False when the verdict finds model errors in every candidate (the choice is then only the
    least bad)."""
    htf: Optional[HtfEstimate] = field(default=None, repr=False)
    """The nonparametric HTF the harmonic count is guided by (None if the excitation is too dense)."""
    htf_harmonics: Optional[int] = None
    """The highest branch |k| of ``htf`` that stands above the noise (None without a guide)."""
    warnings: Tuple[str, ...] = ()
    executor: str = ""
    elapsed: float = 0.0

    def table(self):
        """The ranked rows as a pandas DataFrame (``pip install 'lptv[batch]'``)."""
        pd = require("pandas", "SelectionResult.table")
        return pd.DataFrame(list(self.rows), columns=list(COLUMNS))

    def summary(self, top: int = 10) -> str:
        """The first ``top`` rows of the ranking, the choice and the warnings, as text."""
        top = as_int(top, "top", minimum=1)
        out = [f"{'rank':>4} {'na':>3} {'nb':>3} {'k':>3} {'n':>4} {'method':>6} {'V':>11} "
               f"{'aic':>11} {'mdl':>11} {'>0dB':>6}  verdict"]
        for r in self.rows[:top]:
            if r["error"]:
                out.append(f"{r['rank']:4d} {r['na']:3d} {r['nb']:3d} {r['k']:3d}  failed: {r['error']}")
                continue
            flag = r["verdict"]
            if r["nearly_unidentifiable"] and r["verdict"] != "NOT DETERMINED":
                flag += ", nearly unidentifiable"
            out.append(f"{r['rank']:4d} {r['na']:3d} {r['nb']:3d} {r['k']:3d} {r['n_free_parameters']:4d} "
                       f"{r['method']:>6} {r['V']:11.5g} {r['aic']:11.5g} {r['mdl']:11.5g} "
                       f"{100 * r['fraction_above_0db']:5.1f}%  {flag}")
        if len(self.rows) > top:
            out.append(f"... {len(self.rows) - top} more")
        na, nb, k = self.choice
        out.append(f"choice ({self.criterion.upper()}): na = {na}, nb = {nb}, k = {k}"
                   + ("" if self.choice_ok else "  (the verdict rejects EVERY candidate)"))
        if self.htf_harmonics is not None:
            out.append(f"nonparametric HTF: branches up to |k| = {self.htf_harmonics} stand above the noise "
                       f"(tested up to {self.htf.branches})")
        out += [f"warning: {w}" for w in self.warnings]
        return "\n".join(out)


def _grid_values(v, name):
    if np.ndim(v) == 0:
        return [as_int(v, name)]
    try:
        vals = [as_int(x, name) for x in v]
    except TypeError:
        raise ValueError(f"{name} must be a non-negative integer or a range of them, got {v!r}") from None
    if not vals:
        raise ValueError(f"{name} must hold at least one value")
    if len(set(vals)) != len(vals):
        raise ValueError(f"{name}: a value is given twice in {vals}")
    return sorted(vals)


def _guide(data: FrequencyData, alpha: float):
    """The HTF branches at the largest Kh the excitation allows: (estimate, highest significant |k|, note)."""
    try:
        e0 = htf_estimate(data, branches=0)
    except ValueError as e:
        return None, None, f"no HTF guide for the harmonic count: {' '.join(str(e).split())}"
    lines = np.sort(e0.lines)
    gap = int(np.min(np.diff(lines))) if lines.size > 1 else 2 * MAX_GUIDE_BRANCHES + 1
    kh = min((gap - 1) // 2, int(lines[0]) - 1, data.max_line - int(lines[-1]), MAX_GUIDE_BRANCHES)
    if kh < 1:
        return None, None, (f"no HTF guide for the harmonic count: the excited lines are {gap} apart "
                            f"(from line {int(lines[0])}); branches k != 0 need lines at least 3 apart, "
                            "above line 1")
    est = htf_estimate(data, branches=kh, excited=lines)
    sig = est.significant(alpha)
    return est, int(np.max(np.abs(sig))) if sig.size else 0, ""


def _penalties(n, n_rows, c):
    """(AIC, MDL) penalties of n free parameters on n_rows complex rows, scaled by c."""
    return 2.0 * c * n, c * n * math.log(2 * n_rows)


def _data_of(shared) -> FrequencyData:
    return FrequencyData(shared["U"], shared["Y"], shared["varU"], shared["varY"], shared["covYU"],
                         w0=shared["w0"], ts=shared["ts"], periods=shared["periods"])


def _fit(shared, na, nb, k, method, covariance="analytic"):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = identify(_data_of(shared), na=na, nb=nb, ka=k, kb=k, lines=shared["lines"], method=method,
                       tol=shared["tol"], max_iter=shared["max_iter"], covariance=covariance)
    extra = tuple(str(w.message) for w in caught if str(w.message) not in res.warnings)
    return res, tuple(res.warnings) + extra


def fit_structure(item, shared) -> dict:
    """One candidate (the task :func:`select` sends out): fit (na, nb, k) by ``method``, score it."""
    na, nb, k, method = item
    # the score reads the cost and the residues, never the covariance: the chosen structure is
    # fitted again with it at the end
    res, warns = _fit(shared, na, nb, k, method, covariance="none")
    n_rows = res.lines.size
    if method == "sml":
        V = 2.0 * n_rows * float(res.cost)          # the exact cost (METHOD.md eq. 17)
    else:
        V = 2.0 * float(np.sum(res.normalized_residue ** 2))   # its diagonal approximation
    n = int(res.n_free_parameters)
    p_aic, p_mdl = _penalties(n, n_rows, shared["c"])
    errors = tuple(res.model_errors)
    verdict = "MODEL ERRORS" if errors else ("NOT DETERMINED" if res.undetermined is not None else "consistent")
    return dict(na=na, nb=nb, k=k, n_free_parameters=n, method=method, V=V, aic=V + p_aic, mdl=V + p_mdl,
                verdict=verdict, model_ok=not errors,
                residue_ok=bool(res.residue_ok), fraction_above_0db=float(res.fraction_above_0db),
                converged=bool(res.converged), nearly_unidentifiable=bool(res.nearly_unidentifiable),
                error="", model_errors="; ".join(errors), warnings="; ".join(warns))


def _failed(item, failure) -> dict:
    na, nb, k, method = item
    return dict(na=na, nb=nb, k=k, n_free_parameters=0, method=method, V=math.inf, aic=math.inf,
                mdl=math.inf, verdict="failed", model_ok=False, residue_ok=False, fraction_above_0db=math.nan,
                converged=False, nearly_unidentifiable=False, error=failure.message, model_errors="",
                warnings="")


def _key(criterion):
    return lambda r: (bool(r["error"]), not r["model_ok"], r["method"] != "sml", r[criterion],
                      r["n_free_parameters"], r["na"], r["nb"], r["k"])


MAX_GRID = 2000
"""The most structures :func:`select` fits in one call: at a few ms to a few hundred ms per fit
(more for high orders), larger grids run for hours; a grid above it is refused before any fit."""


def select(u, y=None, *, na, nb, k=None, w0: Optional[float] = None, ts: Optional[float] = None,
           lines=None, criterion: str = "mdl", refine: int = 2, alpha: float = 1e-3, tol: float = 1e-10,
           max_iter: int = 50, executor="processes", workers: Optional[int] = None,
           progress=None) -> SelectionResult:
    """Choose the orders and the harmonic count: fit a grid of structures, score them, rank them.

    Every structure (na, nb, k) of the grid (k harmonics on every coefficient; k = 0 is LTI) is
    fitted by WGTLS on the same rows and scored; the ``refine`` best are fitted again by the
    exact likelihood (``method='sml'``) and scored on its cost. The score (METHOD.md section 13):

    - V, the cost in chi-square units: for SML ``V = 2 |R| res.cost`` = r^T S^-1 r (eq. 17),
      about chi2(2|R| - n) at the true structure with known noise variances; for WGTLS the
      diagonal version 2 sum_l |e_l|^2 / var e_l (rows treated as independent);
    - AIC = V + 2 c n and MDL = V + c n ln(2|R|), n the free real parameters, 2|R| the real
      equations (the forms Pintelon and Schoukens give for frequency-domain maximum likelihood
      costs, System Identification: A Frequency Domain Approach, 2nd ed., 2012, on model
      selection), with c = (P-1)/(P-2) when the noise variances come from P > 2 periods: the
      sample variances inflate V, and each parameter's decrease of it, by about c (eq. 17 with
      F(2, 2(P-1)) instead of Exp(1) terms), so the penalties are scaled alike (c = 1 otherwise).
      MDL (the default) is consistent: an unneeded parameter lowers V by about c chi2(1) and
      costs c ln(2|R|) (6 to 7 for a few hundred rows); AIC's 2 c lets an unneeded group of d
      parameters in with probability P(chi2(d) > 2d) (3 % for d = 10) however long the record;
    - the verdict (``IdentificationResult.model_ok``, what :func:`lptv.identify` says of the
      candidate's fit: its residue tests, cost and prediction error): a structure it rejects is
      never chosen while another passes. The ranking is by (passes, refined by SML, criterion, n).

    The rows are those of the largest k in the grid (k_max + 1 .. Lmax - k_max), or ``lines``
    (``'excited'``: the excited lines and those within +-k_max of them, :func:`lptv.identify`'s):
    criteria compare costs on the same equations only. The nonparametric HTF
    (:func:`lptv.htf_estimate`, at the largest branch count the excitation allows) guides the
    harmonic count: without ``k`` the grid is k = 0 .. the highest branch above the noise.

    Parameters
    ----------
    u, y : array_like, shape (P, N)
        Steady-state periods (or a :class:`lptv.FrequencyData` as ``u``).
    na, nb, k : int or sequence of int
        The orders and harmonic counts to try (e.g. ``range(1, 4)``). ``k=None``: from the HTF.
        At most :data:`MAX_GRID` (2000) structures in all.
    w0, ts : float
        Fundamental (rad/s); sample period for discrete time.
    lines : sequence of int or 'excited', optional
        Rows of every fit (default: those of the largest k; 'excited': the input's excited lines
        and their neighbours within +-k_max, the same for every candidate).
    criterion : {'mdl', 'aic'}
    refine : int
        How many of the best WGTLS candidates (those passing the residue test first) are refitted
        by SML (0: rank on WGTLS alone).
    alpha : float
        Significance level of the HTF branches (:meth:`lptv.HtfEstimate.significant`).
    tol, max_iter :
        As for :func:`lptv.identify`.
    executor, workers, progress :
        As for :func:`lptv.batch.run_tasks` ('processes' by default, 'serial', a Dask scheduler
        address or client); the progress bar shows on a terminal.

    Returns
    -------
    SelectionResult
        ``rows`` ranked, ``choice`` (na, nb, k), ``result`` its fit, ``summary()``, ``table()``.
        Warns (and says in ``warnings``) when the verdict rejects every candidate.

    Examples
    --------
    >>> import lptv
    >>> from lptv.examples import paper_measurements
    >>> m = paper_measurements(seed=1, periods=8)
    >>> sel = lptv.select(m["u"], m["y"], w0=m["w0"], na=[1, 2], nb=[1], k=[2, 3, 4],
    ...                   lines=range(1, 244), executor="serial")
    >>> sel.choice, sel.choice_ok
    ((2, 1, 3), True)
    """
    t_start = time.perf_counter()
    criterion = as_str(criterion, "criterion", CRITERIA)
    refine = as_int(refine, "refine")
    alpha = as_positive_float(alpha, "alpha")
    if not alpha < 1:
        raise ValueError(f"alpha must lie in (0, 1), got {alpha!r}")
    tol = as_positive_float(tol, "tol")
    max_iter = as_int(max_iter, "max_iter")
    na_list, nb_list = _grid_values(na, "na"), _grid_values(nb, "nb")
    data = frequency_data_of(u, y, w0, ts)
    est, k_htf, note = _guide(data, alpha)
    notes = [note] if note else []
    if k is None:
        if k_htf is None:
            raise ValueError(f"k: give the harmonic counts to try ({note})")
        k_list = list(range(0, k_htf + 1))
    else:
        k_list = _grid_values(k, "k")
    if est is not None and k_htf == est.branches:
        notes.append(f"every HTF branch up to |k| = {k_htf} (the most this excitation can separate) stands "
                     "above the noise: the data do not bound the harmonic count from above (a time-varying "
                     "denominator has branches beyond k)")
    size = len(na_list) * len(nb_list) * len(k_list)
    if size > MAX_GRID:
        raise ValueError(f"na, nb, k: the grid holds {size} structures ({len(na_list)} na x {len(nb_list)} nb x "
                         f"{len(k_list)} k), more than lptv.selection.MAX_GRID = {MAX_GRID}: narrow the ranges "
                         "(the HTF estimate and a first coarse grid tell where to look)")
    k_max = max(k_list)
    if lines is None:
        rows = list(range(k_max + 1, data.max_line - k_max + 1))
        if not rows:
            raise ValueError(f"k: the largest k ({k_max}) leaves no rows in lines 0..{data.max_line}")
    elif isinstance(lines, str):
        if lines != "excited":
            raise ValueError(f"lines must be a sequence of integers or 'excited', got {lines!r}")
        rows = [int(x) for x in excited_rows(data, k_max)]
    else:
        rows = _rows(lines)
    P = data.periods
    c = (P - 1) / (P - 2) if P > 2 else 1.0
    shared = dict(U=data.U, Y=data.Y, varU=data.varU, varY=data.varY, covYU=data.covYU, w0=data.w0,
                  ts=data.ts, periods=P, lines=rows, tol=tol, max_iter=max_iter, c=c)
    grid = [(a, b, kk, "wgtls") for a in na_list for b in nb_list for kk in k_list]
    label = describe_executor(executor, workers)
    # executor="processes": both stages on the process pool kept between calls (lptv.batch.warm)
    scored, ranked = _rank(grid, k_list, shared, criterion, refine, executor, workers, progress)
    top = ranked[0]
    choice = (top["na"], top["nb"], top["k"])
    choice_ok = bool(top["model_ok"])
    if not choice_ok:
        notes.insert(0, f"the verdict rejects EVERY candidate: the choice na = {choice[0]}, nb = {choice[1]}, "
                     f"k = {choice[2]} is only the least bad by {criterion.upper()}; widen the grid "
                     "(orders, harmonics) or check the data")
        warnings.warn(notes[0], UserWarning, stacklevel=2)
    if k_htf is not None and choice[2] > k_htf:
        notes.append(f"the chosen k = {choice[2]} exceeds the highest HTF branch above the noise ({k_htf})")
    restore = one_blas_thread()      # the same rounding as the tasks
    try:
        res, _ = _fit(shared, *choice, top["method"])
    finally:
        restore()
    return SelectionResult(rows=ranked, choice=choice, result=res, criterion=criterion,
                           lines=np.asarray(rows), correction=c, choice_ok=choice_ok, htf=est,
                           htf_harmonics=k_htf, warnings=tuple(notes), executor=label,
                           elapsed=time.perf_counter() - t_start)


def _rank(grid, k_list, shared, criterion, refine, executor, workers, progress):
    """WGTLS on the grid, SML on the shortlist; (scored rows, ranked rows)."""
    out = run_tasks(fit_structure, grid, shared, executor=executor, workers=workers, progress=progress,
                    desc="select: WGTLS", unit="fit")
    scored = [r if isinstance(r, dict) else _failed(item, r) for item, r in zip(grid, out)]
    if all(r["error"] for r in scored):
        raise ValueError(f"every structure failed to fit; the first: {scored[0]['error']}")
    for r in scored:
        r["V_wgtls"] = r["V"]
    if refine:
        # the shortlist per harmonic count (those the verdict passes first): the diagonal WGTLS
        # cost ignores the correlation of rows that share lines, which grows with k, and drops far
        # more than the exact cost when k is overestimated; its scores are compared within one k only
        ordered = [r for r in sorted(scored, key=_key(criterion)) if not r["error"]]
        best = [r for kk in k_list for r in [r for r in ordered if r["k"] == kk][:refine]]
        items = [(r["na"], r["nb"], r["k"], "sml") for r in best]
        out = run_tasks(fit_structure, items, shared, executor=executor, workers=workers, progress=progress,
                        desc="select: SML", unit="fit")
        for item, r, w in zip(items, out, best):
            new = r if isinstance(r, dict) else _failed(item, r)
            new["V_wgtls"] = w["V"]
            scored[scored.index(w)] = new
    ranked = sorted(scored, key=_key(criterion))
    return scored, tuple({"rank": i + 1, **{c_: r[c_] for c_ in COLUMNS if c_ != "rank"}}
                         for i, r in enumerate(ranked))
