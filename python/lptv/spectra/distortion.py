"""Nonlinear distortion and the best linear (time-periodic) approximation from M random-phase
realisations of P periods (METHOD.md section 16).

An LPTV system and a nonlinear one both put output power on lines the input does not excite.
What tells them apart is how that power depends on the input's phases: an LPTV system's
output line j is a fixed linear combination of the excited lines within its HTF's reach,
Y_j = sum_c G_{j-c}(w_c) U_c, the same coefficients for every realisation; a nonlinear
system's stochastic distortion Y_S,j varies from realisation to realisation like a noise
that does not average out over the periods. So, per output line j, the M realisations' period
means are regressed on the excited lines within +-Kh of j (their conjugates near DC):

    Y_j^[m] = sum_c G_{j-c}(w_c) U_c^[m] + E_j^[m],   m = 1..M,   q_j regressors

by least squares. The residual power over its 2 (M - q_j) real degrees of freedom estimates
the variance of E_j per realisation: the noise of the period means plus the stochastic
nonlinear distortion. The noise part alone comes from the periods (2 M (P-1) degrees of
freedom); their ratio is F(2 (M - q_j), 2 M (P - 1)) without a nonlinearity, and the
difference estimates the nonlinear level. The regression coefficients are the best linear
time-periodic approximation (BLA) of the HTF branches, with their total covariance (noise and
nonlinear distortion) s_j^2 (X^H X)^-1; overlapping branches of neighbouring excited lines are
estimated jointly rather than leaking into each other.

The per-line regression runs in the compiled core (``_core.distortion_lines``; its NumPy
twin is :mod:`lptv.reference.distortion`); the spectra, the excited lines and Kh come before it,
the F tests and the overall statistic (SciPy) after it, here.
"""
from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from .. import _core
from .._validate import as_int, as_lines, as_positive_float
from .frequency_data import FrequencyData

ALPHA = 0.01


LOF_ALL_PERMUTATIONS = 720
"""Up to this many permutations of the realisations (M! <= 720, M <= 6) all are taken; beyond,
the identity and ``LOF_RANDOM_PERMUTATIONS - 1`` drawn with a fixed seed (the p-value is then
that of a randomisation test, as exact, with a resolution of 1 / LOF_RANDOM_PERMUTATIONS)."""
LOF_RANDOM_PERMUTATIONS = 2000
LOF_CONDITION_MAX = 1e10
"""A model whose steady state has a larger condition on some line (six of the 16 digits lost)
has no reliable predicted output there: its lack of fit is not computed, it is rejected."""
LOF_TRUNCATION_MAX = 1e-6
"""Nor one whose predicted output carries a larger truncation error (relative to its peak)."""
OUTPUT_SPREAD_MAX = 4.0
"""Realisations' output powers differing more than this (6 dB; at most 1.4 over 6 realisations of
the weakly time-varying examples, 25 in the median of the discrete-time one) are said in the
summary: a phase-dependent response."""


def _reliable_response(m, U):
    """The model's steady-state response to the input spectra ``U`` (the FDS, full output), and
    None; or None and the reason it cannot be trusted (a NumericalError, a non-finite output, a
    condition above LOF_CONDITION_MAX on some line, a truncation error above
    LOF_TRUNCATION_MAX): the solve's own figures, with its warnings silenced."""
    from ..simulation.fds import simulate

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # judged below, from the solve's own figures
            sim = simulate(m, U, warn_unstable=False, full_output=True)
    except _core.NumericalError as e:
        return None, " ".join(str(e).split())
    if not np.all(np.isfinite(sim.Y)):
        return None, "its predicted output is not finite"
    if sim.condition > LOF_CONDITION_MAX:
        return None, (f"its steady state is nearly singular on line {sim.condition_line}: condition "
                      f"{sim.condition:.2g}, a pole within about {1 / sim.condition:.1g} of that line")
    if sim.truncation_error > LOF_TRUNCATION_MAX:
        return None, f"the truncation error of its predicted output is {sim.truncation_error:.2g} of its peak"
    return sim, None


@dataclass(frozen=True)
class LackOfFit:
    """A parametric model of the best linear approximation judged against the per-line
    regression across the realisations (:meth:`DistortionResult.lack_of_fit`, METHOD.md section
    16, "Judging the parametric BLA"). Per judged output line j, with q_j regressors (the
    realisations' excited lines within +-Kh) and the model's predicted output for each
    realisation, the residual rows split into a lack of fit (their projection on the
    regressors) and the pure error of the regression; without a model error their ratio is
    F(2 q_j, 2 (M - q_j)). The lines' normal scores are summed and that sum is referred to its
    distribution over the permutations of the realisations' residual rows against their
    regressors (one permutation for all lines, so that the distortion's correlation across
    lines is kept)."""

    lines: np.ndarray
    """The judged output lines."""
    regressors: np.ndarray
    """Per judged line: q_j, the rank of its regressors."""
    F: np.ndarray
    """Per judged line: (lack of fit / q_j) / (pure error / (M - q_j))."""
    p_lines: np.ndarray
    """Per judged line: P(F(2 q_j, 2 (M - q_j)) > F). Calibrated line by line; not the decision
    (the extreme tails of the distortion are heavier than the F distribution's)."""
    statistic: float
    """The sum of the lines' normal scores Phi^-1(1 - p_j) over sqrt(their number)."""
    p_value: float
    """Its permutation p-value: the share of permutations (the identity included) whose sum is
    at least the observed one. Reject when at or below ``alpha``."""
    permutations: int
    realisations: int
    alpha: float = ALPHA
    unreliable: Optional[str] = None
    """Why the model's predicted output on the data's lines cannot be trusted (its steady state
    nearly singular on a line, or its truncation error large), else None. A model whose output
    cannot be computed there is not the best linear approximation: the test then rejects."""

    @property
    def rejects(self) -> bool:
        return bool(self.unreliable is not None or self.p_value <= self.alpha)

    @property
    def can_reject(self) -> bool:
        """Whether the permutations can reach ``alpha`` at all (M >= 5 realisations)."""
        return bool(1.0 / self.permutations <= self.alpha)

    def worst(self, k: int = 3) -> np.ndarray:
        """The ``k`` judged lines with the smallest line p-values."""
        return self.lines[np.argsort(self.p_lines, kind="stable")[:k]]

    def sentence(self) -> str:
        """The verdict's sentence when the test rejects (it is one-sided: a lack of fit)."""
        if self.unreliable is not None:
            return ("the model's output on the data's lines cannot be computed reliably, so it is not the best "
                    f"linear approximation the realisations give ({self.unreliable})")
        return (f"the model departs from the best linear approximation that the {self.realisations} realisations give "
                f"line by line (lack of fit on {self.lines.size} lines: z = {self.statistic:.2f}, permutation "
                f"p = {self.p_value:.2g} <= {self.alpha:g}; largest on lines "
                f"{', '.join(str(int(j)) for j in self.worst())})")


def _permutations(M: int) -> np.ndarray:
    if math.factorial(M) <= LOF_ALL_PERMUTATIONS:
        return np.array(list(itertools.permutations(range(M))), dtype=int)
    rng = np.random.default_rng(20261126 + M)
    rest = np.array([rng.permutation(M) for _ in range(LOF_RANDOM_PERMUTATIONS - 1)], dtype=int)
    return np.vstack([np.arange(M)[None, :], rest])


@dataclass(frozen=True)
class DistortionResult:
    """What :func:`distortion` returns. Levels are variances of one realisation's period mean on
    each output line (``lines``), in the units of |Y|^2."""

    lines: np.ndarray
    """Output lines 1 .. max_line."""
    w: np.ndarray
    """Their angular frequencies (rad/s)."""
    kind: np.ndarray
    """Per line: 'excited', 'sideband' (within +-Kh of an excited line) or 'other'."""
    signal: np.ndarray
    """Mean over the realisations of |Y_j|^2."""
    noise: np.ndarray
    """Noise variance of a period mean (from the periods, input noise carried through the BLA)."""
    total: np.ndarray
    """Residual variance of the regression across realisations: noise + nonlinear distortion."""
    nonlinear: np.ndarray
    """max(total - noise, 0): the stochastic nonlinear distortion's variance."""
    nonlinear_std: np.ndarray
    """Standard deviation of ``total - noise`` (from their degrees of freedom)."""
    p_value: np.ndarray
    """Per line: P(F(2 (M - q), 2 M (P - 1)) > total / noise) (NaN where M <= q)."""
    dof: np.ndarray
    """Per line: M - q_j, the realisations left after the regression."""
    excited: np.ndarray
    branches: int
    """Kh: the HTF branches -Kh..Kh regressed."""
    bla: np.ndarray
    """(2 Kh + 1, n_excited) complex: branch k (row Kh + k) of the BLA at each excited line; NaN
    where the output line l + k is outside the lines or has no residual degree of freedom."""
    bla_var: np.ndarray
    """Total variance (noise and nonlinear distortion) of each ``bla`` entry."""
    realisations: int
    periods: int
    statistic: float
    """Over all lines with a residual degree of freedom: the sum of the normal scores of the
    lines' F ratios over sqrt(count) (standard normal without a nonlinearity)."""
    p_overall: float
    """One-sided p-value of ``statistic``."""
    alpha: float = ALPHA
    spectra: tuple = field(default=(), repr=False)
    """Per realisation: (U, Y, varU, varY, covYU) of its period means, lines 0..max_line."""
    w0: float = 0.0
    ts: Optional[float] = None

    @property
    def detected(self) -> bool:
        """Nonlinear distortion above the noise (``p_overall`` below ``alpha``)."""
        return bool(self.p_overall < self.alpha)

    def nonlinear_smooth(self, width: int = 5) -> np.ndarray:
        """The nonlinear level on lines 0..max_line, averaged over the ``width`` nearest lines on
        either side at the same signed distance from their nearest excited line (or, beyond the
        excitation's reach, of the lines there): the level is smooth across excited lines
        while each line's estimate has only 2 (M - q) degrees of freedom; clipped at 0. **(choice)**
        Zero everywhere when no distortion is detected (``detected`` False): the clipped noise of
        the estimate would otherwise inflate the variances of a system without distortion (its
        residues then too small); a threshold per line instead (the average above twice its
        standard deviation) left the weakly distorted lines without their level, and their
        residues too large. Zero on line 0 and where nothing was estimated."""
        width = as_int(width, "width")
        out = np.zeros(self.lines.size + 1)
        if not self.detected:
            return out
        ok = np.isfinite(self.p_value)
        diff = np.where(ok, self.total - self.noise, np.nan)
        # classes: the signed offset from the nearest excited line (the level changes fast with
        # it around each excited line), and the lines beyond the excitation's reach
        ex = np.sort(self.excited)
        pos = np.clip(np.searchsorted(ex, self.lines), 1, max(ex.size - 1, 1))
        lo, hi = ex[np.maximum(pos - 1, 0)], ex[np.minimum(pos, ex.size - 1)]
        near_ex = np.where(np.abs(self.lines - lo) <= np.abs(self.lines - hi), lo, hi)
        offset = np.where(self.kind == "other", 10 ** 9, self.lines - near_ex)
        for c in np.unique(offset):
            idx = np.flatnonzero((offset == c) & ok)
            for i, j in enumerate(idx):
                near = idx[max(0, i - width): i + width + 1]
                out[j + 1] = max(float(np.mean(diff[near])), 0.0)
        return out

    def experiments(self, width: int = 5, referred: str = "output", model=None):
        """The realisations as experiments for :func:`lptv.identify` (a list of
        :class:`lptv.FrequencyData`), each output variance raised by the nonlinear level
        (:meth:`nonlinear_smooth`), so that WGTLS and SML weigh the lines by noise and
        nonlinear distortion together and their parameter covariance includes both: the
        parametric fit of the best linear time-periodic approximation. Each remembers this
        result and its realisation (``distortion``, ``realisation``), so that a fit of all M of
        them is judged by :meth:`lack_of_fit` (the verdict of section 7 assumes residues
        independent across lines, which the distortion is not).

        ``referred="input"`` (with ``model``, a first fit's model or result): the distortion
        referred to the input instead, for a nonlinearity before the dynamics (an actuator): the
        input variances are raised by the level divided by the model's |G_0|^2 on the lines
        where a multisine's distortion lives (the multiples of the excited lines' common
        spacing, which must exceed the model's harmonics K) and at DC (from output lines 1..K
        through the branches G_k(0)); the output variances keep the noise alone
        (:meth:`input_level`, METHOD.md section 16). Measured on two Hammerstein systems: the
        output-referred fit was 1.5 std off the exact BLA (the paper's model), the
        input-referred one 0.1 std, with 2.7-2.9 times smaller spread; on Wiener systems (the
        nonlinearity after the dynamics) the output-referred fit is the better one (bench/HISTORY.md).
        The first fit may be of these experiments, or, where one common level on the outputs
        swamps a weak realisation (a strongly time-varying system whose output power depends on
        the phases; :func:`lptv.identify` then refuses it and says so), of the realisations with
        their noise alone (``lptv.identify(d.experiments(referred="none"), ...)``). A first
        model whose branches cannot be computed reliably on the lines (a pole on a line, as a fit
        one order short may stop at) is refused with a ``ValueError`` naming ``model``.

        Where the response depends on the phases (:attr:`output_spread` above 4: far HTF
        branches), neither level is an exact noise model: on the discrete-time example the
        input-referred fit was biased, more so with more realisations, while the fit of the
        realisations with their noise alone and ``covariance="realisations"`` was not; a
        ``UserWarning`` says so (METHOD.md section 16).

        ``referred="none"``: the realisations with their noise alone (each its own P periods'
        variances, no level added), for that fit: ``lptv.identify(d.experiments(referred="none"),
        ..., covariance="realisations")`` weighs the lines by the noise, which does not depend on
        the phases, and takes the parameters' variance, distortion included, from the spread of
        the leave-one-realisation-out refits. Consistent whatever the HTF's reach; less efficient
        where the distortion dominates the noise (the weights then ignore it), and there its
        intervals need not be right: measured, they covered the exact BLA 94.7 % of the time on
        the discrete-time example and 95.0 % on the third-order one, but 89.0 % on the paper's
        model at P = 4 (bench/HISTORY.md). Its analytic
        covariance would be the noise's alone, so :func:`lptv.identify` warns when it is asked for
        one and the distortion is detected.

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
        >>> rows = [range(1, 244)] * 6
        >>> bla = lptv.identify(d.experiments(), na=2, nb=1, ka=3, kb=3, lines=rows, method="sml")
        >>> plain = lptv.identify([(u[i], y[i]) for i in range(6)], na=2, nb=1, ka=3, kb=3,
        ...                       w0=m.w0, lines=rows, method="sml")
        >>> z_plain, z_bla = (r.residue_tests.tests[0].statistic for r in (plain, bla))  # all rows
        >>> bool(z_plain > 10 and abs(z_bla) < 5)   # N(0, 1) if the variances explain the residues
        True
        """
        if not isinstance(referred, str) or referred not in ("output", "input", "none"):
            raise ValueError(f"referred must be 'output', 'input' or 'none', got {referred!r}")
        nl = self.nonlinear_smooth(width) if referred != "none" else None
        if referred == "input":
            if model is None:
                raise ValueError("model: referred='input' needs a first fit's model (e.g. lptv.identify("
                                 "d.experiments(), ...).model) for the branches that refer the level to the input")
            lu = self.input_level(model, width)
        if referred != "none" and self.depends_on_phases:
            warnings.warn(f"the realisations' output powers differ up to {self.output_spread:.3g} times (a response "
                          "that depends on the phases): the nonlinear level "
                          + ("referred to the input" if referred == "input" else "on the outputs")
                          + " is no exact noise model there (on the discrete-time example the input-referred fit "
                          "was biased, more so with more realisations); the fit of the realisations with their "
                          "noise alone (experiments(referred='none')) and covariance='realisations' is consistent "
                          "(METHOD.md section 16)",
                          UserWarning, stacklevel=2)
        out = []
        for m, (U, Y, varU, varY, cov) in enumerate(self.spectra):
            P_eff = self.periods if referred == "none" else self.effective_periods(varY, nl, width)
            if referred == "none":        # the realisation's own periods, nothing added
                fd = FrequencyData(U, Y, varU, varY, cov, w0=self.w0, ts=self.ts, periods=P_eff)
            elif referred == "input":
                fd = FrequencyData(U, Y, varU + lu[:varU.size], varY, cov, w0=self.w0, ts=self.ts, periods=P_eff)
            else:
                fd = FrequencyData(U, Y, varU, varY + nl[:varY.size], cov, w0=self.w0, ts=self.ts, periods=P_eff)
            # so that lptv.identify judges a fit of all M of them by lack_of_fit
            fd.distortion, fd.realisation, fd.referred = self, m, referred
            out.append(fd)
        return out

    def input_level(self, model, width: int = 5) -> np.ndarray:
        """The nonlinear level referred to the input, per input line 0..max_line (variance of a
        period mean, in the units of |U|^2), for a nonlinearity before the dynamics (METHOD.md
        section 16). A multisine's distortion lives on the multiples of the excited lines'
        common spacing s (sums and differences of excited lines); with the model's harmonics
        K < s an output line j = c + k (c such a line, |k| <= K) receives it from c alone:
        Y_S,j = G_k(w_c) U_S,c. Hence at each multiple c >= s the output level over
        |G_0(w_c)|^2, averaged over the ``width`` nearest multiples on either side and clipped at
        0, and at DC the mean over k = 1..K of the level on line k over |G_k(0)|^2. Zero
        elsewhere, and everywhere when no distortion is detected.

        Parameters
        ----------
        model : lptv.Model or lptv.IdentificationResult
            A first fit of the best linear approximation (e.g. of :meth:`experiments`): its
            branches refer the output level to the input.
        """
        from ..model.siso import Model

        width = as_int(width, "width")
        m = getattr(model, "model", model)
        if not isinstance(m, Model):
            raise ValueError(f"model must be an lptv.Model or an IdentificationResult, got {type(model).__name__}")
        if not np.isclose(m.w0, self.w0, rtol=1e-9, atol=0.0):
            raise ValueError(f"model: its w0 = {m.w0:g} is not the data's {self.w0:g}")
        L = int(self.lines.size)
        out = np.zeros(L + 1)
        if not self.detected:
            return out
        K = int(max(m.ka, m.kb))
        s = int(np.gcd.reduce(np.asarray(self.excited, dtype=int)))
        if s <= K:
            raise ValueError(f"model: referred='input' needs the excited lines' common spacing ({s}) above the "
                             f"model's harmonics (K = {K}), so that each distortion line reaches the output alone")
        lat = np.arange(s, L + 1, s)
        E = np.zeros((L + 1, lat.size + 1), complex)       # unit inputs on the multiples of s and on DC
        E[lat, np.arange(lat.size)] = 1.0
        E[0, lat.size] = 1.0
        sim, unreliable = _reliable_response(m, E)
        if unreliable is not None:
            raise ValueError(f"model: its branches cannot refer the level to the input ({unreliable}); "
                             "fit the approximation with a structure whose fit converges, or refer the level "
                             "to the output")
        G = sim.Y
        g0 = np.abs(G[lat, np.arange(lat.size)]) ** 2
        ok = np.isfinite(self.p_value[lat - 1]) & (g0 > 1e-12 * max(float(g0.max()), 1e-300))
        raw = np.where(ok, (self.total[lat - 1] - self.noise[lat - 1]) / np.where(ok, g0, 1.0), np.nan)
        for i in range(lat.size):
            near = raw[max(0, i - width): i + width + 1]
            near = near[np.isfinite(near)]
            out[lat[i]] = max(float(near.mean()), 0.0) if near.size else 0.0
        ks = np.arange(1, min(K, L) + 1)
        gk = np.abs(G[ks, lat.size]) ** 2
        ok0 = np.isfinite(self.p_value[ks - 1]) & (gk > 1e-12 * max(float(gk.max()) if gk.size else 0.0, 1e-300))
        if ok0.any():
            out[0] = max(float(np.mean((self.total[ks - 1] - self.noise[ks - 1])[ok0] / gk[ok0])), 0.0)
        return out

    def effective_periods(self, varY, nl, width: int = 5) -> int:
        """The P that the output variance ``varY + nl`` of one realisation is worth, for the
        small-sample statistics that read P (the covariance factor (P-1)/(P-3), the residues'
        F(2, 2(P-1)), the score tests' (P-2)/(P-3)): the noise part has 2 (P - 1) real degrees of
        freedom, the smoothed nonlinear part about 2 (M - q) (2 width + 1) (its lines' residual
        degrees of freedom times the lines averaged); their sum's by Satterthwaite,
        nu = (v_n + v_nl)^2 / (v_n^2 / nu_n + v_nl^2 / nu_nl), and P_eff = 1 + nu / 2, the median
        over the excited lines and their sidebands, rounded down, never below P. (METHOD.md
        section 16: with P as the periods' count the factor 3 of P = 4 was applied to a variance
        that the distortion dominates, and the intervals covered 99 %.)"""
        P = int(self.periods)
        near = np.flatnonzero((self.kind != "other") & np.isfinite(self.p_value))
        if not self.detected or near.size == 0:
            return P
        j = self.lines[near]
        vn, vnl = np.asarray(varY)[j], np.asarray(nl)[j]
        nu_n = 2.0 * (P - 1)
        nu_nl = 2.0 * np.maximum(self.dof[near], 1) * (2 * int(width) + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            nu = (vn + vnl) ** 2 / (vn ** 2 / nu_n + vnl ** 2 / nu_nl)
        nu = nu[np.isfinite(nu)]
        if nu.size == 0:
            return P
        return max(P, int(np.floor(1.0 + float(np.median(nu)) / 2.0)))

    def lack_of_fit(self, model, lines=None) -> LackOfFit:
        """Judge a parametric model of the best linear approximation (a fit of
        :meth:`experiments`) against the per-line regression across the realisations.

        The verdict of section 7 reads a fit's residues as independent across lines with the
        variances the data carry; the nonlinear distortion is neither (it is correlated across
        neighbouring lines, and where it enters before the dynamics it is shaped by them), so
        that verdict rejects good BLA fits. This test makes no assumption on how the
        distortion is correlated across lines (METHOD.md section 16, "Judging the parametric
        BLA"). :func:`lptv.identify` uses it for the verdict of a fit of these experiments
        (:attr:`lptv.IdentificationResult.lack_of_fit`).

        Parameters
        ----------
        model : lptv.Model or lptv.IdentificationResult
            The model (its w0 and ts must be the data's).
        lines : sequence of int, optional
            The output lines to judge (default: every line with at least one regressor and one
            residual degree of freedom); lines without them are left out.

        Returns
        -------
        LackOfFit
            ``rejects`` at 1 %; with M = 4 realisations (24 permutations) it cannot.

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
        >>> rows = [range(1, 244)] * 6
        >>> good = lptv.identify(d.experiments(), na=2, nb=1, ka=3, kb=3, lines=rows, method="sml")
        >>> poor = lptv.identify(d.experiments(), na=2, nb=1, ka=2, kb=2, lines=rows, method="sml")
        >>> d.lack_of_fit(good).rejects, d.lack_of_fit(poor).rejects
        (False, True)
        """
        from scipy import stats

        from ..model.siso import Model

        m = getattr(model, "model", model)
        if not isinstance(m, Model):
            raise ValueError(f"model must be an lptv.Model or an IdentificationResult, got {type(model).__name__}")
        if not np.isclose(m.w0, self.w0, rtol=1e-9, atol=0.0):
            raise ValueError(f"model: its w0 = {m.w0:g} is not the data's {self.w0:g}")
        if (m.ts is None) != (self.ts is None) or (m.ts is not None and not np.isclose(m.ts, self.ts, rtol=1e-9)):
            raise ValueError(f"model: its ts = {m.ts} is not the data's {self.ts}")
        if not self.spectra:
            raise ValueError("this DistortionResult holds no spectra (made without them): nothing to judge")
        M = self.realisations
        U = np.array([s[0] for s in self.spectra]).T      # (L + 1, M)
        Y = np.array([s[1] for s in self.spectra]).T
        Uex = np.zeros_like(U)
        Uex[self.excited] = U[self.excited]
        wanted = self.lines if lines is None else np.unique(np.asarray(as_lines(lines, "lines", minimum=1)))
        bad = wanted[(wanted < 1) | (wanted > self.lines.size)]
        if bad.size:
            raise ValueError(f"lines: line {int(bad[0])} is not an output line 1..{self.lines.size} of the data")
        ex = np.asarray(self.excited, dtype=int)
        judged, ranks, projections = [], [], []
        for j in wanted:
            cs = np.concatenate([ex[np.abs(j - ex) <= self.branches], -ex[ex + j <= self.branches]])
            if cs.size == 0 or M - cs.size < 1:
                continue
            X = np.where(cs > 0, U[np.abs(cs)].T, np.conj(U[np.abs(cs)].T))    # (M, q)
            W, sv, _ = np.linalg.svd(X, full_matrices=False)
            rank = int(np.sum(sv > np.finfo(float).eps * max(X.shape) * (sv[0] if sv.size else 0.0)))
            if rank == 0 or M - rank < 1:
                continue
            judged.append(int(j))
            ranks.append(rank)
            projections.append(W[:, :rank])
        if not judged:
            raise ValueError("lines: no line with a regressor and a residual degree of freedom to judge")
        judged, ranks = np.array(judged), np.array(ranks)
        perms = _permutations(M)
        sim, unreliable = _reliable_response(m, Uex)
        if unreliable is not None:
            nan = np.full(judged.size, np.nan)
            return LackOfFit(lines=judged, regressors=ranks, F=nan, p_lines=nan.copy(), statistic=float("nan"),
                             p_value=0.0, permutations=int(perms.shape[0]), realisations=M, unreliable=unreliable)
        Rl = (Y - sim.Y)[judged]                            # (n, M): the residual rows of the model
        total = np.sum(np.abs(Rl) ** 2, axis=1)

        def lof_of(block):                                 # (n, len(block)): the lack of fit per permutation
            Rp = Rl[:, block]                              # (n, b, M)
            out = np.empty((judged.size, block.shape[0]))
            for i, Wq in enumerate(projections):
                c = Rp[i] @ np.conj(Wq)                    # coordinates on the regressors' span
                out[i] = np.sum(np.abs(c) ** 2, axis=1)
            return out

        q, rdof = ranks[:, None], (M - ranks)[:, None]
        sums = []
        for k in range(0, perms.shape[0], 500):
            lof = lof_of(perms[k:k + 500])
            pure = np.maximum(total[:, None] - lof, np.finfo(float).tiny)
            F = (lof / q) / (pure / rdof)
            p = stats.f.sf(F, 2 * q, 2 * rdof)
            if k == 0:
                F0, p0 = F[:, 0], p[:, 0]
            sums.append(stats.norm.isf(np.clip(p, 1e-300, 1.0)).sum(axis=0))
        sums = np.concatenate(sums)
        p_perm = float(np.mean(sums >= sums[0] - 1e-12 * max(1.0, abs(sums[0]))))
        return LackOfFit(lines=judged, regressors=ranks, F=F0, p_lines=p0,
                         statistic=float(sums[0] / np.sqrt(judged.size)), p_value=p_perm,
                         permutations=int(perms.shape[0]), realisations=M)

    @property
    def output_spread(self) -> float:
        """The largest over the smallest of the realisations' output powers (lines 1 and up of
        their period means). Random phases leave a weakly time-varying system's output power
        nearly alike (at most 1.4 times over 6 realisations of the paper's and the third-order
        examples with a cubic actuator); a response that depends on the phases (the
        discrete-time example: 25 times in the median, up to 317) has far HTF branches, and one
        common level on the outputs, and even the level referred to the input, are then no exact
        noise model (METHOD.md section 16)."""
        power = [float(np.sum(np.abs(np.asarray(Y)[1:]) ** 2)) for _, Y, *_ in self.spectra]
        return float(max(power) / max(min(power), 1e-300))

    @property
    def depends_on_phases(self) -> bool:
        """The distortion is detected and the realisations' outputs differ more than 4 times
        (:attr:`output_spread`): neither level (on the outputs, referred to the input) is an
        exact noise model, and the realisations with their noise alone
        (``experiments(referred="none")``) with ``covariance="realisations"`` are the consistent
        fit (METHOD.md section 16). ``lptv identify`` takes that route by itself then."""
        return bool(self.detected and self.output_spread > OUTPUT_SPREAD_MAX)

    def summary(self) -> str:
        ok = np.isfinite(self.p_value)
        out = [f"{self.realisations} realisations x {self.periods} periods, branches -{self.branches}.."
               f"{self.branches}, {int(ok.sum())} lines tested",
               f"nonlinear distortion {'DETECTED' if self.detected else 'not detected'} "
               f"(z = {self.statistic:.2f}, p = {self.p_overall:.2g}, level {self.alpha:g})"]
        for kind in ("excited", "sideband", "other"):
            sel = ok & (self.kind == kind)
            if sel.any():
                s, n, d = (10 * np.log10(max(float(np.mean(x[sel])), 1e-300))
                           for x in (self.signal, self.noise, self.nonlinear))
                out.append(f"{kind:9s} lines ({int(sel.sum())}): signal {s:.1f} dB, noise {n:.1f} dB, "
                           f"nonlinear {d:.1f} dB (mean powers)")
        spread = self.output_spread
        if spread > OUTPUT_SPREAD_MAX:
            out.append(f"the realisations' output powers differ up to {spread:.3g} times: the response depends on "
                       "the phases (far HTF branches of a strongly time-varying system, or a strong nonlinearity); part "
                       "of the level may be branches that "
                       f"{self.realisations} realisations cannot regress, and a level on the outputs or referred to "
                       "the input is no exact noise model: fit the realisations with their noise alone "
                       "(experiments(referred='none')) and covariance='realisations' (METHOD.md section 16)")
        return "\n".join(out)


def _as_realisations(x, name):
    x = np.asarray(x, dtype=float)
    if x.ndim != 3:
        raise ValueError(f"{name} must have shape (M, P, N): M realisations of P periods of N samples, "
                         f"got shape {x.shape}")
    if x.shape[0] < 2:
        raise ValueError(f"{name}: at least 2 realisations are needed, got {x.shape[0]}")
    if x.shape[1] < 2:
        raise ValueError(f"{name}: at least 2 periods per realisation are needed, got {x.shape[1]}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} contains NaN or inf")
    return x


def _most_regressors(src, lines, Kh):
    """The largest number of excited lines (and conjugates) within +-Kh of any output line."""
    srt = np.sort(src)
    return int(np.max(np.searchsorted(srt, lines + Kh, side="right") - np.searchsorted(srt, lines - Kh)))


def _default_branches(src, lines, spacing, M):
    """The largest Kh (at least spacing - 1) that leaves every line two realisations' worth of
    residual degrees of freedom (at most M - 2 regressors): the far branches of a time-varying
    denominator reach the neighbouring excited lines, and a branch left out of the regression
    would count as nonlinear distortion. (Capped at 4 spacings before: the discrete-time
    example, whose branches reach beyond +-23 near DC, was then "detected" in 40 % of purely
    LPTV data sets at M = 16, with Kh = 23; bench/HISTORY.md.)"""
    best = max(spacing - 1, 0)
    if M - 2 >= src.size:                       # every excited line fits on every output line
        return int(lines.size)
    if _most_regressors(src, lines, best) > M - 2:
        return best
    lo, hi = best, int(lines.size) + 1          # the count grows with Kh: ok at lo, too many at hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if _most_regressors(src, lines, mid) > M - 2:
            hi = mid
        else:
            lo = mid
    return lo


def distortion(u, y, *, w0: float, ts: Optional[float] = None, branches: Optional[int] = None,
               ratio: float = 100.0) -> DistortionResult:
    """Noise and nonlinear distortion levels per line, and the best linear time-periodic
    approximation, from M random-phase realisations of one amplitude spectrum.

    Parameters
    ----------
    u, y : array_like, shape (M, P, N)
        M realisations (each its own random phases, the same amplitude spectrum and lines) of
        P steady-state periods of N samples.
    w0 : float
        The period's fundamental (rad/s).
    ts : float, optional
        Sample period of a discrete-time system.
    branches : int, optional
        Kh, the HTF branches -Kh..Kh regressed per output line. Default: the largest Kh (at
        least the spacing of the excited lines minus 1) with at most M - 2 excited lines within
        +-Kh of any line, so that the far branches of neighbouring excited lines are regressed
        rather than counted as distortion (M = 6 reaches two spacings).
    ratio : float
        A line counts as excited when its input power exceeds ``ratio`` times its noise variance
        in every realisation.

    Returns
    -------
    DistortionResult

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import noisy_periods, paper_model
    >>> m = paper_model()
    >>> u, y = [], []
    >>> for r in range(6):              # 6 realisations, 4 periods each; a cubic at the output
    ...     ms = lptv.multisine(range(10, 241, 10), 2048, amplitudes=np.sqrt(2 / 24), seed=r)
    ...     y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 2048)
    ...     a, b = noisy_periods(ms.signal, y0 + 0.02 * y0 ** 3, 4, 50, 30, seed=100 + r)
    ...     u.append(a); y.append(b)
    >>> d = lptv.distortion(np.array(u), np.array(y), w0=m.w0)
    >>> d.detected, d.branches
    (True, 19)
    """
    u = _as_realisations(u, "u")
    y = _as_realisations(y, "y")
    if u.shape != y.shape:
        raise ValueError(f"u and y must have the same shape, got {u.shape} and {y.shape}")
    w0 = as_positive_float(w0, "w0")
    ratio = as_positive_float(ratio, "ratio")
    M, P, N = u.shape
    datas = [FrequencyData.from_periods(u[m], y[m], w0=w0, ts=ts) for m in range(M)]
    L = datas[0].max_line
    U = np.array([d.U for d in datas])               # (M, L+1)
    Y = np.array([d.Y for d in datas])
    varU = np.array([d.varU for d in datas])
    varY = np.array([d.varY for d in datas])
    cov = np.array([d.covYU for d in datas])
    ex_sets = [set(int(x) for x in _core.excited_lines(d._cpp, ratio)) for d in datas]
    excited = np.array(sorted(set.intersection(*ex_sets)), dtype=int)
    excited = excited[excited > 0]
    if excited.size == 0:
        raise ValueError("u: no line stands above its noise in every realisation")
    spacing = int(np.min(np.diff(excited))) if excited.size > 1 else L
    # Regressors of output line j: excited lines c (and -c) with |j - c| <= Kh.
    src = np.concatenate([excited, -excited])
    lines = np.arange(1, L + 1)
    if branches is None:
        Kh = _default_branches(src, lines, spacing, M)
    else:
        Kh = as_int(branches, "branches", maximum=L)
    core = _core.distortion_lines(U, Y, varU, varY, cov, [int(c) for c in excited], Kh)
    total, noise = np.array(core.total), np.array(core.noise)      # copies: the result's own arrays
    dof = np.array(core.dof, dtype=int)
    bla, bla_var = np.array(core.bla), np.array(core.bla_var)
    n = lines.size
    from scipy import stats

    ok = dof >= 1
    d1 = 2.0 * np.maximum(dof, 1)
    d2 = 2.0 * M * (P - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        F = total / noise
    p = np.where(ok & (noise > 0), stats.f.sf(F, d1, d2), np.nan)
    diff = total - noise
    nl = np.where(ok, np.maximum(diff, 0.0), np.nan)
    nl_std = np.where(ok, np.sqrt(total ** 2 / np.maximum(dof, 1) + noise ** 2 / (M * (P - 1))), np.nan)
    good = np.isfinite(p)
    score = stats.norm.isf(np.clip(p[good], 1e-300, 1.0))
    z = float(score.sum() / np.sqrt(max(score.size, 1)))
    kind = np.full(n, "other", dtype=object)
    near = np.zeros(n, bool)
    for c in excited:
        near |= np.abs(lines - c) <= Kh
    kind[near] = "sideband"
    kind[np.isin(lines, excited)] = "excited"
    signal = np.array(core.signal)
    return DistortionResult(
        lines=lines, w=lines * w0, kind=kind.astype(str), signal=signal, noise=noise, total=total,
        nonlinear=nl, nonlinear_std=nl_std, p_value=p, dof=dof, excited=excited, branches=Kh,
        bla=bla, bla_var=bla_var, realisations=M, periods=P, statistic=z,
        p_overall=float(stats.norm.sf(z)), w0=w0, ts=ts,
        spectra=tuple((U[m], Y[m], varU[m], varY[m], cov[m]) for m in range(M)))
