"""One non-periodic record with its transient: lptv.identify_record (METHOD.md section 17).

The records come from the time recursion of the discrete-time example (lptv.examples.
transient_record: a random initial state, white-noise input, L whole periods), not from the
FDS the estimator uses. The checks: the estimate lies in its joint 99 % region around the
truth (several seeds); without the transient term it is visibly biased; it agrees with the
periodic route (lptv.identify on steady-state periods of the same system) within the two
routes' uncertainty; the residual's noise level is the true one.
"""
import numpy as np
import pytest
from scipy.stats import chi2

import lptv
from lptv import _core
from lptv.examples import DISCRETE_STRUCTURE, discrete_model, transient_record

NOISE = 0.01


def truth_eta(m):
    par = _core.Parametrisation(2, 1, [2, 1, 0], [2, 0], [], m.w0, 1.0)
    return np.asarray(par.xi_from_theta(par.theta_from_model(m._cpp)))


def chi_square(res, eta):
    free = res.parameter_std > 0
    d = (res.eta - eta)[free]
    return float(d @ np.linalg.solve(res.covariance[np.ix_(free, free)], d)), int(free.sum())


def fit(u, y, **kw):
    m = discrete_model()
    return lptv.identify_record(u, y, **DISCRETE_STRUCTURE, w0=m.w0, ts=1.0, **kw)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_inside_the_99_percent_region_and_biased_without_the_transient(seed):
    m = discrete_model()
    u, y = transient_record(m, periods=4, noise_std=NOISE, seed=seed)
    res = fit(u, y)
    assert res.converged and res.periods == 4 and res.transient.size == 2
    eta = truth_eta(m)
    c2, dof = chi_square(res, eta)
    assert dof == 14
    assert c2 <= chi2.ppf(0.99, dof)
    # the noise level from the residual is the true one (white noise: var = sigma^2 / N)
    true_var = NOISE**2 / u.size
    assert 0.8 < np.median(res.noise_var) / true_var < 1.25
    assert 0.85 < res.cost_ratio < 1.15
    # the steady-state model alone, with the same noise model: far outside
    biased = fit(u, y, transient=False, noise=res.noise_var)
    c2b, _ = chi_square(biased, eta)
    assert c2b > 10 * chi2.ppf(0.99, dof)
    assert biased.cost_ratio > 10


def test_noise_free_record_is_fitted_exactly_with_the_boundary_coefficients():
    """On a noise-free record the fit is the truth, and its c_j are those of the formula of
    section 17 (the boundary values weighted by the coefficients at t = -j)."""
    from lptv import reference as ref

    m = discrete_model()
    N0, na, nb = m.samples_per_period, m.na, m.nb
    N = 3 * N0
    rng = np.random.default_rng(7)
    u = rng.standard_normal(N + 4)
    y = np.zeros(N + 4)
    y[:na] = rng.standard_normal(na)
    A, B = ref.coefficients_at(m, np.arange(N + 2))
    for t in range(N + 2):
        y[t + na] = (B[t] @ u[t:t + nb + 1] - A[t, :na] @ y[t:t + na]) / A[t, na]
    res = fit(u[:N], y[:N], noise=1e-24)
    assert np.abs(res.Y - res.Y_fit).max() < 1e-10 * np.abs(res.Y).max()
    assert np.abs(res.eta - truth_eta(m)).max() < 1e-8
    c = []
    for j in (1, 2):
        Aj, Bj = ref.coefficients_at(m, [-float(j)])
        c.append((sum(Aj[0, i] * (y[N + i - j] - y[i - j]) for i in range(j, na + 1))
                  - sum(Bj[0, i] * (u[N + i - j] - u[i - j]) for i in range(j, nb + 1))) / N)
    assert np.allclose(res.transient, c, rtol=1e-7, atol=1e-12)


def test_agrees_with_the_periodic_route():
    m = discrete_model()
    N0 = m.samples_per_period
    u, y = transient_record(m, periods=4, noise_std=NOISE, seed=11)
    rec = fit(u, y)
    rng = np.random.default_rng(12)
    u1 = rng.standard_normal(N0)
    y1 = lptv.time_signal(lptv.simulate(m, lptv.spectrum(u1)), N0)
    P = 8
    up = np.tile(u1, (P, 1)) + 1e-6 * rng.standard_normal((P, N0))
    yp = np.tile(y1, (P, 1)) + NOISE * rng.standard_normal((P, N0))
    per = lptv.identify(up, yp, **DISCRETE_STRUCTURE, w0=m.w0, ts=1.0, method="sml")
    free = rec.parameter_std > 0
    assert np.array_equal(free, per.parameter_std > 0)
    z = (rec.eta - per.eta)[free] / np.hypot(rec.parameter_std[free], per.parameter_std[free])
    assert np.abs(z).max() < 3.5                     # 14 parameters: 3.5 std is a 0.7 % event


def test_noise_given_or_by_the_local_polynomial_method():
    """A known variance is used as given; the local polynomial method on a mildly time-varying
    system (the example's harmonics scaled by 0.2, its branches decaying fast) finds the noise
    level within 25 %."""
    m = discrete_model()
    a, b = m.a.copy(), m.b.copy()
    for c in (a, b):
        K = (c.shape[1] - 1) // 2
        c[:, :K] *= 0.2
        c[:, K + 1:] *= 0.2
    mild = lptv.Model(a, b, w0=m.w0, ts=1.0)
    u, y = transient_record(mild, periods=8, noise_std=0.05, seed=3)
    true_var = 0.05**2 / u.size
    given = lptv.identify_record(u, y, **DISCRETE_STRUCTURE, w0=m.w0, ts=1.0, noise=true_var)
    assert np.all(given.noise_var == true_var) and given.noise_dof == 0
    lpm = lptv.identify_record(u, y, **DISCRETE_STRUCTURE, w0=m.w0, ts=1.0, noise="lpm")
    assert 0.75 < np.median(lpm.noise_var) / true_var < 1.25
    assert lpm.noise_dof > 0


@pytest.mark.parametrize("kwargs, match", [
    (dict(u=np.ones(1000)), "u and y"),
    (dict(u=np.ones(1000), y=np.ones(1000)), "whole number of parameter periods"),
    (dict(ts=0.0), "ts must be a positive"),
    (dict(ts=0.7), "whole number of samples per period"),
    (dict(noise="flat"), "noise must be"),
    (dict(noise=-1.0), "noise must be positive"),
    (dict(lines=[0, 5]), "lines must lie in"),
    (dict(lines=[1, 2]), "lines: 2 lines give 4 real equations"),
    (dict(na=0), "na must be"),
    (dict(ka=[1, 1]), "ka must give one harmonic count per coefficient"),
])
def test_bad_input(kwargs, match):
    m = discrete_model()
    u, y = transient_record(m, periods=2, noise_std=NOISE, seed=0)
    args = dict(u=u, y=y, **DISCRETE_STRUCTURE, w0=m.w0, ts=1.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        lptv.identify_record(args.pop("u"), args.pop("y"), **args)


def test_docstring_examples_run():
    import doctest

    import lptv.estimation.one_record

    result = doctest.testmod(lptv.estimation.one_record, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
