"""Floquet multipliers and frozen poles of the matrix system (METHOD.md section 19, "Stability of
the matrix system") against routes outside lptv:

- continuous time: the monodromy matrix from SciPy's solve_ivp (DOP853) of the state equations
  written out here by hand: x = (y, y') with y'' = -M(t)^-1 (C(t) y' + K(t) y) for the
  M(t)-form, and for a system whose rows have the degrees 2 and 1 the state (y1, y1', y2) with
  y2'' obtained by differentiating the second row by hand; the coefficients evaluated from the
  model's Fourier arrays in NumPy;
- discrete time: the product of the one-step matrices built in NumPy;
- 1 x 1 models: the SISO route (the companion form, section 12) and, for LTI models, the exact
  multipliers exp(p T0) of numpy.roots;
- frozen poles: numpy.roots of the determinant polynomial of 2 x 2 systems, formed with
  numpy.polymul.

Tolerances (conftest, MIMO_FLOQUET_*) are relative to ||Phi||_2 and stated there.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eig
from scipy.optimize import linear_sum_assignment

import lptv
from lptv.model.floquet import monodromy
from conftest import (MIMO_FLOQUET_DT, MIMO_FLOQUET_IVP_RTOL, MIMO_FLOQUET_KAPPA_MAX, MIMO_FLOQUET_MARGIN,
                      MIMO_FLOQUET_SISO, MIMO_FLOQUET_VS_IVP, MIMO_FROZEN_POLES, SEEDS)


# ------------------------------------------------------------------------------ the NumPy routes

def fourier(c, w0, t, derivative=0):
    """sum_k c[..., K + k] (j k w0)^d exp(j k w0 t), real part (the coefficients are symmetric)."""
    K = (c.shape[-1] - 1) // 2
    k = np.arange(-K, K + 1)
    return np.real(np.sum(c * (1j * k * w0) ** derivative * np.exp(1j * k * w0 * t), axis=-1))


def matching(a, b):
    """max |a_i - b_pi(i)| over the best pairing pi of two sets of multipliers."""
    d = np.abs(np.subtract.outer(a, b))
    r, c = linear_sum_assignment(d)
    return d[r, c].max() if d.size else 0.0


def eig_conditions(Phi):
    """The eigenvalues of Phi and their condition numbers |x||y| / |y^H x|."""
    w, vl, vr = eig(Phi, left=True, right=True)
    kappa = np.linalg.norm(vl, axis=0) * np.linalg.norm(vr, axis=0) / np.abs(np.sum(vl.conj() * vr, axis=0))
    return w, kappa


def ivp_monodromy(F, n, T):
    """Phi of x' = F(t) x over one period by DOP853 (the fundamental matrix, column by column)."""
    sol = solve_ivp(lambda t, z: (F(t) @ z.reshape(n, n)).ravel(), (0, T), np.eye(n).ravel(), method="DOP853",
                    rtol=MIMO_FLOQUET_IVP_RTOL, atol=MIMO_FLOQUET_IVP_RTOL * 1e-3)
    assert sol.success
    return sol.y[:, -1].reshape(n, n)


def check_against(f, Phi):
    """The core's multipliers against eig(Phi), relative to ||Phi||, and the verdict."""
    w, kappa = eig_conditions(Phi)
    assert kappa.max() <= MIMO_FLOQUET_KAPPA_MAX                  # the premise of the tolerance
    rho = np.abs(w).max()
    assert abs(rho - 1) > MIMO_FLOQUET_MARGIN                     # not marginal: the verdict is defined
    assert f.multipliers.size == w.size
    err = matching(f.multipliers, w) / np.linalg.norm(Phi, 2)
    assert f.is_stable == (rho < 1)
    return err, rho


def random_mechanical(seed, ny, depth, damping, w0=1.0):
    """M(t) y'' + C(t) y' + K(t) y = u with every matrix periodic (one harmonic), M(t) positive
    definite over the period: (lptv.MimoModel, the (M, C, K) harmonics arrays)."""
    rng = np.random.default_rng(seed)

    def sym(scale):
        X = rng.normal(size=(ny, ny))
        return scale * (X + X.T) / 2

    def periodic(mean, scale):
        h = np.zeros((ny, ny, 3), complex)
        h[:, :, 1] = mean
        c = scale * (rng.normal(size=(ny, ny)) + 1j * rng.normal(size=(ny, ny)))
        h[:, :, 2], h[:, :, 0] = c, c.conj()
        return h

    M = periodic(np.eye(ny) + sym(0.1), 0.05)
    C = periodic(damping * np.eye(ny) + sym(0.05 * abs(damping)), 0.05 * abs(damping))
    K0 = sym(1.0) + (1.0 + 3.0 * ny) * np.eye(ny)
    K = periodic(K0, depth)
    model = lptv.MimoModel.mechanical(M, C, K, np.eye(ny), w0=w0)
    return model, (M, C, K)


def mechanical_F(mats, w0):
    M, C, K = mats
    ny = M.shape[0]

    def F(t):
        Mt, Ct, Kt = (fourier(x, w0, t) for x in (M, C, K))
        low = -np.linalg.solve(Mt, np.hstack([Kt, Ct]))
        return np.block([[np.zeros((ny, ny)), np.eye(ny)], [low]])
    return F


# ------------------------------------------------------------------------------ continuous time

@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("ny", [2, 3])
def test_mechanical_systems_with_a_periodic_mass_against_solve_ivp(seed, ny):
    """Random M(t), C(t), K(t): a damped system (stable) and the same with negative damping
    (unstable); Hill's multipliers against eig of the monodromy by DOP853."""
    verdicts = set()
    for damping in (0.3, -0.05):
        model, mats = random_mechanical(seed, ny, depth=0.3, damping=damping)
        f = lptv.floquet(model)
        Phi = ivp_monodromy(mechanical_F(mats, model.w0), 2 * ny, model.period)
        err, rho = check_against(f, Phi)
        assert err <= MIMO_FLOQUET_VS_IVP, err
        verdicts.add(f.is_stable)
        # the core's product route (its observer-form state: Phi up to a similarity)
        products = np.linalg.eigvals(monodromy(model))
        assert matching(products, np.linalg.eigvals(Phi)) <= MIMO_FLOQUET_VS_IVP * np.linalg.norm(Phi, 2)
    assert verdicts == {True, False}


def two_mass(depth, damping=0.02, w0=None):
    """The two-mass system of test_mimo_timedomain.py with light damping, its coupling spring
    k_c(t) = 2 (1 + depth cos(w0 t)); by default w0 = 2 w_1, the principal parametric resonance
    of the first mode."""
    Mm, Cm, K0 = np.diag([1.0, 2.0]), damping * np.diag([1.0, 2.0]), np.diag([5.0, 3.0])
    S = np.array([[1.0, -1.0], [-1.0, 1.0]])
    Kmean = K0 + 2.0 * S
    w1 = np.sqrt(np.min(np.linalg.eigvals(np.linalg.solve(Mm, Kmean)).real))
    w0 = 2 * w1 if w0 is None else w0
    K = np.zeros((2, 2, 3), complex)
    K[:, :, 1] = Kmean
    K[:, :, 0] = K[:, :, 2] = 2.0 * depth / 2 * S
    mats = (Mm[:, :, None].astype(complex), Cm[:, :, None].astype(complex), K)
    return lptv.MimoModel.mechanical(Mm, Cm, K, np.eye(2), w0=w0), mats


def test_two_masses_across_the_parametric_resonance_tongue_against_solve_ivp():
    """The coupling spring's depth swept at w0 = 2 w_1: below the tongue's edge the system is
    stable (every frozen pole damped all along), above it unstable; each verdict and every
    multiplier as solve_ivp's."""
    verdicts = []
    for depth in (0.02, 0.05, 0.2, 0.4, 0.8):
        model, mats = two_mass(depth)
        poles = lptv.frozen_poles(model, np.linspace(0, model.period, 33))
        assert np.all(poles.real < 0)
        f = lptv.floquet(model)
        Phi = ivp_monodromy(mechanical_F(mats, model.w0), 4, model.period)
        err, rho = check_against(f, Phi)
        assert err <= MIMO_FLOQUET_VS_IVP, (depth, err)
        verdicts.append(f.is_stable)
    assert verdicts[0] and not verdicts[-1]


CT_MEANS = dict(al=0.2, f=0.3, e=0.8, h=0.4, g=0.3, k=4.0, c=0.4)
DT_MEANS = dict(al=0.1, f=0.1, e=-0.5, h=0.1, g=0.1, k=0.81, c=-1.2)     # roots near 0.9 exp(+-0.73j), 0.5


def test_simulate_warns_for_an_unstable_matrix_model():
    """simulate's stability check (lptv.model.floquet.stability_check) on the pumped two masses: the
    periodic solution is returned either way, with UnstableModelWarning above the tongue's edge."""
    import warnings

    U = np.zeros((40, 2), complex)
    U[7] = [0.5, 0.2j]
    for depth, unstable in ((0.05, False), (0.4, True)):
        model, _ = two_mass(depth)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            Y = lptv.simulate(model, U)
            lptv.simulate(model, U, warn_unstable=False)
        found = [w for w in caught if issubclass(w.category, lptv.UnstableModelWarning)]
        assert len(found) == unstable and Y.shape == (40, 2)
        if unstable:
            assert "Floquet multiplier of magnitude 1.0272" in str(found[0].message)


def test_an_undamped_system_is_marginal_neither_stable_nor_reported_unstable():
    """C = 0, K constant: every multiplier on the unit circle. The products' radii sit at 1 and
    never settle, Hill's method decides: not stable (marginal), and simulate's check reports
    nothing (neither unstable nor undecided)."""
    from lptv.model.floquet import stability_check

    model = lptv.MimoModel.mechanical(np.diag([1.0, 2.0]), np.zeros((2, 2)), [[7.0, -2.0], [-2.0, 5.0]],
                                      np.eye(2), w0=1.0)
    f = lptv.floquet(model)
    assert not f.is_stable and np.all(np.abs(np.abs(f.multipliers) - 1) <= 1e-9)
    assert stability_check(model) == (None, None)


def mixed_degrees(seed, w0=1.0, ts=None, **means):
    """Row 1: y1'' + al(t) y2'' + c y1' + k(t) y1 + g(t) y2 = 0; row 2: y2' + f(t) y1' + e(t) y2
    + h(t) y1 = 0 (row degrees 2 and 1, A_2 = [[1, al], [0, 0]] singular, L = [[1, al], [f, 1]]);
    discrete time (``ts``) the same with the shift for d/dt."""
    rng = np.random.default_rng(seed)
    mu = {**(CT_MEANS if ts is None else DT_MEANS), **means}
    small = 1.0 if ts is None else 0.2

    def coef(mean, scale, K=2):
        c = np.zeros(2 * K + 1, complex)
        c[K] = mean
        h = scale * (rng.normal(size=K) + 1j * rng.normal(size=K))
        c[K + 1:], c[:K] = h, h[::-1].conj()
        return c

    al, f, e, h, g, k = (coef(mu["al"], 0.05 * small), coef(mu["f"], 0.05 * small), coef(mu["e"], 0.1 * small),
                         coef(mu["h"], 0.1 * small), coef(mu["g"], 0.1 * small), coef(mu["k"], 0.5 * small))
    c = coef(mu["c"], 0.0)
    one = coef(1.0, 0.0)
    a = np.zeros((3, 2, 2, 5), complex)
    a[2, 0, 0], a[2, 0, 1] = one, al
    a[1, 0, 0], a[0, 0, 0], a[0, 0, 1] = c, k, g
    a[1, 1, 1], a[1, 1, 0], a[0, 1, 1], a[0, 1, 0] = one, f, e, h
    model = lptv.MimoModel(a, np.ones((1, 2, 1)), w0=w0, ts=ts)
    return model, dict(al=al, f=f, e=e, h=h, g=g, k=k, c=c)


def mixed_F(cf, w0):
    """The state (y1, y1', y2): y2' from row 2, y2'' its derivative, y1'' from row 1 (by hand)."""
    def F(t):
        v = {n: fourier(x, w0, t) for n, x in cf.items()}
        d = {n: fourier(x, w0, t, 1) for n, x in cf.items()}
        # y2' = -f y1' - e y2 - h y1 as a row over (y1, y1', y2), and y2'' = D + P y1'' with
        # D = -f' y1' - e' y2 - e y2' - h' y1 - h y1', P = -f.
        dy2 = np.array([-v["h"], -v["f"], -v["e"]])
        D = np.array([-d["h"], -d["f"] - v["h"], -d["e"]]) - v["e"] * dy2
        P = -v["f"]
        # row 1: (1 + al P) y1'' = -al D - c y1' - k y1 - g y2
        y1dd = (-v["al"] * D - np.array([v["k"], v["c"], v["g"]])) / (1 + v["al"] * P)
        return np.array([[0.0, 1.0, 0.0], y1dd, dy2])
    return F


@pytest.mark.parametrize("seed", SEEDS)
def test_rows_of_different_degrees_against_solve_ivp(seed):
    """A row-reduced A(t, s) whose leading matrix A_2 is singular: three multipliers (the row
    degrees 2 + 1), against DOP853 on the state (y1, y1', y2) written out by hand; damped
    (c = 0.4) and with a negative damping (c = -0.3, unstable)."""
    verdicts = set()
    for c in (-0.3, 0.4):
        model, cf = mixed_degrees(seed, c=c)
        f = lptv.floquet(model)
        assert f.multipliers.size == 3
        Phi = ivp_monodromy(mixed_F(cf, model.w0), 3, model.period)
        err, rho = check_against(f, Phi)
        assert err <= MIMO_FLOQUET_VS_IVP, err
        verdicts.add(f.is_stable)
    assert verdicts == {True, False}
    # the same rows, the output equation of row 2 scaled and mixed into row 1: one system
    # (a constant P0 from the left), the same multipliers
    P0 = np.array([[2.0, 0.5], [0.0, 1.0]])
    mixed = lptv.MimoModel(np.einsum("pr,nrqk->npqk", P0, model.a), np.ones((1, 2, 1)), w0=model.w0)
    g = lptv.floquet(mixed)
    assert matching(g.multipliers, f.multipliers) <= MIMO_FLOQUET_VS_IVP * np.linalg.norm(Phi, 2)


# ------------------------------------------------------------------------------ discrete time

def dt_product(G, N):
    Phi = np.eye(G(0).shape[0])
    for k in range(N):
        Phi = G(k) @ Phi
    return Phi


def check_dt(f, Phi):
    w, kappa = eig_conditions(Phi)
    assert kappa.max() <= MIMO_FLOQUET_KAPPA_MAX and abs(np.abs(w).max() - 1) > MIMO_FLOQUET_MARGIN
    assert f.multipliers.size == w.size and f.method == "product"
    assert matching(f.multipliers, w) <= MIMO_FLOQUET_DT * kappa.max() * np.linalg.norm(Phi, 2)
    assert f.is_stable == (np.abs(w).max() < 1)
    return f.is_stable


@pytest.mark.parametrize("seed", SEEDS)
def test_discrete_time_against_the_product_in_numpy(seed):
    """sum_n A_n[k] y[k+n] = 0 with A_2[k] = I + a periodic part, each channel a resonance of
    radius r per step (r = 0.9: stable, r = 1.03: unstable over N = 24 steps) coupled by random
    periodic terms; and a system with the row degrees 2 and 1. The core's multipliers against
    eig of the product of the one-step matrices written out in NumPy."""
    rng = np.random.default_rng(seed)
    N, ny, w0 = 24, 2, 1.0
    ts = 2 * np.pi / (w0 * N)
    theta = rng.uniform(0.3, 1.0, ny)
    verdicts = set()
    for r in (0.9, 1.03):
        a = np.zeros((3, ny, ny, 3), complex)
        means = [np.diag(r ** 2 * np.ones(ny)), np.diag(-2 * r * np.cos(theta)), np.eye(ny)]
        for n in range(3):
            h = 0.03 * (rng.normal(size=(ny, ny)) + 1j * rng.normal(size=(ny, ny)))
            a[n, :, :, 1] = means[n] + 0.03 * rng.normal(size=(ny, ny))
            a[n, :, :, 2], a[n, :, :, 0] = h, h.conj()
        model = lptv.MimoModel(a, np.ones((1, ny, 1)), w0=w0, ts=ts)

        def G(k):
            A = [fourier(a[n], w0, k * ts) for n in range(3)]
            low = -np.linalg.solve(A[2], np.hstack([A[0], A[1]]))
            return np.block([[np.zeros((ny, ny)), np.eye(ny)], [low]])
        verdicts.add(check_dt(lptv.floquet(model), dt_product(G, N)))
    assert verdicts == {True, False}

    # rows of degrees 2 and 1 (y1[k+2] + al y2[k+2] + c y1[k+1] + kk y1[k] + g y2[k] = 0,
    # y2[k+1] + f y1[k+1] + e y2[k] + h y1[k] = 0), the state (y1[k], y1[k+1], y2[k]) by hand
    verdicts = set()
    for kk in (0.81, 1.1):
        model2, cf = mixed_degrees(seed, ts=ts, k=kk)
        v = {n: np.array([fourier(x, w0, k * ts) for k in range(N)]) for n, x in cf.items()}

        def G2(k):
            k1 = (k + 1) % N
            y2n = np.array([-v["h"][k], -v["f"][k], -v["e"][k]])                  # y2[k+1]
            y2nn_rest = -v["e"][k1] * y2n + np.array([0.0, -v["h"][k1], 0.0])     # y2[k+2] + f[k+1] y1[k+2]
            y1nn = (-v["al"][k] * y2nn_rest - np.array([v["k"][k], v["c"][k], v["g"][k]])) \
                / (1 - v["al"][k] * v["f"][k1])
            return np.array([[0.0, 1.0, 0.0], y1nn, y2n])
        verdicts.add(check_dt(lptv.floquet(model2), dt_product(G2, N)))
    assert verdicts == {True, False}


# ------------------------------------------------------------------------------ one output

@pytest.mark.parametrize("seed", SEEDS)
def test_a_one_by_one_model_has_the_siso_multipliers(seed):
    """The observer form of a 1 x 1 model against section 12's companion form (continuous time,
    a periodic a_na(t) included, and discrete time), and LTI models against exp(p T0)."""
    from lptv.examples import mathieu_model, paper_model

    rng = np.random.default_rng(seed)
    models = [paper_model(), mathieu_model(eps=0.1), mathieu_model(eps=0.06)]
    a = np.zeros((3, 5), complex)
    a[:, 2] = [3.0, 0.5 + rng.uniform(0, 0.5), 1.0]
    h = 0.1 * (rng.normal(size=(3, 2)) + 1j * rng.normal(size=(3, 2)))
    a[:, 3:], a[:, :2] = h, h[:, ::-1].conj()
    models += [lptv.Model(a, [[1.0]], w0=1.0), lptv.Model(a, [[1.0]], w0=1.0, ts=2 * np.pi / 16)]
    for m in models:
        f, g = lptv.floquet(m), lptv.floquet(lptv.MimoModel.from_siso(m))
        assert g.is_stable == f.is_stable and g.multipliers.size == f.multipliers.size
        # ln(mu) paired (imaginary parts modulo 2 pi), within both error estimates
        lf, lg = np.log(f.multipliers.astype(complex)), np.log(g.multipliers.astype(complex))
        diff = np.subtract.outer(lf, lg)
        dist = np.abs(diff.real + 1j * (np.mod(diff.imag + np.pi, 2 * np.pi) - np.pi))
        r, c = linear_sum_assignment(dist)
        bound = (2 * (f.error_estimate[r] + g.error_estimate[c])
                 + MIMO_FLOQUET_SISO * (1 + np.abs(lf[r].real)))
        assert np.all(dist[r, c] <= bound), (m, dist[r, c], bound)
    # LTI: the exact multipliers exp(p T0) of the poles
    poles = np.roots([1.0, 0.6, 5.0, 2.0])
    lti = lptv.MimoModel(np.poly(poles)[::-1].real[:, None, None], [[[1.0]]], w0=0.7)
    exact = np.exp(poles * lti.period)
    assert matching(lptv.floquet(lti).multipliers, exact) <= MIMO_FLOQUET_SISO * np.abs(exact).max()


def test_decoupled_identical_channels_have_each_multiplier_twice():
    """diag(m, m) for the Mathieu equation above and below its tongue's edge, and an LTI system
    with a double pole per channel pair: Hill's matrix has every eigenvalue twice, and both
    copies of each family are kept (METHOD.md section 12: two eigenpairs at one centroid are two
    exponents)."""
    from lptv.examples import mathieu_model

    for eps in (0.1, 0.06):
        s = mathieu_model(eps=eps)
        a = np.zeros((3, 2, 2, s.a.shape[1]), complex)
        a[:, 0, 0], a[:, 1, 1] = s.a, s.a
        f, g = lptv.floquet(lptv.MimoModel(a, np.ones((1, 2, 1)), w0=s.w0)), lptv.floquet(s)
        assert f.is_stable == g.is_stable
        twice = np.repeat(g.multipliers, 2)
        assert matching(f.multipliers, twice) <= MIMO_FLOQUET_SISO * 10 + 4 * g.error_estimate.max()
    lti = lptv.MimoModel(np.stack([2 * np.eye(2), 3 * np.eye(2), np.eye(2)]), np.ones((1, 2, 1)), w0=1.0)
    exact = np.exp(np.array([-1.0, -1.0, -2.0, -2.0]) * lti.period)     # s^2 + 3 s + 2 = (s + 1)(s + 2)
    assert matching(lptv.floquet(lti).multipliers, exact) <= MIMO_FLOQUET_SISO * exact.max()


# ------------------------------------------------------------------------------ frozen poles

def poly_of(entry_coeffs):
    """numpy.poly1d-order coefficients (highest first) of sum_n c_n s^n given c_0..c_na."""
    return np.trim_zeros(np.asarray(entry_coeffs)[::-1], "f")


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("kind", ["mechanical", "mixed", "discrete"])
def test_frozen_poles_are_the_roots_of_the_determinant(seed, kind):
    """det sum_n A_n(t) s^n of 2 x 2 systems by numpy.polymul at a few t, its numpy.roots
    against lptv.frozen_poles."""
    if kind == "mixed":
        model, _ = mixed_degrees(seed)
    else:
        model, _ = random_mechanical(seed, 2, depth=0.3, damping=0.3)
        if kind == "discrete":
            model = lptv.MimoModel(model.a, model.b, w0=1.0, ts=2 * np.pi / 16)
    ts = np.array([0.0, 0.7, 2.9]) if kind != "discrete" else np.array([0.0, 3, 11]) * model.ts
    frozen = lptv.frozen_poles(model, ts)
    for i, t in enumerate(ts):
        A = fourier(model.a, model.w0, t)                          # (na+1, 2, 2)
        p = [[poly_of(A[:, r, c]) for c in range(2)] for r in range(2)]
        det = np.polysub(np.polymul(p[0][0], p[1][1]), np.polymul(p[0][1], p[1][0]))
        roots = np.roots(det)
        assert frozen.shape[1] == roots.size
        scale = max(1.0, np.abs(roots).max())
        assert matching(frozen[i], roots) <= MIMO_FROZEN_POLES * scale


def test_where_the_leading_matrix_is_singular_a_frozen_pole_is_infinite():
    """M_11(t) = 1 + cos(t) vanishes at t = pi: det A(t, s) drops from degree 4 to 3 there; the
    three finite poles are numpy.roots' of the determinant, the fourth is inf (first)."""
    a = np.zeros((3, 2, 2, 3), complex)
    a[2, :, :, 1] = np.eye(2)
    a[2, 0, 0, 0] = a[2, 0, 0, 2] = 0.5
    a[1, :, :, 1] = 0.3 * np.eye(2)
    a[0, :, :, 1] = [[4.0, -1.0], [-1.0, 3.0]]
    model = lptv.MimoModel(a, np.ones((1, 2, 1)), w0=1.0)
    for t in (np.pi, 1.0):
        poles = lptv.frozen_poles(model, [t])[0]
        A = fourier(model.a, model.w0, t)
        p = [[poly_of(np.where(np.abs(A[:, r, c]) < 1e-15, 0, A[:, r, c])) for c in range(2)] for r in range(2)]
        roots = np.roots(np.polysub(np.polymul(p[0][0], p[1][1]), np.polymul(p[0][1], p[1][0])))
        finite = poles[np.isfinite(poles)]
        assert finite.size == roots.size == (3 if t == np.pi else 4)
        assert np.all(np.isinf(poles[:4 - finite.size]))
        assert matching(finite, roots) <= MIMO_FROZEN_POLES * max(1.0, np.abs(roots).max())


def test_frozen_poles_of_the_two_masses_are_their_modes():
    """LTI (depth 0): the roots of det(K - w^2 M) = 0 as +-j w, damped by C = 0.02 M."""
    model, _ = two_mass(0.0)
    Kmean = np.diag([5.0, 3.0]) + 2.0 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    w2 = np.linalg.eigvals(np.linalg.solve(np.diag([1.0, 2.0]), Kmean)).real
    exact = np.concatenate([-0.01 + 1j * np.sqrt(w2 - 1e-4), -0.01 - 1j * np.sqrt(w2 - 1e-4)])
    assert matching(lptv.frozen_poles(model, [0.0])[0], exact) <= MIMO_FROZEN_POLES * 3


# ------------------------------------------------------------------------------ bad input

def test_a_singular_leading_matrix_and_a_zero_row_are_refused_naming_where():
    a = np.zeros((3, 2, 2, 3), complex)
    a[2, :, :, 1] = np.eye(2)
    a[2, 0, 0, 0] = a[2, 0, 0, 2] = 0.5                # M_11(t) = 1 + cos(t) vanishes at t = pi
    a[0, :, :, 1] = 4 * np.eye(2)
    with pytest.raises(ValueError, match=r"leading row coefficient matrix .* singular near t = 3\.14"):
        lptv.floquet(lptv.MimoModel(a, np.ones((1, 2, 1)), w0=1.0))
    z = np.zeros((2, 2, 2))
    z[1, 0, 0] = 1.0
    z[0, 0, 0] = 2.0                                   # row 1 of A is zero at every order
    with pytest.raises(ValueError, match="row 1 of A"):
        lptv.floquet(lptv.MimoModel(z, np.ones((1, 2, 1)), w0=1.0))
    with pytest.raises(ValueError, match="row 1 of A"):
        lptv.frozen_poles(lptv.MimoModel(z, np.ones((1, 2, 1)), w0=1.0), [0.0])
    with pytest.raises(ValueError, match="lptv.Model or lptv.MimoModel"):
        lptv.floquet("model")
    d = np.zeros((2, 2, 2, 3), complex)
    d[1, :, :, 1] = np.eye(2)
    d[1, 0, 0, 0] = d[1, 0, 0, 2] = 0.5                # A_1[k]_11 = 1 + cos(w0 t_k), 0 at k = N/2
    d[0, :, :, 1] = 0.3 * np.eye(2)
    with pytest.raises(ValueError, match="singular at sample k = 9"):
        lptv.floquet(lptv.MimoModel(d, np.ones((1, 2, 1)), w0=1.0, ts=2 * np.pi / 16))


def test_docstring_examples_run():
    """lptv.model.floquet's examples (the two masses pumped at 2 sqrt(3)) run in test_floquet.py; the
    frozen poles' here."""
    import doctest
    import importlib

    result = doctest.testmod(importlib.import_module("lptv.judgement.validation"), optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
