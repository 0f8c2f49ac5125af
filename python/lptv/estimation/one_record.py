"""One non-periodic record with its transient (METHOD.md section 17).

``lptv.identify_record(u, y, ...)``: a single record of L whole parameter periods, started from an
unknown state under an arbitrary input (no repeated periods). On the record's DFT grid (spacing
w0 / L) the model's harmonic k shifts a spectrum by k L lines, and the transient is a polynomial
T of degree max(na, nb) with real coefficients (section 17). The model and T are fitted by
output-error maximum likelihood (the input is taken as exact: one record cannot tell input noise
from input; the model discrete-time, or continuous-time with ``continuous=True``) in the C++ core (``lptv::fit_record``: the equation-error start, Levenberg-Marquardt
with the exact Jacobian on one factorisation of A per step, the residual's noise level, the
covariance); this module checks the arguments, takes the DFTs and, for ``noise="lpm"``, runs the
local polynomial method. The NumPy and SciPy route it replaced is :mod:`lptv.reference.record`.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from .. import _core
from .._validate import as_counts, as_int, as_positive_float, as_real_1d, as_seed
from ..model.siso import Model
from ..judgement.one_record_score import harmonic_score_tests, score_estimates, score_parts
from .one_record_input_noise import input_noise_operator, residue_covariance, sandwich, smooth, split_noise, stacked
from ..judgement.one_record_verdict import RecordVerdict, noisy_input_verdict, record_verdict, window_estimates


INPUT_NOISE_EXCESS = 8.0
"""``identify_record`` warns when the stated ``input_noise_std`` alone, through the fitted model,
would give more than this many times the residual the fit leaves on the lines where it is
largest (the 99th percentile over the lines of the ratio of the two levels, each averaged over
2 noise_width + 1 lines): a level the record cannot hold, such as a std in the wrong units.
Measured on the two systems of bench/python/bench_record_input_noise.py (15 records each at 2
and 10 % input noise): the right level gives 1.2-3.6 (the input noise can be all of a line's
residual, and the fit's leverage lowers the residual near the resonance), twice the right std
4.8-14 (a factor 4 in variance, not always told), so only a level about three times the right
std or more is flagged."""


@dataclass(frozen=True)
class RecordResult:
    """What :func:`identify_record` found."""

    model: Model
    """The estimated LPTV model (the record's own w0 and ts)."""
    eta: np.ndarray
    """Real parameters, named by ``eta_names`` (as ``lptv.identify``: Re a_na,0 = 1, its std 0)."""
    eta_names: list
    covariance: np.ndarray
    """Covariance of ``eta`` (output-error ML: the inverse Fisher information at the estimate;
    with ``input_noise_std`` the sandwich with the residue's covariance that the input noise
    adds, METHOD.md section 17, "A noisy input: the covariance and the verdict")."""
    parameter_std: np.ndarray
    transient: np.ndarray
    """Coefficients c_1..c_n of T(z) = sum c_j z^j (METHOD.md section 17: the record's boundary
    values weighted by the coefficients); continuous time c_0..c_d of T = sum c_j (j w_l ts)^j;
    empty without the transient term."""
    transient_std: np.ndarray
    periods: int
    """L: whole parameter periods in the record."""
    lines: np.ndarray
    """The record's DFT lines fitted (spacing w0 / L)."""
    noise_var: np.ndarray
    """Output noise variance E|V_l|^2 per fitted line (from the residual, the local polynomial
    method, or given); with ``input_noise_std`` the weights, that plus the input noise's share of
    each line."""
    noise_dof: int
    """Lines behind each line's variance: the residual route's average, or the local polynomial
    method's complex degrees of freedom (0 when given)."""
    Y: np.ndarray
    """Measured output spectrum on ``lines``."""
    Y_fit: np.ndarray
    """Predicted output spectrum (with the transient) on ``lines``."""
    cost: float
    """sum |Y - Y_fit|^2 / noise_var over the lines: about the number of real residues
    2 n_lines minus the parameters when the model and the noise level are right."""
    dof: int
    """2 n_lines - number of real parameters."""
    converged: bool
    iterations: int
    """Levenberg-Marquardt iterations of the last fit (the residual route fits three times)."""
    record_verdict: Optional[RecordVerdict] = None
    """The cross-correlation test of the residual with the input and its shifts
    (:mod:`lptv.record_verdict`), which needs no noise level, and the score tests: behind
    :attr:`model_ok`. With ``input_noise_std`` both take the input noise's covariance and bias
    into account (METHOD.md section 17)."""
    warnings: Tuple[str, ...] = ()
    """What the fit warned about (also issued as warnings): no convergence, a noise level the
    residual contradicts, the bias a noisy input causes."""
    input_noise_bias: Optional[np.ndarray] = None
    """With ``input_noise_std``: the first-order bias of ``eta`` that the input's noise causes
    (the output-error fit takes the input as exact), measured by refitting with that much more
    noise added to the input (METHOD.md section 17, "A noisy input"); None otherwise."""
    input_noise_spread: Optional[np.ndarray] = None
    """The standard deviation of those refits' shifts per parameter (None without
    ``input_noise_std``)."""

    @property
    def eta_corrected(self) -> np.ndarray:
        """``eta`` less :attr:`input_noise_bias` (``eta`` itself without ``input_noise_std``)."""
        return self.eta if self.input_noise_bias is None else self.eta - self.input_noise_bias

    @property
    def std_corrected(self) -> np.ndarray:
        """The std of :attr:`eta_corrected`: ``parameter_std`` with the bias estimate's own
        sampling variance (spread^2 / draws) added."""
        if self.input_noise_bias is None:
            return self.parameter_std
        return np.sqrt(self.parameter_std ** 2 + self.input_noise_spread ** 2 / self.input_noise_draws)

    input_noise_draws: int = 0
    """The refits behind :attr:`input_noise_bias` (0 without ``input_noise_std``)."""

    def confidence_interval(self, level: float = 0.95) -> np.ndarray:
        """Two-sided intervals ``eta +- z std`` for each entry of ``eta``: array (n_eta, 2).

        ``z`` is the normal quantile of ``level``. With ``input_noise_std`` the intervals are
        those of the corrected estimate, ``eta_corrected +- z std_corrected`` (the input noise's
        bias removed, its share of the variance and the bias estimate's own included: METHOD.md
        section 17, "A noisy input"); without it ``eta +- z parameter_std``. The normalised
        parameter has a zero-width interval.

        Examples
        --------
        >>> import numpy as np, lptv
        >>> from lptv.examples import discrete_model
        >>> m = discrete_model()
        >>> u, y = lptv.examples.transient_record(m, periods=4, noise_std=0.01, seed=1)
        >>> res = lptv.identify_record(u, y, na=2, nb=1, ka=[2, 1, 0], kb=[2, 0], w0=m.w0, ts=1.0)
        >>> res.confidence_interval(0.95).shape == (res.eta.size, 2)
        True
        """
        from .._dist import norm_ppf

        level = as_positive_float(level, "level")
        if not 0.0 < level < 1.0:
            raise ValueError(f"level must be in (0, 1), got {level!r}")
        half = norm_ppf(0.5 + level / 2.0) * self.std_corrected
        return np.column_stack([self.eta_corrected - half, self.eta_corrected + half])

    @property
    def cost_ratio(self) -> float:
        """cost / dof: about 1 when the model and the noise level fit the data."""
        return self.cost / self.dof

    @property
    def model_errors(self) -> Tuple[str, ...]:
        """The signs of a model error, each as a sentence (empty when none): the residual
        explained by the input on the same line (an order too few) or shifted by k w0 (a
        missing harmonic k), or by a coefficient's next harmonic (its score test), at the
        verdict's size of 1 % (Holm over the tests); a fit that did not converge."""
        errs = () if self.record_verdict is None else self.record_verdict.model_errors
        if not self.converged:
            errs = errs + (f"the fit did not converge in {self.iterations} iterations: its estimate is not "
                           "the likelihood's optimum",)
        return errs

    @property
    def model_ok(self) -> bool:
        """No sign of a model error (:attr:`model_errors` is empty)."""
        return not self.model_errors

    @property
    def verdict(self) -> str:
        """One sentence: is the model consistent with the record, and if not, why."""
        if self.model_ok:
            v = self.record_verdict
            more = (f", and no coefficient's next harmonic explains it ({len(v.score_tests)} score tests, "
                    f"smallest p = {min(t[4] for t in v.score_tests):.2g})") if v.score_tests else ""
            return ("the model is consistent with the record: its residual is not explained by the input or "
                    f"its shifts by up to {max(v.shifts)} w0 (F = {v.statistic:.3g}, p = {v.p_value:.2g})" + more
                    + f"; Holm's size {100 * v.alpha:g} %")
        return "MODEL ERRORS: " + "; ".join(self.model_errors)


def _record_periods(n_total, n0, name):
    if n_total % n0:
        raise ValueError(f"{name} must hold a whole number of parameter periods of {n0} samples, "
                         f"got {n_total} samples ({n_total / n0:.3f} periods): drop "
                         f"{n_total % n0} samples at the start")
    return n_total // n0


EXCITED_RATIO = 1e-2
"""A line of the record's input carries content when its power is at least this share (-20 dB,
the periodic route's line ratio) of the input's mean power per line; the fitted lines are
excited when their mean power per line is."""


def _span(lines, dw) -> str:
    n = len(lines)
    if n == 1:
        return f"line {lines[0]} ({lines[0] * dw:.4g} rad/s)"
    return f"lines {lines[0]} to {lines[-1]} ({n} lines, {lines[0] * dw:.4g} to {lines[-1] * dw:.4g} rad/s)"


def _check_excited(U, lines, L, kmax, continuous, dw):
    """Refuses a record whose input has no content on the fitted lines and the lines their
    harmonics reach (l + k L, |k| <= kmax): the fit would read the output's transient and noise
    alone, and its verdict, a regression on that input, could not see it."""
    N = U.size
    half = np.arange(1, (N + 1) // 2)
    power = np.abs(U[half]) ** 2
    mean = power.mean() if power.size else 0.0
    reach = (np.asarray(lines)[:, None] + L * np.arange(-kmax, kmax + 1)[None, :]).ravel() % N
    reach = np.minimum(reach, N - reach)
    region = np.unique(reach[(reach >= 1) & (reach < (N + 1) // 2)])
    where = f"the fitted {_span(list(lines), dw)}" + (f" and their +-{kmax} w0 neighbours" if kmax else "")
    if not mean > 0 or not np.isfinite(mean):
        raise ValueError("u: the input spectrum is zero on every line of the record (a constant, dead or "
                         "disconnected input channel): the system is not excited, so nothing can be identified")
    inside = power[region - 1].mean()
    if inside >= EXCITED_RATIO * mean:
        return
    mask = np.zeros(half.size, bool)
    mask[region - 1] = True
    elsewhere = half[(power >= EXCITED_RATIO * mean) & ~mask]
    fix = ("; a continuous-time fit reads the lines up to a quarter of the Nyquist frequency: an input with "
           "content there, a discrete-time model (continuous=False), or lines where the input is excited "
           "(lines=...)" if continuous else "; fit lines at or next to those the input excites (lines=...)")
    level = (f"its power per line on the fitted ones is {10 * np.log10(mean / inside):.0f} dB below its mean over the record"
             if inside > 0 else "its spectrum is zero on the fitted ones")
    raise ValueError(f"u: the input is not excited on {where}: "
                     + (f"it is excited on {_span(list(elsewhere), dw)}, " if elsewhere.size else "")
                     + f"{level}, so the fit would read the output's transient and noise alone" + fix)


def local_polynomial_noise(U, Y, L, lines, *, branches: int, degree: int = 2, half_width: Optional[int] = None,
                           transient: bool = True):
    """Output noise variance per line by the local polynomial method on the record's grid.

    On the 2R + 1 lines l + r around line l: Y_{l+r} = sum_{|k|<=branches} P_k(r) U_{l+r-kL} +
    P_T(r) + V, each P a complex polynomial of ``degree`` (the HTF's branches and the output
    transient, smooth across lines); the residual's mean square over its 2R + 1 - q complex
    degrees of freedom is the line's variance, then averaged over the 2R + 1 lines around it
    (noise spectra are smooth; the average steadies the weights). Returns (variance, dof).
    """
    N = U.size
    q = (2 * branches + 1 + (1 if transient else 0)) * (degree + 1)
    R = q if half_width is None else half_width
    if 2 * R + 1 <= q:
        raise ValueError(f"half_width must leave degrees of freedom: 2 R + 1 > {q}, got R = {R}")
    r = np.arange(-R, R + 1)
    powers = np.stack([r.astype(float) ** d for d in range(degree + 1)], axis=1)  # (2R+1, D+1)
    lo, hi = max(1, int(lines.min()) - 2 * R), min(N // 2, int(lines.max()) + 2 * R)
    est = {}
    for l in range(lo, hi + 1):
        m = (l + r) % N
        cols = []
        for k in range(-branches, branches + 1):
            cols.append(powers * U[(m - k * L) % N][:, None])
        if transient:
            cols.append(powers.astype(complex))
        X = np.concatenate(cols, axis=1)
        g, *_ = np.linalg.lstsq(X, Y[m], rcond=None)
        res = Y[m] - X @ g
        est[l] = np.sum(np.abs(res) ** 2) / (2 * R + 1 - q)
    var = np.array([np.mean([est[j] for j in range(max(lo, l - R), min(hi, l + R) + 1)]) for l in lines])
    return var, 2 * R + 1 - q


def identify_record(u, y, *, na: int, nb: int, ka=0, kb=0, w0: float, ts: float, lines=None, transient: bool = True, noise="residual",
                    noise_width: int = 10, lpm_branches: Optional[int] = None, lpm_degree: int = 2,
                    max_iterations: int = 100, continuous: bool = False,
                    transient_degree: Optional[int] = None, input_noise_std: Optional[float] = None,
                    input_noise_draws: int = 8, seed=None) -> RecordResult:
    """Identify an LPTV model from one record (not periodic, with a start-up transient).

    Parameters
    ----------
    u, y : array_like, 1-D
        The record: input and output samples, L whole parameter periods (the start of a longer
        record can be dropped to make it whole).
    na, nb, ka, kb
        The structure, as for :func:`lptv.identify` (ka, kb: a count for all coefficients or one
        per coefficient).
    w0 : float
        The parameter fundamental (rad/s), 2 pi / period.
    ts : float
        The sample time of the record; with ``continuous=False`` also that of the discrete-time
        model (forward shift, as :class:`lptv.Model` with ``ts``), where the transient term is
        exact.
    lines : sequence of int, optional
        The record's DFT lines to fit (spacing w0 / L). Default: 1..N/2 - 1; continuous time
        1..(N - 1) // 8 (a quarter of the Nyquist frequency, see ``continuous``).
    transient : bool
        Estimate the transient term (False: the steady-state model alone, biased by the
        transient; for comparison).
    noise : {"residual", "lpm"} or float or array
        The output noise variance E|V_l|^2 per line. ``"residual"`` (default): from the fit's own
        residual, |Y_l - Y_fit,l|^2 over 1 - h_l (h_l the line's leverage in the fit: the share
        of its noise the parameters absorb) averaged over the 2 ``noise_width`` + 1 lines around
        l, the fit then repeated with those weights (twice); it needs the structure to be right.
        ``"lpm"``: the local polynomial method (:func:`local_polynomial_noise`), which needs no
        model but assumes the HTF's branches beyond ``lpm_branches`` negligible and each branch
        and the output transient locally polynomial over its window: on a strongly time-varying
        system (far branches decaying slowly) it overestimates the noise (METHOD.md section 17).
        A number or one per line: the variance, when known.
    noise_width : int
        Half width of the residual route's average.
    lpm_branches : int, optional
        HTF branches of the local polynomial method (default: the largest harmonic count + 1).
    lpm_degree : int
        Degree of its local polynomials.
    max_iterations : int
        Bound on the Levenberg-Marquardt iterations.
    continuous : bool
        Fit a continuous-time model (:class:`lptv.Model` without ``ts``, derivatives) to the
        record sampled every ``ts`` seconds. The input must be band-limited below the Nyquist
        frequency (its samples must describe it: not a zero-order hold), and the fitted lines
        well below Nyquist: the transient term T = sum_{j=0}^{d} c_j (j w_l ts)^j is exact for
        the record's Fourier coefficients at degree n - 1 but the DFT of samples adds the
        record's jump (degree n) and its aliasing; at degree n + 1 (the default) what remains
        falls like (w ts)^4 (METHOD.md section 17: measured 1e-5 to 7e-5 of the output's rms,
        in noise-equivalent std, with the fitted band at a quarter of Nyquist).
    transient_degree : int, optional
        Continuous time: d, at least n - 1; default n + 1 (n = max(na, nb)). Not for
        discrete time.
    input_noise_std : float, optional
        The standard deviation of the input's measurement noise (white, in the units of u), when
        it is known (a sensor's specification, a record at rest). The fit takes the input as
        exact, so a noisy input biases it (towards a smaller gain, about the input's
        noise-to-signal power ratio); with this the bias is measured to first order by refitting
        with as much noise again added to the input, ``input_noise_draws`` times, and reported
        (``input_noise_bias``, in the warnings in std units) and removed in ``eta_corrected``,
        whose std ``std_corrected`` is (``confidence_interval`` gives its intervals). The input
        noise also adds to each line's residue, through the model's HTF branches, and correlates
        the lines that share input lines: with this the weights are each line's output noise
        plus that share, ``covariance`` the sandwich with the residue's full covariance, and the
        verdict's tests account for it and for the bias (METHOD.md section 17, "A noisy input:
        the covariance and the verdict"); ``noise_var`` then holds the weights. Measured
        (bench/HISTORY.md, "One record with a noisy input: the covariance and the verdict"; a
        discrete LPTV system, 400 records per level): at 2-10 % input noise the corrected 95 %
        intervals cover 94.6-96.1 % pooled (92.8-98.5 % per parameter), the verdict rejects
        the right structure in 0-1 % of the records (0.5-28 % without ``input_noise_std``).
        Its cost: 0.35 s on a record of 512 samples against 0.04 s without (the refits' score
        and window estimates, the Jacobians by differences).
    input_noise_draws : int
        Refits behind the bias (each one fit's cost).
    seed : int or numpy Generator, optional
        The draws' random numbers (in a simulation study, not the stream that made the record's
        input: draws equal to the input's own samples are not independent of it).

    Raises
    ------
    ValueError
        Besides bad arguments, an input without content on the fitted lines and the lines their
        harmonics reach (their mean power per line below 1 % of the input's over the record, as
        an input above the continuous route's band): "u: the input is not excited on the fitted
        lines ..., it is excited on lines ...".

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import discrete_model, DISCRETE_N
    >>> m = discrete_model()
    >>> u, y = lptv.examples.transient_record(m, periods=4, noise_std=0.01, seed=1)
    >>> res = lptv.identify_record(u, y, na=2, nb=1, ka=[2, 1, 0], kb=[2, 0], w0=m.w0, ts=1.0)
    >>> res.periods, res.converged, 0.7 < res.cost_ratio < 1.3
    (4, True, True)
    """
    u = as_real_1d(u, "u", min_len=2)
    y = as_real_1d(y, "y", min_len=2)
    if u.shape != y.shape:
        raise ValueError(f"u and y must have the same length, got {u.size} and {y.size}")
    if not isinstance(continuous, (bool, np.bool_)):
        raise ValueError(f"continuous must be a bool, got {continuous!r}")
    continuous = bool(continuous)
    if transient_degree is not None:
        if not continuous:
            raise ValueError("transient_degree is for continuous time only (the discrete-time term "
                             f"z^1..z^n is exact), got {transient_degree!r}")
    step, name = ts, "ts"
    if isinstance(step, (bool, np.bool_)) or not (isinstance(step, (int, float, np.floating, np.integer)) and np.isfinite(step) and step > 0):
        raise ValueError(f"{name} must be a positive number of seconds, got {step!r}")
    if not (isinstance(w0, (int, float, np.floating, np.integer)) and np.isfinite(w0) and w0 > 0):
        raise ValueError(f"w0 must be a positive angular frequency (rad/s), got {w0!r}")
    n0f = 2 * np.pi / (w0 * step)
    n0 = int(round(n0f))
    if n0 < 2 or abs(n0f - n0) > 1e-9 * n0f:
        raise ValueError(f"w0 and {name} must give a whole number of samples per period, "
                         f"2 pi / (w0 {name}) = {n0f:.6g}")
    N = u.size
    L = _record_periods(N, n0, "u")
    na = as_int(na, "na", minimum=1, maximum=50)
    nb = as_int(nb, "nb", minimum=0, maximum=50)
    ka_l, kb_l = as_counts(ka, na, "ka"), as_counts(kb, nb, "kb")
    max_iterations = as_int(max_iterations, "max_iterations", minimum=1, maximum=10**5)
    lpm_degree = as_int(lpm_degree, "lpm_degree", maximum=6)
    n_order = max(na, nb)
    if transient_degree is not None:
        transient_degree = as_int(transient_degree, "transient_degree", minimum=n_order - 1,
                                  maximum=n_order + 20)
    t_degree = (n_order + 1 if transient_degree is None else transient_degree) if continuous else -1
    par = _core.Parametrisation(na, nb, ka_l, kb_l, [], float(w0), 0.0 if continuous else float(ts))
    if lines is None:
        lines = np.arange(1, (N - 1) // 8 + 1) if continuous else np.arange(1, N // 2)
    else:
        lines = np.unique(np.asarray(lines))
        if lines.size == 0 or not np.issubdtype(lines.dtype, np.integer):
            raise ValueError(f"lines must be whole line numbers, got {lines!r}")
        if lines.min() < 1 or lines.max() > N // 2 - 1:
            raise ValueError(f"lines must lie in 1..{N // 2 - 1} (the record's grid), got "
                             f"{lines.min()}..{lines.max()}")
    U = np.fft.fft(u) / N
    Y = np.fft.fft(y) / N
    kmax = max(ka_l + kb_l)
    _check_excited(U, lines, L, kmax, continuous, w0 / L)
    nT = (t_degree + 1 if continuous else n_order) if transient else 0
    n_eta = len(par.free_indices)        # the free real parameters (eta without Re a_na,0 = 1)
    if 2 * lines.size <= n_eta + nT:
        raise ValueError(f"lines: {lines.size} lines give {2 * lines.size} real equations for "
                         f"{n_eta + nT} parameters")

    # the noise level
    noise_width = as_int(noise_width, "noise_width", minimum=1, maximum=10**6)
    if isinstance(noise, str):
        if noise not in ("residual", "lpm"):
            raise ValueError(f"noise must be 'residual', 'lpm' or a variance, got {noise!r}")
        if noise == "lpm":
            branches = kmax + 1 if lpm_branches is None else as_int(lpm_branches, "lpm_branches", maximum=10**4)
            var, noise_dof = local_polynomial_noise(U, Y, L, lines, branches=branches, degree=lpm_degree)
        else:
            var, noise_dof = np.ones(lines.size), 0
    else:
        if isinstance(noise, (bool, np.bool_)):
            raise ValueError(f"noise must be 'residual', 'lpm' or a variance, got {noise!r}")
        try:
            var = np.broadcast_to(np.asarray(noise, dtype=float), lines.shape).copy() \
                if np.ndim(noise) == 0 else np.asarray(noise, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"noise must be 'residual', 'lpm' or a variance, got {noise!r}") from None
        if var.shape != lines.shape or not np.all(np.isfinite(var)) or np.any(var <= 0):
            raise ValueError(f"noise must be positive and finite, a scalar or one per line "
                             f"({lines.size}), got shape {np.shape(noise)}")
        noise_dof = 0

    residual = isinstance(noise, str) and noise == "residual"
    if input_noise_std is not None:
        input_noise_std = as_positive_float(input_noise_std, "input_noise_std")
        draws = as_int(input_noise_draws, "input_noise_draws", minimum=2, maximum=1000)
    fit_args = dict(transient=bool(transient), noise_width=noise_width, max_iterations=max_iterations,
                    ts=float(ts), transient_degree=t_degree)
    line_list = [int(v) for v in lines]
    fit = _core.fit_record(par, U, Y, L, line_list, noise_var=None if residual else var, **fit_args)
    if residual:
        var, noise_dof = np.asarray(fit.noise_var), fit.noise_dof
    free = list(par.free_indices)
    ts_par = 0.0 if continuous else float(ts)
    idx = lines + (N - 1) // 2 if continuous else lines
    sigma = excess = None
    if input_noise_std is not None:
        # the input noise's share of each line's residue (METHOD.md section 17, "A noisy input: the
        # covariance and the verdict"): into the weights, then the sandwich covariance
        M = input_noise_operator(par, L, np.asarray(fit.eta)[free], float(ts), t_degree, idx, lines, N)
        out_var, cu = split_noise(var, stacked(M), input_noise_std, noise_width, isinstance(noise, str))
        if isinstance(noise, str):
            # the stated input noise alone, through the model, against the residual's own level:
            # well above 1 it is more noise than the record's residual holds
            excess = float(np.quantile(smooth(cu, noise_width) / var, 0.99))
        var = out_var + cu
        fit = _core.fit_record(par, U, Y, L, line_list, noise_var=var, **fit_args)
        Mr = stacked(input_noise_operator(par, L, np.asarray(fit.eta)[free], float(ts), t_degree, idx, lines, N))
        scale = np.sqrt(2.0 / np.concatenate([var, var]))
        sigma = scale[:, None] * residue_covariance(out_var, Mr, input_noise_std) * scale[None, :]

    # the estimated model: theta's harmonics laid out as Model holds them
    Ka, Kb = max(ka_l), max(kb_l)
    a = np.zeros((na + 1, 2 * Ka + 1), dtype=complex)
    b = np.zeros((nb + 1, 2 * Kb + 1), dtype=complex)
    for (is_a, order, k), v in zip(par.params, np.asarray(fit.theta)):
        if is_a:
            a[order, Ka + k] = v
        else:
            b[order, Kb + k] = v
    cov_eta = np.asarray(fit.covariance)
    transient_std = np.asarray(fit.transient_std)
    Y_fit = np.asarray(fit.Y_fit)
    structure = (na, nb, ka_l, kb_l, w0, ts_par)
    tail = (float(ts), t_degree, continuous)
    parts = score_parts(*structure, U, Y[lines] - Y_fit, L, lines, np.asarray(fit.eta), np.asarray(fit.transient),
                        var, *tail)
    said = []
    bias = spread = None
    draws_est, draws_win = [], []
    if input_noise_std is not None:
        cov_x = sandwich(parts.J, sigma)
        nf = len(free)
        cov_eta = np.zeros_like(cov_eta)
        cov_eta[np.ix_(free, free)] = cov_x[:nf, :nf]
        transient_std = np.sqrt(np.maximum(np.diag(cov_x)[nf:], 0.0))
        # the bias: K refits on the input with as much noise again, the same output and weights
        rng = as_seed(seed)
        shifts = []
        for _ in range(draws):
            ud = u + input_noise_std * rng.standard_normal(u.size)
            Ud = np.fft.fft(ud) / N
            fd = _core.fit_record(par, Ud, Y, L, line_list, noise_var=var, **fit_args)
            shifts.append(np.asarray(fd.eta) - np.asarray(fit.eta))
            res_d = Y[lines] - np.asarray(fd.Y_fit)
            draws_est.append(score_estimates(score_parts(
                *structure, Ud, res_d, L, lines, np.asarray(fd.eta), np.asarray(fd.transient), var, *tail)))
            draws_win.append(window_estimates(Ud, res_d / np.sqrt(var), lines, L, kmax))
        shifts = np.array(shifts)
        bias, spread = shifts.mean(axis=0), shifts.std(axis=0, ddof=1)
    scores = harmonic_score_tests(*structure, U, Y[lines] - Y_fit, L, lines, np.asarray(fit.eta),
                                  np.asarray(fit.transient), var, *tail, parts=parts, sigma=sigma,
                                  draws=draws_est)
    if input_noise_std is None:
        verdict = record_verdict(U, (Y[lines] - Y_fit) / np.sqrt(var), lines, L, kmax, scores=scores)
    else:
        level = parts.cost / (float(np.trace(sigma)) - float(np.sum(parts.Q * (sigma @ parts.Q))))
        verdict = noisy_input_verdict(U, (Y[lines] - Y_fit) / np.sqrt(var), lines, L, kmax, sigma=sigma / 2,
                                      level=level, dof=int(fit.dof), noise_power=input_noise_std ** 2 / N,
                                      draws=draws_win, scores=scores)
    if not fit.converged:
        said.append(f"identify_record: the fit did not converge in {int(fit.iterations)} iterations "
                    f"(max_iterations={max_iterations}); its estimate is not the likelihood's optimum")
    if isinstance(noise, str) and noise == "lpm":
        ratio = float(fit.cost) / int(fit.dof)
        if ratio < 0.25:
            said.append(f"identify_record: the local polynomial method's noise level is {1 / ratio:.3g} times "
                        "what the fit's residual shows: it overestimates the noise where the HTF's branches "
                        "decay slowly (raise lpm_branches), and weighs the lines wrongly; use noise='residual'")
    if excess is not None and excess > INPUT_NOISE_EXCESS:
        said.append(f"identify_record: input_noise_std = {input_noise_std:.3g} is more input noise than this record "
                    f"holds: through the model it alone would give {excess:.3g} times the residual the fit leaves "
                    "(the 99th percentile over the lines); the estimates and intervals rest on it. Give the std of the input "
                    "sensor's noise in the input's own units (a record at rest measures it)")
    if input_noise_std is not None:
        std = np.sqrt(np.diag(cov_eta))
        isfree = std > 0
        worst = int(np.argmax(np.where(isfree, np.abs(bias) / np.where(isfree, std, 1), -1)))
        snr = 10 * np.log10(np.var(u) / input_noise_std ** 2)
        said.append(f"identify_record: the input's noise (std {input_noise_std:.3g}, SNR {snr:.1f} dB) biases the "
                    f"output-error estimate by up to {abs(bias[worst]) / std[worst]:.2g} std ({par.eta_names[worst]}); "
                    "eta_corrected removes it (std_corrected)")
    else:
        draws = 0
    for msg in said:
        warnings.warn(msg, RuntimeWarning, stacklevel=2)
    return RecordResult(
        model=Model(a, b, w0=float(w0), ts=None if continuous else ts), eta=np.asarray(fit.eta), eta_names=list(par.eta_names),
        covariance=cov_eta, parameter_std=np.sqrt(np.diag(cov_eta)), transient=np.asarray(fit.transient),
        transient_std=transient_std, periods=L, lines=lines, noise_var=var,
        noise_dof=int(noise_dof), Y=Y[lines], Y_fit=Y_fit, cost=float(fit.cost),
        dof=int(fit.dof), converged=bool(fit.converged), iterations=int(fit.iterations),
        record_verdict=verdict, warnings=tuple(said), input_noise_bias=bias, input_noise_spread=spread,
        input_noise_draws=draws)
