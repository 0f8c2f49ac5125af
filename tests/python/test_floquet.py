"""Floquet stability (METHOD.md section 12): Hill's method in the core against independent routes.

- the product of short-interval matrix exponentials (lptv.model.floquet.monodromy, continuous time);
- the monodromy matrix of lptv.simulation.timedomain's CVODE shooting (modestly damped models);
- the product of the one-step companion matrices in NumPy (discrete time);
- the poles of LTI models; the damped Mathieu equation's first instability tongue.

And what lptv.simulate and lptv.identify do with an unstable periodic system.
Tolerances: the ``floquet_tol`` fixture (conftest.py, Floquet block).
"""
import doctest
import importlib
import itertools
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

import lptv
import lptv.simulation.timedomain as td
from conftest import _coefficient_row  # the random stable coefficient rows the FDS tests use
from lptv.examples import mathieu_model, noisy_periods
from lptv.model.floquet import monodromy
from lptv.reference import simulate as reference_simulate

CT_SEEDS = [0, 1, 2, 3, 4, 5]


def matched_distance(a, b):
    """max |a_i - b_pi(i)| over the best pairing pi (na <= 3: all permutations)."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape
    return min(np.max(np.abs(a[list(p)] - b), initial=0.0) for p in itertools.permutations(range(a.size)))


def eig_condition(P):
    """Eigenvalues of P and their condition numbers ||x|| ||y|| / |y^H x|."""
    w, vl, vr = scipy.linalg.eig(P, left=True, right=True)
    kappa = np.linalg.norm(vl, axis=0) * np.linalg.norm(vr, axis=0) / np.abs(np.sum(vl.conj() * vr, axis=0))
    return w, kappa


def coefficients_at(c, w, t):
    """Fourier rows c (rows, 2K+1) at times t, in NumPy: (len(t), rows)."""
    K = (c.shape[1] - 1) // 2
    return (np.exp(1j * w * np.outer(t, np.arange(-K, K + 1))) @ c.T).real


def modestly_damped_model(seed):
    """Poles 0.02 .. 0.08 from the axis (real ones 0.05 .. 0.2), w0 in [0.5, 1.5] rad/s, the
    coefficients within 5 % of their mean: every |mu| >= exp(-0.2 * 12.6) = 0.08."""
    rng = np.random.default_rng([seed, 12])
    na = int(rng.integers(1, 4))
    pairs, single = divmod(na, 2)
    cplx = -rng.uniform(0.02, 0.08, pairs) + 1j * rng.uniform(0.5, 2.0, pairs)
    roots = np.concatenate([cplx, cplx.conj(), -rng.uniform(0.05, 0.2, single)])
    a_dc = np.real(np.poly(roots))[::-1]
    K = int(rng.integers(1, 4))
    a = np.array([_coefficient_row(rng, c, K, 0.05) for c in a_dc])
    return lptv.Model(a, [[1.0]], w0=float(rng.uniform(0.5, 1.5)))


# ------------------------------------------------------------------------ independent routes
@pytest.mark.parametrize("seed", CT_SEEDS)
def test_hill_matches_product_of_exponentials(seed, make_model, floquet_tol):
    model = make_model(seed, "ct")
    f = lptv.floquet(model)
    assert f.method == "hill" and f.multipliers.shape == (model.na,)
    P = monodromy(model, 2000)
    norm = np.linalg.norm(P, 2)
    # Premises of the tolerance: the product has converged in its step, eig(P) is well posed.
    assert np.linalg.norm(monodromy(model, 4000) - P, 2) <= floquet_tol.PRODUCT_STEP * norm
    w, kappa = eig_condition(P)
    assert kappa.max() <= floquet_tol.KAPPA_MAX
    assert matched_distance(f.multipliers, w) <= floquet_tol.VS_PRODUCT * norm
    # The random models are stable (poles well inside, coefficients within 20 % of the mean).
    assert f.is_stable and f.spectral_radius < 1
    assert np.all(np.abs(f.exponents.imag) <= model.w0 / 2 + 1e-15)


@pytest.mark.parametrize("seed", range(5))
def test_hill_matches_cvode_shooting_monodromy(seed, floquet_tol):
    model = modestly_damped_model(seed)
    f = lptv.floquet(model)
    U = np.array([0.0, 0.5])  # any input: the monodromy comes from the homogeneous runs
    ss = td.periodic_steady_state(model, U, 8, rtol=floquet_tol.CVODE_RTOL, full_output=True)
    P = ss.monodromy
    assert np.abs(f.multipliers).min() >= 0.05  # "modestly damped"
    tol = floquet_tol.VS_CVODE_RTOLS * floquet_tol.CVODE_RTOL * np.linalg.norm(P, 2)
    assert matched_distance(f.multipliers, np.linalg.eigvals(P)) <= tol


@pytest.mark.parametrize("seed", range(8))
def test_discrete_time_equals_numpy_product(seed, make_model, floquet_tol):
    model = make_model(seed, "dt")
    N, na = model.samples_per_period, model.na
    A = coefficients_at(model.a, 2 * np.pi / N, np.arange(N))  # a_n[k], k = 0..N-1
    P = np.eye(na)
    for k in range(N):  # x[k+1] = C_k x[k], x[k] = (y[k], ..., y[k+na-1])
        C = np.eye(na, k=1)
        C[-1] = -A[k, :na] / A[k, na]
        P = C @ P
    f = lptv.floquet(model)
    assert f.method == "product" and f.truncation == 0
    w = np.linalg.eigvals(P)
    bound = floquet_tol.DT_BOUND_FACTOR * f.error_estimate * np.abs(f.multipliers) \
        + 64 * floquet_tol.EPS * np.linalg.norm(P, 2)
    best = min(itertools.permutations(range(na)), key=lambda p: np.max(np.abs(w[list(p)] - f.multipliers)))
    assert np.all(np.abs(w[list(best)] - f.multipliers) <= bound)
    assert np.allclose(monodromy(model), P, rtol=0, atol=64 * floquet_tol.EPS * np.linalg.norm(P, 2))
    assert f.is_stable == bool(np.abs(w).max() < 1)
    # exponents: ln(mu) / (N ts) on the principal branch
    assert np.allclose(np.exp(f.exponents * N * model.ts), f.multipliers, rtol=1e-12, atol=0)


@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("seed", range(5))
def test_lti_multipliers_are_exp_of_the_poles(seed, domain, make_model, floquet_tol):
    model = make_model(seed, domain, lti=True)
    poles = np.roots(model.a[::-1, 0].real)
    f = lptv.floquet(model)
    if domain == "ct":
        expected = np.exp(poles * f.period)
        rel = matched_distance(f.multipliers, expected) / np.abs(expected).min()
        assert rel <= floquet_tol.LTI
        # The exponents are the poles, reduced modulo j w0 to the principal strip.
        reduced = poles.real + 1j * (poles.imag - model.w0 * np.round(poles.imag / model.w0))
        assert matched_distance(f.exponents, reduced) <= floquet_tol.LTI * model.w0
    else:
        # z^N: the core's product rounds every step (error_estimate); relative to the largest.
        expected = poles ** model.samples_per_period
        assert matched_distance(f.multipliers, expected) <= floquet_tol.LTI * np.abs(expected).max()
    assert f.is_stable


@pytest.mark.parametrize("seed", range(20))
def test_first_order_multiplier_is_exp_of_the_mean_rate(seed):
    """y' a_1(t) + a_0(t) y = 0: mu = exp(-int_0^T0 a_0/a_1 dt), whatever the harmonics; with
    a_1(t) varying Hill's matrix uses the harmonics of the ratio (sampled and transformed)."""
    rng = np.random.default_rng([seed, 21])
    K0, K1 = int(rng.integers(0, 4)), int(rng.integers(0, 4))
    a0 = _coefficient_row(rng, rng.uniform(-0.3, 1.0), K0, rng.uniform(0, 1.5))
    a1 = _coefficient_row(rng, rng.uniform(0.5, 2.0), K1, rng.uniform(0, 0.9))
    K = max(K0, K1)
    a = np.zeros((2, 2 * K + 1), complex)
    a[0, K - K0:K + K0 + 1], a[1, K - K1:K + K1 + 1] = a0, a1
    model = lptv.Model(a, [[1.0]], w0=float(rng.uniform(0.2, 2.0)))
    t = np.arange(4096) * model.period / 4096  # the trapezoid rule is spectrally exact here
    v = coefficients_at(model.a, model.w0, t)
    rate = np.mean(v[:, 0] / v[:, 1])
    f = lptv.floquet(model)
    # Within the core's own error estimate (an honest one: measured at most 0.85 of it over
    # 40 seeds), plus the rounding of the mean.
    err = abs(f.exponents[0] + rate) * f.period
    assert err <= 2 * f.error_estimate[0] + 64 * np.finfo(float).eps * (1 + abs(rate) * f.period)
    assert f.exponents[0].imag == 0 and f.multipliers[0].imag == 0
    assert f.is_stable == (rate > 0)


# ------------------------------------------------------------------------ the Mathieu equation
# Boundary of the first instability tongue of y'' + 2 zeta wn y' + wn^2 (1 + eps cos w0 t) y = 0
# at w0 = 2 wn: a solution of period 2 T0, y = A cos(w0 t/2) + B sin(w0 t/2), balanced on those two
# harmonics (first-order harmonic balance, i.e. Hill's determinant truncated to them) exists iff
# (1 - (w0/2wn)^2)^2 - eps^2/4 + (zeta w0/wn)^2 = 0, so eps_c = 4 zeta at w0 = 2 wn. Higher
# harmonics shift it by O(zeta^2) relative (measured: eps_c / 4 zeta - 1 = 2.2e-5 .. 2.2e-3 for
# zeta = 0.01 .. 0.1).
@pytest.mark.parametrize("zeta", [0.01, 0.02, 0.05])
def test_mathieu_frozen_stable_but_floquet_unstable_above_the_tongue(zeta):
    wn = 1.3
    w0 = 2 * wn
    for factor, stable in [(0.75, True), (1.25, False), (2.0, False)]:
        m = mathieu_model(zeta, wn, factor * 4 * zeta, w0)
        t = np.linspace(0, m.period, 101)
        poles = lptv.frozen_poles(m, t)
        assert np.allclose(poles.real, -zeta * wn, rtol=1e-12)  # every frozen pole: stable
        f = lptv.floquet(m)
        assert f.is_stable is stable
        # In the tongue's neighbourhood both multipliers are real and negative (period
        # doubling), their product exp(-2 zeta wn T0) (Liouville: trace F = -2 zeta wn).
        assert np.all(f.multipliers.imag == 0) and np.all(f.multipliers.real < 0)
        assert np.prod(f.multipliers).real == pytest.approx(np.exp(-2 * zeta * wn * m.period), rel=1e-12)
    # The boundary itself, by bisection on the spectral radius.
    lo, hi = 0.5 * 4 * zeta, 1.5 * 4 * zeta
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if lptv.floquet(mathieu_model(zeta, wn, mid, w0)).spectral_radius < 1 else (lo, mid)
    assert lo / (4 * zeta) == pytest.approx(1.0, abs=0.01)


def test_mathieu_detuned_boundary_follows_harmonic_balance():
    # eps_c = 2 sqrt((1 - r^2)^2 + (2 zeta r)^2), r = w0 / (2 wn); to first order in eps.
    zeta, wn = 0.01, 1.0
    for r in [0.99, 1.01, 1.02]:
        lo, hi = 0.0, 0.5
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            stable = lptv.floquet(mathieu_model(zeta, wn, mid, 2 * r * wn)).spectral_radius < 1
            lo, hi = (mid, hi) if stable else (lo, mid)
        predicted = 2 * np.sqrt((1 - r ** 2) ** 2 + (2 * zeta * r) ** 2)
        assert lo == pytest.approx(predicted, rel=0.02)


# ------------------------------------------------------------------------ an unstable system
def _mathieu_input(N=64, lines=range(1, 9), seed=3):
    ms = lptv.multisine(list(lines), N, seed=seed)
    return ms


def test_simulate_returns_the_periodic_solution_of_an_unstable_system():
    m = mathieu_model(0.02, 1.0, 0.1, 2.0)
    f = lptv.floquet(m)
    assert not f.is_stable and f.spectral_radius > 1.01
    ms = _mathieu_input()
    Y = lptv.simulate(m, ms.spectrum, lines_out=32)
    # The same band system, solved densely in NumPy (lptv.reference: an independent code).
    Yref = reference_simulate(m, ms.spectrum, guard=64, lines_out=32)
    assert np.abs(Y - Yref).max() <= 1e-12 * np.abs(Y).max()
    # It is a solution of the differential equation: CVODE's shooting (which needs no
    # stability: x0 = (I - Phi)^-1 x_forced, I - Phi well conditioned as no mu is near 1)
    # finds the same period.
    rtol = 1e-12
    y = td.periodic_steady_state(m, ms.spectrum, ms.n_samples, rtol=rtol)
    y_fds = lptv.time_signal(Y, ms.n_samples)
    assert np.abs(y - y_fds).max() <= 1e3 * rtol * np.abs(y).max()
    # ... but an unstable one: a deviation from it grows by mu_1 per period (sampled at whole
    # periods, y(k T0) = c1 mu1^k + c2 mu2^k, and (mu2 / mu1)^38 < 3e-3).
    dev = td.free_response(m, None, np.arange(41) * m.period, x0=np.array([1e-3, 0.0]), rtol=rtol)
    assert dev[40] / dev[38] == pytest.approx(f.multipliers[0].real ** 2, rel=1e-2)
    assert abs(dev[40]) > abs(dev[20]) > abs(dev[10])
    ss = td.periodic_steady_state(m, ms.spectrum, ms.n_samples, rtol=rtol, full_output=True)
    mu = np.linalg.eigvals(ss.monodromy)
    assert matched_distance(mu, f.multipliers) <= 1e-8


def test_identify_recovers_an_unstable_system_from_its_periodic_data():
    # Every line lies above the resonance (w0 = 2 wn), where a_0 weighs 1/w^2 of a_2: the
    # low lines 1..6 and 100 dB SNR pin it down to a few 1e-3 (its standard deviation).
    m = mathieu_model(0.02, 1.0, 0.1, 2.0)
    ms = _mathieu_input(lines=range(1, 7))
    y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), ms.n_samples)
    u, y = noisy_periods(ms.signal, y0, 4, 100.0, 100.0, seed=5)
    res = lptv.identify(u, y, na=2, nb=0, ka=1, kb=0, w0=m.w0, lines=range(2, 7))
    assert res.converged and not res.warnings
    a = res.model.a / res.model.a[2, 1].real  # normalise on a_2's mean
    assert np.abs(a - m.a).max() <= 5 * res.parameter_std.max()
    f_hat, f = lptv.floquet(res.model), lptv.floquet(m)
    assert not f_hat.is_stable  # identify does not refuse it; floquet tells the user
    assert np.abs(f_hat.multipliers - f.multipliers).max() <= 5e-3


# ------------------------------------------------------------------------ errors, README
def test_vanishing_leading_coefficient_is_refused_with_its_time():
    m = lptv.Model([[0.0, 1.0, 0.0], [0.3, 0.5, 0.3]], [[1.0]], w0=1.0)  # a_1 = 0.5 + 0.6 cos t
    with pytest.raises(ValueError, match=r"a_1\(t\) vanishes near t = "):
        lptv.floquet(m)
    with pytest.raises(ValueError, match=r"vanishes near t = "):
        monodromy(m)
    dt = lptv.Model([[0.0, 1.0, 0.0], [0.25, 0.5, 0.25]], [[1.0]], w0=2 * np.pi / 8, ts=1.0)
    with pytest.raises(ValueError, match=r"k = 4"):
        lptv.floquet(dt)


@pytest.mark.parametrize("kwargs, name", [
    (dict(tol=0.0), "tol"), (dict(tol=np.nan), "tol"), (dict(min_truncation=0), "min_truncation"),
    (dict(max_truncation=-1), "max_truncation"), (dict(min_truncation=20, max_truncation=10), "max_truncation"),
])
def test_bad_arguments_are_value_errors_naming_them(kwargs, name):
    with pytest.raises(ValueError, match=name):
        lptv.floquet(mathieu_model(), **kwargs)


def test_non_convergence_names_the_truncation_reached():
    a = lptv.examples.paper_model().a
    a[2] = 0
    a[2, 3] = 1.0  # a_2 = 1: F(t) has 3 harmonics, and M = 9 is far from enough (52 are needed)
    m = lptv.Model(a, [[1.0]], w0=0.04)
    with pytest.raises(lptv.NumericalError, match=r"M = 9"):
        lptv.floquet(m, max_truncation=9)
    with pytest.raises(ValueError, match="model"):
        lptv.floquet("not a model")


def test_paper_example_is_stable_with_its_accuracy():
    f = lptv.floquet(lptv.examples.paper_model())
    assert f.is_stable and f.truncation >= f.harmonics
    assert f.spectral_radius < 1e-30  # exponents near the frozen poles' -0.5: exp(-0.53 * 157)
    assert f.error_estimate.max() <= 1e-8 and f.convergence <= f.error_estimate.max()


def test_readme_mathieu_example_runs():
    """The Mathieu example of the user guide (docs/guide/06-structure.md; the README links it)."""
    root = Path(__file__).resolve().parents[2]
    text = "\n".join(p.read_text() for p in [root / "README.md", *sorted((root / "docs" / "guide").glob("*.md"))])
    blocks = [b for b in re.findall(r"```python\n(.*?)```", text, flags=re.S) if "f = lptv.floquet(m)" in b]
    assert len(blocks) == 1, "the README and the guide have no Floquet example, or several"
    ns = {}
    exec(compile(blocks[0], "06-structure.md", "exec"), ns)
    assert ns["f"].is_stable is False


def test_docstring_examples_run():
    # lptv.floquet is the function once the package is imported; the module is in sys.modules.
    module = importlib.import_module("lptv.model.floquet")
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
