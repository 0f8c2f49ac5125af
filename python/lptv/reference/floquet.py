"""Floquet exponents and their sensitivity to the parameters, by routes independent of the core
(METHOD.md sections 12 and 22): the monodromy matrix by SciPy's solve_ivp (continuous time, the
truth of the tests and benchmarks) or the product of the one-step companion matrices in NumPy
(discrete time), its eigenvalues, and the derivative d lambda / d eta by central differences of
the exponents of a fixed-step product (the matrix exponential (Taylor series, scaled and squared) of the midpoint Magnus step
on 4000 steps: the same discretisation for both sides of a difference, so the difference is
the derivative of that map, whose error is O(h^2) of the map's own, far below the tolerances).
Reads the coefficient arrays only (``model.a``, ``model.w0``, ``model.ts``)."""
from __future__ import annotations

import re

import numpy as np

_NAME = re.compile(r"([ab])(\d+)\.(re|im)(\d+)")


def _a_at(a, w0, t):
    K = (a.shape[1] - 1) // 2
    k = np.arange(-K, K + 1)
    return np.real(np.exp(1j * np.outer(np.atleast_1d(t), k) * w0) @ a.T)  # (len t, na+1)


def monodromy(a, w0, ts=None, rtol=1e-12):
    """Phi of the companion form of sum_n a_n(t) y^(n) = 0 over one period (a: (na+1, 2K+1))."""
    a = np.asarray(a, complex)
    na = a.shape[0] - 1
    if ts:
        N = int(round(2 * np.pi / (w0 * ts)))
        Phi = np.eye(na)
        for k in range(N):
            v = _a_at(a, w0, k * ts)[0]
            G = np.eye(na, k=1)
            G[-1] = -v[:na] / v[na]
            Phi = G @ Phi
        return Phi
    from scipy.integrate import solve_ivp

    def rhs(t, x):
        v = _a_at(a, w0, t)[0]
        X = x.reshape(na, na)
        d = np.empty_like(X)
        d[:-1] = X[1:]
        d[-1] = -(v[:na] @ X) / v[na]
        return d.ravel()

    T0 = 2 * np.pi / w0
    sol = solve_ivp(rhs, (0.0, T0), np.eye(na).ravel(), method="DOP853", rtol=rtol, atol=1e-14)
    return sol.y[:, -1].reshape(na, na)


def magnus_monodromy(a, w0, steps=4000):
    """Phi by the product of expm(h F(t_mid)) over ``steps`` equal steps (midpoint Magnus)."""
    a = np.asarray(a, complex)
    na = a.shape[0] - 1
    T0 = 2 * np.pi / w0
    h = T0 / steps
    v = _a_at(a, w0, (np.arange(steps) + 0.5) * h)
    F = np.zeros((steps, na, na))
    F[:, np.arange(na - 1), np.arange(1, na)] = 1.0
    F[:, -1, :] = -v[:, :na] / v[:, na:na + 1]
    # exp(h F) by its Taylor series on the scaled matrix, squared back (batched matmuls)
    X = h * F
    sq = max(0, int(np.ceil(np.log2(max(np.abs(X).sum(axis=2).max(), 1e-300) / 0.05))))
    X = X / 2 ** sq
    E, term = np.broadcast_to(np.eye(na), X.shape).copy(), np.broadcast_to(np.eye(na), X.shape).copy()
    for j in range(1, 12):
        term = term @ X / j
        E = E + term
    for _ in range(sq):
        E = E @ E
    Phi = np.eye(na)
    for k in range(steps):
        Phi = E[k] @ Phi
    return Phi


def exponents(a, w0, ts=None, route="solve_ivp"):
    """ln(mu_i) / T0 on the principal branch, sorted by decreasing real part, then imaginary;
    continuous time by ``route`` 'solve_ivp' or 'magnus' (:func:`magnus_monodromy`)."""
    Phi = magnus_monodromy(a, w0) if (route == "magnus" and not ts) else monodromy(a, w0, ts)
    mu = np.linalg.eigvals(Phi)
    T0 = 2 * np.pi / w0
    lam = np.log(mu.astype(complex)) / T0
    return lam[np.lexsort((-lam.imag, -lam.real))]


def set_parameter(a, name, value):
    """A copy of a with the real parameter ``name`` ('a1.re2') set to ``value``."""
    m = _NAME.fullmatch(name)
    a = np.array(a, complex)
    n, part, k = int(m.group(2)), m.group(3), int(m.group(4))
    K = (a.shape[1] - 1) // 2
    c = a[n, K + k]
    c = complex(value, c.imag) if part == "re" else complex(c.real, value)
    a[n, K + k] = c
    if k:
        a[n, K - k] = np.conj(c)
    return a


def exponent_jacobian(a, w0, names, ts=None, rel_step=1e-5):
    """d lambda_i / d eta_j (complex, (na, len names)) by central differences of
    :func:`exponents`; the b parameters have none. Each perturbed exponent is paired with the
    nearest unperturbed one (modulo j w0)."""
    a = np.asarray(a, complex)
    lam0 = exponents(a, w0, ts, route="magnus")
    J = np.zeros((lam0.size, len(names)), complex)
    K = (a.shape[1] - 1) // 2
    for j, name in enumerate(names):
        m = _NAME.fullmatch(name)
        if m is None or m.group(1) == "b":
            continue
        n, part, k = int(m.group(2)), m.group(3), int(m.group(4))
        v = a[n, K + k].real if part == "re" else a[n, K + k].imag
        h = rel_step * max(abs(v), 1e-2)
        lp = exponents(set_parameter(a, name, v + h), w0, ts, route="magnus")
        lm = exponents(set_parameter(a, name, v - h), w0, ts, route="magnus")
        J[:, j] = (_paired(lam0, lp, w0) - _paired(lam0, lm, w0)) / (2 * h)
    return lam0, J


def _paired(ref, lam, w0):
    out = np.empty_like(ref)
    free = list(range(lam.size))
    for i, r in enumerate(ref):
        d = [abs(complex(r.real - lam[j].real,
                         (r.imag - lam[j].imag + w0 / 2) % w0 - w0 / 2)) for j in free]
        j = free.pop(int(np.argmin(d)))
        dim = (lam[j].imag - r.imag + w0 / 2) % w0 - w0 / 2
        out[i] = complex(lam[j].real, r.imag + dim)
    return out
