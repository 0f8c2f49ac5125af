"""The frequency-domain simulator against the NumPy reference, exact LTI responses, and itself
at larger guards (the adaptive guard and its truncation estimate)."""
import functools
import warnings

import numpy as np
import pytest
from scipy import signal

import lptv
from lptv import reference as ref


def rel_diff(X, Xref):
    return float(np.max(np.abs(X - Xref)) / np.max(np.abs(Xref)))


# Continuous-time guard of the comparisons on a fixed grid: large enough that the grid holds
# the skirts (not needed for the comparison, which is exact on the truncated grid either way),
# small enough to keep n <= 200 lines for the FDS_VS_REFERENCE argument.
CT_GUARD = 40


# ------------------------------------------------------------- band matrices and the reference

def test_band_matrices_match_reference(make_model, seed, domain, tol):
    model = make_model(seed, domain)
    L = 25
    A, B = lptv.band_matrices(model, L)
    s = ref.line_variable(model, ref.grid(model, L))
    for M, Mref, c in ((A, ref.band_matrix_A(model, L), model.a),
                       (B, ref.band_matrix_B(model, L), model.b)):
        assert M.shape == Mref.shape == (s.size, s.size)
        # Per column: sum_n max_k |c_{n,k}| |s_i|^n bounds every entry's terms.
        scale = np.abs(c).max(axis=1) @ (np.abs(s)[None, :] ** np.arange(c.shape[0])[:, None])
        assert np.all(np.abs(M.toarray() - Mref) <= tol.BAND_ENTRY * scale[None, :])


def test_band_matrices_structure(make_model, seed):
    # The band wraps around the corners only on the circular (discrete-time) grid.
    ct = make_model(seed, "ct", ka=2, kb=1)
    A = ref.band_matrix_A(ct, 10)
    assert np.count_nonzero(A[0, -2:]) == 0 and np.count_nonzero(A[0, :3]) == 3
    dt = make_model(seed, "dt", ka=2, kb=1)
    A = ref.band_matrix_A(dt)
    assert A.shape[0] == dt.samples_per_period
    assert np.count_nonzero(A[0, -2:]) == 2 and np.count_nonzero(A[0, :3]) == 3
    Ac = lptv.band_matrices(dt)[0].toarray()
    assert np.array_equal(Ac != 0, A != 0)


def test_simulate_matches_reference(make_model, make_spectrum, kappa, seed, domain, solver, tol):
    model = make_model(seed, domain)
    U = make_spectrum(seed, model)  # three input columns share one factorisation
    guard = CT_GUARD if domain == "ct" else 0
    L = U.shape[0] - 1 + guard
    assert kappa(ref.band_matrix_A(model, L)) <= tol.KAPPA_MAX
    Y = lptv.simulate(model, U, guard=guard, solver=solver)
    Yref = ref.simulate(model, U, guard=guard)
    assert Y.shape == U.shape
    assert rel_diff(Y, Yref) <= tol.FDS_VS_REFERENCE
    # One column at a time gives the same as the block.
    y1 = lptv.simulate(model, U[:, 1], guard=guard, solver=solver)
    assert y1.shape == (U.shape[0],)
    assert rel_diff(y1, Yref[:, 1]) <= tol.FDS_VS_REFERENCE


@pytest.mark.parametrize("lines_out", [5, 30, 45])
def test_simulate_lines_out_matches_reference(make_model, make_spectrum, seed, solver, lines_out,
                                              tol):
    model = make_model(seed, "ct")
    U = make_spectrum(seed, model, Lu=30, ncols=2)
    Y = lptv.simulate(model, U, guard=CT_GUARD, lines_out=lines_out, solver=solver)
    Yref = ref.simulate(model, U, guard=CT_GUARD, lines_out=lines_out)
    assert Y.shape == (lines_out + 1, 2)
    assert rel_diff(Y, Yref) <= tol.FDS_VS_REFERENCE


def test_simulate_discrete_partial_band(make_model, make_spectrum, seed, solver, tol):
    # Fewer input lines than the grid's one-sided half: the rest are zero inputs, and the
    # output still lives on the whole circular grid.
    model = make_model(seed, "dt")
    U = make_spectrum(seed, model, Lu=5, ncols=2)
    half = model.samples_per_period // 2
    Y = lptv.simulate(model, U, lines_out=half, solver=solver)
    Yref = ref.simulate(model, U, lines_out=half)
    assert rel_diff(Y, Yref) <= tol.FDS_VS_REFERENCE


def test_output_of_real_signal_is_real(make_model, make_spectrum, seed, domain, tol):
    # A conjugate-symmetric input gives a conjugate-symmetric output: DC (and Nyquist) real.
    model = make_model(seed, domain)
    U = make_spectrum(seed, model)
    Y = lptv.simulate(model, U, guard=CT_GUARD if domain == "ct" else None)
    peak = np.abs(Y).max()
    assert np.abs(Y[0].imag).max() <= tol.FDS_VS_REFERENCE * peak
    if domain == "dt" and model.samples_per_period % 2 == 0:
        assert np.abs(Y[-1].imag).max() <= tol.FDS_VS_REFERENCE * peak


def test_htf_matches_reference(make_model, seed, domain, solver, tol):
    model = make_model(seed, domain)
    L = 20
    lines = [0, 1, 3, -4, 7] if domain == "ct" else [0, 1, 3, -4, model.samples_per_period + 2]
    G = lptv.htf(model, L, lines, solver=solver)
    Gref = ref.htf(model, L, lines)
    assert G.shape == Gref.shape == (ref.grid(model, L).size, len(lines))
    assert rel_diff(G, Gref) <= tol.FDS_VS_REFERENCE
    # Default: every column of the grid.
    assert lptv.htf(model, L, solver=solver).shape == (ref.grid(model, L).size,) * 2


# ----------------------------------------------------- the reference against other routes

def test_reference_discrete_time_equals_time_domain_solution(make_model, make_spectrum, seed, tol):
    # The periodic steady state written directly in time, N equations
    # sum_n a_n[t] y[(t+n) mod N] = sum_m b_m[t] u[(t+m) mod N], shares no frequency-domain step
    # with the reference; agreement pins the band's orientation (a_{n,l-i}, not a_{n,i-l}).
    model = make_model(seed, "dt")
    N = model.samples_per_period
    U = make_spectrum(seed, model, ncols=1)[:, 0]
    u = ref.time_signal(U, N)
    t = np.arange(N)
    a_t, b_t = ref.coefficients_at(model, t * model.ts)
    Ay = np.zeros((N, N))
    rhs = np.zeros(N)
    for n in range(model.na + 1):
        Ay[t, (t + n) % N] += a_t[:, n]
    for m in range(model.nb + 1):
        rhs += b_t[:, m] * u[(t + m) % N]
    y = np.linalg.solve(Ay, rhs)
    Yt = ref.spectrum(y)
    assert rel_diff(ref.simulate(model, U), Yt) <= tol.TIME_DOMAIN
    assert rel_diff(lptv.simulate(model, U), Yt) <= tol.TIME_DOMAIN


def test_reference_continuous_time_satisfies_the_ode(make_model, make_spectrum, seed, tol):
    # Synthesise y(t) and its derivatives from the reference's output lines and check
    # sum_n a_n(t) y^(n)(t) = sum_m b_m(t) u^(m)(t) at random times: the products are formed in
    # time, not by the band matrices, so this pins the band's orientation in continuous time.
    model = make_model(seed, "ct")
    U = make_spectrum(seed, model, Lu=30, ncols=1)[:, 0]
    L = 90
    Y = ref.simulate(model, U, guard=L - 30, lines_out=L)
    assert np.abs(Y[-model.ka - 1:]).max() <= 1e-16 * np.abs(Y).max()  # nothing truncated
    t = np.random.default_rng(seed).uniform(0, model.period, 7)
    a_t, b_t = ref.coefficients_at(model, t)

    def derivatives(X, order):
        """x^(n)(t) for n = 0..order, and the sums of the magnitudes of their terms."""
        lines = np.arange(-(X.size - 1), X.size)
        two_sided = np.concatenate([np.conj(X[:0:-1]), X])
        s = 1j * model.w0 * lines
        terms = [np.exp(1j * model.w0 * np.outer(t, lines)) * (s ** n * two_sided)
                 for n in range(order + 1)]
        value = np.array([x.sum(axis=1).real for x in terms]).T
        magnitude = np.array([np.abs(x).sum(axis=1) for x in terms]).T
        return value, magnitude

    dy, dy_mag = derivatives(Y, model.na)
    du, du_mag = derivatives(U, model.nb)
    residual = np.sum(a_t * dy, axis=1) - np.sum(b_t * du, axis=1)
    scale = np.sum(np.abs(a_t) * dy_mag, axis=1) + np.sum(np.abs(b_t) * du_mag, axis=1)
    assert np.all(np.abs(residual) <= tol.ODE_RESIDUAL * scale)
    # The check sees the time variation: the same Y violates the mean (LTI) equation.
    a_mean = np.broadcast_to(model.a[:, model.ka].real, a_t.shape)
    b_mean = np.broadcast_to(model.b[:, model.kb].real, b_t.shape)
    lti_residual = np.sum(a_mean * dy, axis=1) - np.sum(b_mean * du, axis=1)
    assert np.max(np.abs(lti_residual) / scale) > 1e3 * tol.ODE_RESIDUAL


# --------------------------------------------------------------------------- the LTI case

def _poly_condition(c, s):
    """sum |c_n| |s|^n / |sum c_n s^n| (coefficients lowest power first)."""
    powers = s[None, :] ** np.arange(c.size)[:, None]
    return np.abs(c) @ np.abs(powers) / np.abs(c @ powers)


def test_lti_continuous_equals_freqs(make_model, make_spectrum, seed, solver, tol):
    model = make_model(seed, "ct", lti=True)
    U = make_spectrum(seed, model, ncols=2)
    a, b = model.a[:, 0].real, model.b[:, 0].real
    w = model.w0 * np.arange(U.shape[0])
    s = 1j * w
    assert _poly_condition(a, s).max() <= tol.POLY_COND_MAX
    assert _poly_condition(b, s).max() <= tol.POLY_COND_MAX
    _, H = signal.freqs(b[::-1], a[::-1], worN=w)  # scipy wants the highest power first
    r = lptv.simulate(model, U, solver=solver, full_output=True)
    expected = H[:, None] * U
    assert np.all(np.abs(r.Y - expected) <= tol.LTI_VS_SCIPY * np.abs(expected))
    # Lines do not couple: nothing is truncated, whatever the guard.
    assert r.truncation_error == 0 and r.converged


def test_lti_discrete_equals_freqz(make_model, make_spectrum, seed, solver, tol):
    # lptv's discrete-time model is the forward-shift equation sum a_n y[t+n] = sum b_m u[t+m],
    # so G(z) = B(z)/A(z) with polynomials in z. freqz evaluates sum c'_i z^-i; with both
    # coefficient vectors reversed and padded to a common degree p it gets
    # z^-p B(z) / (z^-p A(z)) = B(z)/A(z).
    model = make_model(seed, "dt", lti=True)
    N = model.samples_per_period
    U = make_spectrum(seed, model, ncols=2)
    a, b = model.a[:, 0].real, model.b[:, 0].real
    p = max(a.size, b.size)
    a_rev = np.pad(a, (0, p - a.size))[::-1]
    b_rev = np.pad(b, (0, p - b.size))[::-1]
    w = 2 * np.pi * np.arange(U.shape[0]) / N  # rad/sample
    z = np.exp(1j * w)
    assert _poly_condition(a, z).max() <= tol.POLY_COND_MAX
    assert _poly_condition(b, z).max() <= tol.POLY_COND_MAX
    _, H = signal.freqz(b_rev, a_rev, worN=w)
    Y = lptv.simulate(model, U, solver=solver)
    expected = H[:, None] * U
    assert np.all(np.abs(Y - expected) <= tol.LTI_VS_SCIPY * np.abs(expected))


# ----------------------------------------------------------------------- the adaptive guard

def slow_decay_model(seed, rho=0.49):
    """First order with a_1(t) = 1 + 2 rho cos(w0 t + phi): a_1 has complex zeros at distance
    acosh(1 / (2 rho)) = 0.2 from the real axis of w0 t, so the skirts decay by only ~0.8 per
    line and the adaptive guard has to double several times (random phases, gains and w0)."""
    rng = np.random.default_rng([seed, 99])
    ph = np.exp(1j * rng.uniform(0, 2 * np.pi, 3))
    a0, b0 = rng.uniform(0.5, 2.0, 2)
    a = np.array([[0.1 * a0 * np.conj(ph[0]), a0, 0.1 * a0 * ph[0]],
                  [rho * np.conj(ph[1]), 1.0, rho * ph[1]]])
    b = np.array([[0.2 * b0 * np.conj(ph[2]), b0, 0.2 * b0 * ph[2]]])
    return lptv.Model(a, b, w0=float(rng.uniform(0.1, 0.5)))


BIG_GUARD = 256
SLOW_SEEDS = [0, 1, 2]


@functools.lru_cache(maxsize=None)
def _slow_case(seed, make_spectrum, kappa):
    """(model, U, converged reference Y, Skeel condition, reference Y one guard doubling
    earlier); the dense solves at BIG_GUARD are the slow part, so each seed is solved once."""
    model = slow_decay_model(seed)
    U = make_spectrum(seed, model, Lu=30, ncols=2)
    Y = ref.simulate(model, U, guard=BIG_GUARD)
    Y_half = ref.simulate(model, U, guard=BIG_GUARD // 2)
    return model, U, Y, kappa(ref.band_matrix_A(model, 30 + 64)), Y_half


@pytest.fixture
def slow_case(make_spectrum, kappa, tol):
    def case(seed):
        model, U, Ybig, kappa_A, Y_half = _slow_case(seed, make_spectrum, kappa)
        assert kappa_A <= tol.KAPPA_MAX
        # The reference itself is free of truncation at BIG_GUARD: halving it changes
        # nothing beyond rounding.
        assert rel_diff(Y_half, Ybig) <= tol.FDS_VS_REFERENCE
        return model, U, Ybig
    return case


@pytest.mark.parametrize("seed", SLOW_SEEDS)
def test_adaptive_guard_agrees_with_large_guard_reference(slow_case, seed, solver, tol):
    model, U, Ybig = slow_case(seed)
    # The premise: at the first guard tried the truncation is far above the tolerance.
    assert rel_diff(ref.simulate(model, U, guard=16), Ybig) > 1e-8
    r = lptv.simulate(model, U, solver=solver, full_output=True)
    assert r.converged and r.truncation_error <= 1e-13 and r.guard > 16
    assert rel_diff(r.Y, Ybig) <= tol.FDS_VS_REFERENCE


@pytest.mark.parametrize("seed", SLOW_SEEDS)
@pytest.mark.parametrize("tol_guard", [1e-4, 1e-6, 1e-10])
def test_adaptive_truncation_error_is_honest(slow_case, seed, tol_guard, tol):
    # A loose tolerance stops the adaptive guard early, where truncation dominates rounding:
    # the reported error must not understate the true one (against a converged reference).
    model, U, Ybig = slow_case(seed)
    r = lptv.simulate(model, U, tol=tol_guard, full_output=True)
    true_error = rel_diff(r.Y, Ybig)
    assert r.converged and r.truncation_error <= tol_guard
    assert true_error <= r.truncation_error + tol.FDS_VS_REFERENCE
    assert true_error <= tol_guard


@pytest.mark.parametrize("seed", SLOW_SEEDS)
@pytest.mark.parametrize("guard", [0, 4, 8, 16])
def test_fixed_guard_truncation_error_bounds_true_error(slow_case, seed, guard, tol):
    model, U, Ybig = slow_case(seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lptv.TruncationWarning)
        r = lptv.simulate(model, U, guard=guard, full_output=True)
    true_error = rel_diff(r.Y, Ybig)
    assert true_error > 1e-10  # the premise: truncation dominates at these guards
    assert true_error <= r.truncation_error
    assert r.guard == guard and r.converged == (r.truncation_error <= 1e-13)


def test_truncation_warning_when_guard_cannot_grow(slow_case):
    model, U, _ = slow_case(0)
    with pytest.warns(lptv.TruncationWarning, match="truncation error"):
        r = lptv.simulate(model, U, max_guard=32, full_output=True)
    assert not r.converged and r.truncation_error > 1e-13
