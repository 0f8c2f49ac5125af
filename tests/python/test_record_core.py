"""One record with its transient: the compiled core (lptv::fit_record, behind
lptv.identify_record) against its NumPy and SciPy twin lptv.reference.record (the computation
lptv.identify_record had before: SciPy's MINPACK Levenberg-Marquardt, SuperLU per residue class
of the record's lines, numpy.linalg.lstsq for the start). Records from lptv.examples.
transient_record (the time recursion, a random initial state, white input and output noise) of
two systems, several seeds and lengths; tolerances in conftest (RECORD_*), from how precisely
each route can stop at the same minimum."""
import numpy as np
import pytest

import lptv
from lptv import _core
from lptv import reference as ref
from lptv.examples import DISCRETE_STRUCTURE, discrete_model, transient_record
from lptv.reference.record import _Grid
from conftest import (RECORD_COST, RECORD_COVARIANCE, RECORD_KAPPA_MAX, RECORD_NOISE_VAR, RECORD_PREDICTION,
                      RECORD_REGRESSION, RECORD_STD_UNITS)


def first_order_model():
    """y[t+1] + a0(t) y[t] = b1(t) u[t+1] + b0(t) u[t]: a time-varying numerator of order
    nb = na, N0 = 64 samples per period, poles of the mean system at 0.6."""
    a = np.array([[0.1 + 0.05j, -0.6, 0.1 - 0.05j], [0.0, 1.0, 0.0]])
    b = np.array([[-0.1j, 1.0, 0.1j], [0.2, 0.5, 0.2]])
    return lptv.Model(a, b, w0=2 * np.pi / 64, ts=1.0), dict(na=1, nb=1, ka=[1, 0], kb=[1, 1])


def system(name):
    if name == "discrete":
        return discrete_model(), DISCRETE_STRUCTURE
    return first_order_model()


def compare(core, r):
    """The estimates within RECORD_STD_UNITS of the reported std, and what follows from it."""
    free = core.parameter_std > 0
    std = core.parameter_std[free]
    assert np.array_equal(free, np.diag(r.covariance) > 0)
    assert np.max(np.abs(core.eta - r.eta)[free] / std) <= RECORD_STD_UNITS
    assert core.eta[~free].tolist() == r.eta[~free].tolist() == [1.0]
    assert core.transient.size == r.transient.size
    if core.transient.size:
        assert np.max(np.abs(core.transient - r.transient) / core.transient_std) <= RECORD_STD_UNITS
        assert np.max(np.abs(core.transient_std / r.transient_std - 1)) <= RECORD_COVARIANCE
    assert np.max(np.abs(std / np.sqrt(np.diag(r.covariance))[free] - 1)) <= RECORD_COVARIANCE
    assert np.max(np.abs(core.noise_var / r.noise_var - 1)) <= RECORD_NOISE_VAR
    assert core.noise_dof == r.noise_dof
    assert abs(core.cost / r.cost - 1) <= RECORD_COST
    assert np.max(np.abs(core.Y_fit - r.Y_fit) / np.sqrt(core.noise_var)) <= RECORD_STD_UNITS
    np.testing.assert_array_equal(core.Y, r.Y)
    np.testing.assert_array_equal(core.lines, r.lines)
    assert core.dof == r.dof and core.periods == r.periods
    assert core.converged and r.converged


@pytest.mark.parametrize("name, periods, seed", [
    ("discrete", 4, 0), ("discrete", 4, 1), ("discrete", 4, 2), ("discrete", 2, 7), ("discrete", 8, 3),
    ("first_order", 3, 0), ("first_order", 3, 1), ("first_order", 1, 2),
])
def test_residual_noise_route_matches_the_reference(name, periods, seed):
    m, structure = system(name)
    u, y = transient_record(m, periods=periods, noise_std=0.01, seed=seed)
    core = lptv.identify_record(u, y, **structure, w0=m.w0, ts=1.0)
    r = ref.record.identify_record(u, y, **structure, w0=m.w0, ts=1.0)
    compare(core, r)
    assert 0.8 < core.cost_ratio < 1.2


@pytest.mark.parametrize("transient", [True, False])
@pytest.mark.parametrize("name", ["discrete", "first_order"])
def test_given_noise_and_no_transient_match_the_reference(name, transient):
    m, structure = system(name)
    u, y = transient_record(m, periods=4, noise_std=0.01, seed=9)
    var = 0.01**2 / u.size
    lines = np.arange(5, u.size // 2 - 20)                   # a band, not the default lines
    core = lptv.identify_record(u, y, **structure, w0=m.w0, ts=1.0, noise=var, lines=lines,
                                transient=transient)
    r = ref.record.identify_record(u, y, **structure, w0=m.w0, ts=1.0, noise=var, lines=lines,
                                   transient=transient)
    compare(core, r)
    assert np.all(core.noise_var == var) and core.noise_dof == 0
    # without the transient term the fit is visibly wrong (the record's start-up is not modelled)
    assert (core.cost_ratio < 1.2) == transient


def test_local_polynomial_noise_route_matches_the_reference():
    m, structure = first_order_model()
    u, y = transient_record(m, periods=6, noise_std=0.05, seed=4)
    core = lptv.identify_record(u, y, **structure, w0=m.w0, ts=1.0, noise="lpm")
    r = ref.record.identify_record(u, y, **structure, w0=m.w0, ts=1.0, noise="lpm")
    compare(core, r)
    assert core.noise_dof > 0


@pytest.mark.parametrize("name", ["discrete", "first_order"])
def test_noise_free_record_both_routes_exact(name):
    """No noise: both routes reach the truth to the rounding of the prediction."""
    m, structure = system(name)
    u, y = transient_record(m, periods=3, noise_std=0.0, seed=5)
    par = _core.Parametrisation(structure["na"], structure["nb"], structure["ka"], structure["kb"], [], m.w0, 1.0)
    truth = np.asarray(par.xi_from_theta(par.theta_from_model(m._cpp)))
    core = lptv.identify_record(u, y, **structure, w0=m.w0, ts=1.0, noise=1e-24)
    r = ref.record.identify_record(u, y, **structure, w0=m.w0, ts=1.0, noise=1e-24)
    for res in (core, r):
        assert np.abs(res.Y - res.Y_fit).max() < 1e-10 * np.abs(res.Y).max()
        assert np.abs(res.eta - truth).max() < 1e-8
    assert np.abs(core.transient - r.transient).max() < 1e-10 * np.abs(r.transient).max()


def skeel_condition(grid, a):
    """max over the residue classes of || |A^-1| |A| ||_inf, densely."""
    N0 = grid.N // grid.L
    K = (a.shape[1] - 1) // 2
    worst = 0.0
    for r in range(grid.L):
        lines = r + grid.L * np.arange(N0)
        A = np.zeros((N0, N0), complex)
        for k in range(-K, K + 1):
            src = (np.arange(N0) - k) % N0
            z = grid.x[lines[src]]
            A[np.arange(N0), src] += sum(a[n, K + k] * z**n for n in range(a.shape[0]))
        worst = max(worst, np.max(np.abs(np.linalg.inv(A)) @ np.abs(A) @ np.ones(N0)))
    return worst


@pytest.mark.parametrize("periods", [1, 4])
@pytest.mark.parametrize("name", ["discrete", "first_order"])
def test_prediction_and_regression_match_the_reference(name, periods):
    m, structure = system(name)
    u, y = transient_record(m, periods=periods, noise_std=0.01, seed=periods)
    N = u.size
    U, Y = np.fft.fft(u) / N, np.fft.fft(y) / N
    par = _core.Parametrisation(structure["na"], structure["nb"], structure["ka"], structure["kb"], [], m.w0, 1.0)
    free = list(par.free_indices)
    eta = np.asarray(par.xi_from_theta(par.theta_from_model(m._cpp)))[free]
    n = max(structure["na"], structure["nb"])
    c = 0.01 * np.arange(1, n + 1)
    grid = _Grid(N, periods)
    a, b = np.asarray(m.a), np.asarray(m.b)
    assert skeel_condition(grid, a) <= RECORD_KAPPA_MAX
    core = np.asarray(_core.record_prediction(par, U, periods, eta, c))
    want = grid.solve(grid.factor(a), grid.apply(b, U) - grid.transient_basis(n) @ c)
    assert np.abs(core - want).max() <= RECORD_PREDICTION * np.abs(want).max()
    # the regression: columns of the free directions of theta, then z^1..z^n; e0 the normalised one
    lines = np.arange(1, N // 2)
    M, e0 = (np.asarray(x) for x in _core.record_regression(par, U, Y, periods, lines.tolist()))
    rpar = ref.identification.Parametrisation(structure["na"], structure["nb"], structure["ka"], structure["kb"],
                                              (), m.w0, 1.0)
    Ka, Kb = max(structure["ka"]), max(structure["kb"])

    def column(j):
        ad = np.zeros((structure["na"] + 1, 2 * Ka + 1), complex)
        bd = np.zeros((structure["nb"] + 1, 2 * Kb + 1), complex)
        for (is_a, order, k), v in zip(rpar.params, rpar.Text[:, j]):
            (ad if is_a else bd)[order, (Ka if is_a else Kb) + k] = v
        return (grid.apply(ad, Y) - grid.apply(bd, U))[lines]

    want_M = np.column_stack([column(j) for j in free] + [grid.x[lines] ** j for j in range(1, n + 1)])
    terms = (np.abs(a).sum() * np.abs(Y).max() + np.abs(b).sum() * np.abs(U).max())
    assert np.abs(M - want_M).max() <= RECORD_REGRESSION * max(terms, 1.0)
    assert np.abs(e0 - column(rpar.norm_index)).max() <= RECORD_REGRESSION * terms


def test_bad_arguments_of_the_core_are_named():
    m = discrete_model()
    par = _core.Parametrisation(2, 1, [2, 1, 0], [2, 0], [], m.w0, 1.0)
    u, y = transient_record(m, periods=2, noise_std=0.01, seed=0)
    U, Y = np.fft.fft(u) / u.size, np.fft.fft(y) / y.size
    lines = list(range(1, 255))
    with pytest.raises(ValueError, match="periods N0"):
        _core.fit_record(par, U, Y, 3, lines)
    with pytest.raises(ValueError, match="ascending"):
        _core.fit_record(par, U, Y, 2, lines[::-1])
    with pytest.raises(ValueError, match="noise_var must hold"):
        _core.fit_record(par, U, Y, 2, lines, noise_var=np.ones(3))
    ct = _core.Parametrisation(2, 1, [2, 1, 0], [2, 0], [], m.w0, 0.0)
    with pytest.raises(ValueError, match="ts: a continuous-time record needs its sample time"):
        _core.fit_record(ct, U, Y, 2, lines)
    with pytest.raises(ValueError, match="ts: the record's sample time"):
        _core.fit_record(par, U, Y, 2, lines, ts=2.0)
    with pytest.raises(ValueError, match="transient_degree: discrete time takes only -1"):
        _core.fit_record(par, U, Y, 2, lines, transient_degree=3)
    with pytest.raises(ValueError, match="transient_degree must lie in"):
        _core.fit_record(ct, U, Y, 2, lines, ts=1.0, transient_degree=0)
