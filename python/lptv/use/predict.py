"""The model's output for a given input (METHOD.md section 21): from rest, or in periodic steady state.

From rest (``initial="rest"``): the system at rest before the first sample, the input starting
there. Continuous time: the equation integrated from y = y' = ... = 0 at the first sample, the
input between the samples taken as the band-limited signal its samples define (trigonometric
interpolation over the record, exact for a multisine of whole periods in the record; its
derivatives for b_m, m >= 1, exact with it): SUNDIALS CVODE through :mod:`lptv.timedomain` for
one output, SciPy's solve_ivp (DOP853) for several. Discrete time: the forward recursion with
y and u zero before the first sample.

In periodic steady state (``initial="steady"``): the record, L whole periods of the model,
taken as one period of a periodic input, and the model's periodic response to it by the FDS on
the record's grid (the model written with the fundamental w0 / L, its harmonic k moved to kL).
"""
from __future__ import annotations

import warnings
from typing import Optional

import numpy as np

from .._validate import as_float, as_str, check_finite, _array
from ..model.mimo import MimoModel
from ..model.siso import Model

INITIAL = ("rest", "steady")
RTOL = 1e-10
"""Relative tolerance of the continuous-time integration from rest."""


def _model(model):
    if not isinstance(model, (Model, MimoModel)):
        raise ValueError(f"model must be an lptv.Model or lptv.MimoModel, got {type(model).__name__}")
    return model


def _input(model, u):
    """u as (n, nu) float samples, checked."""
    nu = getattr(model, "n_inputs", 1)
    a = _array(u, "u")
    if np.iscomplexobj(a):
        raise ValueError("u must be real samples, got complex values")
    a = a.astype(float)
    if a.ndim == 1 and nu == 1:
        a = a[:, None]
    if a.ndim != 2 or a.shape[1] != nu:
        want = "(n,) or (n, 1)" if nu == 1 else f"(n, {nu}): one column per input"
        raise ValueError(f"u must have shape {want}, got {a.shape}")
    check_finite(a, "u")
    order = max(model.na, model.nb) + 1
    if a.shape[0] < max(order, 2):
        raise ValueError(f"u must hold at least {max(order, 2)} samples (the model's order + 1: na = {model.na}, "
                         f"nb = {model.nb}), got {a.shape[0]}")
    return a


def sampling(model, fs) -> float:
    """The sampling frequency (Hz): ``fs`` for a continuous-time model (required), 1 / ts for a
    discrete-time one (``fs``, when given, must agree)."""
    if model.discrete:
        if fs is not None:
            fs = as_float(fs, "fs", minimum=0.0, open_min=True, what="a positive sampling frequency (Hz)")
            if not np.isclose(fs * model.ts, 1.0, rtol=1e-9, atol=0):
                raise ValueError(f"fs = {fs:g} Hz, but the discrete-time model samples at 1 / ts = "
                                 f"{1 / model.ts:g} Hz")
        return 1.0 / model.ts
    if fs is None:
        raise ValueError("fs must be given (Hz) for a continuous-time model: the samples' spacing in time")
    return as_float(fs, "fs", minimum=0.0, open_min=True, what="a positive sampling frequency (Hz)")


def whole_periods(model, n: int, fs: float, what: str = "u") -> int:
    """L, the model periods that n samples at fs hold; a ValueError when not a whole number."""
    per = model.period * fs
    N = int(round(per))
    if N < 1 or abs(per - N) > 1e-6 * per or n % N:
        raise ValueError(f"{what}: {n} samples at {fs:g} Hz are not whole periods of the model's "
                         f"{model.period:g} s ({per:.6g} samples a period)")
    return n // N


def predict(model, u, *, fs: Optional[float] = None, initial: str = "rest", t0: float = 0.0):
    """The model's output for the input samples ``u``.

    Parameters
    ----------
    model : lptv.Model or lptv.MimoModel
    u : array_like, shape (n,) or (n, n_inputs)
        Input samples, uniformly spaced at ``fs``.
    fs : float
        Sampling frequency (Hz); required in continuous time, 1 / ts (optional) in discrete time.
    initial : {'rest', 'steady'}
        'rest': from rest at the first sample (the transient included); 'steady': the periodic
        steady state for the record repeated, which must then hold whole periods of the model.
    t0 : float
        The model's time (s) at the first sample: the phase of its periodic coefficients (0:
        the first sample at the start of a period, as ``lptv identify`` cuts its records).

    Returns
    -------
    y : ndarray, shape (n,) for one output, (n, n_outputs) for several

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model.from_tf([1.0], [1.0, 1.0], w0=2 * np.pi / 10)       # 1 / (s + 1)
    >>> y = lptv.predict(m, np.ones(101), fs=10.0)                          # a unit step
    >>> bool(abs(y[-1] - (1 - np.exp(-10.0))) < 1e-8)
    True
    """
    model = _model(model)
    initial = as_str(initial, "initial", INITIAL)
    fs = sampling(model, fs)
    t0 = as_float(t0, "t0", what="a finite time (s)")
    u = _input(model, u)
    if model.discrete and t0 != round(t0 * fs) / fs:
        raise ValueError(f"t0 must be a whole number of samples ts = {model.ts:g} s for a discrete-time model, got {t0:g}")
    if initial == "steady":
        y = _steady(model, u, fs, t0)
    elif model.discrete:
        y = _dt_rest(model, u, int(round(t0 * fs)))
    elif isinstance(model, Model):
        y = _ct_rest_siso(model, u[:, 0], fs, t0)[:, None]
    else:
        y = _ct_rest_mimo(model, u, fs, t0)
    if not np.all(np.isfinite(y)):
        from .._core import NumericalError

        raise NumericalError("the prediction is not finite: the model is unstable enough to overflow on this record")
    return y[:, 0] if isinstance(model, Model) else y


# ------------------------------------------------------------------------------ steady state

def _spread(c, L):
    """Harmonics on the last axis, k -> k L (zeros between)."""
    K = (c.shape[-1] - 1) // 2
    out = np.zeros(c.shape[:-1] + (2 * K * L + 1,), complex)
    out[..., K * L + L * np.arange(-K, K + 1)] = c
    return out


def on_record_grid(model, L: int):
    """The same model with fundamental w0 / L (a record of L periods is one of its periods)."""
    return type(model)(_spread(model.a, L), _spread(model.b, L), w0=model.w0 / L, ts=model.ts)


def _steady(model, u, fs, t0):
    from ..simulation.fds import simulate
    from ..excitation.multisine import spectrum, time_signal

    n = u.shape[0]
    L = whole_periods(model, n, fs)
    if t0:
        raise ValueError("t0: the periodic steady state starts at the start of a period (t0 = 0)")
    m = on_record_grid(model, L)
    U = np.stack([spectrum(u[:, i]) for i in range(u.shape[1])], axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the record may hold lines up to Nyquist: the FDS truncates far out
        Y = np.asarray(simulate(m, U[:, 0] if isinstance(model, Model) else U, warn_unstable=True))
    Y = Y.reshape(Y.shape[0], -1)[: n // 2 + 1]
    return np.stack([time_signal(Y[:, j], n) for j in range(Y.shape[1])], axis=1)


# ------------------------------------------------------------------------------ from rest

class _Interpolant:
    """u(t) and its derivatives from the trigonometric interpolation of n samples at fs."""

    def __init__(self, u, fs, order):
        n = u.shape[0]
        C = np.fft.rfft(u, axis=0) / n
        C[1:] *= 2.0
        if n % 2 == 0:
            C[-1] /= 2.0                     # the Nyquist line is its own conjugate
        self.w = 2 * np.pi * fs * np.arange(C.shape[0]) / n
        self.D = np.stack([C * (1j * self.w[:, None]) ** m for m in range(order + 1)])   # (m, line, channel)
        self.scale = float(np.abs(C).sum())
        # exp(j w_k t) for the lines k = q B + r as exp(j w_qB t) exp(j w_r t): about 2 sqrt(lines)
        # complex exponentials per call instead of one per line (the integrator calls this
        # thousands of times), each product within a few rounding errors of the direct value
        lines = C.shape[0]
        self._block = max(1, int(np.sqrt(lines)))
        self._w1 = 2 * np.pi * fs / n
        self._outer = np.arange(-(-lines // self._block)) * self._block
        self._inner = np.arange(self._block)
        self._lines = lines

    def __call__(self, t):
        """(order + 1, channels) at the time t (s) from the first sample."""
        e = (np.exp(1j * (self._w1 * t) * self._outer)[:, None] * np.exp(1j * (self._w1 * t) * self._inner)[None, :])
        return (e.ravel()[:self._lines] @ self.D).real


def _ct_rest_siso(model, u, fs, t0):
    from .. import timedomain

    f = _Interpolant(u[:, None], fs, model.nb)
    t = t0 + np.arange(u.size) / fs
    atol = 1e-2 * RTOL * max(f.scale, 1e-300)
    return timedomain.free_response(model, lambda tt: f(tt - t0)[:, 0], t, rtol=RTOL, atol=atol)


def _ct_rest_mimo(model, u, fs, t0):
    from scipy.integrate import solve_ivp

    na, ny = model.na, model.n_outputs
    n = u.shape[0]
    t = t0 + np.arange(n) / fs
    f = _Interpolant(u, fs, model.nb)
    grid = np.linspace(0.0, model.period, 64 * (max(model.ka, model.kb) + 1) + 1)
    lead = model.a_at(grid)[:, na]
    if na == 0 or np.any(np.abs(np.linalg.det(lead)) <= 1e-12 * np.abs(lead).max(axis=(1, 2)) ** ny):
        raise ValueError("model: the prediction from rest of a matrix model integrates A_na(t) y^(na) = ..., "
                         "which needs A_na(t) invertible at every t (every output of order na)")

    def rhs(tt, x):
        A = model.a_at([tt])[0]               # (na+1, ny, ny)
        B = model.b_at([tt])[0]               # (nb+1, ny, nu)
        du = f(tt - t0)                        # (nb+1, nu)
        X = x.reshape(na, ny)
        r = np.einsum("mpq,mq->p", B, du) - np.einsum("npq,nq->p", A[:na], X)
        return np.concatenate([X[1:].ravel(), np.linalg.solve(A[na], r)])

    sol = solve_ivp(rhs, (t[0], t[-1]), np.zeros(na * ny), t_eval=t, method="DOP853", rtol=RTOL,
                    atol=1e-2 * RTOL * max(f.scale, 1e-300))
    if not sol.success:
        from .._core import NumericalError

        raise NumericalError(f"the integration from rest failed: {sol.message}")
    return sol.y[:ny].T


def _dt_rest(model, u, k0):
    """sum_n A_n[k] y[k+n] = sum_m B_m[k] u[k+m] solved for y[k + na], y and u zero before the
    first sample (k0: the model's sample index of the first sample)."""
    n, nu = u.shape
    na, nb = model.na, model.nb
    if nb > na:
        raise ValueError(f"model: nb = {nb} > na = {na} in discrete time needs inputs after the output it "
                         "predicts; the prediction from rest needs nb <= na")
    mimo = isinstance(model, MimoModel)
    ny = model.n_outputs if mimo else 1
    k = np.arange(-na, n - na)               # equation at time k gives y[k + na]
    tk = (k0 + k) * model.ts
    A = model.a_at(tk).reshape(k.size, na + 1, ny, ny)
    B = model.b_at(tk).reshape(k.size, nb + 1, ny, nu)
    upad = np.vstack([np.zeros((na, nu)), u])  # u[-na .. n-1]
    y = np.zeros((n + na, ny))                  # y[-na .. n-1]
    for i in range(n):
        r = sum(B[i, m] @ upad[i + m] for m in range(nb + 1))
        r = r - sum(A[i, j] @ y[i + j] for j in range(na))
        y[i + na] = np.linalg.solve(A[i, na], r) if ny > 1 else r / A[i, na, 0, 0]
    return y[na:]
