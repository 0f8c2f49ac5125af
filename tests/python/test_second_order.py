"""The second-order noise of WGTLS's estimating equation (METHOD.md section 10): the core's
`second_order_meat` against the dense NumPy reference (lptv.reference.likelihood, a different
route: complex maps over signed lines and einsum instead of the core's loop over row pairs),
the reference against a Monte Carlo of the estimating equation's noise itself, and the
covariance `lptv.identify` reports for WGTLS against the reference's sandwich with that term."""
import warnings

import numpy as np
import pytest

import lptv
from lptv import _core
from lptv.reference import identification as ref
from lptv.reference import likelihood as lk

from test_likelihood_core import cases, core_data, core_par
from test_likelihood_reference import make_case, random_data, rows_of

# Both routes sum the same O(|R| K^2 n^2) products of O(1) numbers in different orders: a
# rounding error of a few hundred eps relative to the largest entry.
TERMS = 1e-11


@cases
@pytest.mark.parametrize("which", ["near_dc", "default"])
@pytest.mark.parametrize("known", [False, True], ids=["free", "known_a2"])
def test_second_order_meat_matches_reference(seed, domain, lti, which, known):
    case = make_case(seed, domain, lti, known=known)
    rng = np.random.default_rng([seed, 11])
    d, rows = random_data(rng, case.L), [int(r) for r in rows_of(case, which)]
    lik = _core.ExactLikelihood(core_data(d), core_par(case), rows)
    for theta in (case.theta, case.par.theta_from_xi(rng.normal(size=case.par.n_xi))):
        w = rng.uniform(0.3, 3.0, len(rows))
        got = np.asarray(lik.second_order_meat(core_par(case), theta, w))
        want = lk.second_order_meat(lk.second_order_terms(d, case.par, rows, theta, w), case.par, theta)
        assert got.shape == want.shape == (case.par.n_xi - 1,) * 2
        assert np.max(np.abs(got - want)) <= TERMS * np.max(np.abs(want))
        # A covariance: symmetric, positive semidefinite (to rounding).
        assert np.array_equal(got, got.T)
        assert np.linalg.eigvalsh(want).min() >= -1e-10 * np.abs(want).max()


def _circular(rng, n, size, var):
    return np.sqrt(var / 2) * (rng.normal(size=(n, size)) + 1j * rng.normal(size=(n, size)))


@pytest.mark.parametrize("seed,domain", [(0, "ct"), (1, "dt")])
def test_second_order_meat_monte_carlo(seed, domain):
    """Draw circular noise on the lines, form the estimating equation's noise at the true theta
    directly (the Jacobian is linear in the data: dJ = the Jacobian of the noise alone, r0 = dJ xi,
    q = Re(sum_l w_l conj(dJ_l) r0_l), lambda = sum w |r0|^2 / xi^T CJ_W xi) and compare its
    sample covariance with the formula. The formula leaves out Q's pseudo-covariance, a few
    per cent of the whole on these cases; 20 000 draws put a diagonal entry's sampling error
    near 1 %: the check allows 6 % on the diagonal and rejects the formula without the lambda
    terms (they move some entries by 15-60 % here)."""
    case = make_case(seed, domain, False)
    rng = np.random.default_rng([seed, 12])
    d = random_data(rng, case.L, rho=0.0)
    rows = ref.default_rows(case.par, case.L)  # every line read is >= 1: circular noise
    theta = case.theta
    w = 1.0 / ref.residue_variance(d, case.par, rows, theta)
    n_draw, L = 20000, case.L
    T = case.par.Text
    xi = lk.xi_of_theta(case.par, theta)
    cj = ref.real_column_covariance(d, case.par, rows, w)
    free = lk._free(case.par)
    Qs = np.empty((n_draw, free.size))
    # Noise on lines 0..L (line 0 unused by the default rows), Y and U independent here.
    dY = _circular(rng, n_draw, L + 1, d.varY)
    dU = _circular(rng, n_draw, L + 1, d.varU)
    for t in range(n_draw):
        noise = ref.Data(U=dU[t], Y=dY[t], varU=d.varU, varY=d.varY, covYU=d.covYU)
        Jn = ref.jacobian(noise, case.par, rows) @ T
        r0 = Jn @ xi
        q = (np.conj(Jn) * (w * r0)[:, None]).sum(axis=0).real
        lam = np.sum(w * np.abs(r0) ** 2) / (xi @ cj @ xi)
        Qs[t] = (q - lam * (cj @ xi))[free]
    mc = np.cov(Qs, rowvar=False)
    terms = lk.second_order_terms(d, case.par, rows, theta, w)
    want = lk.second_order_meat(terms, case.par, theta)
    rel = np.abs(np.diag(mc) / np.diag(want) - 1)
    assert rel.max() <= 0.06, rel.max()
    # Off the diagonal, relative to the entries' scale sqrt(M_aa M_bb).
    scale = np.sqrt(np.outer(np.diag(want), np.diag(want)))
    assert np.max(np.abs(mc - want) / scale) <= 0.06
    # Without the lambda terms (Cov(q) alone) the same draws disagree.
    alone = terms["qq"][np.ix_(free, free)]
    assert np.max(np.abs(np.diag(mc) / np.diag(alone) - 1)) > 0.15


@pytest.mark.parametrize("seed,domain", [(0, "ct"), (1, "dt"), (2, "ct")])
def test_identify_wgtls_covariance_has_the_second_order_term(seed, domain):
    """res.covariance of WGTLS = (P-1)/(P-3) H^-1 (meat + second-order meat) H^-1, H and meat the
    reference's sandwich terms at the denoised data, the second-order meat the reference's."""
    case = make_case(seed, domain, False)
    rng = np.random.default_rng([seed, 13])
    P = 6
    su, sy = 10 ** (-40 / 20) * np.std(case.u0), 10 ** (-30 / 20) * np.std(case.y0)
    nu = rng.standard_normal((P, case.N))
    u, y = case.u0 + su * nu, case.y0 + sy * (0.6 * nu + 0.8 * rng.standard_normal((P, case.N)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify(u, y, na=case.par.na, nb=case.par.nb, ka=case.par.ka, kb=case.par.kb,
                            w0=case.par.w0, ts=case.par.ts or None, method="wgtls", tol=1e-13)
    d = ref.frequency_data(u, y)
    rows = np.asarray(res.lines)
    theta = np.asarray(res.theta)
    v = ref.residue_variance(d, case.par, rows, theta)
    w = 1.0 / np.maximum(v, ref.VARIANCE_FLOOR * v.max())
    H, meat = lk.sandwich_terms(d, case.par, rows, theta, w)
    second = lk.second_order_meat(lk.second_order_terms(d, case.par, rows, theta, w), case.par, theta)
    Hinv = np.linalg.inv(H)
    cov = lk._eta_covariance(case.par, (P - 1) / (P - 3) * Hinv @ (meat + second) @ Hinv)
    first = lk._eta_covariance(case.par, (P - 1) / (P - 3) * Hinv @ meat @ Hinv)
    assert np.max(np.abs(res.covariance - cov)) <= 1e-8 * np.max(np.abs(cov))
    # The term is there: larger than the first-order covariance on the diagonal.
    assert np.all(np.diag(res.covariance) >= np.diag(first) * (1 - 1e-9))
    assert np.max(np.diag(res.covariance) / np.where(np.diag(first) > 0, np.diag(first), 1)) > 1.0 + 1e-6
