"""What :func:`lptv.identify` returns: :class:`IdentificationResult` (the estimate, its
covariance, the residues and the verdict read from them), and the rows the verdict judges
(:func:`excited_rows`). Importable from :mod:`lptv.estimation.identify` as well, where they were first."""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from functools import cached_property
from typing import Optional, Tuple

import numpy as np

from .. import _core
from ..spectra.frequency_data import FrequencyData
from .._validate import as_positive_float
from ..model.siso import Model


class IdentifiabilityWarning(UserWarning):
    """The two smallest generalised singular values are close: the model is nearly unidentifiable."""


def _cost_limit(P: int) -> float:
    """3 times the cost's noise level (P-1)/(P-2); 10 for P = 2, 3 for known variances."""
    if P == 0:
        return 3.0
    return 10.0 if P == 2 else 3.0 * (P - 1) / (P - 2)


@dataclass(frozen=True)
class IdentificationResult:
    """What :func:`identify` returns (built from the core's ``Identification``)."""

    model: Model
    """The estimate, normalised so that a_{na,0} = 1 (or scaled by the known coefficients)."""
    method: str
    lines: np.ndarray
    """Rows (lines) of the fit."""
    theta: np.ndarray
    """All complex parameters: harmonics -K..K of a_0..a_na, then of b_0..b_nb."""
    eta: np.ndarray
    """The free real parameters (Re c_0, Re c_1, Im c_1, ... per free coefficient)."""
    n_free_parameters: int
    iterations: int
    """WGTLS: weighted solves after the GTLS start; SML: Levenberg-Marquardt steps; 0 otherwise."""
    converged: bool
    cost: float
    """The method's objective at the estimate (WGTLS: the smallest generalised eigenvalue;
    SML: V / (2 |rows|) with V the exact cost, METHOD.md eq. 17)."""
    cost_history: np.ndarray
    singular_values: np.ndarray
    """Generalised (GTLS, WGTLS, SML: those of the WGTLS start) or ordinary (TLS) singular values,
    ascending; empty for LS."""
    residue: np.ndarray
    """e_l = A(theta) Y - B(theta) U on the rows."""
    residue_variance: np.ndarray
    """var e_l with the estimate (METHOD.md eq. 15)."""
    normalized_residue: np.ndarray
    """|e_l| / sqrt(var e_l)."""
    fraction_above_0db: float
    fraction_expected: float
    fraction_band: Tuple[float, float]
    """Band around the expected fraction (3 binomial standard deviations)."""
    noise_free: bool
    """The data carried no noise, so GTLS/WGTLS reduced to TLS."""
    warnings: Tuple[str, ...] = field(default_factory=tuple)
    data: Optional[FrequencyData] = field(default=None, repr=False)
    eta_names: Tuple[str, ...] = field(default_factory=tuple)
    """Names of the entries of ``eta``, e.g. 'a0.re1' (Re of harmonic 1 of a_0)."""
    covariance: Optional[np.ndarray] = field(default=None, repr=False)
    """WGTLS and SML: covariance of ``eta`` (zero row and column for the normalised parameter),
    corrected for noise variances estimated from the periods (see :func:`covariance_correction`);
    None for LS, TLS and GTLS."""
    nearly_unidentifiable: bool = False
    """The two smallest generalised singular values are close while the residue test passes (LS,
    TLS: those of the GTLS problem on the same lines, whatever the residues); see :attr:`undetermined`."""
    unstable: Optional[str] = None
    """A sentence when the identified model is unstable (a Floquet multiplier outside the unit
    circle; also warned as :class:`lptv.UnstableModelWarning`), None otherwise. Steady-state data
    of a stabilised experiment identify an unstable system correctly; the sentence says what its
    predicted output means."""
    stability_undecided: Optional[str] = None
    """A sentence when the stability check could not decide within its cost bound (a_na(t)
    vanishing or nearly so: an over-fitted or unconverged estimate), None otherwise; also
    warned as :class:`lptv.StabilityUndecidedWarning`. ``lptv.floquet(res.model,
    max_truncation=...)`` can try harder."""
    experiment: Optional[np.ndarray] = field(default=None, repr=False)
    """Per row of ``lines``: the index of the experiment it belongs to (all 0 for one data set)."""
    experiments: Tuple[FrequencyData, ...] = field(default_factory=tuple, repr=False)
    """Several experiments fitted together: their data in the order given (``data`` is then None)."""
    structure: Optional[object] = field(default=None, repr=False, compare=False)
    """The core's Structure of the fit (orders, harmonic counts, known coefficients)."""
    noise: str = "sample"
    """'sample' (each line's own sample (co)variances) or 'moderated' (moderated across
    neighbouring lines, :func:`lptv.moderated_noise`): the noise model the fit weighed by."""
    noise_choice: str = "asked for"
    """Why ``noise`` is what it is: 'asked for', or with ``noise='auto'`` the smoothness check's
    sentence (e.g. "moderated: the noise spectrum is smooth across lines (prior degrees of
    freedom d0 = 1e+06 >= 6; 0 of 255 lines outlying)")."""
    moderation: Tuple[object, ...] = field(default_factory=tuple, repr=False, compare=False)
    """noise='moderated': per experiment, the :class:`lptv.ModeratedNoise` the fit used (None for
    an experiment whose variances could not be moderated); empty otherwise."""
    covariance_dof: Optional[np.ndarray] = field(default=None, repr=False, compare=False)
    """covariance='realisations': per entry of ``eta``, the degrees of freedom behind its variance
    (M - 1 for realisations of equal information, fewer where a few carry most of it; the
    variance is scaled so that eta +- 1.96 std is the t interval with them); None otherwise."""
    disturbances: Tuple[object, ...] = field(default_factory=tuple, repr=False, compare=False)
    """disturbances='remove': the :class:`lptv.Disturbance` sinusoids (off the period's grid)
    found in the records and subtracted before the fit; empty otherwise or when none was found."""
    covariance_option: str = "analytic"
    """The ``covariance`` argument of the fit: 'analytic', 'bootstrap', 'realisations' or
    'none' (no covariance computed)."""

    @property
    def n_experiments(self) -> int:
        """How many experiments (data sets) the fit used."""
        return max(len(self.experiments), 1)

    def _rows_of(self, e: int) -> np.ndarray:
        """Positions in ``lines`` of experiment e's rows."""
        return np.flatnonzero(self.experiment == e)

    @property
    def parameter_std(self) -> Optional[np.ndarray]:
        """WGTLS, SML: standard deviation of each entry of ``eta`` (None for the other methods)."""
        return None if self.covariance is None else np.sqrt(np.diag(self.covariance))

    def confidence_interval(self, level: float = 0.95) -> np.ndarray:
        """Two-sided intervals ``eta +- z std`` for each entry of ``eta``: array (n_eta, 2).

        ``z`` is the normal quantile of ``level``; the covariance is the calibrated one (the Monte
        Carlo in bench/HISTORY.md shows their coverage). The normalised parameter has a zero-width
        interval.

        Examples
        --------
        >>> import numpy as np, lptv
        >>> m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2)
        >>> ms = lptv.multisine(range(1, 60), 256, seed=0)
        >>> y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
        >>> rng = np.random.default_rng(1)
        >>> u = ms.periods(8) + 1e-3 * rng.standard_normal((8, 256))
        >>> y = np.tile(y1, (8, 1)) + 1e-3 * rng.standard_normal((8, 256))
        >>> res = lptv.identify(u, y, na=1, nb=0, w0=0.1, method="sml")
        >>> lo, hi = res.confidence_interval(0.95)[0]                # a0: true value 2
        >>> bool(lo < 2.0 < hi)
        True
        """
        from .._dist import norm_ppf

        level = as_positive_float(level, "level")
        if not 0.0 < level < 1.0:
            raise ValueError(f"level must be in (0, 1), got {level!r}")
        if self.covariance is None:
            raise ValueError(self._no_covariance()[0])
        half = norm_ppf(0.5 + level / 2.0) * self.parameter_std
        return np.column_stack([self.eta - half, self.eta + half])

    def htf_band(self, lines=None, branches=(0,), *, level: float = 0.95):
        """The model's HTF branches G_k(j w_l) at ``lines`` (default: the excited lines) with their
        first-order covariance: a :class:`lptv.judgement.uncertainty.HtfBand` (METHOD.md section 22)."""
        from .uncertainty import htf_band

        if self.covariance is None:
            raise ValueError(f"htf_band: {self._no_covariance()[0]}")
        return htf_band(self, lines, branches, level=level)

    def _no_covariance(self) -> Tuple[str, str]:
        """Why ``covariance`` is None: (the error's message, the summary's note)."""
        if self.covariance_option == "none":
            return ("no covariance was computed (covariance='none'): fit with covariance='analytic' for intervals",
                    "no covariance: covariance='none'")
        if self.method not in ("wgtls", "sml"):
            return (f"method {self.method!r} gives no covariance: use method='wgtls' or 'sml'",
                    "no covariance with this method")
        return "the covariance could not be computed (see the warnings)", "no covariance: see the warnings"

    @property
    def residue_ok(self) -> bool:
        """The fraction of normalised residues above 0 dB lies in the predicted band."""
        lo, hi = self.fraction_band
        return lo <= self.fraction_above_0db <= hi

    # -- the verdict --------------------------------------------------------------
    @cached_property
    def verdict_mask(self) -> np.ndarray:
        """Per row of ``lines``: does the verdict judge it (see :attr:`verdict_lines`)? With
        several experiments each experiment's own excited lines."""
        K = max(self.model.ka, self.model.kb)
        if self.experiments:
            mask = np.zeros(self.lines.size, bool)
            for e, d in enumerate(self.experiments):
                idx = self._rows_of(e)
                try:
                    mask[idx] = np.isin(self.lines[idx], excited_rows(d, K))
                except ValueError:
                    mask[idx] = True
            return mask if mask.any() else np.ones(self.lines.size, bool)
        if self.data is None:
            return np.ones(self.lines.size, bool)
        try:
            ex = excited_rows(self.data, K)
        except ValueError:
            return np.ones(self.lines.size, bool)
        mask = np.isin(self.lines, ex)
        return mask if mask.any() else np.ones(self.lines.size, bool)

    @cached_property
    def verdict_lines(self) -> np.ndarray:
        """The rows the verdict judges: the fit rows at the excited lines (and within +-K of them
        for an LPTV model); all fit rows when no line stands above the input noise. With several
        experiments, each experiment's own excited lines, in the order of ``lines``."""
        return self.lines[self.verdict_mask]

    def _periods(self) -> np.ndarray:
        """P per row of ``lines`` (0: statistics from elsewhere)."""
        if self.experiments:
            return np.array([d.periods for d in self.experiments])[self.experiment]
        return np.full(self.lines.size, self.data.periods if self.data is not None else 0)

    @cached_property
    def _verdict_stats(self):
        mask = self.verdict_mask
        r = self.normalized_residue[mask]
        n = int(mask.sum())
        frac = float(np.mean(r > 1.0)) if n else float("nan")
        n_free = int(round(self.n_free_parameters * n / max(self.lines.size, 1)))
        periods = self._periods()[mask]
        try:
            if np.all(periods == periods[0]):
                expected, band = _core.expected_fraction_above_0db(n, n_free, int(periods[0]))
            else:
                # Rows of experiments with different P: each row's own probability, the band
                # +-3 standard deviations of the count (as the core's fraction over all rows).
                p = np.array([_core.expected_fraction_above_0db(n, n_free, int(P))[0] for P in periods])
                expected = float(p.mean())
                half = 3.0 * np.sqrt(np.sum(p * (1 - p))) / n
                band = (max(0.0, expected - half), min(1.0, expected + half))
        except Exception:
            expected, band = self.fraction_expected, self.fraction_band
        return frac, float(expected), tuple(band)

    @property
    def verdict_fraction(self) -> float:
        """Fraction of normalised residues above 0 dB on :attr:`verdict_lines`."""
        return self._verdict_stats[0]

    @property
    def verdict_band(self) -> Tuple[float, float]:
        """The predicted band of :attr:`verdict_fraction` (3 binomial standard deviations)."""
        return self._verdict_stats[2]

    @property
    def cost_limit(self) -> Optional[float]:
        """WGTLS, SML: the cost above which the model is rejected. A model the noise explains has a
        cost near (P-1)/(P-2) (the mean of F(2, 2(P-1)) / 2 ... per row, sample variances); the limit
        is 3 times that (10 for P = 2, 3 for known variances). None for the other methods, whose
        cost is not normalised by the noise."""
        if self.method not in ("wgtls", "sml") or self.noise_free:
            return None
        if self.experiments:  # the cost is a mean over the rows: their limits' mean
            limits = [_cost_limit(P) for P in self._periods()]
            return float(np.mean(limits))
        return _cost_limit(self.data.periods if self.data is not None else 0)

    @cached_property
    def prediction_error_db(self) -> Optional[float]:
        """Mean power of Y - Y_model (the model's output from the measured mean input) over the
        variance that the noise gives it, on :attr:`verdict_lines`, in dB (about 0 dB for a model
        the noise explains). That variance is the output's plus the input noise carried through
        the model, sum_i |G_{l,i}|^2 var U_i (G the model's HTF): where the gain is high the
        input noise dominates it; and, for WGTLS and SML, the estimate's own uncertainty carried
        to the predicted output, g_l^T Cov(eta) g_l (g_l = dY_model,l / d eta): where the output is
        sensitive to the parameters it can exceed the noise of a line many times over. None
        without data or where it cannot be computed."""
        datas = self.experiments or ((self.data,) if self.data is not None else ())
        if not datas:
            return None
        from ..simulation.fds import simulate

        experiment = self.experiment if self.experiments else np.zeros(self.lines.size, int)
        err, noise = [], []
        for e, d in enumerate(datas):
            rows = self.lines[self.verdict_mask & (experiment == e)]
            if rows.size == 0:
                continue
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    Yp = np.asarray(simulate(self.model, d.U, warn_unstable=False))
            except Exception:
                return None
            if Yp.shape != d.Y.shape:
                return None
            from .verdict import prediction_variance, propagated_input_noise

            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    spread = propagated_input_noise(self.model, d, rows) + prediction_variance(self, d, rows, Yp)
            except (ValueError, _core.NumericalError):   # the model's HTF cannot be had
                return None
            err.append(np.abs(d.Y[rows] - Yp[rows]) ** 2)
            noise.append(d.varY[rows] + spread)
        if not err:
            return None
        err, noise = float(np.mean(np.concatenate(err))), float(np.mean(np.concatenate(noise)))
        if not (noise > 0 and err > 0):
            return None
        return float(10 * np.log10(err / noise))

    @cached_property
    def residue_tests(self):
        """The verdict's residue tests (:class:`lptv.verdict.ResidueTests`, METHOD.md section 7):
        every row that reads a line with signal is judged, per group of rows at the same distance
        from the excited lines and over all of them, each row's normalised residue corrected for
        the fit's shrinkage and put on a standard normal scale, the tests combined by Holm's
        method at an overall size of 1 %. None when the data carry no noise or were not kept."""
        from .verdict import residue_tests

        try:
            return residue_tests(self, self.structure)
        except (ValueError, np.linalg.LinAlgError, _core.NumericalError):
            return None

    @cached_property
    def lack_of_fit(self):
        """For a fit of all M realisations of one :class:`lptv.DistortionResult`
        (``d.experiments()``, the parametric best linear approximation): the model judged
        against the per-line regression across the realisations
        (:meth:`lptv.DistortionResult.lack_of_fit` on the fit's lines, METHOD.md section 16). The
        verdict then rests on it instead of :attr:`residue_tests`, whose reference (residues
        independent across lines, with the variances the data carry) the nonlinear distortion
        does not meet: on a Hammerstein system whose best linear approximation has the fitted
        structure those tests rejected every fit (bench/HISTORY.md). None for other data."""
        exps = self.experiments
        d = exps[0].distortion if exps else None
        if d is None or len(exps) != d.realisations or any(
                e.distortion is not d or e.realisation != k for k, e in enumerate(exps)):
            return None
        try:
            return d.lack_of_fit(self.model, lines=np.unique(self.lines))
        except (ValueError, _core.NumericalError):
            return None

    @property
    def judged_lines(self) -> np.ndarray:
        """The rows the residue tests judge: those that read an output or input line standing
        above its noise (within +-K of the row); for a fit of a DistortionResult's realisations
        the lines :attr:`lack_of_fit` judges."""
        lof = self.lack_of_fit
        if lof is not None:
            return lof.lines
        t = self.residue_tests
        return self.verdict_lines if t is None else self.lines[t.judged]

    PREDICTION_LIMIT_DB = 10.0
    """A prediction error this far above the output noise (dB) rejects the model."""

    @property
    def model_errors(self) -> Tuple[str, ...]:
        """The signs of a model error, each as a sentence (empty when none): a residue test of
        :attr:`residue_tests` that rejects (for a fit of a DistortionResult's realisations
        :attr:`lack_of_fit` instead; without either, residues outside the predicted band
        on the excited lines), a cost far above 1, a prediction error far above the noise (not for
        realisations weighed by their noise alone, ``referred='none'``, whose cost holds the
        distortion: the lack of fit alone judges those). Any one rejects the model, whatever the
        fraction on all rows says."""
        out = []
        lof = self.lack_of_fit
        tests = None if lof is not None else self.residue_tests
        if lof is not None:
            if lof.rejects:
                out.append(lof.sentence())
        elif tests is not None:
            out.extend(tests.sentences())
        else:
            lo, hi = self.verdict_band
            if not lo <= self.verdict_fraction <= hi:
                out.append(f"{100 * self.verdict_fraction:.1f} % of the normalised residues on the "
                           f"{self.verdict_lines.size} excited lines are above 0 dB, outside the predicted "
                           f"{100 * lo:.1f}-{100 * hi:.1f} %")
        if lof is not None and _noise_alone(self.experiments):
            # the realisations weighed by their noise alone: cost and prediction error hold the
            # distortion, which their limits (the noise's) leave out; the lack of fit judges
            return tuple(out)
        lim = self.cost_limit
        if lim is not None and self.cost > lim:
            out.append(f"the cost {self.cost:.3g} is far above its noise level (limit {lim:.3g})")
        gap = self.prediction_error_db
        if gap is not None and gap > self.PREDICTION_LIMIT_DB:
            out.append(f"the model's output misses the measured output by {gap:.1f} dB above the noise")
        return tuple(out)

    @property
    def model_ok(self) -> bool:
        """No sign of a model error (:attr:`model_errors` is empty)."""
        return not self.model_errors

    @property
    def undetermined(self) -> Optional[str]:
        """Why the data do not determine the estimate (None when they do).

        A residue test has no power when the noise explains anything: at a signal-to-noise ratio
        near 0 dB every model passes it. What exposes such a fit is the identifiability test of
        the core (:attr:`nearly_unidentifiable`: the two smallest generalised singular values of
        the noise-weighted problem are within the Marchenko-Pastur band of a noise-only
        subspace, i.e. a second parameter direction explains the data as well as the estimate;
        for LS and TLS the GTLS problem on the same lines is tested). The verdict then does not
        call the model consistent. A fit of a DistortionResult's M = 4 realisations is not
        determined either: its lack-of-fit test (:attr:`lack_of_fit`) cannot reach 1 %; nor is a fit
        that did not converge (``converged`` False: ``max_iter`` reached)."""
        if not self.converged:
            return (f"the fit did not converge in {self.iterations} iterations: the estimate is not a minimum of the "
                    "cost, so its residues cannot vouch for the model (more iterations, another start, or fewer "
                    "parameters)")
        lof = self.lack_of_fit
        if lof is not None and not lof.can_reject:
            return (f"{lof.realisations} realisations cannot show a lack of fit at {100 * lof.alpha:g} % "
                    f"(their {lof.permutations} permutations are the test's reference): measure 5 or more")
        if self.nearly_unidentifiable:
            sv = self.singular_values
            vals = f" ({sv[0]:.3g}, {sv[1]:.3g})" if sv.size >= 2 and self.method != "ls" else ""
            return ("the data do not determine the model: a second parameter direction explains them "
                    f"as well as the estimate (the two smallest generalised singular values are close{vals}); "
                    "too little signal above the noise, too many harmonics or too high orders")
        return None

    @property
    def verdict(self) -> str:
        """One sentence: is the model consistent with the noise, and if not, why. A fit the data
        do not determine (:attr:`undetermined`) is never called consistent."""
        if self.model_ok and self.undetermined is None:
            lof = self.lack_of_fit
            if lof is not None:
                return ("the model is consistent with the best linear approximation: no lack of fit against "
                        f"the per-line regression across the {lof.realisations} realisations (on "
                        f"{lof.lines.size} lines, permutation p = {lof.p_value:.2g})")
            where = (f"{self.judged_lines.size} rows with signal" if self.residue_tests is not None
                     else f"{self.verdict_lines.size} excited lines")
            return ("the model is consistent with the noise: the fit shows no sign of modelling errors "
                    f"(on the {where})")
        if self.model_ok:
            return "NOT DETERMINED: no sign of modelling errors, but " + self.undetermined
        out = "MODEL ERRORS: the model is rejected: " + "; ".join(self.model_errors)
        return out + ("; and " + self.undetermined if self.undetermined else "")

    def parameters(self, level: float = 0.95):
        """The parameter table: see :func:`lptv.parameter_table`."""
        from .parameters import parameter_table

        return parameter_table(self, level)

    def summary(self) -> str:
        lo, hi = self.fraction_band
        verdict = "in the predicted band" if self.residue_ok else "OUTSIDE the predicted band"
        lines = [
            f"method {self.method}: {self.n_free_parameters} free parameters on {self.lines.size} lines",
        ]
        if self.noise in ("full", "full-moderated", "full-rows"):
            lines.append("noise: from the whole record's bins between the lines (a disturbance that passes "
                         "through the system, METHOD.md section 20)")
        if self.noise in ("moderated", "full-moderated"):
            worth = [("not moderated" if m is None else f"worth about {d.periods} periods per line (prior degrees of freedom d0 = {m.prior_dof:.3g}"
                      + (f", {m.outliers.size} lines kept their own)" if m.outliers.size else ")"))
                     for m, d in zip(self.moderation, self.experiments or (self.data,))]
            lines.append("noise: moderated across neighbouring lines, " + "; ".join(worth))
        if self.noise_choice != "asked for":
            lines.append("noise route (noise='auto'): " + self.noise_choice)
        if self.disturbances:
            lines.append("removed before the fit: " + "; ".join(
                f"{d.signal}: a sinusoid at line {d.line:.3f} (amplitude {d.amplitude:.3g})" for d in self.disturbances))
        if self.experiments:
            lines.append(f"{self.n_experiments} experiments fitted together: " + "; ".join(
                f"#{e}: {self._rows_of(e).size} lines, P = {d.periods}, lines 0..{d.max_line}"
                for e, d in enumerate(self.experiments)))
        lines += [
            f"iterations {self.iterations}, converged {self.converged}, cost {self.cost:.4g}",
            f"normalised residue above 0 dB: {100 * self.fraction_above_0db:.1f} % "
            f"(expected {100 * self.fraction_expected:.1f} %, band {100 * lo:.1f}-{100 * hi:.1f} %): {verdict}",
        ]
        lof = self.lack_of_fit
        if lof is not None:
            lines[-1] += " (not the verdict's test for these realisations: the line below is)"
            lines.append(f"lack of fit against the per-line regression across the {lof.realisations} realisations: "
                         f"z = {lof.statistic:.2f}, permutation p = {lof.p_value:.2g} ({lof.permutations} permutations, "
                         f"{lof.lines.size} lines; the largest on lines {', '.join(str(int(j)) for j in lof.worst())})")
        from .parameters import format_parameter_table

        if self.covariance is None:
            head = f" ({self._no_covariance()[1]})"
        elif self.covariance_dof is not None:
            dof = self.covariance_dof[self.parameter_std > 0] if np.any(self.parameter_std > 0) else self.covariance_dof
            head = (f" (intervals from the {self.n_experiments} realisations' jackknife, its degrees of freedom "
                    f"{dof.min():.3g}-{dof.max():.3g})")
        elif lof is not None and _noise_alone(self.experiments, detected=False):
            head = (" (analytic intervals of the noise alone, without the nonlinear distortion: "
                    "covariance='realisations' includes it)")
        elif lof is not None:
            head = (" (analytic intervals take the lines' distortion independent; measured to cover 78-97 % per "
                    "parameter, less with the level referred to the input: covariance='realisations' is calibrated)")
        else:
            head = ""
        lines.append("parameters" + head + ":")
        lines.append(format_parameter_table(self))
        lines.append(f"verdict: {self.verdict}")
        lines += [f"warning: {w}" for w in self.warnings]
        if self.unstable:
            lines.append(f"warning: {self.unstable}")
        if self.stability_undecided:
            lines.append(f"warning: {self.stability_undecided}")
        return "\n".join(lines)


def excited_rows(data: FrequencyData, K: int = 0, ratio: float = 100.0) -> np.ndarray:
    """The lines the input excites (power above ``ratio`` times its noise variance) and, for
    K > 0, the lines within +-K of them, restricted to the usable rows K+1 .. Lmax-K.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.estimation.identify import excited_rows
    >>> ms = lptv.multisine([3, 5], 64, seed=0)
    >>> rng = np.random.default_rng(0)
    >>> u = ms.periods(4) + 1e-3 * rng.standard_normal((4, 64))
    >>> d = lptv.FrequencyData.from_periods(u, u, w0=1.0)
    >>> excited_rows(d).tolist(), excited_rows(d, K=1).tolist()
    ([3, 5], [2, 3, 4, 5, 6])
    """
    ex = np.asarray(_core.excited_lines(data._cpp, float(ratio)), dtype=int)
    if ex.size == 0:
        raise ValueError("lines='excited': no line of the input stands above its noise; pass lines explicitly")
    K = int(K)
    if 2 * K + 1 > data.max_line:  # no usable rows; and the +-K offsets below would not fit memory
        raise ValueError(f"lines='excited': no excited line lies within the usable rows {K + 1}..{data.max_line - K}")
    rows = np.unique((ex[:, None] + np.arange(-K, K + 1)[None, :]).ravel())
    rows = rows[(rows >= K + 1) & (rows <= data.max_line - K)]
    if rows.size == 0:
        raise ValueError(f"lines='excited': no excited line lies within the usable rows {K + 1}..{data.max_line - K}")
    return rows


def _noise_alone(datas, detected: bool = True) -> bool:
    """The experiments are DistortionResult.experiments(referred='none') (the realisations with
    their noise alone), and, with ``detected``, their distortion is detected."""
    return (bool(datas) and all(getattr(d, "referred", None) == "none" for d in datas)
            and (not detected or (datas[0].distortion is not None and datas[0].distortion.detected)))
