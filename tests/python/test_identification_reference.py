"""The identification core against the NumPy reference, step by step, and both against exact
data, a Monte Carlo estimate of the residue variance and the WGTLS fixed-point identity.

The reference (lptv.reference.identification) shares no code or algorithm with the core: a dense
Jacobian, noise terms as quadratic forms with explicit per-line covariance matrices, estimators
on the tall real Jacobian, GTLS as a pivoted-Cholesky whitened SVD instead of the GSVD.
Tolerances: the ``id_tol`` fixture (conftest.py, identification block).
"""
import functools
import itertools
import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import lptv
import lptv.examples as ex
from lptv import _core
# The identification reference, by its full name.
from lptv.reference import identification as ref
from conftest import _coefficient_row  # the random stable coefficient rows the FDS tests use

METHODS = ["ls", "tls", "gtls", "wgtls"]
SEEDS = [0, 1, 2]
VARIANTS = ["plain", "known", "exact_input"]
# WGTLS stopping tolerance of the comparisons: both routes stop within ~tol of the same
# fixed point (they converge geometrically, ~1e-2 per iteration, in 4-8 iterations).
TOL = 1e-12
MAX_ITER = 100


# ------------------------------------------------------------------------------- test problems

def _pad(row, K):
    k = (row.size - 1) // 2
    out = np.zeros(2 * K + 1, complex)
    out[K - k:K + k + 1] = row
    return out


@functools.lru_cache(maxsize=None)
def make_case(seed, domain, lti, variant, periods=None):
    """A second-order model (na = 2, nb = 1), its noise-free response to a multisine on nearly
    every line, and P noisy periods with correlated input/output noise.

    LPTV: harmonic counts differ per coefficient (a permutation of 0, 1, 2 on a_0..a_2, of 1, 2
    on b_0, b_1), depth 20 %. Continuous time: w0 = 0.04 rad/s, N = 255 (odd, so no Nyquist
    line: the sampled periods carry every line exactly), poles near 1 rad/s. Discrete time:
    N = 128, ts = 1, poles at radius 0.5-0.8. SNR 40 dB (input), 30 dB (output), noise
    correlation 0.6. Variants: ``known`` gives a_2 (all its harmonics) as known; ``exact_input``
    has no input noise and P = 4, whose mean the core computes exactly, so var U = cov YU = 0
    exactly (a singular column covariance; test_steps_match_reference checks it).
    """
    rng = np.random.default_rng([seed, domain == "dt", lti, VARIANTS.index(variant)])
    if lti:
        ka, kb = [0, 0, 0], [0, 0]
    else:
        ka = [int(v) for v in rng.permutation([0, 1, 2])]
        kb = [int(v) for v in rng.permutation([1, 2])]
    if domain == "ct":
        N, w0, ts = 255, 0.04, None
        wn, zeta = rng.uniform(0.8, 1.5), rng.uniform(0.2, 0.5)
        a_dc = [wn ** 2, 2 * zeta * wn, 1.0]
        g = rng.uniform(0.5, 2.0)
        b_dc = [g * rng.uniform(0.5, 2.0), g]
    else:
        N, w0, ts = 128, 2 * np.pi / 128, 1.0
        r, phi = rng.uniform(0.5, 0.8), rng.uniform(0.2, 1.0)
        a_dc = [r * r, -2 * r * np.cos(phi), 1.0]
        g = rng.uniform(0.5, 2.0)
        b_dc = [-g * rng.uniform(-0.5, 0.5), g]
    a = [_coefficient_row(rng, c, K, 0.2) for c, K in zip(a_dc, ka)]
    b = [_coefficient_row(rng, c, K, 0.2) for c, K in zip(b_dc, kb)]
    model = lptv.Model(np.array([_pad(x, max(ka)) for x in a]),
                       np.array([_pad(x, max(kb)) for x in b]), w0=w0, ts=ts)
    ms = lptv.multisine(np.arange(1, N // 2 - 2), N, seed=rng)
    Y0 = lptv.simulate(model, ms.spectrum)
    u0, y0 = ms.signal, lptv.time_signal(Y0, N)
    P = periods or (4 if variant == "exact_input" else 6)
    su = 0.0 if variant == "exact_input" else 1e-2 * np.sqrt(np.mean(u0 ** 2))
    sy = 10 ** (-30 / 20) * np.sqrt(np.mean(y0 ** 2))
    nu = rng.standard_normal((P, N))
    ny = 0.6 * nu + 0.8 * rng.standard_normal((P, N))
    known = [(True, 2, a[2])] if variant == "known" else []
    par = ref.Parametrisation(2, 1, ka, kb, known, w0, ts or 0.0)
    return SimpleNamespace(
        model=model, na=2, nb=1, ka=ka, kb=kb, known=known,
        known_dict={"a2": a[2]} if variant == "known" else None, w0=w0, ts=ts, N=N,
        U0=ms.spectrum, Y0=Y0, u0=u0, y0=y0, u=u0 + su * nu, y=y0 + sy * ny, par=par,
        theta_true=ref.theta_of_coefficients(par, model.a, model.b))


def core_par(case):
    return _core.Parametrisation(case.na, case.nb, case.ka, case.kb, case.known, case.w0,
                                 case.ts or 0.0)


def rel(x, x_ref):
    return float(np.linalg.norm(np.asarray(x) - x_ref) / np.linalg.norm(x_ref))


def estimate_condition(Jx, norm_index, values, method):
    """The condition number that turns rounding into error in the estimate (column-scaled):
    LS: cond of the columns other than the normalised one; TLS: sigma_max / gap of the two
    smallest singular values; GTLS/WGTLS: the same with the generalised singular values."""
    A = Jx / np.linalg.norm(Jx, axis=0)
    if method == "ls":
        return np.linalg.cond(np.delete(A, norm_index, axis=1))
    if method == "tls":
        s = np.linalg.svd(A, compute_uv=False)
        return s[0] / (s[-2] - s[-1])
    return values[-1] / (values[1] - values[0])


case_params = pytest.mark.parametrize(
    "seed,domain,lti,variant",
    [(s, d, l, v) for s in SEEDS for d in ("ct", "dt") for l in (True, False) for v in VARIANTS],
    ids=lambda v: str(v) if not isinstance(v, bool) else ("lti" if v else "lptv"))


# ------------------------------------------------------------------------- step by step

@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("domain", ["ct", "dt"])
def test_noise_statistics(seed, domain, id_tol):
    case = make_case(seed, domain, False, "plain")
    d = ref.frequency_data(case.u, case.y)
    for dc in (_core.FrequencyData.from_periods(case.u, case.y),
               lptv.FrequencyData.from_periods(case.u, case.y, w0=case.w0, ts=case.ts)):
        assert dc.periods == d.periods == case.u.shape[0]
        for f in ("U", "Y", "varU", "varY", "covYU"):
            assert rel(getattr(dc, f), getattr(d, f)) <= id_tol.STEP, f
    # The correlation is there to be tested: |covYU| is a sizeable fraction of sqrt(varU varY).
    rho = np.abs(d.covYU[1:]) / np.sqrt(d.varU[1:] * d.varY[1:])
    assert np.median(rho) > 0.3


@case_params
def test_parametrisation(seed, domain, lti, variant):
    case = make_case(seed, domain, lti, variant)
    pc, pr = core_par(case), case.par
    assert [tuple(p) for p in pc.params] == pr.params
    assert (pc.n_theta, pc.n_eta, pc.n_xi, pc.has_known, pc.norm_index) == \
        (pr.n_theta, pr.n_eta, pr.n_xi, pr.has_known, pr.norm_index)
    # 0, +-1, +-j and copies of the known values: exact.
    for f in ("T", "Text", "d"):
        assert np.array_equal(np.asarray(getattr(pc, f)), getattr(pr, f)), f
    assert np.array_equal(pc.default_rows(case.N // 2), ref.default_rows(pr, case.N // 2))
    xi = np.random.default_rng(seed).normal(size=pr.n_xi)
    assert rel(pc.theta_from_xi(xi), pr.theta_from_xi(xi)) <= 1e-15


@case_params
def test_steps_match_reference(seed, domain, lti, variant, id_tol):
    """J, e, var e, C, CJ_W and R, each relative to the magnitude of the terms it sums (so that
    cancellation counts against neither route), on the default rows and on rows near DC whose
    lines include conjugate lines and line 0."""
    case = make_case(seed, domain, lti, variant)
    pc, pr = core_par(case), case.par
    dc = _core.FrequencyData.from_periods(case.u, case.y)
    d = ref.Data.of(dc)
    rng = np.random.default_rng([seed, 5])
    default = ref.default_rows(pr, d.max_line)
    for rows in (default, np.concatenate([np.arange(1, pr.K + 1), default[::3]])):
        rl = [int(r) for r in rows]
        J, Jr = np.asarray(_core.jacobian(dc, pc, rl)), ref.jacobian(d, pr, rows)
        assert np.all(np.abs(J - Jr) <= id_tol.STEP * np.abs(Jr))
        w = rng.uniform(0.2, 5.0, rows.size)
        for theta in (case.theta_true, pr.theta_from_xi(rng.normal(size=pr.n_xi))):
            e = np.asarray(_core.residue(dc, pc, rl, theta))
            assert np.all(np.abs(e - Jr @ theta) <= id_tol.STEP * (np.abs(Jr) @ np.abs(theta)))
            v = np.asarray(_core.residue_variance(dc, pc, rl, theta))
            A, B = ref.band_rows(pr, theta, rows)
            S = ref.line_noise(d, rows[:, None] - np.arange(-pr.K, pr.K + 1)[None, :])
            terms = np.sum(np.abs(A) ** 2 * S[..., 0, 0].real + np.abs(B) ** 2 * S[..., 1, 1].real
                           + 2 * np.abs(A * B * S[..., 0, 1]), axis=1)
            vr = ref.residue_variance(d, pr, rows, theta)
            assert np.all(np.abs(v - vr) <= id_tol.STEP * terms)
            # The core's grouped C against its own residue variance: var e_l = theta^H C_l theta.
            C = np.asarray(_core.column_covariance(dc, pc, rl, w))
            quad = np.real(np.conj(theta) @ C @ theta)
            assert abs(quad - w @ v) <= id_tol.STEP * (np.abs(theta) @ np.abs(C) @ np.abs(theta))
        # C and CJ are positive semidefinite: |C_pq| <= sqrt(C_pp C_qq), so the norm-wise error
        # relative to ||C|| is the entry-wise rounding.
        Cr = ref.column_covariance(d, pr, rows, w)
        assert rel(C, Cr) <= id_tol.STEP
        CJ = np.asarray(_core.real_column_covariance(dc, pc, rl, w))
        CJr = ref.real_column_covariance(d, pr, rows, w)
        assert rel(CJ, CJr) <= id_tol.STEP
        assert np.array_equal(CJ, CJ.T)
        # Householder QR is backward stable: ||R^T R - Jx^T Jx|| <= c m n eps ||Jx||^2.
        for weights in (w, np.empty(0)):
            R = np.asarray(_core.weighted_r_factor(dc, pc, rl, weights))
            Jx = ref.real_jacobian(d, pr, rows, weights if weights.size else None)
            assert np.allclose(R, np.triu(R), rtol=0, atol=0)
            assert np.linalg.norm(R.T @ R - Jx.T @ Jx) <= id_tol.STEP * np.linalg.norm(Jx, 2) ** 2
    if variant == "exact_input":
        # The premise of the singular-CJ case: every b-column is exactly noise-free.
        assert np.max(dc.varU) == 0.0 and np.max(np.abs(dc.covYU)) == 0.0
        bcols = np.flatnonzero(np.any(pr.Text[~pr.p_is_a] != 0, axis=0))
        assert bcols.size and np.all(CJ[bcols] == 0.0)


# ------------------------------------------------------------------------------- estimators

def _fields(r):
    """The core's EstimateResult as the reference's dict."""
    return {k: getattr(r, k) for k in ("theta", "eta", "iterations", "converged", "cost", "cost_history",
                                       "singular_values", "noise_free")}


def _compare_estimates(rc, rr, method, id_tol):
    assert rel(rc["theta"], rr["theta"]) <= id_tol.ESTIMATE, method
    assert rel(rc["eta"], rr["eta"]) <= id_tol.ESTIMATE, method
    assert abs(rc["cost"] - rr["cost"]) <= id_tol.ESTIMATE * rr["cost"], method
    assert rc["noise_free"] == rr["noise_free"]
    sv, svr = np.asarray(rc["singular_values"]), np.asarray(rr["singular_values"])
    assert sv.shape == svr.shape, method
    assert np.all(np.abs(sv - svr) <= id_tol.ESTIMATE * svr), method
    if method == "wgtls":
        assert rc["converged"] and rr["converged"]
        # Both stop at the same rule from the same start; the changes are far above rounding.
        assert rc["iterations"] == rr["iterations"]
        assert np.allclose(rc["cost_history"], rr["cost_history"], rtol=id_tol.ESTIMATE, atol=0)


@case_params
def test_estimators_match_reference(seed, domain, lti, variant, id_tol):
    case = make_case(seed, domain, lti, variant)
    pc, pr = core_par(case), case.par
    dc = _core.FrequencyData.from_periods(case.u, case.y)
    d = ref.Data.of(dc)
    rows = ref.default_rows(pr, d.max_line)
    Jx = ref.real_jacobian(d, pr, rows)
    for method in METHODS:
        rc = _fields(_core.estimate(dc, pc, [int(r) for r in rows], method=method, tol=TOL,
                            max_iter=MAX_ITER))
        rr = ref.estimate(d, pr, rows, method, tol=TOL, max_iter=MAX_ITER)
        kappa = estimate_condition(Jx, pr.norm_index, rr["singular_values"], method)
        assert kappa <= id_tol.COND_MAX
        _compare_estimates(rc, rr, method, id_tol)
        if method == "wgtls":
            # Consistent: near the truth at this SNR, where a wrong estimator agreeing with a
            # wrong reference would not land (LS and TLS are biased and may be 15 % off).
            assert rel(rr["theta"], case.theta_true) < 0.1
    if variant == "exact_input":
        # The GSVD's infinite values are the noise-free directions: one per b-column of xi.
        n_b = np.count_nonzero(np.any(pr.Text[~pr.p_is_a] != 0, axis=0))
        assert len(rr["singular_values"]) == pr.n_xi - n_b


# Unweighted GTLS on this example has close smallest generalised singular values (about 1.0
# and 1.2): identify warns, rightly; the comparison is unaffected (condition checked below).
@pytest.mark.filterwarnings("ignore::lptv.IdentifiabilityWarning")
@pytest.mark.parametrize("method", METHODS)
def test_paper_example_matches_reference(method, id_tol):
    """The paper-like example (35 parameters, every 10th line excited, rows 1..243 from DC):
    the largest and least well-conditioned problem of this file (condition up to ~1e4)."""
    m, ms = ex.paper_model(), ex.paper_multisine(0)
    y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), ex.PAPER_N)
    u, y = ex.noisy_periods(ms.signal, y0, 8, 50, 30, seed=1, pole_in=0.5, pole_out=0.8,
                            correlation=0.5)
    res = lptv.identify(u, y, na=2, nb=1, ka=3, kb=3, w0=ex.PAPER_W0, lines=ex.PAPER_ID_LINES,
                        method=method, tol=TOL, max_iter=MAX_ITER, noise="sample")
    pr = ref.Parametrisation(2, 1, [3] * 3, [3] * 2, (), ex.PAPER_W0)
    d = ref.frequency_data(u, y)
    rr = ref.estimate(d, pr, ex.PAPER_ID_LINES, method, tol=TOL, max_iter=MAX_ITER)
    Jx = ref.real_jacobian(d, pr, ex.PAPER_ID_LINES)
    assert estimate_condition(Jx, pr.norm_index, rr["singular_values"], method) <= id_tol.COND_MAX
    _compare_estimates(dict(theta=res.theta, eta=res.eta, cost=res.cost, noise_free=res.noise_free,
                            singular_values=res.singular_values, converged=res.converged,
                            iterations=res.iterations, cost_history=res.cost_history),
                       rr, method, id_tol)


@functools.lru_cache(maxsize=None)
def reference_estimate(seed, domain, lti, variant, method):
    case = make_case(seed, domain, lti, variant)
    d = ref.frequency_data(case.u, case.y)
    rows = ref.default_rows(case.par, d.max_line)
    return d, rows, ref.estimate(d, case.par, rows, method, tol=TOL, max_iter=MAX_ITER)


# -------------------------------------------------------------------- the public identify()
# The reference weighs by each line's own sample (co)variances: identify is asked for that
# route (its default, noise='auto', may moderate them; that route has its own reference in
# tests/python/test_moderation_core.py).

def _identify(case, method, data=None):
    args = (data,) if data is not None else (case.u, case.y)
    return lptv.identify(*args, na=case.na, nb=case.nb, ka=case.ka, kb=case.kb,
                         w0=None if data is not None else case.w0,
                         ts=None if data is not None else case.ts, known=case.known_dict,
                         method=method, tol=TOL, max_iter=MAX_ITER, noise="sample")


@case_params
def test_identify_matches_reference(seed, domain, lti, variant, id_tol):
    case = make_case(seed, domain, lti, variant)
    pr = case.par
    for method in METHODS:
        d, rows, rr = reference_estimate(seed, domain, lti, variant, method)
        res = _identify(case, method)
        assert np.array_equal(res.lines, rows)
        assert rel(res.theta, rr["theta"]) <= id_tol.ESTIMATE, method
        assert np.array_equal(ref.theta_of_coefficients(pr, res.model.a, res.model.b), res.theta)
        assert res.n_free_parameters == pr.n_xi - 1
        # The residue is small against its terms: compare it on their scale.
        e, v, r = ref.normalized_residue(d, pr, rows, rr["theta"])
        scale = np.abs(ref.jacobian(d, pr, rows)) @ np.abs(rr["theta"])
        assert np.all(np.abs(res.residue - e) <= id_tol.ESTIMATE * scale)
        assert np.all(np.abs(res.residue_variance - v) <= id_tol.ESTIMATE * v)
        assert np.all(np.abs(res.normalized_residue - r)
                      <= id_tol.ESTIMATE * (scale / np.sqrt(v) + r))
        p = ref.expected_fraction_above_0db(rows.size, pr.n_xi - 1, case.u.shape[0])
        assert res.fraction_expected == pytest.approx(p, rel=id_tol.FRACTION, abs=0)
        assert res.fraction_above_0db == np.mean(r > 1.0)


@case_params
def test_wgtls_fixed_point_identity(seed, domain, lti, variant, id_tol):
    """METHOD.md section 6: at the WGTLS fixed point, w = 1/var e(theta) makes xi^T CJ_W xi =
    sum_l w_l var e_l = |R| exactly, so the cost (the smallest generalised eigenvalue) equals
    mean_l |e_l|^2 / var e_l. The iteration stops with weights from the previous iterate, a
    relative change below TOL, so the two agree to ~TOL times the sensitivity of var e."""
    case = make_case(seed, domain, lti, variant)
    res = _identify(case, "wgtls")
    assert res.converged
    ratio = np.mean(res.normalized_residue ** 2)
    assert abs(res.cost - ratio) <= id_tol.SELF_CHECK * ratio
    d, rows, rr = reference_estimate(seed, domain, lti, variant, "wgtls")
    _, _, r = ref.normalized_residue(d, case.par, rows, rr["theta"])
    assert abs(rr["cost"] - np.mean(r ** 2)) <= id_tol.SELF_CHECK * np.mean(r ** 2)
    # Not an identity that holds anywhere: at the GTLS start (unit weights) it fails.
    g = _identify(case, "gtls")
    assert abs(g.cost - np.mean(g.normalized_residue ** 2)) > 1e3 * id_tol.SELF_CHECK * ratio


# ---------------------------------------------------------------------------- noiseless data

def _exact_condition(Jx, norm_index):
    """Condition of the estimate on exact data (column-scaled Jx, whose smallest singular value
    is ~0): sigma_max / sigma_{n-1} for the null vector (TLS, and GTLS whose minimiser is the
    same null vector), and cond of the other columns for LS."""
    A = Jx / np.linalg.norm(Jx, axis=0)
    s = np.linalg.svd(A, compute_uv=False)
    return max(s[0] / s[-2], np.linalg.cond(np.delete(A, norm_index, axis=1)))


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("lti", [True, False], ids=["lti", "lptv"])
def test_noiseless_periods_recover_truth(seed, domain, lti, id_tol):
    """Identical periods: the variances are exactly zero (the mean of P = 2 equal numbers is
    exact), so GTLS and WGTLS fall back to TLS; every estimator lands on the true parameters.
    Exact up to the FDS's 1e-13 truncation and the FFT's rounding, amplified by the condition."""
    case = make_case(seed, domain, lti, "plain")
    data = lptv.FrequencyData.from_periods(np.tile(case.u0, (2, 1)), np.tile(case.y0, (2, 1)),
                                           w0=case.w0, ts=case.ts)
    assert data.varU.max() == data.varY.max() == np.abs(data.covYU).max() == 0.0
    pc, pr = core_par(case), case.par
    d = ref.Data.of(data)
    rows = ref.default_rows(pr, d.max_line)
    kappa = _exact_condition(ref.real_jacobian(d, pr, rows), pr.norm_index)
    assert kappa <= id_tol.NOISELESS_COND_MAX
    for method in METHODS:
        rc = _fields(_core.estimate(data._cpp, pc, [int(r) for r in rows], method=method, tol=TOL,
                            max_iter=MAX_ITER))
        rr = ref.estimate(d, pr, rows, method, tol=TOL, max_iter=MAX_ITER)
        assert rc["noise_free"] == rr["noise_free"] == (method in ("gtls", "wgtls"))
        assert rel(rc["theta"], case.theta_true) <= id_tol.NOISELESS, method
        assert rel(rr["theta"], case.theta_true) <= id_tol.NOISELESS, method


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("lti", [True, False], ids=["lti", "lptv"])
@pytest.mark.parametrize("variant", ["plain", "known"])
def test_noiseless_spectra_with_variances_recover_truth(seed, domain, lti, variant, id_tol):
    """Exact spectra with small synthetic (correlated) variances: GTLS and WGTLS take their
    noise-weighted path, not the TLS fallback, and the true parameters still zero the residue,
    so every estimator recovers them, through the public identify()."""
    case = make_case(seed, domain, lti, variant)
    rng = np.random.default_rng([seed, 9])
    n = case.U0.size
    varU = 1e-8 * rng.uniform(0.5, 2.0, n)
    varY = 1e-8 * rng.uniform(0.5, 2.0, n)
    covYU = 0.5 * np.sqrt(varU * varY) * np.exp(2j * np.pi * rng.uniform(size=n))
    covYU[0] = covYU[0].real
    data = lptv.FrequencyData(case.U0, case.Y0, varU, varY, covYU, w0=case.w0, ts=case.ts)
    d = ref.Data.of(data)
    rows = ref.default_rows(case.par, d.max_line)
    kappa = _exact_condition(ref.real_jacobian(d, case.par, rows), case.par.norm_index)
    assert kappa <= id_tol.NOISELESS_COND_MAX
    for method in METHODS:
        res = _identify(case, method, data=data)
        assert not res.noise_free
        assert rel(res.theta, case.theta_true) <= id_tol.NOISELESS, method
        if method == "wgtls":
            assert res.converged
        rr = ref.estimate(d, case.par, rows, method, tol=TOL, max_iter=MAX_ITER)
        assert rel(rr["theta"], case.theta_true) <= id_tol.NOISELESS, method


@pytest.mark.parametrize("domain", ["ct", "dt"])
def test_identify_accepts_noise_free_periods(domain, id_tol):
    case = make_case(0, domain, False, "plain")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = lptv.identify(np.tile(case.u0, (2, 1)), np.tile(case.y0, (2, 1)), na=case.na,
                            nb=case.nb, ka=case.ka, kb=case.kb, w0=case.w0, ts=case.ts,
                            method="wgtls")
    assert any("no noise" in str(w.message) for w in caught)
    assert res.noise_free
    assert rel(res.theta, case.theta_true) <= id_tol.NOISELESS


# --------------------------------------------------------- residue variance by Monte Carlo

@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("lti", [True, False], ids=["lti", "lptv"])
def test_residue_variance_monte_carlo(domain, lti, id_tol):
    """var e_l (eq. 15, with the input-output correlation) against the sample mean of |e_l|^2
    over draws of (dU, dY) with a prescribed per-line covariance (|correlation| 0.9, random
    phase), e = A dY - B dU with A and B written out here from theta. Rows start at 1, so the
    rows near DC use conjugate lines (same noise, conjugated) and line 0 (real noise).

    |e_l|^2 has a finite fourth moment, so its sample mean over n draws has standard error
    std(|e_l|^2) / sqrt(n), estimated from the draws; MC_SIGMAS of them bound every row."""
    case = make_case(0, domain, lti, "plain")
    theta, pr = case.theta_true, case.par
    rng = np.random.default_rng([17, domain == "dt", lti])
    L, K = 40, pr.K
    lines = np.arange(L + 1)
    s = np.exp(1j * case.w0 * case.ts * lines) if case.ts else 1j * case.w0 * lines
    a0, b0 = case.model.a[:, case.model.ka], case.model.b[:, case.model.kb]
    # Input noise scaled by |A/B| so that the two terms, and the correlation, weigh alike.
    ratio = np.abs(np.polyval(a0[::-1], s) / np.polyval(b0[::-1], s)) ** 2
    varY = rng.uniform(0.5, 2.0, L + 1)
    varU = varY * ratio * rng.uniform(0.5, 2.0, L + 1)
    covYU = 0.9 * np.sqrt(varU * varY) * np.exp(2j * np.pi * rng.uniform(size=L + 1))
    covYU[0] = 0.9 * np.sqrt(varU[0] * varY[0])  # line 0 of a real signal: real noise
    U = rng.normal(size=L + 1) + 1j * rng.normal(size=L + 1)
    Y = rng.normal(size=L + 1) + 1j * rng.normal(size=L + 1)
    U[0], Y[0] = U[0].real, Y[0].real
    rows = np.arange(1, L - K + 1)

    # Draws: z_m = [dY_m, dU_m] with E{z z^H} = Sigma_m, circular on m >= 1, real on m = 0.
    n = id_tol.MC_DRAWS
    dY = np.empty((2 * L + 1, n), complex)
    dU = np.empty((2 * L + 1, n), complex)
    for m in lines:
        Sig = np.array([[varY[m], covYU[m]], [np.conj(covYU[m]), varU[m]]])
        G = np.linalg.cholesky(Sig)
        g = rng.standard_normal((2, n)) if m == 0 else \
            (rng.standard_normal((2, n)) + 1j * rng.standard_normal((2, n))) / np.sqrt(2)
        z = G @ g
        dY[L + m], dU[L + m] = z[0], z[1]
        dY[L - m], dU[L - m] = np.conj(z[0]), np.conj(z[1])
    # Rows of the band matrices A, B (eq. 5) on lines -L..L.
    A = np.zeros((rows.size, 2 * L + 1), complex)
    B = np.zeros((rows.size, 2 * L + 1), complex)
    for r, l in enumerate(rows):
        for t, (is_a, order, k) in zip(theta, pr.params):
            i = l - k
            si = np.exp(1j * case.w0 * case.ts * i) if case.ts else 1j * case.w0 * i
            (A if is_a else B)[r, L + i] += t * si ** order
    e2 = np.abs(A @ dY - B @ dU) ** 2
    mc, se = e2.mean(axis=1), e2.std(axis=1) / np.sqrt(n)

    pc = core_par(case)
    rl = [int(x) for x in rows]

    def core_variance(cov):
        return np.asarray(_core.residue_variance(_core.FrequencyData(U, Y, varU, varY, cov, 0),
                                                 pc, rl, theta))

    v = core_variance(covYU)
    assert np.all(np.abs(mc - v) <= id_tol.MC_SIGMAS * se)
    d = ref.Data(U=U, Y=Y, varU=varU, varY=varY, covYU=covYU)
    assert np.all(np.abs(mc - ref.residue_variance(d, pr, rows, theta)) <= id_tol.MC_SIGMAS * se)
    # The draws are numerous enough to reject the likely mistakes: no correlation term, and
    # the transposed convention E{dU conj(dY)}.
    for wrong in (np.zeros_like(covYU), np.conj(covYU)):
        assert np.max(np.abs(mc - core_variance(wrong)) / se) > 2 * id_tol.MC_SIGMAS


# ------------------------------------------------------------------------------- validation

@pytest.mark.parametrize("periods", [0, 2, 4, 8])
@pytest.mark.parametrize("n_rows,n_free", [(243, 34), (60, 17), (500, 0)])
def test_expected_fraction_matches_reference(periods, n_rows, n_free, id_tol):
    p, (lo, hi) = lptv.expected_fraction_above_0db(n_rows, n_free, periods)
    assert p == pytest.approx(ref.expected_fraction_above_0db(n_rows, n_free, periods),
                              rel=id_tol.FRACTION, abs=0)
    assert lo < p < hi


@pytest.mark.parametrize("periods", [0, 4])
def test_expected_fraction_monte_carlo(periods, id_tol):
    """The distribution behind the prediction: a circular Gaussian residue normalised by its
    exact variance (Exp(1)), or by the variance of the mean estimated from P periods
    (F(2, 2(P-1))). The standard error of a fraction over n draws is sqrt(p (1-p) / n)."""
    rng = np.random.default_rng(23)
    n = id_tol.FRACTION_DRAWS
    if periods:
        z = rng.standard_normal((n, periods)) + 1j * rng.standard_normal((n, periods))
        z /= np.sqrt(2)
        mean = z.mean(axis=1)
        var = np.sum(np.abs(z - mean[:, None]) ** 2, axis=1) / (periods * (periods - 1))
        ratio = np.abs(mean) ** 2 / var
    else:
        ratio = np.abs(rng.standard_normal(n) + 1j * rng.standard_normal(n)) ** 2 / 2
    frac = np.mean(ratio > 1.0)
    p = ref.expected_fraction_above_0db(1, 0, periods)
    se = np.sqrt(p * (1 - p) / n)
    assert abs(frac - p) <= id_tol.MC_SIGMAS * se
    if periods:
        # Distinguishes F(2, 2(P-1)) from exp(-1): 0.42 against 0.37 for P = 4.
        assert abs(frac - np.exp(-1)) > 4 * id_tol.MC_SIGMAS * se


# --------------------------------------------- exactly known input at rounding-level variance

def _rounding_level_cases():
    """Exact input over P = 5 periods: the mean of five equal spectra is not always exact, so
    var U is at the rounding level (~1e-33) rather than zero; the core and the reference must
    both treat the b-columns as noise-free."""
    for seed, domain, lti in itertools.product(SEEDS, ("ct", "dt"), (True, False)):
        case = make_case(seed, domain, lti, "exact_input", periods=5)
        dc = _core.FrequencyData.from_periods(case.u, case.y)
        d = ref.Data.of(dc)
        rows = ref.default_rows(case.par, d.max_line)
        yield case, dc, d, rows


def test_estimates_with_rounding_level_input_noise(id_tol):
    rounding = 0
    for case, dc, d, rows in _rounding_level_cases():
        rounding += 0 < d.varU.max() <= id_tol.EPS ** 2 * np.max(np.abs(d.U)) ** 2
        for method in ("gtls", "wgtls"):
            rc = _fields(_core.estimate(dc, core_par(case), [int(r) for r in rows], method=method,
                                tol=TOL, max_iter=MAX_ITER))
            rr = ref.estimate(d, case.par, rows, method, tol=TOL, max_iter=MAX_ITER)
            assert rel(rc["theta"], rr["theta"]) <= id_tol.ESTIMATE
            sv, svr = np.asarray(rc["singular_values"]), rr["singular_values"]
            assert abs(sv[0] - svr[0]) <= id_tol.ESTIMATE * svr[0]
    assert rounding >= 4  # the premise: these cases do exercise rounding-level variances


def test_generalised_values_with_rounding_level_input_noise(id_tol):
    for case, dc, d, rows in _rounding_level_cases():
        rc = _fields(_core.estimate(dc, core_par(case), [int(r) for r in rows], method="gtls"))
        rr = ref.estimate(d, case.par, rows, "gtls")
        sv, svr = np.asarray(rc["singular_values"]), rr["singular_values"]
        assert sv.shape == svr.shape
        assert np.all(np.abs(sv - svr) <= id_tol.ESTIMATE * svr)
