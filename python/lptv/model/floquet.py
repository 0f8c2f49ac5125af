"""Stability of the periodic system: Floquet multipliers and exponents (METHOD.md section 12)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Tuple

import numpy as np

from .. import _core
from .._validate import as_int, as_positive_float
from .mimo import MimoModel
from .siso import Model

__all__ = ["FloquetResult", "UnstableModelWarning", "floquet", "monodromy", "stability_check",
           "StabilityUndecidedWarning"]


class UnstableModelWarning(UserWarning):
    """The model is unstable (a Floquet multiplier outside the unit circle, an exponent with a
    positive real part): its periodic steady state solves the equation, but a simulation from
    rest does not settle into it (deviations grow like ``spectral_radius ** (t / T0)``)."""


class StabilityUndecidedWarning(UserWarning):
    """The stability check of an identified model could not decide within its cost bound
    (:func:`stability_check`): typically a_na(t) vanishes or nearly vanishes over the period."""


@dataclass(frozen=True)
class FloquetResult:
    """Result of :func:`floquet`."""

    multipliers: np.ndarray
    """The na characteristic multipliers mu_i by decreasing magnitude (conjugate pairs with the
    positive imaginary part first): the eigenvalues of the monodromy matrix. Continuous time:
    ``exp(exponents * period)``, which underflows to 0 for exponents below about -745 / T0."""
    exponents: np.ndarray
    """Floquet exponents lambda_i = ln(mu_i) / T0 in 1/s on the principal branch,
    ``-w0/2 < Im lambda <= w0/2``; defined modulo j w0 only (lambda + j n w0 gives the same
    multiplier). Discrete time: the same with T0 = N ts, and -inf for a zero multiplier."""
    is_stable: bool
    """Every |mu_i| < 1 by more than its estimated error (asymptotic stability). A multiplier
    within its error of the unit circle (a marginal system) counts as not stable."""
    spectral_radius: float
    """max |mu_i| (0 for na = 0)."""
    error_estimate: np.ndarray
    """Estimated relative error of each multiplier (see :func:`floquet`)."""
    truncation: int
    """Continuous time: M, the harmonics -M..M of the last Hill matrix; 0 in discrete time."""
    harmonics: int
    """Continuous time: harmonics of F(t) kept (those above eps of the largest); 0 in discrete time."""
    convergence: float
    """Continuous time: largest change of ln(mu_i) between the last two truncations."""
    method: str
    """'hill' (continuous time) or 'product' (discrete time)."""
    period: float
    """T0 = 2 pi / w0 in seconds."""
    exponents_std: Optional[np.ndarray] = None
    """Of an identification result (METHOD.md section 22): (n, 2), the std of Re and Im of each
    exponent (1/s, rad/s); None for a model."""
    exponents_covariance: Optional[np.ndarray] = field(default=None, repr=False)
    """First order: (2n, 2n), the covariance of (Re l_0, Im l_0, Re l_1, ...); bootstrap: the draws'."""
    stable_probability: Optional[float] = None
    """P(every decay rate Re lambda_i < 0) under the estimate's distribution (the normal
    approximation of the first-order route, or the bootstrap draws' fraction); None for a model."""
    first_order_ok: Optional[bool] = None
    """False where first order does not hold (a repeated exponent, a pair about to split or to
    meet: see ``uncertainty_notes``); None for a model."""
    uncertainty_notes: Tuple[str, ...] = ()
    """Sentences on the intervals: where first order fails, an undecided stability."""
    uncertainty_method: Optional[str] = None
    """'first-order' or 'bootstrap' (None for a model)."""
    condition: Optional[np.ndarray] = field(default=None, repr=False)
    """First order, one output: each exponent's eigenvalue condition number |u| |v| / |u^H v|."""
    draws: Optional[np.ndarray] = field(default=None, repr=False)
    """Bootstrap: the exponents of the B draws (B, n), on the branches of ``exponents``."""

    def _need_uncertainty(self):
        if self.exponents_std is None:
            raise ValueError("this FloquetResult carries no uncertainty: pass the identification result "
                             "(lptv.floquet(res)), not its model")

    def confidence_interval(self, level: float = 0.95) -> np.ndarray:
        """(n, 2, 2): ``[i, 0]`` the interval of Re lambda_i (1/s), ``[i, 1]`` that of Im lambda_i
        (rad/s, on the branch of ``exponents``), two-sided at ``level``: the normal one
        (first order) or the draws' percentiles (bootstrap)."""
        from .._dist import norm_ppf
        from .._validate import as_float

        level = as_float(level, "level", minimum=0.0, maximum=1.0, open_min=True, open_max=True)
        self._need_uncertainty()
        lam = self.exponents
        if self.draws is not None:
            q = np.array([0.5 - level / 2, 0.5 + level / 2])
            re = np.quantile(self.draws.real, q, axis=0).T
            im = np.quantile(self.draws.imag, q, axis=0).T
            return np.stack([re, im], axis=1)
        z = float(norm_ppf(0.5 + level / 2.0))
        mid = np.stack([lam.real, lam.imag], axis=1)
        return np.stack([mid - z * self.exponents_std, mid + z * self.exponents_std], axis=2)

    @property
    def multiplier_modulus_std(self) -> np.ndarray:
        """First-order std of |mu_i| = exp(T0 Re lambda_i): T0 |mu_i| std(Re lambda_i)."""
        self._need_uncertainty()
        return self.period * np.abs(self.multipliers_of_exponents) * self.exponents_std[:, 0]

    @property
    def multipliers_of_exponents(self) -> np.ndarray:
        """The multipliers in the order of ``exponents``, exp(lambda_i T0)."""
        return np.exp(self.exponents * self.period)

    def multiplier_modulus_interval(self, level: float = 0.95) -> np.ndarray:
        """(n, 2): the interval of |mu_i| (in the order of ``exponents``), the exact image
        exp(T0 [low, high]) of Re lambda_i's interval."""
        return np.exp(self.period * self.confidence_interval(level)[:, 0, :])


def _check_model(model, mimo=False):
    if mimo and isinstance(model, MimoModel):
        return model
    if not isinstance(model, Model):
        kinds = "an lptv.Model or lptv.MimoModel" if mimo else "an lptv.Model"
        raise ValueError(f"model must be {kinds}, got {type(model).__name__}")
    return model


def floquet(model, *, tol: float = 1e-11, min_truncation: int = 8,
            max_truncation: int = 256, method: str = "first-order", draws: int = 400,
            seed=None, level: float = 0.95) -> FloquetResult:
    """Characteristic multipliers and Floquet exponents of ``model``: is it stable?

    The homogeneous equation ``sum_n a_n(t) d^n y/dt^n = 0`` in the state
    x = (y, y', ..., y^(na-1)) is x' = F(t) x with F periodic; over one period T0 the state maps
    as x(T0) = Phi x(0), and the eigenvalues mu_i of the monodromy matrix Phi decide stability:
    every solution decays iff every |mu_i| < 1. The instantaneous ("frozen") poles of
    :func:`lptv.frozen_poles` do not decide it: a system whose frozen poles all have negative
    real parts can be unstable (parametric resonance, see the example).

    Continuous time: Hill's method in the C++ core. The eigenvalues of the truncated harmonic
    matrix ``[F_{p-q}] - diag(j p w0 I)``, p, q = -M..M, approximate lambda_i + j n w0; one per
    exponent is kept (the copy whose eigenvector is centred nearest harmonic 0, which the
    truncation disturbs least), and M grows until the kept exponents change by less than
    ``tol * (1 + |ln|mu_i||)`` in ln(mu_i), or by less than the rounding error their
    condition number allows. ``error_estimate`` is the larger of that change and LAPACK's
    rounding bound. Discrete time (forward shift, state (y[k], ..., y[k+na-1])): the eigenvalues
    of the product of the N one-step companion matrices; ``error_estimate`` is the rounding of
    that product amplified by each eigenvalue's condition number, relative to |mu_i|.

    Stability and steady state are separate questions. :func:`lptv.simulate` solves the band
    system ``A Y = B U``, which has a unique solution whenever no multiplier equals 1 (no
    exponent on the lines j l w0): for an unstable system it still returns the periodic
    solution of the equation, which is exact but which the system does not settle into (any
    deviation from it grows like ``spectral_radius ** (t / T0)``). :func:`lptv.identify` fits
    the equation to the spectra whatever its stability: given steady-state periodic data (a
    stabilised experiment, or simulation), it identifies an unstable system as it does a stable
    one, and does not say so. Check ``lptv.floquet(res.model).is_stable``.

    Several outputs (an :class:`lptv.MimoModel`, METHOD.md section 19): the homogeneous
    equation ``sum_n A_n(t) d^n y/dt^n = 0`` with A(t, s) row-reduced (row degrees d_p, the
    highest order in row p; the matrix L(t) of row p's coefficients of order d_p invertible over
    the period; equal degrees: A_na(t) invertible, as the mass matrix of M y'' + C y' + K(t) y).
    Its state (the observer form, of dimension sum_p d_p) has sum_p d_p multipliers, computed as
    above: Hill's method in continuous time, the product of the N one-step matrices in discrete
    time. A 1 x 1 model gives the multipliers of the SISO model.

    Of an identification result (METHOD.md section 22), the exponents carry the estimate's
    uncertainty: ``exponents_std``, ``confidence_interval(level)`` (n, 2, 2),
    ``stable_probability``, ``multiplier_modulus_interval(level)``; first order through the
    eigenvalue derivative of Hill's matrix (of the monodromy product in discrete time; several
    outputs: central differences of the core's exponents), with ``first_order_ok`` and
    ``uncertainty_notes`` saying where it does not hold, or ``method='bootstrap'``: ``draws``
    models drawn from N(eta, covariance), each one's exponents.

    Parameters
    ----------
    model : lptv.Model, lptv.MimoModel or an identification result
        a_na(t) (several outputs: L(t)) must not vanish (be singular) over the period
        (continuous time: checked on a fine grid; discrete time: at the N samples). A result
        (of :func:`lptv.identify`) needs its covariance (not ``covariance='none'``).
    method : {'first-order', 'bootstrap'}
        Of a result: how the covariance reaches the exponents.
    draws, seed : int, optional
        The bootstrap's number of draws and its seed.
    level : float
        Of a result: the level at which ``uncertainty_notes`` says whether stability is decided.
    tol : float
        Continuous time: convergence tolerance of the truncation on ln(mu_i).
    min_truncation, max_truncation : int
        Continuous time: the first M (raised to the number of harmonics of F(t)) and the largest;
        beyond it an :class:`lptv.NumericalError` names the M reached.

    Returns
    -------
    FloquetResult

    Raises
    ------
    ValueError
        a_na(t) vanishes somewhere over the period (the message gives the time or sample), or an
        argument is out of range.
    lptv.NumericalError
        The exponents did not settle by ``max_truncation``, or 1/a_na(t) needs more harmonics
        than the core resolves.

    Examples
    --------
    The damped Mathieu equation y'' + 2 zeta wn y' + wn^2 (1 + eps cos(w0 t)) y = u with
    w0 = 2 wn: every frozen pole has real part -zeta wn < 0, yet for eps above about 4 zeta the
    system is unstable (a multiplier below -1: the solution grows at half the pump frequency).

    >>> import numpy as np, lptv
    >>> from lptv.examples import mathieu_model
    >>> m = mathieu_model(zeta=0.02, wn=1.0, eps=0.1, w0=2.0)
    >>> bool(np.all(lptv.frozen_poles(m, np.linspace(0, m.period, 50)).real < 0))
    True
    >>> f = lptv.floquet(m)
    >>> f.is_stable, np.round(f.multipliers.real, 4)
    (False, array([-1.0158, -0.8682]))
    >>> lptv.floquet(mathieu_model(zeta=0.02, wn=1.0, eps=0.06, w0=2.0)).is_stable
    True

    Two masses coupled by a spring k_c(t) = 1 + 0.9 cos(w0 t) (k_1 = k_2 = 1, M = I): the
    modes are at 1 and sqrt(3) rad/s, and the spring pumps the second one; at w0 = 2 sqrt(3)
    (its parametric resonance) the system is unstable though every frozen pole is damped.

    >>> kc = np.array([0.45, 1.0, 0.45])                     # harmonics -1, 0, 1 of k_c(t)
    >>> S = np.array([[1.0, -1.0], [-1.0, 1.0]])
    >>> K = S[:, :, None] * kc
    >>> K[:, :, 1] += np.eye(2)                              # k_1 = k_2 = 1
    >>> two = lptv.MimoModel.mechanical(np.eye(2), 0.01 * np.eye(2), K, np.eye(2), w0=2 * 3 ** 0.5)
    >>> f = lptv.floquet(two)
    >>> f.multipliers.size, f.is_stable
    (4, False)
    """
    tol = as_positive_float(tol, "tol")
    min_truncation = as_int(min_truncation, "min_truncation", minimum=1)
    max_truncation = as_int(max_truncation, "max_truncation", minimum=1)
    if not isinstance(model, (Model, MimoModel)) and hasattr(model, "covariance"):
        return _of_result(model, dict(tol=tol, min_truncation=min_truncation, max_truncation=max_truncation),
                          method, draws, seed, level)
    _check_model(model, mimo=True)
    route = _core.floquet_mimo if isinstance(model, MimoModel) else _core.floquet
    r = route(model._cpp, tol=tol, min_truncation=min_truncation,
              max_truncation=max_truncation)
    return FloquetResult(
        multipliers=np.asarray(r.multipliers), exponents=np.asarray(r.exponents),
        is_stable=bool(r.is_stable), spectral_radius=float(r.spectral_radius),
        error_estimate=np.asarray(r.error_estimate), truncation=int(r.truncation),
        harmonics=int(r.harmonics), convergence=float(r.convergence), method=r.method,
        period=model.period if not model.discrete else model.samples_per_period * model.ts)


def _from_core(r, model, **extra) -> FloquetResult:
    return FloquetResult(
        multipliers=np.asarray(r.multipliers), exponents=np.asarray(r.exponents),
        is_stable=bool(r.is_stable), spectral_radius=float(r.spectral_radius),
        error_estimate=np.asarray(r.error_estimate), truncation=int(r.truncation),
        harmonics=int(r.harmonics), convergence=float(r.convergence), method=r.method,
        period=model.period if not model.discrete else model.samples_per_period * model.ts, **extra)


def _of_result(res, opt, method, draws, seed, level) -> FloquetResult:
    """The exponents of ``res.model`` with their uncertainty (METHOD.md section 22)."""
    from . import floquet_uncertainty as fu
    from .._validate import as_float

    if method not in ("first-order", "bootstrap"):
        raise ValueError(f"method must be 'first-order' or 'bootstrap', got {method!r}")
    level = as_float(level, "level", minimum=0.0, maximum=1.0, open_min=True, open_max=True)
    model = fu.source(res)[0]
    w0 = model.w0
    if method == "bootstrap":
        draws = as_int(draws, "draws", minimum=10)
        r, lam, d = fu.bootstrap(res, opt, draws, seed)
        X = np.empty((draws, 2 * lam.size))
        X[:, 0::2], X[:, 1::2] = d.real, d.imag
        fin = np.all(np.isfinite(X), axis=0)
        C = np.zeros((X.shape[1],) * 2)
        C[np.ix_(fin, fin)] = np.cov(X[:, fin], rowvar=False).reshape(fin.sum(), fin.sum())
        p = float(np.mean(np.all(d.real < 0, axis=1)))
        notes = []
        extra = dict(draws=d, stable_probability=p, first_order_ok=None, condition=None)
    else:
        r, lam, C, cond = fu.first_order(res, opt)
        idx = fu.distinct_rates(lam, w0)
        p = fu.stable_probability(lam.real[idx], C[np.ix_(2 * idx, 2 * idx)])
        notes = list(fu.first_order_notes(lam, C, cond, w0))
        extra = dict(stable_probability=p, first_order_ok=not notes, condition=cond)
    std = np.sqrt(np.maximum(np.stack([np.diag(C)[0::2], np.diag(C)[1::2]], axis=1), 0.0))
    T0 = model.period if not model.discrete else model.samples_per_period * model.ts
    err = np.asarray(r.error_estimate)
    err_re = (err if not model.discrete else np.log1p(err)) / T0
    for i in np.flatnonzero(np.isfinite(lam.real) & ~(err_re < std[:, 0])):
        notes.append(f"exponent {i} ({lam[i].real:.4g}{lam[i].imag:+.4g}j) is computed no better than its std "
                     f"(numerical error {err_re[i]:.2g} 1/s): its interval is not resolved")
    if method == "first-order":
        extra["first_order_ok"] = not notes
    if lam.size and 1 - level < p < level:
        notes.append(f"stability is not decided at level {level:g}: P(stable) = {p:.4g}")
    return _from_core(r, model, exponents_std=std, exponents_covariance=C, uncertainty_method=method,
                      uncertainty_notes=tuple(notes), **extra)


def monodromy(model, steps: Optional[int] = 2000) -> np.ndarray:
    """The monodromy matrix Phi (na x na) by a route independent of Hill's method, for checks.

    An :class:`lptv.MimoModel` gives the monodromy matrix of its state form (the observer form
    of METHOD.md section 19, sum_p d_p square) by the same products; its eigenvalues are the
    multipliers of :func:`floquet`.

    Continuous time: the product of the matrix exponentials of a fourth-order Magnus step over
    ``steps`` equal sub-intervals of one period (F(t) evaluated from the coefficients at the two
    Gauss points of each), extrapolated with ``2 * steps`` to sixth order. Discrete time: the
    product of the N one-step companion matrices (``steps`` is ignored). The multipliers are
    ``numpy.linalg.eigvals(Phi)``; those far below the largest are only as accurate as
    eps * ||Phi||.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.model.floquet import monodromy
    >>> m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=1.0)           # y' + 2 y: mu = exp(-4 pi)
    >>> bool(np.isclose(monodromy(m)[0, 0], np.exp(-4 * np.pi), rtol=1e-12))
    True
    """
    _check_model(model, mimo=True)
    steps = 0 if model.discrete else as_int(steps, "steps", minimum=1)
    route = _core.monodromy_mimo if isinstance(model, MimoModel) else _core.monodromy
    return np.asarray(route(model._cpp, steps))


# The stability check of simulate and identify runs on every estimate, including over-fitted,
# non-converged candidates of lptv.select whose a_na(t) nearly vanishes; its cost is bounded
# before it starts (METHOD.md section 15): products with at most CHECK_MAX_STEPS steps (about
# 10 ms), then Hill's method with its matrix at most CHECK_MAX_HILL rows (a few tenths of a
# second per truncation), and what that does not decide is said, not guessed.
CHECK_MAX_STEPS = 4096
CHECK_MAX_HILL = 400


def stability_check(model) -> Tuple[Optional[str], Optional[str]]:
    """``(unstable, undecided)``: a sentence when ``model`` is unstable beyond its multipliers'
    error (else None), and a sentence when the check could not decide within its cost bound
    (else None); at most one of the two is set.

    LTI models: the roots of a(s) (a(z)). A :class:`lptv.MimoModel`: the products below on its
    state form (:func:`monodromy`), then :func:`floquet` as below. LPTV models: the monodromy matrix by products
    (:func:`monodromy` with 32, 64, ... up to ``CHECK_MAX_STEPS`` steps, until two successive
    spectral radii differ by less than a tenth of their distance to 1: under a millisecond on
    the paper's model), then :func:`floquet` with Hill's matrix at most ``CHECK_MAX_HILL`` rows.
    A model whose a_na(t) vanishes, whose products overflow or do not settle and whose Hill
    truncation does not converge within that size is undecided, with the reason. The answer is
    kept on the model (its coefficients cannot change), so repeated checks of one model pay
    for it once. Marginal models (a multiplier on the unit circle within its error) are
    neither: their steady state is reached only in the limit, and the FDS's conditioning check
    speaks for them when a line sits on the resonance.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.model.floquet import stability_check
    >>> from lptv.examples import mathieu_model
    >>> unstable, undecided = stability_check(mathieu_model(eps=0.1))
    >>> unstable[:21], undecided
    ('the model is unstable', None)
    >>> a = np.array([[0, 1, 0], [0, 1, 0], [1, 0, 1]], dtype=complex)   # a_1(t) = 2 cos(w0 t)
    >>> stability_check(lptv.Model(a, [[1.0]], w0=1.0))[1][:57]
    'stability not decided: a: the leading coefficient a_2(t) '
    """
    cached = model.__dict__.get("_stability")
    if cached is not None and cached[0] is model._cpp:
        return cached[1]
    undecided = None
    try:
        if isinstance(model, MimoModel):
            text, undecided = _mimo_stability(model)
        elif model.is_lti:
            text = _lti_unstable_text(model)
        else:
            text, undecided = _lptv_stability(model)
    except (ValueError, _core.NumericalError) as err:
        text, undecided = None, f"stability not decided: {err}"
    if text is not None:
        text += (": the periodic steady state returned solves the equation, but a simulation "
                 "from rest never settles into it")
    model.__dict__["_stability"] = (model._cpp, (text, undecided))
    return text, undecided


# An LTI model of several channels whose leading matrix A_na is this well conditioned is judged by
# the eigenvalues of its block companion matrix; a worse one goes the products' way below.
LTI_LEADING_COND = 1e10


def _mimo_lti_unstable_text(model: MimoModel) -> Tuple[bool, Optional[str]]:
    """(decided, text) of an LTI model of several channels: the roots of det A(s) (A(z)) are the
    eigenvalues of the block companion matrix of A_na^-1 A_n, one eigenvalue problem of na ny
    rows (the products below cost na ny matrix exponentials of that size per step: a 120 x 120
    model of order 3 took minutes). Not decided when A_na is singular or nearly so (a row-reduced
    model whose rows have lower degrees: its companion form is the observer form of the core)."""
    ny, na = model.n_outputs, model.na
    A = model.a[..., model.ka]
    if np.all(A.imag == 0):
        A = A.real
    lead = A[na]
    if na == 0 or np.linalg.cond(lead) > LTI_LEADING_COND:
        return (na == 0), None
    F = np.zeros((na * ny, na * ny), dtype=A.dtype)
    F[:-ny, ny:] = np.eye((na - 1) * ny)
    F[-ny:] = -np.linalg.solve(lead, np.concatenate([A[n] for n in range(na)], axis=1))
    roots = np.linalg.eigvals(F)
    if model.discrete:
        mag = np.abs(roots)
        if mag.max() > 1.0 + 1e-9:
            return True, f"the model is unstable (a root of det A(z) at |z| = {mag.max():.6g} > 1)"
    elif roots.real.max() > 1e-9 * max(1.0, np.abs(roots).max()):
        return True, f"the model is unstable (a root of det A(s) at s = {roots[np.argmax(roots.real)]:.6g})"
    return True, None


def _mimo_stability(model: MimoModel) -> Tuple[Optional[str], Optional[str]]:
    if model.is_lti:
        decided, text = _mimo_lti_unstable_text(model)
        if decided:
            return text, None
    # As for one output: the products first (the monodromy of the observer form with 32, 64, ...
    # CHECK_MAX_STEPS Magnus steps until two spectral radii differ by less than a tenth of their
    # distance to 1; discrete time the one exact product), then Hill's method with its matrix at
    # most CHECK_MAX_HILL rows (the state has sum_p d_p components).
    prev = None
    for steps in ([0] if model.discrete else [32 * 2 ** i for i in range(int(np.log2(CHECK_MAX_STEPS // 32)) + 1)]):
        try:
            Phi = np.asarray(_core.monodromy_mimo(model._cpp, steps))
        except _core.NumericalError:
            prev = None
            continue
        rho = float(np.abs(np.linalg.eigvals(Phi)).max()) if Phi.size else 0.0
        if not np.isfinite(rho):
            prev = None
            continue
        if (model.discrete and rho != 1.0) or (prev is not None and abs(rho - prev) < 0.1 * abs(rho - 1.0)):
            if rho > 1.0:
                return f"the model is unstable (Floquet multiplier of magnitude {rho:.6g} > 1)", None
            return None, None
        prev = rho
    n = int(sum(_core.mimo_row_degrees(model._cpp)))
    try:
        f = floquet(model, max_truncation=max(1, (CHECK_MAX_HILL // max(n, 1) - 1) // 2))
    except _core.NumericalError as err:
        return None, (f"stability not decided within the check's cost bound: Hill's method did not "
                      f"converge ({err}); lptv.floquet(model, max_truncation=...) can try harder")
    if f.multipliers.size == 0:
        return None, None
    k = int(np.argmax(np.abs(f.multipliers)))
    mu, err = abs(f.multipliers[k]), f.error_estimate[k]
    if mu > 1.0 and (mu - 1.0) > err * max(mu, 1.0):
        return (f"the model is unstable (Floquet multiplier of magnitude {mu:.6g} > 1, "
                f"Floquet exponent with real part {f.exponents[k].real:.6g} 1/s)"), None
    return None, None


def unstable_warning_text(model: Model) -> Optional[str]:
    """A sentence when ``model`` is unstable beyond its multipliers' error, None otherwise
    (also None when the check is undecided: see :func:`stability_check`)."""
    return stability_check(model)[0]


def _lti_unstable_text(model: Model) -> Optional[str]:
    a = model.a[:, model.ka].real if np.all(model.a.imag == 0) else model.a[:, model.ka]
    roots = np.roots(a[::-1])
    if model.discrete:
        mag = np.abs(roots)
        # roots of a polynomial with coefficients exact to eps are accurate to about
        # eps times their condition; 1e-9 is far above that for the orders used here
        if mag.size and mag.max() > 1.0 + 1e-9:
            return f"the model is unstable (a root of a(z) at |z| = {mag.max():.6g} > 1)"
    elif roots.size and roots.real.max() > 1e-9 * max(1.0, np.abs(roots).max()):
        return f"the model is unstable (a root of a(s) at s = {roots[np.argmax(roots.real)]:.6g})"
    return None


def _lptv_stability(model: Model) -> Tuple[Optional[str], Optional[str]]:
    # The products in the core (_core.product_spectral_radius): monodromy(model, s) for s = 32,
    # 64, ... CHECK_MAX_STEPS, each run reused for the next s, until two successive radii settle.
    pr = _core.product_spectral_radius(model._cpp, 32, CHECK_MAX_STEPS)
    if pr.settled:
        if pr.rho > 1.0:
            return f"the model is unstable (Floquet multiplier of magnitude {pr.rho:.6g} > 1)", None
        return None, None
    reason = pr.reason or None
    hill_max = max(1, (CHECK_MAX_HILL // max(model.na, 1) - 1) // 2)
    try:
        f = floquet(model, max_truncation=hill_max)
    except _core.NumericalError as err:
        why = f"; the products: {reason}" if reason else ""
        return None, (f"stability not decided within the check's cost bound: the products of up to "
                      f"{CHECK_MAX_STEPS} steps did not settle and Hill's method did not converge "
                      f"({err}){why}; lptv.floquet(model, max_truncation=...) can try harder")
    k = int(np.argmax(np.abs(f.multipliers)))
    mu, err = abs(f.multipliers[k]), f.error_estimate[k]
    if mu > 1.0 and (mu - 1.0) > err * max(mu, 1.0):
        return (f"the model is unstable (Floquet multiplier of magnitude {mu:.6g} > 1, "
                f"Floquet exponent with real part {f.exponents[k].real:.6g} 1/s)"), None
    return None, None
