"""The block band FDS (METHOD.md section 19) against time integration outside lptv: SciPy's
solve_ivp of mechanical systems with a periodically varying spring, driven by multisines made
with NumPy, at periodic steady state; the last period's DFT against lptv.simulate on the excited
lines and their neighbours +-1, +-2 (the sidebands of the time variation).

Steady state by shooting: one period from rest with the input and, in the same integration, the
fundamental matrix Phi of the homogeneous system; the periodic state is x0 = (I - Phi)^-1 x(T0),
and a second integration of two periods from x0 checks that it repeats.

Tolerance: DOP853 at rtol = 1e-12, atol = 1e-14 holds each step's local error below rtol |x| +
atol; the systems are damped (Floquet multipliers below exp(-0.4 T0) in modulus, checked), so the
local errors do not grow along the period, (I - Phi)^-1 amplifies them by at most
1 / (1 - max |mu|) <= 1.1, and a DFT line is a mean of the samples, no larger than their largest
error. 10 rtol of the largest output line is therefore a bound with a margin (measured: 3e-14 to
1.5e-13 of it). The lines compared are the excited ones and their +-1, +-2 neighbours (and then
the whole band), and the sidebands are checked to lie far above the tolerance (+-1: >= 1e-5 of
the peak, +-2: >= 1.3e-8, i.e. >= 1000 tolerances), so the comparison tests the time variation.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lptv

RTOL, ATOL = 1e-12, 1e-14
TIME_DOMAIN_MIMO = 10 * RTOL
W0 = 1.0
N = 64
LINES = np.array([2, 7, 12, 17])


class Multisine:
    """u_q(t) = sum_l A cos(l w0 t + phi_ql) and its derivative, in NumPy."""

    def __init__(self, nu, seed):
        rng = np.random.default_rng(seed)
        self.phi = rng.uniform(0, 2 * np.pi, (nu, LINES.size))

    def __call__(self, t, derivative=False):
        arg = np.multiply.outer(LINES * W0, np.atleast_1d(t))[None] + self.phi[:, :, None]
        if derivative:
            return np.sum(-(LINES * W0)[None, :, None] * np.sin(arg), axis=1)
        return np.sum(np.cos(arg), axis=1)


def steady_state(f, n_states, n_out):
    """One period of the periodic solution of x' = f(t, x) = F(t) x + g(t), sampled N times; the
    first n_out states are the outputs. f(t, x, forced) evaluates F x (+ g when forced)."""
    T = 2 * np.pi / W0

    def augmented(t, z):
        Phi = z[n_states:].reshape(n_states, n_states)
        cols = np.column_stack([f(t, Phi[:, j], False) for j in range(n_states)])
        return np.concatenate([f(t, z[:n_states], True), cols.ravel()])

    z0 = np.concatenate([np.zeros(n_states), np.eye(n_states).ravel()])
    sol = solve_ivp(augmented, (0, T), z0, method="DOP853", rtol=RTOL, atol=ATOL)
    Phi = sol.y[n_states:, -1].reshape(n_states, n_states)
    assert np.max(np.abs(np.linalg.eigvals(Phi))) < np.exp(-0.4 * T)      # damped: the premise above
    x0 = np.linalg.solve(np.eye(n_states) - Phi, sol.y[:n_states, -1])
    t = np.arange(2 * N) * T / N
    sol = solve_ivp(lambda t, x: f(t, x, True), (0, 2 * T), x0, method="DOP853", rtol=RTOL, atol=ATOL,
                    t_eval=t)
    y = sol.y[:n_out].T
    assert np.abs(y[:N] - y[N:]).max() <= TIME_DOMAIN_MIMO * np.abs(y).max()   # periodic
    return t[:N], y[:N]


def spectra(x):
    return np.fft.fft(x, axis=0)[: N // 2 + 1] / N


def two_mass(B, depth=0.3, kc0=2.0):
    """M y'' + C y' + K(t) y = B u, coupling spring k_c(t) = kc0 (1 + depth cos(w0 t))."""
    M, C, K0 = np.diag([1.0, 2.0]), np.diag([1.0, 2.0]), np.diag([5.0, 3.0])
    S = np.array([[1.0, -1.0], [-1.0, 1.0]])
    Kh = np.zeros((2, 2, 3))
    Kh[:, :, 1] = K0 + kc0 * S
    Kh[:, :, 0] = Kh[:, :, 2] = kc0 * depth / 2 * S
    model = lptv.MimoModel.mechanical(M, C, Kh, B, w0=W0)
    Minv = np.linalg.inv(M)

    def ode(u):
        def f(t, x, forced):
            y, v = x[:2], x[2:]
            K = K0 + kc0 * (1 + depth * np.cos(W0 * t)) * S
            acc = -Minv @ (C @ v + K @ y)
            if forced:
                acc = acc + Minv @ (B @ u(t)[:, 0])
            return np.concatenate([v, acc])
        return f
    return model, ode, 4


def one_mass_two_inputs(depth=0.3):
    """y'' + 0.8 y' + 4 (1 + depth cos w0 t) y = u1 + 0.3 u1' + (0.5 + 0.2 sin w0 t) u2: a
    periodic stiffness and a periodic gain on the second input (B_0 with harmonics +-1), and an
    input derivative (B_1)."""
    a = np.zeros((3, 1, 1, 3), complex)
    a[2, 0, 0, 1], a[1, 0, 0, 1], a[0, 0, 0, 1] = 1.0, 0.8, 4.0
    a[0, 0, 0, 0] = a[0, 0, 0, 2] = 4.0 * depth / 2
    b = np.zeros((2, 1, 2, 3), complex)
    b[0, 0, 0, 1], b[1, 0, 0, 1] = 1.0, 0.3
    b[0, 0, 1, 1], b[0, 0, 1, 2], b[0, 0, 1, 0] = 0.5, -0.1j, 0.1j      # 0.2 sin = 0.2 (e^jt - e^-jt) / 2j
    model = lptv.MimoModel(a, b, w0=W0)

    def ode(u):
        def f(t, x, forced):
            y, v = x
            acc = -0.8 * v - 4.0 * (1 + depth * np.cos(W0 * t)) * y
            if forced:
                uu, du = u(t)[:, 0], u(t, derivative=True)[:, 0]
                acc += uu[0] + 0.3 * du[0] + (0.5 + 0.2 * np.sin(W0 * t)) * uu[1]
            return np.array([v, acc])
        return f
    return model, ode, 2


CASES = {
    "2-in-2-out": lambda: two_mass(np.array([[1.0, 0.5], [0.0, 1.0]])),
    "1-in-2-out": lambda: two_mass(np.array([[1.0], [0.0]])),
    "2-in-1-out": one_mass_two_inputs,
}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("seed", [0, 1])
def test_fds_against_solve_ivp(case, seed):
    model, ode, n_states = CASES[case]()
    u = Multisine(model.n_inputs, seed)
    t, y = steady_state(ode(u), n_states, model.n_outputs)
    Y_ivp = spectra(y)
    U = spectra(u(t).T)
    Y = lptv.simulate(model, U, lines_out=N // 2)
    assert Y.shape == (N // 2 + 1, model.n_outputs)
    peak = np.abs(Y).max()
    near = np.unique(np.concatenate([LINES + d for d in (-2, -1, 0, 1, 2)]))
    err = np.abs(Y[near] - Y_ivp[near]).max()
    assert err <= TIME_DOMAIN_MIMO * peak, err / peak
    # the +-1 and +-2 sidebands carry the time variation, far above the tolerance
    side = np.concatenate([LINES + d for d in (-2, -1, 1, 2)])
    assert np.abs(Y[side]).max(axis=1).min() >= 1e3 * TIME_DOMAIN_MIMO * peak
    # and the whole band agrees as well, not only the lines near the excited ones
    assert np.abs(Y - Y_ivp).max() <= TIME_DOMAIN_MIMO * peak
