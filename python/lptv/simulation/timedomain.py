"""Time-domain simulation of the model's equation (METHOD.md eq. 1).

An independent route to the frequency-domain simulator: it reads only a model's coefficient
arrays and integrates

    a_na(t) y^(na) + ... + a_0(t) y = r(t),   r(t) = sum_m b_m(t) u^(m)(t)

in the state x = (y, y', ..., y^(na-1)). With the input given as a one-sided spectrum the
derivatives u^(m) are exact, so r(t) is a known function of time and the time-varying
numerator needs no state-space realisation. Continuous time is integrated with SUNDIALS CVODE
(scikit-sundae, imported only when needed); discrete time (``sum_n a_n[t] y[t+n] =
sum_m b_m[t] u[t+m]``) is the plain forward recursion.

The periodic steady state is found by shooting (METHOD.md section 3): one period from x = 0
with the input, one period of the homogeneous equation from each unit state (the monodromy
matrix Phi), x0 = (I - Phi)^-1 x_forced(T0), then the period from x0 that is returned.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Optional

import numpy as np

from .._core import NumericalError  # the exception type only; no computation of the core is used
from .._validate import as_spectrum, check_finite
from ..model.floquet import UnstableModelWarning  # the warning class only
from ..model.siso import Model

__all__ = ["SteadyState", "Response", "periodic_steady_state", "free_response"]

# Adams suits this non-stiff equation (poles of order 1 rad/s, inputs up to tens of rad/s)
# better than BDF: orders up to 12, long steps. rtol = 1e-12 puts the paper example's steady
# state about 225 dB below the output peak against the FDS (the tests ask for 150 dB) in
# about 0.3 s; atol follows the size of the signals (see _atol).
DEFAULT_RTOL = 1e-12
DEFAULT_MAX_NUM_STEPS = 100_000


@dataclass(frozen=True)
class SteadyState:
    """Periodic steady state from :func:`periodic_steady_state` with ``full_output=True``."""

    t: np.ndarray
    """Sample times k T0 / n_samples in seconds (continuous time), or sample indices k."""
    y: np.ndarray
    """Output at the sample times."""
    x0: np.ndarray
    """Periodic state at t = 0: (y, y', ...) in continuous time, (y[0], y[1], ...) in discrete."""
    monodromy: np.ndarray
    """Phi: the state after one period of the homogeneous equation from each unit state."""
    periodicity_error: float
    """max |x(T0) - x0| of the returned period, relative to max(|x0|, |y|)."""
    n_rhs: int
    """Right-hand-side evaluations over all CVODE integrations (0 in discrete time)."""
    n_integrations: int
    """Periods integrated: na + 2 (forced, na homogeneous, final)."""
    elapsed: float
    """Wall time in seconds."""


@dataclass(frozen=True)
class Response:
    """Response from :func:`free_response` with ``full_output=True``."""

    t: np.ndarray
    y: np.ndarray
    x: np.ndarray
    """State at each time, shape (len(t), na): (y, y', ...) or (y[k], y[k+1], ...)."""
    n_rhs: int
    elapsed: float


# --------------------------------------------------------------------------- shared helpers
def _check_model(model):
    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model, got {type(model).__name__}")
    return model


def _check_bool(value, name):
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be a bool, got {value!r}")
    return bool(value)


def _onesided(c):
    """(rows, 2K+1) conjugate-symmetric coefficients -> (rows, K+1) with
    c(t) = Re(sum_k out[:, k] exp(j k w t)): harmonics k >= 1 doubled for their conjugates."""
    K = (c.shape[1] - 1) // 2
    out = c[:, K:].copy()
    out[:, 1:] *= 2.0
    out[:, 0] = out[:, 0].real
    return out


def _coef_at(c, w, t):
    """Coefficient values at times t (1-D): shape (len(t), rows)."""
    co = _onesided(c)
    return (np.exp(1j * w * np.outer(t, np.arange(co.shape[1]))) @ co.T).real


def _input_spectrum(U, name):
    arr, was_1d = as_spectrum(U, name)
    if not was_1d and arr.shape[1] != 1:
        raise ValueError(f"{name} must be one spectrum (lines 0..L), got shape {arr.shape}")
    arr = arr[:, 0]
    if abs(arr[0].imag) > 1e-12 * max(np.abs(arr).max(), 1e-300):
        raise ValueError(f"{name}: line 0 (DC) must be real for a real input signal, "
                         f"got imaginary part {arr[0].imag:g}")
    return arr


# The periodic state solves (I - Phi) x0 = x_forced(T0). Phi is known only to its computation's
# accuracy tau relative to 1 + ||Phi|| (continuous time: CVODE's global error, a modest multiple
# of rtol for these well-resolved runs, hence 100 rtol; discrete time: N products of the
# one-step maps, each rounding ~ eps, hence 100 N eps), so an I - Phi whose smallest singular
# value is below tau (1 + ||Phi||) is singular within that accuracy and x0 is noise amplified by
# 1 / sigma_min. The scale matters: an undamped oscillator whose period divides T0 has
# Phi = I up to the integration error, ||I - Phi|| ~ 1e-11, and a harmless-looking condition
# number, yet x0 ~ 1e12. The floor 1e-12 keeps the condition-number refusal this test replaced
# (cond(I - Phi) > 1e12 implies sigma_min < (1 + ||Phi||) 1e-12).
def _periodic_tolerance(model: Model, rtol: float) -> float:
    if model.discrete:
        return max(1e-12, 100.0 * model.samples_per_period * np.finfo(float).eps)
    return max(1e-12, 100.0 * rtol)


def _solve_periodic(Phi, xf, tau):
    if Phi.size == 0:
        return np.zeros(0)
    M = np.eye(Phi.shape[0]) - Phi
    scale = 1.0 + np.linalg.norm(Phi, 2)
    smin = np.linalg.svd(M, compute_uv=False)[-1]
    if not smin > tau * scale:
        mu = np.linalg.eigvals(Phi)
        near = mu[np.argmin(np.abs(mu - 1.0))]
        raise NumericalError(
            "I - Phi is singular within the accuracy of the monodromy matrix Phi (smallest "
            f"singular value {smin:.3g}, relative to 1 + ||Phi|| = {scale:.3g}: {smin / scale:.2g}, "
            f"below {tau:.2g}): a Floquet multiplier at 1 (nearest {near:.12g}), e.g. an undamped "
            "resonance on a harmonic of w0 or a free integrator, so the homogeneous equation has a "
            "periodic solution and the periodic steady state is not determined (add damping, or "
            "move the resonance off the lines)")
    _warn_if_unstable(Phi, tau)
    return np.linalg.solve(M, xf)


def _warn_if_unstable(Phi, tau):
    """Multipliers (eigenvalues of Phi) outside the unit circle by more than Phi's accuracy."""
    mu = np.linalg.eigvals(Phi)
    rho = float(np.abs(mu).max())
    if rho > 1.0 + tau * (1.0 + np.linalg.norm(Phi, 2)):
        warnings.warn(
            f"the model is unstable (largest Floquet multiplier magnitude {rho:.6g} > 1): the "
            "periodic steady state returned solves the equation but is not what a simulation "
            "from rest reaches (deviations from it grow like "
            f"{rho:.3g}**(t / T0))", UnstableModelWarning, stacklevel=5)


def _periodicity_error(x_end, x0, y):
    if x0.size == 0:
        return 0.0
    return float(np.abs(x_end - x0).max() / max(np.abs(x0).max(), np.abs(y).max(), 1e-300))


# --------------------------------------------------------------------------- continuous time
class _Forcing:
    """r(t) = sum_m b_m(t) u^(m)(t) for an input given by its spectrum or by a callable."""

    def __init__(self, model: Model, u, name: str):
        self.w0, self.nb, self.name = model.w0, model.nb, name
        self.bc = _onesided(model.b)
        self.kb = np.arange(self.bc.shape[1])
        self.func, self.scale = None, 0.0
        if callable(u):
            self.func = u
            return
        U = _input_spectrum(u, name)
        self.lines = np.flatnonzero(U)
        coef = np.where(self.lines == 0, U[self.lines].real, 2.0 * U[self.lines])
        jw = 1j * self.w0 * self.lines
        # u^(m)(t) = Re(sum_l D[m, l] exp(j l w0 t))
        self.D = np.array([coef * jw ** m for m in range(self.nb + 1)]).reshape(self.nb + 1, -1)
        self.scale = float(np.abs(coef).sum())  # bounds |u(t)|

    def derivatives(self, t: float) -> np.ndarray:
        if self.func is None:
            return (self.D @ np.exp(1j * self.w0 * t * self.lines)).real
        v = np.asarray(self.func(t), dtype=float).reshape(-1)
        if v.size != self.nb + 1:
            raise ValueError(f"{self.name}(t) must return (u, u', ..., u^(nb)): {self.nb + 1} "
                             f"values for nb = {self.nb}, got {v.size}")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{self.name}(t) returned NaN or inf at t = {t!r}")
        return v

    def __call__(self, t: float) -> float:
        return float((self.bc @ np.exp(1j * self.w0 * t * self.kb)).real @ self.derivatives(t))


def _ct_options(rtol, atol, method, max_num_steps):
    if not (np.isfinite(rtol) and 0 < rtol < 1):
        raise ValueError(f"rtol must be in (0, 1), got {rtol!r}")
    if atol is not None and not (np.isfinite(atol) and atol > 0):
        raise ValueError(f"atol must be positive, got {atol!r}")
    if method not in ("Adams", "BDF"):
        raise ValueError(f"method must be 'Adams' or 'BDF', got {method!r}")
    if isinstance(max_num_steps, bool) or int(max_num_steps) != max_num_steps or max_num_steps < 1:
        raise ValueError(f"max_num_steps must be a positive integer, got {max_num_steps!r}")
    return dict(rtol=float(rtol), method=method, max_num_steps=int(max_num_steps))


def _atol(rtol, scale):
    # The state is of the size of the input times a gain of order one; an absolute tolerance
    # a hundred times below rtol * scale only keeps the zero crossings of y from forcing steps.
    return 1e-2 * rtol * (scale if scale > 0 else 1.0)


def _check_leading(model: Model):
    """The equation is singular where a_na(t) vanishes: refuse before integrating."""
    t = np.linspace(0.0, model.period, 64 * (model.ka + 1) + 1)
    lead = _coef_at(model.a, model.w0, t)[:, -1]
    if np.any(lead == 0) or np.any(np.sign(lead) != np.sign(lead[0])):
        i = int(np.argmin(np.abs(lead)))
        raise NumericalError(f"a_na(t) vanishes near t = {t[i]:.6g} s: the equation is singular "
                             f"there and cannot be integrated")


class _Integrator:
    """CVODE on x' = f(t, x); counts rhs evaluations over its integrations."""

    def __init__(self, model: Model, forcing: Optional[_Forcing], options: dict):
        try:
            from sksundae.cvode import CVODE
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("continuous-time simulation needs scikit-sundae "
                              "(pip install 'lptv[timedomain]')") from e
        self.CVODE = CVODE
        self.ac = _onesided(model.a)
        self.ka = np.arange(self.ac.shape[1])
        self.w0 = model.w0
        self.forcing = forcing
        self.options = options
        self.n_rhs = 0

    def _rhs(self, with_input: bool):
        ac, ka, w0, forcing = self.ac, self.ka, self.w0, self.forcing

        def rhs(t, x, xp):
            a = (ac @ np.exp(1j * w0 * t * ka)).real
            r = forcing(t) if with_input else 0.0
            xp[:-1] = x[1:]
            xp[-1] = (r - a[:-1] @ x) / a[-1]

        return rhs

    def run(self, tspan, x0, with_input: bool, atol: float, what: str):
        tspan = np.asarray(tspan, float)
        # With two times scikit-sundae returns every internal step; a third time keeps CVODE
        # in normal mode (output at the requested times, max_num_steps enforced).
        extra = tspan.size == 2
        if extra:
            tspan = np.array([tspan[0], 0.5 * (tspan[0] + tspan[1]), tspan[1]])
        solver = self.CVODE(self._rhs(with_input), atol=atol, **self.options)
        res = solver.solve(tspan, np.asarray(x0, float))
        self.n_rhs += int(res.nfev)
        if not res.success:
            t_fail = float(res.t[-1]) if len(res.t) else float(tspan[0])
            raise NumericalError(f"CVODE failed ({what}) after t = {t_fail:.6g} s: "
                                 f"{res.message} (flag {res.status})")
        X = np.asarray(res.y)
        if X.shape[0] != tspan.size or not np.all(np.isfinite(X)):
            raise NumericalError(f"CVODE returned an incomplete or non-finite solution ({what})")
        return X[[0, 2]] if extra else X


def _algebraic(model, forcing, t):
    """na = 0: y = r(t) / a_0(t), nothing to integrate."""
    a0 = _coef_at(model.a, model.w0, t)[:, 0]
    r = np.array([forcing(tk) for tk in t]) if forcing is not None else np.zeros(t.size)
    if np.any(a0 == 0):
        raise NumericalError("a_0(t) vanishes on a requested time: y = r / a_0 is undefined")
    return r / a0


def _ct_steady_state(model, U, n_samples, options, atol):
    forcing = _Forcing(model, U, "U")
    T0, na = model.period, model.na
    t = np.arange(n_samples) * (T0 / n_samples)
    if na == 0:
        return t, _algebraic(model, forcing, t), np.zeros(0), np.zeros((0, 0)), 0.0, 0
    _check_leading(model)
    atol_f = _atol(options["rtol"], forcing.scale) if atol is None else atol
    atol_h = _atol(options["rtol"], 1.0) if atol is None else atol
    integ = _Integrator(model, forcing, options)
    xf = integ.run([0.0, T0], np.zeros(na), True, atol_f, "forced period from x = 0")[-1]
    Phi = np.empty((na, na))
    for i in range(na):
        Phi[:, i] = integ.run([0.0, T0], np.eye(na)[i], False, atol_h,
                              f"homogeneous period from unit state {i}")[-1]
    x0 = _solve_periodic(Phi, xf, _periodic_tolerance(model, options["rtol"]))
    X = integ.run(np.append(t, T0), x0, True, atol_f, "period from the periodic state")
    y = X[:n_samples, 0]
    return t, y, x0, Phi, _periodicity_error(X[-1], x0, y), integ.n_rhs


# --------------------------------------------------------------------------- discrete time
def _dt_input(u, N, name):
    """k -> u[k] on integer arrays, from a spectrum (periodic, N samples) or a callable."""
    if callable(u):
        def f(k):
            v = np.asarray(u(k), dtype=float)
            if v.shape != k.shape:
                raise ValueError(f"{name}(k) must return one value per sample index: shape "
                                 f"{k.shape}, got {v.shape}")
            check_finite(v, f"{name}(k)")
            return v
        return f
    U = _input_spectrum(u, name)
    if U.size - 1 > N // 2:
        raise ValueError(f"{name} has lines 0..{U.size - 1} but a discrete-time period of {N} "
                         f"samples has one-sided lines 0..{N // 2}")
    F = np.zeros(N, complex)
    F[:U.size] = U
    F[N - np.arange(1, U.size)] += np.conj(U[1:])
    if N % 2 == 0 and U.size > N // 2:
        F[N // 2] = U[N // 2].real  # the Nyquist line is its own conjugate
    x = np.fft.ifft(F).real * N
    return lambda k: x[k % N]


def _dt_recursion(model, u_of_k, k0, n_steps, X0, with_input):
    """y[k+na] = (r[k] - sum_{n<na} a_n[k] y[k+n]) / a_na[k] for k = k0 .. k0+n_steps-1.

    X0: (na, ncols) initial states (y[k0], ..., y[k0+na-1]); only column 0 gets the input.
    Returns y[k0 .. k0+n_steps+na-1] per column, shape (n_steps + na, ncols)."""
    N, na = model.samples_per_period, model.na
    w = 2 * np.pi / N  # w0 ts: a_n[k] = a_n(k ts) exactly periodic in k
    k = np.arange(k0, k0 + n_steps)
    a = _coef_at(model.a, w, k % N)
    if np.any(a[:, -1] == 0):
        bad = int(k[np.flatnonzero(a[:, -1] == 0)[0]])
        raise NumericalError(f"a_na[k] is zero at k = {bad}: the recursion cannot be solved "
                             f"for y[k + na]")
    rhs = np.zeros((n_steps, X0.shape[1]))
    if with_input:
        b = _coef_at(model.b, w, k % N)
        rhs[:, 0] = sum(b[:, m] * u_of_k(k + m) for m in range(model.nb + 1))
    Y = np.zeros((n_steps + na, X0.shape[1]))
    Y[:na] = X0
    for i in range(n_steps):
        Y[i + na] = (rhs[i] - a[i, :na] @ Y[i:i + na]) / a[i, na]
    if not np.all(np.isfinite(Y)):
        raise NumericalError("the discrete-time recursion produced NaN or inf")
    return Y


def _dt_steady_state(model, U, n_samples):
    N, na = model.samples_per_period, model.na
    if n_samples is not None and n_samples != N:
        raise ValueError(f"n_samples must be the model's samples per period ({N}) in discrete "
                         f"time, got {n_samples}")
    u_of_k = _dt_input(U, N, "U")
    # The forced run and the na homogeneous runs share one recursion (one column each).
    Yall = _dt_recursion(model, u_of_k, 0, N, np.hstack([np.zeros((na, 1)), np.eye(na)]), True)
    Phi = Yall[N:, 1:]
    x0 = _solve_periodic(Phi, Yall[N:, 0], _periodic_tolerance(model, 0.0))
    Yp = _dt_recursion(model, u_of_k, 0, N, x0[:, None], True)[:, 0]
    y = Yp[:N]
    return np.arange(N), y, x0, Phi, _periodicity_error(Yp[N:], x0, y), 0


# --------------------------------------------------------------------------- public API
def periodic_steady_state(model: Model, U, n_samples: Optional[int] = None, *,
                          rtol: float = DEFAULT_RTOL, atol: Optional[float] = None,
                          method: str = "Adams", max_num_steps: int = DEFAULT_MAX_NUM_STEPS,
                          full_output: bool = False):
    """Periodic steady-state output of ``model`` for the periodic input with spectrum ``U``.

    Parameters
    ----------
    model : lptv.Model
    U : array_like, shape (L+1,)
        One-sided input spectrum on lines 0..L (``U[l] = fft(u)[l] / N``, as in
        :func:`lptv.simulate`). Continuous time: u and its derivatives are evaluated exactly
        from it. Discrete time: L <= N/2.
    n_samples : int
        Samples per period of the output, at t = k T0 / n_samples. Discrete time: optional,
        must equal the model's samples per period.
    rtol, atol : float
        CVODE's tolerances (continuous time). The default atol is ``1e-2 * rtol`` times the
        input's peak bound ``sum_l 2 |U_l|`` (times 1 for the homogeneous runs).
    method : {'Adams', 'BDF'}
        CVODE's multistep method.
    max_num_steps : int
        CVODE's limit on internal steps between two output times.
    full_output : bool
        Return a :class:`SteadyState` instead of the samples.

    Returns
    -------
    y : ndarray, shape (n_samples,)

    Raises
    ------
    lptv.NumericalError
        CVODE failed (too much work, accuracy out of reach, ...), a_na(t) vanishes, or the
        homogeneous equation has a periodic solution: I - Phi is singular within the accuracy
        of Phi (its smallest singular value below ``max(1e-12, 100 rtol)`` times
        ``1 + ||Phi||``; discrete time ``max(1e-12, 100 N eps)``), e.g. an undamped resonance
        on a harmonic of w0.

    Warns
    -----
    lptv.UnstableModelWarning
        A Floquet multiplier (eigenvalue of Phi) lies outside the unit circle by more than that
        accuracy: the periodic solution is returned, but a simulation from rest never reaches it.

    Examples
    --------
    >>> import numpy as np, lptv, lptv.timedomain as td
    >>> m = lptv.Model([[1.0], [1.0]], [[1.0]], w0=1.0)        # 1 / (s + 1)
    >>> U = np.zeros(2, complex); U[1] = 0.5                     # cos(t)
    >>> y = td.periodic_steady_state(m, U, 8)
    >>> np.round(np.fft.fft(y)[1] / 8, 9)                        # 0.5 / (1j + 1)
    np.complex128(0.25-0.25j)
    """
    _check_model(model)
    full_output = _check_bool(full_output, "full_output")
    if n_samples is not None and (isinstance(n_samples, bool) or int(n_samples) != n_samples
                                  or n_samples < 1):
        raise ValueError(f"n_samples must be a positive integer, got {n_samples!r}")
    t_start = time.perf_counter()
    if model.discrete:
        out = _dt_steady_state(model, U, n_samples)
    else:
        if n_samples is None:
            raise ValueError("n_samples must be given (a positive integer) in continuous time")
        options = _ct_options(rtol, atol, method, max_num_steps)
        out = _ct_steady_state(model, U, int(n_samples), options, atol)
    t, y, x0, Phi, per_err, n_rhs = out
    if not full_output:
        return y
    return SteadyState(t=t, y=y, x0=x0, monodromy=Phi, periodicity_error=per_err, n_rhs=n_rhs,
                       n_integrations=model.na + 2 if model.na else 0,
                       elapsed=time.perf_counter() - t_start)


def free_response(model: Model, u, t, x0=None, *, rtol: float = DEFAULT_RTOL,
                  atol: Optional[float] = None, method: str = "Adams",
                  max_num_steps: int = DEFAULT_MAX_NUM_STEPS, full_output: bool = False):
    """Response of ``model`` from the state ``x0`` at ``t[0]`` to the input ``u``, sampled at ``t``.

    Parameters
    ----------
    model : lptv.Model
    u : array_like, callable or None
        A one-sided spectrum (lines 0..L: the periodic input of :func:`lptv.simulate`); or, in
        continuous time, a callable ``u(t) -> (u, u', ..., u^(nb))`` at a float time (one
        value when nb = 0); in discrete time, a callable ``u(k)`` giving the input at an integer
        array of sample indices; or None for no input.
    t : array_like
        Increasing times in seconds (continuous time) or integer sample indices (discrete
        time). The initial state holds at ``t[0]``.
    x0 : array_like, shape (na,), optional
        Initial state (y, y', ..., y^(na-1)) at t[0]; discrete time: (y[t0], ..., y[t0+na-1]).
        Default zero.
    rtol, atol, method, max_num_steps
        As in :func:`periodic_steady_state` (continuous time).
    full_output : bool
        Return a :class:`Response` with the state trajectory instead of ``y``.

    Returns
    -------
    y : ndarray, shape (len(t),)
    """
    _check_model(model)
    full_output = _check_bool(full_output, "full_output")
    na = model.na
    tt = np.asarray(t)
    if tt.ndim != 1 or tt.size < 1 or not np.issubdtype(tt.dtype, np.number) \
            or np.iscomplexobj(tt):
        raise ValueError(f"t must be a non-empty 1-D array of real times, got shape {tt.shape}")
    check_finite(tt, "t")
    if np.any(np.diff(tt) <= 0):
        raise ValueError("t must be strictly increasing")
    x0 = np.zeros(na) if x0 is None else np.atleast_1d(np.asarray(x0, dtype=float))
    if x0.shape != (na,):
        raise ValueError(f"x0 must have na = {na} entries, got shape {x0.shape}")
    check_finite(x0, "x0")
    t_start = time.perf_counter()
    n_rhs = 0

    if model.discrete:
        if not np.all(tt == np.round(tt)):
            raise ValueError("t must be integer sample indices for a discrete-time model")
        k = tt.astype(np.int64)
        u_of_k = _dt_input(u, model.samples_per_period, "u") if u is not None else None
        Y = _dt_recursion(model, u_of_k, int(k[0]), int(k[-1] - k[0]) + 1, x0[:, None],
                          u is not None)[:, 0]
        idx = k - k[0]
        X = np.stack([Y[idx + n] for n in range(na)], axis=1) if na else np.zeros((k.size, 0))
        tt, y = k, Y[idx]
    else:
        options = _ct_options(rtol, atol, method, max_num_steps)
        forcing = _Forcing(model, u, "u") if u is not None else None
        tt = tt.astype(float)
        if na == 0:
            y, X = _algebraic(model, forcing, tt), np.zeros((tt.size, 0))
        else:
            _check_leading(model)
            if atol is None:
                atol = _atol(options["rtol"], max(np.abs(x0).max(),
                                                  forcing.scale if forcing is not None else 0.0))
            integ = _Integrator(model, forcing, options)
            X = x0[None, :] if tt.size == 1 else integ.run(tt, x0, forcing is not None, atol,
                                                          "free response")
            y, n_rhs = X[:, 0].copy(), integ.n_rhs
    if not full_output:
        return y
    return Response(t=tt, y=y, x=X, n_rhs=n_rhs, elapsed=time.perf_counter() - t_start)
