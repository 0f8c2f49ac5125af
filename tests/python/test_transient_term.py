"""The transient term of one record of an LPTV system (METHOD.md section 17), checked exactly.

A discrete-time LPTV system started from an arbitrary state and driven by an arbitrary
(non-periodic) input over L whole parameter periods: on the record's DFT grid the model's
equation error E_l, the band sum of section 3 with every harmonic k shifted by k L lines, is
-T(z_l), T(z) = sum_{j=1}^{n} c_j z^j a polynomial of degree n = max(na, nb) with real coefficients,
and the coefficients are the record's boundary differences weighted by the coefficients at
t = -j. Computed with NumPy only (time recursion, numpy.fft, the reference's a_n(t), b_m(t)).
"""
import numpy as np
import pytest

from lptv import reference as ref
from lptv.examples import discrete_model


def record(model, L, seed):
    """y and u on t = 0..N-1+n (n samples beyond the record for the boundary terms)."""
    N0 = model.samples_per_period
    na, nb = model.na, model.nb
    n = max(na, nb)
    N = L * N0
    rng = np.random.default_rng(seed)
    T = N + n
    u = rng.standard_normal(T + nb)
    y = np.zeros(T + na)
    y[:na] = 3.0 * rng.standard_normal(na)       # an arbitrary initial state: a transient
    t = np.arange(T)
    A, B = ref.coefficients_at(model, t)
    for s in range(T):
        rhs = sum(B[s, m] * u[s + m] for m in range(nb + 1))
        rhs -= sum(A[s, i] * y[s + i] for i in range(na))
        y[s + na] = rhs / A[s, na]
    return u, y, N


def equation_error(model, U, Y, L):
    """sum_n sum_k a_{n,k} z_{l-kL}^n Y_{l-kL} - sum_m sum_k b_{m,k} z_{l-kL}^m U_{l-kL}, all l."""
    N = Y.size
    l = np.arange(N)
    E = np.zeros(N, dtype=complex)
    for coef, X, sign in ((model.a, Y, 1.0), (model.b, U, -1.0)):
        K = (coef.shape[1] - 1) // 2
        for k in range(-K, K + 1):
            src = (l - k * L) % N
            z = np.exp(2j * np.pi * src / N)
            for p in range(coef.shape[0]):
                E += sign * coef[p, k + K] * z**p * X[src]
    return E


@pytest.mark.parametrize("L", [1, 3])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_transient_is_a_real_polynomial_in_z(L, seed):
    m = discrete_model()
    u, y, N = record(m, L, seed)
    U = np.fft.fft(u[:N]) / N
    Y = np.fft.fft(y[:N]) / N
    E = equation_error(m, U, Y, L)
    n = max(m.na, m.nb)
    z = np.exp(2j * np.pi * np.arange(N) / N)
    # the coefficients the derivation predicts: c_j = (1/N) [sum_{i>=j} a_i(-j) (y(N+i-j) - y(i-j))
    #                                                        - sum_{i>=j} b_i(-j) (u(N+i-j) - u(i-j))]
    c = np.zeros(n)
    for j in range(1, n + 1):
        A, B = ref.coefficients_at(m, [-float(j)])
        c[j - 1] = (sum(A[0, i] * (y[N + i - j] - y[i - j]) for i in range(j, m.na + 1))
                    - sum(B[0, i] * (u[N + i - j] - u[i - j]) for i in range(j, m.nb + 1))) / N
    T = sum(c[j - 1] * z**j for j in range(1, n + 1))
    scale = np.abs(E).max()
    assert scale > 1e-3                                  # the transient is there
    # E sums ~20 terms of size up to |coef| max|Y| that largely cancel: its rounding is a few eps
    # of the terms' size, not of E
    terms = np.abs(m.a).sum() * np.abs(Y).max() + np.abs(m.b).sum() * np.abs(U).max()
    assert np.abs(E + T).max() <= 1e-13 * terms
    # and a least-squares fit of E on z^1..z^n finds real coefficients (no other structure)
    V = np.stack([z**j for j in range(1, n + 1)], axis=1)
    cf, *_ = np.linalg.lstsq(V, E, rcond=None)
    assert np.abs(cf.imag).max() <= 1e-13 * terms and np.allclose(-cf.real, c, rtol=0, atol=1e-13 * terms)


def test_steady_state_record_has_no_transient():
    """The same sums on a periodic steady-state record (one period after many) vanish."""
    m = discrete_model()
    N0 = m.samples_per_period
    L = 2
    rng = np.random.default_rng(5)
    u1 = rng.standard_normal(L * N0)
    reps = 40                                            # poles at |z| = 0.71: 0.71^(80 N0) ~ 0
    u = np.tile(u1, reps + 1)[: reps * L * N0 + m.nb + max(m.na, m.nb)]
    y = np.zeros(u.size + m.na)
    A, B = ref.coefficients_at(m, np.arange(u.size))
    for s in range(u.size - m.nb):
        rhs = sum(B[s, i] * u[s + i] for i in range(m.nb + 1)) - sum(A[s, i] * y[s + i] for i in range(m.na))
        y[s + m.na] = rhs / A[s, m.na]
    start = (reps - 1) * L * N0                          # the last whole record of L periods
    U = np.fft.fft(u[start:start + L * N0]) / (L * N0)
    Y = np.fft.fft(y[start:start + L * N0]) / (L * N0)
    E = equation_error(m, U, Y, L)
    terms = np.abs(m.a).sum() * np.abs(Y).max() + np.abs(m.b).sum() * np.abs(U).max()
    assert np.abs(E).max() <= 1e-13 * terms
