"""The exact-likelihood reference (lptv.reference.likelihood, METHOD.md section 10) on its own:
against the identification reference (eq. 15, the residue), against Monte Carlo draws of
noisy periods, against finite differences, and its estimator and Cramer-Rao bound against
Monte Carlo estimates. Nothing here touches the compiled core.
"""
import functools
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.stats

from lptv.reference import fds
from lptv.reference import identification as ref
from lptv.reference import likelihood as lk
from conftest import _coefficient_row  # the random stable coefficient rows of the FDS tests

SEEDS = [0, 1, 2]
ROW_SETS = ["near_dc", "default"]

# Sums of a few dozen products compared in a different order: each side is within
# ~50 eps of the terms it sums (at most 4(2K+1) = 20 nonzero terms per entry, a few
# multiplications each), and the comparisons are made relative to those terms.
ALGEBRA = 1e-13
# The trace of a 2 x 2 block of S against eq. 15: a relative error of ~eps cond(S) from
# M Cov M^T, relative to var e_l, which loses at most (1 + rho)/(1 - rho) = 4 to cancellation
# at the |correlation| <= 0.6 of the test data.
TRACE = 1e-12


# ------------------------------------------------------------------------------- test problems

def _pad(row, K):
    k = (row.size - 1) // 2
    out = np.zeros(2 * K + 1, complex)
    out[K - k:K + k + 1] = row
    return out


@functools.lru_cache(maxsize=None)
def make_case(seed, domain, lti, known=False, depth=0.2):
    """na = 2, nb = 1; LPTV: harmonic counts a permutation of 0, 1, 2 on a_0..a_2 and of 1, 2
    on b_0, b_1 (K = 2), each coefficient within dc (1 +- depth). N = 63 samples per period
    (odd: no Nyquist line, whose noise would be real like DC's), lines 0..31. Continuous
    time: w0 in [0.1, 0.2] rad/s, poles near 1 rad/s; discrete time: ts = 1, poles at radius
    0.5-0.8. Noiseless spectra from the dense reference FDS (continuous time: 60 guard lines,
    residue ~1e-15 on the rows)."""
    rng = np.random.default_rng([seed, domain == "dt", lti, 31])
    ka = [0, 0, 0] if lti else [int(v) for v in rng.permutation([0, 1, 2])]
    kb = [0, 0] if lti else [int(v) for v in rng.permutation([1, 2])]
    N = 63
    if domain == "ct":
        w0, ts = rng.uniform(0.1, 0.2), 0.0
        wn, zeta = rng.uniform(0.8, 1.5), rng.uniform(0.2, 0.5)
        a_dc = [wn ** 2, 2 * zeta * wn, 1.0]
        b_dc = [rng.uniform(0.5, 2.0), 1.0]
    else:
        w0, ts = 2 * np.pi / N, 1.0
        r, phi = rng.uniform(0.5, 0.8), rng.uniform(0.2, 1.0)
        a_dc = [r * r, -2 * r * np.cos(phi), 1.0]
        b_dc = [rng.uniform(-0.5, 0.5), 1.0]
    g = rng.uniform(0.5, 2.0)
    a = [_coefficient_row(rng, c, K, depth) for c, K in zip(a_dc, ka)]
    b = [_coefficient_row(rng, g * c, K, depth) for c, K in zip(b_dc, kb)]
    model = SimpleNamespace(a=np.array([_pad(x, max(ka)) for x in a]),
                            b=np.array([_pad(x, max(kb)) for x in b]), w0=w0, ts=ts)
    L = N // 2
    U0 = rng.normal(size=L + 1) + 1j * rng.normal(size=L + 1)
    U0[0] = U0[0].real
    Y0 = fds.simulate(model, U0, guard=60, lines_out=L)
    par = ref.Parametrisation(2, 1, ka, kb, [(True, 2, a[2])] if known else [], w0, ts)
    return SimpleNamespace(par=par, N=N, L=L, U0=U0, Y0=Y0, u0=fds.time_signal(U0, N),
                           y0=fds.time_signal(Y0, N),
                           theta=ref.theta_of_coefficients(par, model.a, model.b))


def rows_of(case, which):
    """Default rows, or every row from 1: rows 1..K use the DC line and conjugate lines (for
    K = 0 the two are the same)."""
    if which == "default":
        return ref.default_rows(case.par, case.L)
    return np.arange(1, case.L - case.par.K + 1)


def random_data(rng, L, rho=0.6):
    """Any spectra and (co)variances: the algebraic identities hold for all of them.
    |correlation| <= rho with a random phase; DC real."""
    Y = rng.normal(size=L + 1) + 1j * rng.normal(size=L + 1)
    U = rng.normal(size=L + 1) + 1j * rng.normal(size=L + 1)
    varY, varU = rng.uniform(0.5, 2.0, L + 1), rng.uniform(0.5, 2.0, L + 1)
    covYU = rho * rng.uniform(size=L + 1) * np.sqrt(varY * varU) \
        * np.exp(2j * np.pi * rng.uniform(size=L + 1))
    U[0], Y[0], covYU[0] = U[0].real, Y[0].real, covYU[0].real
    return ref.Data(U=U, Y=Y, varU=varU, varY=varY, covYU=covYU)


def noisy_periods(case, rng, P, snr_u=40.0, snr_y=30.0):
    """P periods of the steady state plus white noise, correlated 0.6 between input and output."""
    su = 10 ** (-snr_u / 20) * np.std(case.u0)
    sy = 10 ** (-snr_y / 20) * np.std(case.y0)
    nu = rng.standard_normal((P, case.N))
    ny = 0.6 * nu + 0.8 * rng.standard_normal((P, case.N))
    return ref.frequency_data(case.u0 + su * nu, case.y0 + sy * ny)


def interleave(e):
    return np.column_stack([e.real, e.imag]).ravel()


algebra_params = pytest.mark.parametrize(
    "seed,domain,lti", [(s, d, l) for s in SEEDS for d in ("ct", "dt") for l in (False, True)],
    ids=lambda v: str(v) if not isinstance(v, bool) else ("lti" if v else "lptv"))


# ------------------------------------------------------------------ identities with eq. 15

@algebra_params
@pytest.mark.parametrize("which", ROW_SETS)
def test_block_traces_are_residue_variance(seed, domain, lti, which):
    """E{Re e^2} + E{Im e^2} = E|e|^2: the trace of each 2 x 2 diagonal block of S is var e_l
    (eq. 15) on every row, near DC too, where the residue is not circular."""
    case = make_case(seed, domain, lti)
    rng = np.random.default_rng([seed, 1])
    d, rows = random_data(rng, case.L), rows_of(case, which)
    for theta in (case.theta, case.par.theta_from_xi(rng.normal(size=case.par.n_xi))):
        S = lk.residue_covariance(d, case.par, rows, theta)
        assert np.array_equal(S, S.T)
        trace = S.diagonal()[0::2] + S.diagonal()[1::2]
        v = ref.residue_variance(d, case.par, rows, theta)
        assert np.all(np.abs(trace - v) <= TRACE * v)


@algebra_params
@pytest.mark.parametrize("which", ROW_SETS)
def test_residue_map_gives_residue(seed, domain, lti, which):
    """r = M x is the residue of the identification reference, interleaved, entry by entry
    relative to the magnitudes |M| |x| it sums."""
    case = make_case(seed, domain, lti)
    rng = np.random.default_rng([seed, 2])
    d, rows = random_data(rng, case.L), rows_of(case, which)
    x = lk.data_vector(d)
    for theta in (case.theta, case.par.theta_from_xi(rng.normal(size=case.par.n_xi))):
        M = lk.residue_map(d, case.par, rows, theta)
        e = interleave(ref.residue(d, case.par, rows, theta))
        assert np.all(np.abs(M @ x - e) <= ALGEBRA * (np.abs(M) @ np.abs(x)))


@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("seed", SEEDS)
def test_lti_cost_is_diagonal_sml(seed, domain):
    """K = 0: each row uses its own line only, so S is block diagonal with circular blocks
    (var e_l / 2) I and V = 2 sum |e_l|^2 / var e_l, to rounding (relative ALGEBRA)."""
    case = make_case(seed, domain, True)
    rng = np.random.default_rng([seed, 3])
    d, rows = random_data(rng, case.L), rows_of(case, "near_dc")
    for theta in (case.theta, case.par.theta_from_xi(rng.normal(size=case.par.n_xi))):
        e, v, _ = ref.normalized_residue(d, case.par, rows, theta)
        diag = 2.0 * np.sum(np.abs(e) ** 2 / v)
        assert abs(lk.exact_cost(d, case.par, rows, theta) - diag) <= ALGEBRA * diag


# ------------------------------------------------------------ S against Monte Carlo draws

MC_DRAWS = 6000
MC_SIGMAS = 5.0


@pytest.mark.parametrize("seed,domain,lti,correlated", [
    (3, "ct", False, True), (0, "dt", False, False), (0, "dt", False, True), (0, "ct", True, True)],
    ids=lambda v: str(v) if not isinstance(v, bool) else str(v))
def test_residue_covariance_monte_carlo(seed, domain, lti, correlated):
    """S (eq. 16) against the sample covariance of the residue at the true theta over
    MC_DRAWS sets of P = 2 noisy periods (white time-domain noise, in two cases correlated
    with the input noise through a 3-sample delay, so that cov YU has every phase). The true
    (co)variances of the means are sigma^2 / (N P) on every line, DC included (there real).

    r is linear in the noise and Gaussian, with mean r0 (the noiseless residue) known, so each
    sample covariance entry has standard error sqrt((S_ii S_jj + S_ij^2) / n). MC_SIGMAS = 5 of
    them bound all ~1700 distinct entries (chance of a false alarm ~1e-3; the draws are seeded).
    Rows start at 1, so the rows near DC exercise the DC line and the conjugate lines: the
    same draws must reject S without the pseudo-covariance (a circular residue) and S without
    the coupling between rows (LPTV only; for LTI both are exact). Those differences are
    small (the conjugate lines enter through the harmonics only), so the LPTV models vary by
    +-50 % (the spectra need only satisfy A Y = B U), and the premise, that the expected
    deviation of each wrong S is at least 3 MC_SIGMAS standard errors, is checked."""
    case = make_case(seed, domain, lti, depth=0.5)
    rng = np.random.default_rng([41, seed, domain == "dt", lti, correlated])
    N, P, n, par = case.N, 2, MC_DRAWS, case.par
    su, sy, rho, delay = 0.05 * np.std(case.u0), 0.05 * np.std(case.y0), 0.7, 3
    nu = rng.standard_normal((n, P, N))
    ny = rng.standard_normal((n, P, N))
    if correlated:
        ny = rho * np.roll(nu, delay, axis=2) + np.sqrt(1 - rho ** 2) * ny
    Um = np.mean(np.fft.fft(case.u0 + su * nu, axis=2), axis=1)[:, :case.L + 1] / N
    Ym = np.mean(np.fft.fft(case.y0 + sy * ny, axis=2), axis=1)[:, :case.L + 1] / N
    rows = rows_of(case, "near_dc")
    zero = np.zeros(case.L + 1)

    def res(U, Y):
        return interleave(ref.residue(ref.Data(U, Y, zero, zero, zero + 0j), par, rows,
                                      case.theta))

    r = np.array([res(U, Y) for U, Y in zip(Um, Ym)]) - res(case.U0, case.Y0)
    mc = r.T @ r / n

    lines = np.arange(case.L + 1)
    cov = (rho * su * sy / (N * P)) * np.exp(-2j * np.pi * lines * delay / N) if correlated \
        else zero + 0j
    d = ref.Data(U=case.U0, Y=case.Y0, varU=zero + su ** 2 / (N * P),
                 varY=zero + sy ** 2 / (N * P), covYU=cov)
    S = lk.residue_covariance(d, par, rows, case.theta)
    se = np.sqrt((np.outer(S.diagonal(), S.diagonal()) + S ** 2) / n)
    assert np.max(np.abs(mc - S) / se) <= MC_SIGMAS
    if not lti:
        # A circular residue: E{e e^H} kept, E{e e^T} dropped.
        Sc = S.copy()
        Sc[0::2, 0::2] = Sc[1::2, 1::2] = 0.5 * (S[0::2, 0::2] + S[1::2, 1::2])
        Sc[1::2, 0::2] = 0.5 * (S[1::2, 0::2] - S[0::2, 1::2])
        Sc[0::2, 1::2] = -Sc[1::2, 0::2]
        # Rows uncorrelated: only the 2 x 2 diagonal blocks.
        Sd = S * np.kron(np.eye(rows.size), np.ones((2, 2)))
        for wrong in (Sc, Sd):
            assert np.max(np.abs(wrong - S) / se) >= 3 * MC_SIGMAS   # the premise
            assert np.max(np.abs(mc - wrong) / se) > 2 * MC_SIGMAS


# ----------------------------------------------------------------------------- gradient

# Central differences with Richardson extrapolation, (4 D(h) - D(2h)) / 3, h = 1e-4 |xi|_inf:
# truncation O(h^4) and rounding ~ eps |V| / h = 2e-12 |V|. Plain central differences would
# not do: at high SNR V is sharply curved (|grad V| ~ 1e2 V at the truth), and their h^2 term
# reaches 1e-4 of the gradient for h = 1e-5. Measured: <= 1e-8 (1e-11 typically).
GRADIENT_FD = 1e-6


@algebra_params
@pytest.mark.parametrize("known", [False, True], ids=["plain", "known"])
def test_gradient_finite_differences(seed, domain, lti, known):
    """dV/dxi against central differences of V on noisy data (rows from 1), at the truth and
    at a perturbed point; V is homogeneous of degree 0 in xi, so xi . grad V = 0 (Euler)."""
    case = make_case(seed, domain, lti, known)
    par = case.par
    rng = np.random.default_rng([seed, 4])
    d, rows = noisy_periods(case, rng, 4), rows_of(case, "near_dc")
    xi_true = lk.xi_of_theta(par, case.theta)
    for xi in (xi_true, xi_true * (1 + 0.05 * rng.normal(size=xi_true.size))):
        g = lk.exact_cost_gradient(d, par, rows, par.Text @ xi)

        def central(h):
            return np.array([(lk.exact_cost(d, par, rows, par.Text @ (xi + h * ej))
                              - lk.exact_cost(d, par, rows, par.Text @ (xi - h * ej))) / (2 * h)
                             for ej in np.eye(xi.size)])

        h = 1e-4 * np.max(np.abs(xi))
        fd = (4 * central(h) - central(2 * h)) / 3
        assert np.linalg.norm(g - fd) <= GRADIENT_FD * np.linalg.norm(g)
        assert abs(xi @ g) <= ALGEBRA * np.abs(xi) @ np.abs(g)


# ------------------------------------------------------------------------ the estimator

# The same minimiser from two starts: each run stops within tol = 1e-13 of the stationary
# point (the Newton-step rule, see sml_estimate) up to the gradient's rounding, ~eps cond(S)
# (cond(S) <= 1e4 here) times the conditioning of the Hessian. Measured: <= 1e-13.
SAME_POINT = 1e-9
# The gradient at the result: rounding level, i.e. within eps cond(S) of the magnitude of
# the terms it sums; relative to its size at the WGTLS start (measured <= 2e-10 for LTI, where
# WGTLS is already close to the SML point, <= 2e-12 for LPTV).
GRADIENT_END = 1e-8


@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("lti", [False, True], ids=["lptv", "lti"])
@pytest.mark.parametrize("seed", SEEDS[:2])
@pytest.mark.parametrize("which", ROW_SETS)
def test_sml_estimate(seed, domain, lti, which):
    """From WGTLS on noisy periods (P = 6, sample variances) the cost decreases, the gradient
    ends at rounding level, and a start 1 % away converges to the same point."""
    case = make_case(seed, domain, lti)
    par = case.par
    rng = np.random.default_rng([seed, 6])
    d, rows = noisy_periods(case, rng, 6), rows_of(case, which)
    start = ref.estimate(d, par, rows, "wgtls")["theta"]
    fit = lk.sml_estimate(d, par, rows, start)
    assert fit["converged"]
    assert fit["xi"][par.norm_index] == 1.0
    assert fit["cost"] < lk.exact_cost(d, par, rows, start)
    assert fit["cost"] == pytest.approx(lk.exact_cost(d, par, rows, fit["theta"]), rel=ALGEBRA)
    free = np.arange(par.n_xi) != par.norm_index
    g0 = lk.exact_cost_gradient(d, par, rows, start)[free]
    g1 = lk.exact_cost_gradient(d, par, rows, fit["theta"])[free]
    assert np.linalg.norm(g1) <= GRADIENT_END * np.linalg.norm(g0)
    xi = fit["xi"]
    other = lk.sml_estimate(d, par, rows, par.Text @ (xi * (1 + 0.01 * rng.normal(size=xi.size))))
    assert other["converged"]
    assert np.linalg.norm(other["xi"] - xi) <= SAME_POINT * np.linalg.norm(xi)


# ------------------------------------------------------------------- Cramer-Rao bound

def test_crb_layout():
    """The bound sits on the free eta entries: a zero row and column for the normalised
    a_{na,0}; with a known a_na every eta entry is free. F is symmetric positive definite."""
    for known in (False, True):
        case = make_case(0, "ct", False, known)
        par, rng = case.par, np.random.default_rng(7)
        d = random_data(rng, case.L)
        d = ref.Data(U=case.U0, Y=case.Y0, varU=d.varU, varY=d.varY, covYU=d.covYU)
        rows = rows_of(case, "near_dc")
        F = lk.fisher_information(d, par, rows, case.theta)
        assert F.shape == (par.n_xi - 1,) * 2 and np.all(np.linalg.eigvalsh(F) > 0)
        cov = lk.crb(d, par, rows, case.theta)
        assert cov.shape == (par.n_eta, par.n_eta)
        free = [j for j in range(par.n_eta) if j != par.norm_index]
        assert len(free) == (par.n_eta if known else par.n_eta - 1)
        assert np.allclose(cov[np.ix_(free, free)] @ F, np.eye(len(free)), rtol=0, atol=1e-9)
        if not known:
            assert not cov[par.norm_index].any() and not cov[:, par.norm_index].any()


CRB_DRAWS = 200
CRB_ALPHA = 1e-3


def test_crb_monte_carlo():
    """LTI, first order, continuous time: G = b0 / (s + a0), a0 = 0.5, b0 = 1, w0 = 0.1,
    unit-amplitude lines 1..20; input 40 dB, output 40 dB below the mean output line, noise
    correlated 0.5 with a random phase per line. The data objects carry the TRUE (co)variances,
    so sml_estimate is the ML estimator and, at this SNR, efficient: (eta - eta0) ~ N(0, CRB)
    up to O(1/SNR). Then n s^2 / CRB_ii ~ chi2(n) with s^2 the mean squared error about the
    truth over n = CRB_DRAWS draws: the ratio must lie in the two-sided chi-square interval of
    level CRB_ALPHA per parameter ([0.71, 1.36] for n = 200), which excludes the factor-2
    errors a wrong circular split would make."""
    L, w0 = 20, 0.1
    par = ref.Parametrisation(1, 0, [0, 0], [0], (), w0, 0.0)
    theta0 = np.array([0.5, 1.0, 1.0], complex)       # a_0, a_1, b_0
    rng = np.random.default_rng(2024)
    lines = np.arange(L + 1)
    s = 1j * w0 * lines
    U0 = np.exp(2j * np.pi * rng.uniform(size=L + 1))
    U0[0] = 0.0
    Y0 = theta0[2] / (s + theta0[0]) * U0
    varU = np.full(L + 1, 1e-4)
    varY = np.full(L + 1, 1e-4 * np.mean(np.abs(Y0[1:]) ** 2))
    covYU = 0.5 * np.sqrt(varU * varY) * np.exp(2j * np.pi * rng.uniform(size=L + 1))
    covYU[0] = covYU[0].real
    rows = np.arange(1, L + 1)
    exact = ref.Data(U=U0, Y=Y0, varU=varU, varY=varY, covYU=covYU)
    bound = lk.crb(exact, par, rows, theta0)
    # Per line z = [dY, dU] circular with E{z z^H} = Sigma: z = G g, G G^H = Sigma.
    sig = np.array([[[vy, c], [np.conj(c), vu]] for vy, vu, c in zip(varY, varU, covYU)])
    G = np.linalg.cholesky(sig)
    err = []
    for _ in range(CRB_DRAWS):
        g = (rng.standard_normal((L + 1, 2)) + 1j * rng.standard_normal((L + 1, 2))) / np.sqrt(2)
        z = np.einsum("lab,lb->la", G, g)
        d = ref.Data(U=U0 + z[:, 1], Y=Y0 + z[:, 0], varU=varU, varY=varY, covYU=covYU)
        fit = lk.sml_estimate(d, par, rows, ref.estimate(d, par, rows, "wgtls")["theta"])
        assert fit["converged"]
        err.append(fit["xi"] - lk.xi_of_theta(par, theta0))
    err = np.array(err)
    lo, hi = (scipy.stats.chi2.ppf([CRB_ALPHA / 2, 1 - CRB_ALPHA / 2], CRB_DRAWS) / CRB_DRAWS)
    assert lo > 0.5 and hi < 2.0
    for j in (0, 2):                                   # a_0 and b_0; a_1 is normalised
        ratio = np.mean(err[:, j] ** 2) / bound[j, j]
        assert lo <= ratio <= hi, (j, ratio)
