"""The result of a fit with several inputs and outputs and its verdict (METHOD.md section 19,
eq. 19.14): each row's normalised vector residue, judged per output against F(2, 2(P-1)) and
jointly against F(2 ny, 2(P - ny)), the p-values of all rows and tests combined by Holm's
method at ALPHA."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Tuple

import numpy as np

from .._validate import as_positive_float
from ..model.mimo import MimoModel

ALPHA = 0.01
"""Overall size of the residue tests (Holm's combination), as for one input and output."""


@dataclass(frozen=True)
class MimoIdentificationResult:
    """What :func:`lptv.identify` returns for data of several inputs or outputs.

    ``eta`` holds the real parameters of every output's row (``parameter_names``: 'a2[0,1].re0'
    is Re of harmonic 0 of entry (0, 1) of A_2; '.re1', '.im1' harmonic 1), the normalised
    entries Re a_{na,pp,0} = 1 and Re a_{na,pq,0} = 0 included with zero variance.
    """

    model: MimoModel
    method: str
    eta: np.ndarray
    parameter_names: Tuple[str, ...]
    covariance: Optional[np.ndarray]
    """Covariance of ``eta`` (None for covariance='none' or noise-free data)."""
    converged: bool
    cost: float
    """Mean normalised squared residue: e^H C_E^-1 e (SML) or sum_l e_l^H C_{e,l}^-1 e_l (WGTLS) over
    the number of scalar residues (about 1 for a right model)."""
    lines: np.ndarray
    """The rows (lines) of the fit, over all experiments."""
    experiment: np.ndarray
    """The experiment of each row."""
    residue: np.ndarray
    """e_l on each row, shape (rows, ny)."""
    residue_covariance: np.ndarray
    """C_{e,l} (eq. 19.12) on each row, shape (rows, ny, ny)."""
    periods: Tuple[int, ...]
    iterations: int
    singular_values: np.ndarray
    """WGTLS's generalised singular values, ascending (the first ny^2 belong to the equivalent models)."""
    n_free_parameters: int
    noise_free: bool
    covariance_factor: float
    """The small-sample factor the covariance holds ((P-1)/(P-3), 1 when left out)."""
    warnings: Tuple[str, ...] = ()
    tests: Tuple = field(default=(), repr=False)
    """(row index, output or -1 for the joint test, statistic, p-value) of each residue test."""
    noise: str = "sample"
    """The noise (co)variances the fit weighed by: 'sample' (each line's own), 'moderated'
    (combined with the neighbouring lines', METHOD.md section 19), or 'full' and
    'full-moderated' (the same two from the whole record's bins, METHOD.md section 20)."""
    noise_choice: str = ""
    """Why: 'asked for', or the smoothness check's sentence for noise='auto'."""
    moderation: Tuple = field(default=(), repr=False)
    """The :class:`lptv.mimo_moderation.MimoModeratedNoise` of each experiment (moderated route)."""
    transient: Optional[np.ndarray] = field(default=None, repr=False)
    """The record's transient term fitted with the model (METHOD.md section 20, eq. 20.5), its
    real coefficients c[e, p, j] of experiment e, output p and power ``transient_powers[j]`` of
    s (continuous time) or z (discrete time); None when the fit had none (``transient=False``,
    or 'auto' on the periods' statistics)."""
    transient_powers: Optional[Tuple[int, ...]] = None
    """The powers of s or z of :attr:`transient`'s last axis."""

    @property
    def transient_note(self) -> str:
        """One sentence on the transient term: fitted (how many coefficients) or not."""
        if self.transient is None:
            return "the record's transient term: not fitted"
        E, ny, n = self.transient.shape
        var = "z" if self.model.ts else "s"
        pw = ", ".join(f"{var}^{m}" for m in self.transient_powers)
        return (f"the record's transient term fitted ({pw}; {E * ny * n} real coefficients, "
                f"per output and experiment: METHOD.md section 20)")

    @property
    def n_inputs(self) -> int:
        return self.model.n_inputs

    @property
    def n_outputs(self) -> int:
        return self.model.n_outputs

    @property
    def eta_names(self) -> Tuple[str, ...]:
        return self.parameter_names

    @property
    def parameter_std(self) -> Optional[np.ndarray]:
        """Standard deviation of each entry of ``eta`` (None without a covariance)."""
        return None if self.covariance is None else np.sqrt(np.diag(self.covariance))

    def confidence_interval(self, level: float = 0.95) -> np.ndarray:
        """Two-sided intervals ``eta +- z std``, array (n_eta, 2); z the normal quantile of ``level``.

        Examples
        --------
        >>> import numpy as np, lptv
        >>> from lptv.examples.mimo import small_fit
        >>> res = small_fit()
        >>> res.confidence_interval(0.95).shape == (res.eta.size, 2)
        True
        """
        from .._dist import norm_ppf

        level = as_positive_float(level, "level")
        if not 0.0 < level < 1.0:
            raise ValueError(f"level must be in (0, 1), got {level!r}")
        if self.covariance is None:
            raise ValueError("no covariance: the fit was made with covariance='none' or on noise-free data")
        half = norm_ppf(0.5 + level / 2.0) * self.parameter_std
        return np.column_stack([self.eta - half, self.eta + half])

    @property
    def rejected(self) -> Tuple:
        """The residue tests Holm's method rejects at ALPHA."""
        if not self.tests:
            return ()
        p = np.array([t[3] for t in self.tests])
        order = np.argsort(p)
        m = p.size
        out = []
        for rank, i in enumerate(order):
            if p[i] > ALPHA / (m - rank):
                break
            out.append(self.tests[i])
        return tuple(out)

    @property
    def model_errors(self) -> list:
        """One sentence per rejected residue test (empty: the residues are consistent with the noise)."""
        out = []
        for r, p, stat, pv in self.rejected[:10]:
            where = f"line {int(self.lines[r])}" + (f" of experiment {int(self.experiment[r])}"
                                                    if self.experiment.max(initial=0) > 0 else "")
            who = "all outputs jointly" if p < 0 else f"output {p}"
            out.append(f"{who}: the residue on {where} is too large for the noise (p = {pv:.2g}; "
                       f"Holm at {ALPHA:g} over {len(self.tests)} tests)")
        extra = len(self.rejected) - 10
        if extra > 0:
            out.append(f"and {extra} more rejected residue tests")
        return out

    @property
    def model_ok(self) -> Optional[bool]:
        """True when no residue test rejects the model, None without noise statistics."""
        if self.noise_free or not self.tests:
            return None
        return not self.rejected

    @property
    def undetermined(self) -> Optional[str]:
        """Why the data do not determine the model or give no verdict (None when they do), as
        :attr:`lptv.IdentificationResult.undetermined`: no noise statistics (noise-free data or
        P < 2), a fit that did not converge, an output that does not respond to the inputs
        (:func:`lptv.estimation.mimo_identify.silent_outputs`), or the identifiability warning (the
        generalised singular value ny^2 + 1 within 1.5 times value ny^2: a second parameter
        direction explains the data nearly as well)."""
        if self.noise_free or not self.tests:
            return "the data carry no noise statistics (noise-free or P < 2): the residues cannot be judged"
        for w in self.warnings:
            if "does not respond" in w:
                return "the data do not determine the model: " + w
        if not self.converged:
            return (f"the fit did not converge in {self.iterations} iterations: the estimate is not a minimum of the "
                    "cost, so its residues cannot vouch for the model (more iterations, another start, or fewer "
                    "parameters)")
        for w in self.warnings:
            if "nearly unidentifiable" in w:
                return "the data do not determine the model: " + w.split(": ", 1)[-1]
        return None

    @property
    def verdict(self) -> str:
        """One sentence in the words of :attr:`lptv.IdentificationResult.verdict`: 'the model is
        consistent with the noise: ...', 'MODEL ERRORS: the model is rejected: ...' or 'NOT
        DETERMINED: ...'."""
        if self.model_ok is None:
            return "NOT DETERMINED: " + self.undetermined
        if self.model_ok and self.undetermined is None:
            return (f"the model is consistent with the noise: the residues of all {self.n_outputs} outputs are at "
                    f"the noise level (on the {len(self.judged_rows)} rows judged, {len(self.tests)} tests, Holm at "
                    f"{ALPHA:g})")
        if self.model_ok:
            return "NOT DETERMINED: no sign of modelling errors, but " + self.undetermined
        out = "MODEL ERRORS: the model is rejected: " + "; ".join(self.model_errors[:3])
        return out + ("; and " + self.undetermined if self.undetermined else "")

    @property
    def judged_rows(self) -> np.ndarray:
        """The indices of the rows the residue tests judge (rows l <= K, which read line 0 or a
        conjugate line, are left out: their residues are not circular)."""
        return np.unique([t[0] for t in self.tests]).astype(int) if self.tests else np.zeros(0, int)

    def parameters(self, level: float = 0.95) -> list:
        """One row per entry of ``eta``: ``name``, ``value``, ``std``, ``low``, ``high`` (the
        two-sided ``level`` interval of :meth:`confidence_interval`) and ``kind`` ('normalised'
        for the entries A_na,0 = I fixes, 'estimate' otherwise); ``std``, ``low``, ``high`` None
        without a covariance.

        Examples
        --------
        >>> from lptv.examples.mimo import small_fit
        >>> row = small_fit().parameters()[0]
        >>> row["name"], bool(row["low"] < 2.0 < row["high"])
        ('a0[0,0].re0', True)
        """
        return parameter_rows(self.parameter_names, self.eta, self.covariance, level, self._fixed_names)

    @property
    def _fixed_names(self) -> frozenset:
        """The entries the normalisation fixes: Re of harmonic 0 of every entry of A_na."""
        na = self.model.na
        return frozenset(n for n in self.parameter_names if n.startswith(f"a{na}[") and n.endswith(".re0"))

    def summary(self, level: float = 0.95, units: Optional[dict] = None) -> str:
        """The fit, its noise route, the parameters with their std and ``level`` intervals (each
        coefficient entry's unit from ``units``, {'a0[0,1]': 'N/m', ...}, where given) and the
        verdict, as :meth:`lptv.IdentificationResult.summary` prints them."""
        lines = [f"method {self.method}: {self.n_free_parameters} free parameters on {self.lines.size} rows "
                 f"({self.n_inputs} inputs, {self.n_outputs} outputs"
                 + (f", {int(self.experiment.max()) + 1} experiments" if self.experiment.size
                    and self.experiment.max() > 0 else "") + ")",
                 f"iterations {self.iterations}, converged {self.converged}, cost {self.cost:.4g}"]
        if self.noise_choice in ("", "asked for"):
            lines.append(f"noise (co)variances: {self.noise} (asked for)")
        else:
            lines.append(f"noise (co)variances (noise='auto'): {self.noise_choice}")
        if self.transient is not None:
            lines.append(self.transient_note)
        if self.covariance is None:
            head = (" (no covariance: noise-free data)" if self.noise_free else
                    " (no covariance: covariance='none' or method 'gtls')")
        else:
            head = ""
        lines.append("parameters" + head + ":")
        lines.append(format_table(self.parameters(level), level, units))
        lines.append(f"verdict: {self.verdict}")
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)


def parameter_rows(names, eta, covariance, level: float = 0.95, fixed=frozenset()) -> list:
    """The rows of :meth:`MimoIdentificationResult.parameters` of any parameters ``eta`` named
    ``names`` with ``covariance`` (or None); ``fixed``: the names set by the normalisation."""
    from .._dist import norm_ppf

    level = as_positive_float(level, "level")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1), got {level!r}")
    z = norm_ppf(0.5 + level / 2.0)
    std = None if covariance is None else np.sqrt(np.maximum(np.diag(covariance), 0.0))
    rows = []
    for i, name in enumerate(names):
        s = None if std is None else float(std[i])
        v = float(eta[i]) + 0.0                # -0.0 shown as 0
        rows.append({"name": name, "value": v, "std": s, "low": None if s is None else v - z * s,
                     "high": None if s is None else v + z * s,
                     "kind": "normalised" if s == 0.0 or (s is None and name in fixed) else "estimate"})
    return rows


def format_table(rows, level: float = 0.95, units: Optional[dict] = None) -> str:
    """The rows of :meth:`MimoIdentificationResult.parameters` as aligned text, the columns of
    :func:`lptv.judgement.parameters.format_parameter_table`; ``units`` by coefficient entry
    ('a0[0,1]') after each interval."""
    width = max([12] + [len(r["name"]) for r in rows])
    pct = f"{100 * level:g} %"
    out = [f"  {'parameter':{width}s} {'value':>12s} {'std':>10s}   {pct + ' interval':>27s}"]
    for r in rows:
        if r["kind"] == "normalised":
            out.append(f"  {r['name']:{width}s} {r['value']:12.6g} {'(normalised)':>10s}")
        elif r["std"] is None:
            out.append(f"  {r['name']:{width}s} {r['value']:12.6g}")
        else:
            unit = (units or {}).get(r["name"].split(".")[0], "")
            out.append(f"  {r['name']:{width}s} {r['value']:12.6g} {r['std']:10.3g}   "
                       f"[{r['low']:12.6g}, {r['high']:12.6g}]" + (f" {unit}" if unit else ""))
    return "\n".join(out)


def residue_tests(residue, covariance, periods) -> Tuple:
    """Eq. 19.14 per row: each output's |e_p|^2 / C_pp ~ F(2, 2(P-1)) and the joint
    (P-ny)/(ny(P-1)) e^H C^-1 e ~ F(2 ny, 2(P-ny)) (for P > ny); ``periods`` per row."""
    from .._dist import f_sf

    R, ny = residue.shape
    P = np.asarray(periods, dtype=float)
    out = []
    if np.any(P < 2):
        return ()
    diag = np.real(np.diagonal(covariance, axis1=1, axis2=2))
    with np.errstate(divide="ignore", invalid="ignore"):
        s_out = np.abs(residue) ** 2 / diag
    p_out = f_sf(s_out, 2.0, 2.0 * (P[:, None] - 1.0))
    for r in range(R):
        for p in range(ny):
            out.append((r, p, float(s_out[r, p]), float(p_out[r, p])))
    if ny > 1:
        q = np.real(np.einsum("rp,rp->r", residue.conj(), np.linalg.solve(covariance, residue[..., None])[..., 0]))
        ok = P > ny
        stat = np.where(ok, (P - ny) / (ny * (P - 1)) * q, np.nan)
        pj = f_sf(stat, 2.0 * ny, 2.0 * np.maximum(P - ny, 1))
        for r in np.flatnonzero(ok):
            out.append((int(r), -1, float(stat[r]), float(pj[r])))
    return tuple(out)

