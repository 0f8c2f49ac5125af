"""The block band FDS of lptv.MimoModel (METHOD.md section 19) against the dense NumPy reference
(lptv.reference.mimo), the SISO FDS for 1 x 1 models, and itself across solvers and experiments."""
import numpy as np
import pytest

import lptv
from lptv.reference import mimo as ref_mimo

from conftest import FDS_VS_REFERENCE, KAPPA_MAX, random_model, skeel_condition


def random_mimo(seed, domain, ny=None, nu=None, ka=None):
    """A random matrix model, well conditioned on its grid: A_na = I plus harmonics, the lower
    orders a damped mechanical-like part (continuous time) or a contraction (discrete time),
    every entry with its own harmonic count 0..ka."""
    rng = np.random.default_rng([seed, 0 if domain == "ct" else 1, 39])
    ny = int(rng.integers(1, 4)) if ny is None else ny
    nu = int(rng.integers(1, 4)) if nu is None else nu
    ka = int(rng.integers(1, 3)) if ka is None else ka
    kb = int(rng.integers(0, 3))
    na = int(rng.integers(1, 3))
    nb = int(rng.integers(0, na + 1))
    a = np.zeros((na + 1, ny, ny, 2 * ka + 1), complex)
    a[na, :, :, ka] = np.eye(ny)
    if domain == "ct":
        G = rng.normal(size=(ny, ny))
        a[0, :, :, ka] = G @ G.T / ny + np.eye(ny) * rng.uniform(1, 3)
        if na == 2:
            a[1, :, :, ka] = np.eye(ny) * rng.uniform(0.5, 1.5)
    else:
        for n in range(na):
            a[n, :, :, ka] = rng.normal(size=(ny, ny)) * 0.3 / (ny * na)
    for n in range(na + 1):
        for p in range(ny):
            for q in range(ny):
                kpq = int(rng.integers(0, ka + 1))        # the entry's own harmonic count
                for k in range(1, kpq + 1):
                    c = 0.1 * (rng.normal() + 1j * rng.normal()) * (abs(a[n, p, q, ka]) + 0.2)
                    a[n, p, q, ka + k], a[n, p, q, ka - k] = c, np.conj(c)
    b = np.zeros((nb + 1, ny, nu, 2 * kb + 1), complex)
    b[:, :, :, kb] = rng.normal(size=(nb + 1, ny, nu))
    for k in range(1, kb + 1):
        c = 0.2 * (rng.normal(size=(nb + 1, ny, nu)) + 1j * rng.normal(size=(nb + 1, ny, nu)))
        b[..., kb + k], b[..., kb - k] = c, np.conj(c)
    if domain == "dt":
        N = int(rng.choice([16, 25, 32]))
        return lptv.MimoModel(a, b, w0=2 * np.pi / N, ts=1.0)
    return lptv.MimoModel(a, b, w0=float(rng.uniform(0.2, 0.6)))


def random_inputs(seed, model, Lu=None, E=None):
    rng = np.random.default_rng([seed, 7])
    if Lu is None:
        Lu = model.samples_per_period // 2 if model.discrete else 20
    shape = (Lu + 1, model.n_inputs) + (() if E is None else (E,))
    U = rng.normal(size=shape) + 1j * rng.normal(size=shape)
    U[0] = U[0].real
    if model.discrete and 2 * Lu == model.samples_per_period:
        U[Lu] = U[Lu].real
    return U


def tolerance(model, L):
    """FDS_VS_REFERENCE (conftest: two backward-stable LU solves of the same system), whose premise
    is the block system's Skeel condition number <= KAPPA_MAX: checked here (measured 1.6-22 on
    these models; the worst difference 8e-16 of the largest output line)."""
    kappa = skeel_condition(ref_mimo.block_matrix_A(model, L))
    assert kappa <= KAPPA_MAX, kappa
    return FDS_VS_REFERENCE, kappa


@pytest.mark.parametrize("solver", ["auto", "klu", "umfpack", "band"])
def test_against_reference(seed, domain, solver):
    if solver == "band" and domain == "dt":
        pytest.skip("the band solver is continuous-time only")
    m = random_mimo(seed, domain)
    U = random_inputs(seed, m)
    guard = 0 if m.discrete else 12
    Y = lptv.simulate(m, U, guard=guard, solver=solver)
    Yr = ref_mimo.simulate(m, U, guard=guard)
    assert Y.shape == (U.shape[0], m.n_outputs) == Yr.shape
    L = 0 if m.discrete else U.shape[0] - 1 + guard
    tol, _ = tolerance(m, L)
    assert np.abs(Y - Yr).max() <= tol * np.abs(Yr).max()


def test_experiments_share_a_factorisation(seed, domain):
    m = random_mimo(seed, domain)
    U = random_inputs(seed, m, E=3)
    Y = lptv.simulate(m, U, guard=10)
    assert Y.shape == (U.shape[0], m.n_outputs, 3)
    for e in range(3):
        np.testing.assert_allclose(Y[:, :, e], lptv.simulate(m, U[:, :, e], guard=10), rtol=0,
                                   atol=1e-14 * np.abs(Y).max())


def test_siso_as_one_by_one(seed, domain):
    """A 1 x 1 MimoModel simulates as the SISO model (different kernels: to rounding)."""
    s = random_model(seed, domain)
    m = lptv.MimoModel.from_siso(s)
    rng = np.random.default_rng(seed)
    Lu = s.samples_per_period // 2 if s.discrete else 25
    U = rng.normal(size=Lu + 1) + 1j * rng.normal(size=Lu + 1)
    U[0] = U[0].real
    if s.discrete and 2 * Lu == s.samples_per_period:
        U[Lu] = U[Lu].real
    Ys = lptv.simulate(s, U, guard=20, warn_unstable=False)
    Ym = lptv.simulate(m, U, guard=20)
    assert Ym.shape == (Lu + 1, 1)
    np.testing.assert_allclose(Ym[:, 0], Ys, rtol=0, atol=1e-12 * np.abs(Ys).max())


def test_adaptive_guard_converges(seed):
    m = random_mimo(seed, "ct")
    U = random_inputs(seed, m)
    r = lptv.simulate(m, U, full_output=True)
    assert r.converged and r.truncation_error <= 1e-13 and r.solver == "band"
    Yr = ref_mimo.simulate(m, U, guard=r.guard + 40)       # a larger grid: the truncation error itself
    tol, _ = tolerance(m, U.shape[0] - 1 + r.guard)
    assert np.abs(r.Y - Yr).max() <= max(tol, 1e-12) * np.abs(Yr).max()


def test_lines_out_beyond_the_input():
    m = random_mimo(0, "ct", ny=2, nu=2)
    U = random_inputs(0, m, Lu=5)
    Y = lptv.simulate(m, U, lines_out=15, guard=20)
    Yr = ref_mimo.simulate(m, U, lines_out=15, guard=20)
    assert Y.shape == (16, 2)
    np.testing.assert_allclose(Y, Yr, rtol=0, atol=1e-12 * np.abs(Yr).max())


def test_htf_and_band_matrices(seed, domain):
    m = random_mimo(seed, domain)
    L = 0 if m.discrete else 15
    lines = [0, 1, 3] if m.discrete else [-4, 0, 2, 7]
    G = lptv.htf(m, L, lines)
    Gr = ref_mimo.htf(m, L, lines)
    assert G.shape == Gr.shape == (Gr.shape[0], m.n_outputs, len(lines), m.n_inputs)
    tol, _ = tolerance(m, L)
    assert np.abs(G - Gr).max() <= tol * np.abs(Gr).max()
    A, B = lptv.band_matrices(m, L)
    Ar, Br = ref_mimo.block_matrix_A(m, L), ref_mimo.block_matrix_B(m, L)
    scale = np.abs(Ar).max()
    assert np.abs(A.toarray() - Ar).max() <= 1e-14 * scale
    assert np.abs(B.toarray() - Br).max() <= 1e-14 * np.abs(Br).max()
    if not m.discrete:
        kl = max(abs(i - j) for i, j in zip(*A.nonzero()))
        assert kl <= m.n_outputs * (m.ka + 1) - 1          # the scalar band of eq. 19.4


def test_lti_lines_do_not_couple():
    """Ka = Kb = 0: each line's output is G(j w) U with G = A(s)^-1 B(s) per line."""
    m = random_mimo(3, "ct", ny=2, nu=3, ka=0)
    m = lptv.MimoModel(m.a[..., [m.ka]], m.b[..., [m.kb]], w0=m.w0)
    U = random_inputs(3, m, Lu=10)
    Y = lptv.simulate(m, U)
    for l in range(11):
        s = 1j * l * m.w0
        A = sum(m.a[n, :, :, 0] * s ** n for n in range(m.na + 1))
        B = sum(m.b[n, :, :, 0] * s ** n for n in range(m.nb + 1))
        np.testing.assert_allclose(Y[l], np.linalg.solve(A, B @ (U[l].real if l == 0 else U[l])), rtol=1e-12,
                                   atol=1e-14)


def test_singular_system_is_refused():
    """An undamped oscillator with its resonance on line 2: AA is singular there."""
    a = np.zeros((3, 2, 2))
    a[2] = np.eye(2)
    a[0] = np.diag([4.0, 2.0])                 # sqrt(4) = 2 rad/s = line 2 of w0 = 1
    m = lptv.MimoModel(a, np.ones((1, 2, 1)), w0=1.0)
    with pytest.raises(lptv.NumericalError, match="line -?2, output 0"):
        lptv.simulate(m, np.array([[0.0], [1.0], [1.0]]), solver="klu")


@pytest.mark.parametrize("U, match", [
    (np.ones((5, 3)), "n_inputs=2"),
    (np.ones((5,)), "n_inputs=2"),
    (np.full((5, 2), np.nan), "NaN"),
    (np.full((5, 2), 1j), "DC"),
])
def test_bad_inputs(U, match):
    m = random_mimo(0, "ct", ny=2, nu=2)
    with pytest.raises(ValueError, match=match):
        lptv.simulate(m, U)
