"""The core's exact likelihood and method='sml' against the NumPy reference of METHOD.md eq. 17
(lptv.reference.likelihood: dense S, dS/deta formed explicitly, Newton on a finite-difference
Hessian), CT and DT, LPTV and LTI, rows from 1 (DC and conjugate lines) and default rows."""
import numpy as np
import pytest

import lptv
from lptv import _core
from lptv.reference import identification as ref
from lptv.reference import likelihood as lk

from test_likelihood_reference import SEEDS, make_case, noisy_periods, random_data, rows_of

# Cost and gradient: the two routes sum the same O(|R| K) products in different orders and solve
# with S (condition <= ~1e3 on these data, measured by the reference's tests): ~1e3 eps relative.
COST = 1e-11
# The gradient is compared relative to its largest entry: at the minimum it is a small difference
# of terms of size ~|r| |J| that cancel, so its accuracy is relative to those terms (bounded by
# the gradient's size away from the minimum, where we compare it).
GRADIENT = 1e-9
# The estimate: both minimise V to a step below 1e-13 relative; the minimiser is determined to
# ~ sqrt(eps) cond / V'' only where V is flat, so allow the 1e-8 the issue asks for.
ESTIMATE = 1e-8

cases = pytest.mark.parametrize(
    "seed,domain,lti", [(s, d, l) for s in SEEDS for d in ("ct", "dt") for l in (False, True)],
    ids=lambda v: str(v) if not isinstance(v, bool) else ("lti" if v else "lptv"))


def core_par(case):
    p = case.par
    known = [(is_a, n, row) for (is_a, n), row in p.known.items()]
    return _core.Parametrisation(p.na, p.nb, p.ka, p.kb, known, p.w0, p.ts)


def core_data(d):
    return _core.FrequencyData(d.U, d.Y, d.varU, d.varY, d.covYU, d.periods)


@cases
@pytest.mark.parametrize("which", ["near_dc", "default"])
def test_cost_and_gradient_match_reference(seed, domain, lti, which):
    case = make_case(seed, domain, lti)
    rng = np.random.default_rng([seed, 7])
    d, rows = random_data(rng, case.L), [int(r) for r in rows_of(case, which)]
    par, dc = core_par(case), core_data(d)
    lik = _core.ExactLikelihood(dc, par, rows)
    for theta in (case.theta, case.par.theta_from_xi(rng.normal(size=case.par.n_xi))):
        v_ref = lk.exact_cost(d, case.par, rows, theta)
        assert abs(lik.cost(theta) - v_ref) <= COST * v_ref
        g_ref = lk.exact_cost_gradient(d, case.par, rows, theta)
        g = np.asarray(lik.gradient(theta))
        assert np.max(np.abs(g - g_ref)) <= GRADIENT * np.max(np.abs(g_ref))
        S_ref = lk.residue_covariance(d, case.par, np.sort(rows), theta)
        S = np.asarray(lik.residue_covariance(theta))
        assert np.max(np.abs(S - S_ref)) <= COST * np.max(np.abs(S_ref))


@cases
def test_lti_cost_is_twice_the_diagonal_sml(seed, domain, lti):
    if not lti:
        pytest.skip("K = 0 only")
    case = make_case(seed, domain, lti)
    rng = np.random.default_rng([seed, 8])
    d, rows = random_data(rng, case.L), [int(r) for r in rows_of(case, "near_dc")]
    theta = case.theta
    e = ref.residue(d, case.par, rows, theta)
    v = ref.residue_variance(d, case.par, rows, theta)
    V = _core.ExactLikelihood(core_data(d), core_par(case), rows).cost(theta)
    assert V == pytest.approx(2 * np.sum(np.abs(e) ** 2 / v), rel=COST)


@cases
@pytest.mark.parametrize("which", ["near_dc", "default"])
def test_sml_estimate_matches_reference(seed, domain, lti, which):
    case = make_case(seed, domain, lti)
    rng = np.random.default_rng([seed, 9])
    d = noisy_periods(case, rng, 6)
    rows = [int(r) for r in rows_of(case, which)]
    par, dc = core_par(case), core_data(d)
    est = _core.estimate(dc, par, rows, method="sml", tol=1e-14, max_iter=200)
    assert est.converged
    wg = ref.estimate(d, case.par, rows, "wgtls", tol=1e-12)
    r = lk.sml_estimate(d, case.par, rows, wg["theta"], tol=1e-14)
    assert r["converged"]
    rel = np.linalg.norm(np.asarray(est.theta) - r["theta"]) / np.linalg.norm(r["theta"])
    assert rel <= ESTIMATE
    # the reported cost is V / (2 |R|)
    assert est.cost * 2 * len(rows) == pytest.approx(r["cost"], rel=COST)


def test_crb_matches_reference():
    case = make_case(0, "ct", False)
    rng = np.random.default_rng(3)
    d = random_data(rng, case.L)
    d = ref.Data(U=case.U0, Y=case.Y0, varU=d.varU * 1e-4, varY=d.varY * 1e-4, covYU=d.covYU * 1e-4)
    rows = [int(r) for r in rows_of(case, "default")]
    C = np.asarray(_core.cramer_rao_bound(core_data(d), core_par(case), rows, case.par.theta_from_xi(
        np.asarray(core_par(case).xi_from_theta(case.theta)))))
    C_ref = lk.crb(d, case.par, rows, case.theta / case.theta[case.par.theta_index(True, 2, 0)].real)
    assert np.max(np.abs(C - C_ref)) <= 1e-8 * np.max(np.abs(C_ref))


def test_public_crb_of_an_lti_design_matches_the_closed_form():
    """1/(s + a): with noise on the output only, F = sum_l 2 |dG/da|^2 |U|^2 / var_y ... computed
    from the transfer function directly (no residue, no likelihood code)."""
    a, w0, N = 2.0, 0.1, 256
    m = lptv.Model([[a], [1.0]], [[1.0]], w0=w0)
    ms = lptv.multisine(range(1, 60), N, seed=0)
    var_y, P = 1e-5, 4
    b = lptv.crb(m, ms, var_y=var_y, periods=P)
    # theta = (a0 = a, a1 = 1 normalised, b0): G = b0 / (s + a0); Y = G U + noise, var Y = var_y / P.
    lines = b.lines
    s = 1j * w0 * lines
    U = ms.spectrum[lines]
    dG = np.column_stack([-1.0 / (s + a) ** 2, 1.0 / (s + a)]) * U[:, None]   # d/d(a0, b0) of G U
    F = 2 * np.real(dG.conj().T @ dG) / (var_y / P)
    C = np.linalg.inv(F)
    assert b.std[[0, 2]] == pytest.approx(np.sqrt(np.diag(C)), rel=1e-10)
    assert b.std[1] == 0.0


def test_public_crb_takes_a_spectrum_or_a_multisine_and_checks_its_arguments():
    m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
    ms = lptv.multisine(range(1, 60), 256, seed=0)
    a = lptv.crb(m, ms, var_y=1e-5, var_u=1e-6, periods=4)
    b = lptv.crb(m, ms.spectrum, var_y=1e-5, var_u=1e-6, periods=4)
    assert np.array_equal(a.covariance, b.covariance)
    with pytest.raises(ValueError, match="u must be one spectrum"):
        lptv.crb(m, np.c_[ms.spectrum, ms.spectrum], var_y=1e-5)
    with pytest.raises(ValueError, match="var_y"):
        lptv.crb(m, ms, var_y=-1.0)
    with pytest.raises(ValueError, match="cov_yu"):
        lptv.crb(m, ms, var_y=1e-6, var_u=1e-6, cov_yu=1e-5)
    with pytest.raises(ValueError, match="periods"):
        lptv.crb(m, ms, var_y=1e-6, periods=0)
