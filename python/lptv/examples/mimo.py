"""Mechanical systems with several inputs and outputs written out by hand, and their periodic
steady state by SciPy's solve_ivp (no lptv computation): the data the MIMO estimators' tests and
benchmarks fit (METHOD.md section 19).

- ``"2-in-2-out"``: two masses, M = diag(1, 2), C = diag(1, 2), K(t) = diag(5, 3) + k_c(t) S,
  S = [[1, -1], [-1, 1]], coupling spring k_c(t) = 2 (1 + 0.3 cos w0 t), B = [[1, 0.5], [0, 1]];
- ``"1-in-2-out"``: the same masses, one force on the first (B = [1; 0]);
- ``"2-in-1-out"``: y'' + 0.8 y' + 4 (1 + 0.3 cos w0 t) y = u1 + 0.3 u1' + (0.5 + 0.2 sin w0 t) u2.

Steady state by shooting: one period from rest with the fundamental matrix Phi, then
x0 = (I - Phi)^-1 x(T0) and one period from x0 (DOP853, rtol 1e-12, atol 1e-14).
"""
from __future__ import annotations

from typing import Callable, Dict, Tuple

import numpy as np

from ..model.mimo import MimoModel

W0 = 1.0
RTOL, ATOL = 1e-12, 1e-14


def two_mass(B, depth: float = 0.3, kc0: float = 2.0) -> Tuple[MimoModel, Callable, int]:
    """M y'' + C y' + K(t) y = B u with k_c(t) = kc0 (1 + depth cos w0 t): (model, ode, states)."""
    B = np.asarray(B, float)
    M, C, K0 = np.diag([1.0, 2.0]), np.diag([1.0, 2.0]), np.diag([5.0, 3.0])
    S = np.array([[1.0, -1.0], [-1.0, 1.0]])
    Kh = np.zeros((2, 2, 3))
    Kh[:, :, 1] = K0 + kc0 * S
    Kh[:, :, 0] = Kh[:, :, 2] = kc0 * depth / 2 * S
    model = MimoModel.mechanical(M, C, Kh, B, w0=W0)
    Minv = np.linalg.inv(M)

    def ode(u, du):
        def f(t, x, forced):
            y, v = x[:2], x[2:]
            K = K0 + kc0 * (1 + depth * np.cos(W0 * t)) * S
            acc = -Minv @ (C @ v + K @ y)
            if forced:
                acc = acc + Minv @ (B @ u(t))
            return np.concatenate([v, acc])
        return f
    return model, ode, 4


def one_mass_two_inputs(depth: float = 0.3) -> Tuple[MimoModel, Callable, int]:
    """y'' + 0.8 y' + 4 (1 + depth cos w0 t) y = u1 + 0.3 u1' + (0.5 + 0.2 sin w0 t) u2."""
    a = np.zeros((3, 1, 1, 3), complex)
    a[2, 0, 0, 1], a[1, 0, 0, 1], a[0, 0, 0, 1] = 1.0, 0.8, 4.0
    a[0, 0, 0, 0] = a[0, 0, 0, 2] = 4.0 * depth / 2
    b = np.zeros((2, 1, 2, 3), complex)
    b[0, 0, 0, 1], b[1, 0, 0, 1] = 1.0, 0.3
    b[0, 0, 1, 1], b[0, 0, 1, 2], b[0, 0, 1, 0] = 0.5, -0.1j, 0.1j
    model = MimoModel(a, b, w0=W0)

    def ode(u, du):
        def f(t, x, forced):
            y, v = x
            acc = -0.8 * v - 4.0 * (1 + depth * np.cos(W0 * t)) * y
            if forced:
                uu, dd = u(t), du(t)
                acc += uu[0] + 0.3 * dd[0] + (0.5 + 0.2 * np.sin(W0 * t)) * uu[1]
            return np.array([v, acc])
        return f
    return model, ode, 2


SYSTEMS: Dict[str, Callable] = {
    "2-in-2-out": lambda: two_mass([[1.0, 0.5], [0.0, 1.0]]),
    "1-in-2-out": lambda: two_mass([[1.0], [0.0]]),
    "2-in-1-out": one_mass_two_inputs,
}


def _signal(U):
    """u(t) and u'(t) of one-sided spectra U (L+1, nu) on lines 1..L: u = sum_l 2 Re(U_l e^{j l w0 t})."""
    lines = np.flatnonzero(np.any(U != 0, axis=1))
    lines = lines[lines > 0]
    c = 2 * U[lines]                                                # (lines, nu)
    w = lines * W0

    def u(t):
        return np.real(np.exp(1j * w * t) @ c)

    def du(t):
        return np.real((1j * w * np.exp(1j * w * t)) @ c)
    return u, du


def steady_state(system: str, U, n_samples: int) -> np.ndarray:
    """One period (n_samples, ny) of the periodic steady-state output of ``SYSTEMS[system]`` driven
    by the input of one-sided spectra U (n_samples//2+1, nu) (``fft(u)[l] / N``; DC and the
    Nyquist line must be zero)."""
    from scipy.integrate import solve_ivp

    model, ode, n = SYSTEMS[system]()
    U = np.asarray(U, complex)
    if U[0].any() or (n_samples % 2 == 0 and U[-1].any()):
        raise ValueError("U: DC and the Nyquist line must be zero")
    f = ode(*_signal(U))
    T = 2 * np.pi / W0

    def augmented(t, z):
        Phi = z[n:].reshape(n, n)
        cols = np.column_stack([f(t, Phi[:, j], False) for j in range(n)])
        return np.concatenate([f(t, z[:n], True), cols.ravel()])

    z0 = np.concatenate([np.zeros(n), np.eye(n).ravel()])
    sol = solve_ivp(augmented, (0, T), z0, method="DOP853", rtol=RTOL, atol=ATOL)
    Phi = sol.y[n:, -1].reshape(n, n)
    x0 = np.linalg.solve(np.eye(n) - Phi, sol.y[:n, -1])
    t = np.arange(n_samples) * T / n_samples
    sol = solve_ivp(lambda t, x: f(t, x, True), (0, T), x0, method="DOP853", rtol=RTOL, atol=ATOL, t_eval=t)
    return sol.y[:model.n_outputs].T.copy()


def true_parameters(model: MimoModel) -> Tuple[np.ndarray, np.ndarray]:
    """The model's coefficients normalised to A_na,0 = I (multiplied by A_na,0^-1 from the left)."""
    Ka = model.a.shape[3] // 2
    P0 = np.linalg.inv(np.real(model.a[model.na, :, :, Ka]))
    return np.einsum("pj,njqk->npqk", P0, model.a), np.einsum("pj,njrk->nprk", P0, model.b)


def small_fit():
    """A small fit for the docstrings: a 1-input 2-output LTI system, 6 periods with noise.

    Examples
    --------
    >>> from lptv.examples.mimo import small_fit
    >>> res = small_fit()
    >>> res.model.n_inputs, res.model.n_outputs, res.parameter_names[:2]
    (1, 2, ('a0[0,0].re0', 'a0[0,1].re0'))
    """
    from ..simulation.fds import simulate
    from ..estimation.identify import identify
    from ..excitation.multisine import multisine

    a = np.zeros((2, 2, 2))
    a[1] = np.eye(2)
    a[0] = [[2.0, 0.5], [0.0, 3.0]]
    b = np.array([[[1.0], [1.0]]])
    m = MimoModel(a, b, w0=0.1)
    ms = multisine(range(1, 40), 128, seed=0)
    Y = simulate(m, ms.spectrum[:, None], lines_out=64)
    y1 = np.fft.irfft(Y * 128, 128, axis=0)
    rng = np.random.default_rng(1)
    u = ms.periods(6)[:, :, None] + 1e-3 * rng.standard_normal((6, 128, 1))
    y = y1[None] + 1e-3 * rng.standard_normal((6, 128, 2))
    return identify(u, y, na=1, nb=0, w0=0.1)
