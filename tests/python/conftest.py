"""Tolerances and random models shared by the tests of the model, multisines and FDS.

Every tolerance of these tests is set here, next to the conditioning argument behind it.
The random models are generated so that the premises of those arguments hold, and the tests
check the premises (a condition number, a decay) instead of assuming them.
"""
from types import SimpleNamespace

import numpy as np
import pytest

import lptv

EPS = np.finfo(float).eps

# ---------------------------------------------------------------------------------- tolerances

# C++ FDS against the dense NumPy reference on the same grid, relative to the largest output
# line. Both are backward-stable LU solves of the same system, so each has a forward error of
# about c eps kappa, kappa = || |A^-1| |A| ||_inf (Skeel's condition number: the one that
# governs after the row scaling both sparse solvers apply), with c a modest growth factor (the
# worst-case c ~ n is not approached by pivoted LU; measured c < 1 on these models). The random
# models keep kappa <= KAPPA_MAX (checked by the tests): 100 * 2.2e-16 = 2.2e-14 per route,
# so 1e-12 leaves a factor 20 for growth on either side. Measured: below 2e-15.
FDS_VS_REFERENCE = 1e-12
KAPPA_MAX = 100.0

# The small band kernel (solver 'band' in continuous time) against the reference, for every
# bandwidth it unrolls and the runtime-K code above: the FDS_VS_REFERENCE argument with the
# models' kappa <= KAPPA_MAX, but at the 1e-13 the kernel was asked to meet (2.2e-14 per route
# at the bound; measured below 1e-15).
BAND_KERNEL = 1e-13

# Entries of the band matrices, relative to sum_n max_k |c_{n,k}| |s_i|^n of their column:
# each is a sum of at most na+1 <= 4 products of a coefficient and a power built by at most 3
# multiplications, so its rounding error is below 8 eps = 1.8e-15. The margin covers pow()
# in the reference against repeated multiplication in the core, and exp(j w ts) against polar.
BAND_ENTRY = 1e-14

# LTI line by line against scipy.signal.freqs / freqz. Horner (scipy) and summed powers (FDS)
# each evaluate B and A to (nb + na + 2) eps times the evaluation condition numbers
# sum |c_n| |s|^n / |C(s)|, which the LTI test models keep below POLY_COND_MAX (checked):
# 8 * 2.2e-16 * 100 * 2 routes = 3.5e-13.
LTI_VS_SCIPY = 1e-12
POLY_COND_MAX = 100.0

# a_n(t), b_m(t) from the core against the reference's Fourier sums, relative to
# sum_k |c_{n,k}|: the phases k w0 t reach 2 pi K P for |t| <= P periods, and their rounding
# (~ eps 2 pi K P = 1e-14 for K <= 3, P <= 2) dominates.
COEFFICIENTS_AT = 1e-13

# Signals and spectra of length N <= 4096 from the core's FFT (kissfft) against numpy.fft and
# against direct sums of cosines, relative to sum_l |X_l| (the largest |x| can be): FFT
# rounding grows like eps log2 N ~ 3e-15; the direct sums use exact integer phase reduction.
SIGNAL = 1e-13

# A handful of floating-point operations on the same data (|exp(j phi)|, an angle, max / rms,
# a mean of squares that is exactly 1): a few eps each; 16 eps keeps them honest but robust to
# libm differences between the core (std::cos) and numpy (SIMD cos).
ROUNDING = 16 * EPS

# Periodic steady state of a discrete-time model solved in the time domain (an N x N dense
# system) against the reference: the same conditioning argument as FDS_VS_REFERENCE.
TIME_DOMAIN = 1e-12

# Continuous-time ODE residual sum_n a_n(t) y^(n)(t) - sum_m b_m(t) u^(m)(t), with y and its
# derivatives synthesised from L <= 90 output lines, relative to the sum of the magnitudes of
# all the terms: the phases l w0 t reach 2 pi L in one period and round to ~ 2 pi L eps =
# 1.3e-13; the truncated lines beyond L are below 1e-16 of the output for the default models
# (checked by the test).
ODE_RESIDUAL = 1e-12

# lptv.predict from rest (CVODE, or solve_ivp for several outputs, at rtol 1e-10, the input
# interpolated from its samples) against solve_ivp's integration of the rig's own equation
# (DOP853 at rtol 1e-9, the input a function of continuous time), relative to the output's
# peak: both integrators' global errors are a small multiple of their rtol over the record's
# few hundred oscillations, the CSV's 10 digits of the input 1e-10; 1e-6 is issue 46's figure.
PREDICT_VS_IVP = 1e-6

SEEDS = [0, 1, 2, 3, 4]
SOLVERS = ["klu", "umfpack", "band"]


@pytest.fixture(scope="session")
def tol():
    """The tolerances above as one namespace (session scope, so hypothesis tests may use it)."""
    return SimpleNamespace(
        EPS=EPS, FDS_VS_REFERENCE=FDS_VS_REFERENCE, KAPPA_MAX=KAPPA_MAX, BAND_ENTRY=BAND_ENTRY,
        BAND_KERNEL=BAND_KERNEL,
        LTI_VS_SCIPY=LTI_VS_SCIPY, POLY_COND_MAX=POLY_COND_MAX, COEFFICIENTS_AT=COEFFICIENTS_AT,
        SIGNAL=SIGNAL, ROUNDING=ROUNDING, TIME_DOMAIN=TIME_DOMAIN, ODE_RESIDUAL=ODE_RESIDUAL)


@pytest.fixture(params=SEEDS, ids=lambda s: f"seed{s}")
def seed(request):
    return request.param


@pytest.fixture(params=SOLVERS)
def solver(request):
    # The band LU is for the continuous-time grid only (its refusal on the circular grid is
    # tested in test_errors.py).
    if request.param == "band":
        params = getattr(request.node, "callspec", None)
        domain = params.params.get("domain") if params else None
        if domain == "dt" or "discrete" in request.node.name:
            pytest.skip("the band solver is continuous-time only")
    return request.param


@pytest.fixture(params=["ct", "dt"])
def domain(request):
    return request.param


# ------------------------------------------------------------------------------ random models

def _coefficient_row(rng, dc, K, depth):
    """Harmonics -K..K around a real DC value, scaled so that the coefficient stays within
    dc (1 +- depth) at all times (2 sum_k |c_k| = depth |dc|)."""
    row = np.zeros(2 * K + 1, complex)
    row[K] = dc
    if K:
        c = rng.normal(size=K) + 1j * rng.normal(size=K)
        c *= depth * abs(dc) / (2 * np.abs(c).sum())
        row[K + 1:] = c
        row[:K] = np.conj(c[::-1])
    return row


def _roots(rng, n, discrete):
    """n roots in conjugate pairs, well inside the stable region: Re s <= -0.2 or |z| <= 0.8."""
    pairs, single = divmod(n, 2)
    if discrete:
        cplx = rng.uniform(0.2, 0.8, pairs) * np.exp(1j * rng.uniform(0.1, 3.0, pairs))
        real = rng.uniform(-0.8, 0.8, single)
    else:
        cplx = -rng.uniform(0.2, 1.5, pairs) + 1j * rng.uniform(0.3, 3.0, pairs)
        real = -rng.uniform(0.2, 2.0, single)
    return np.concatenate([cplx, np.conj(cplx), real])


def random_model(seed, domain, lti=False, depth=0.2, ka=None, kb=None):
    """A random stable model: mean system with poles (and zeros) well inside the stable region,
    every coefficient varying within dc (1 +- depth).

    Continuous time: w0 in [0.1, 0.5] rad/s, so lines 0..30 sweep the poles' frequencies.
    Discrete time: ts = 1 and N in {16, 25, 32, 47, 64} (odd and even, with and without Nyquist).
    """
    rng = np.random.default_rng([seed, 0 if domain == "ct" else 1, int(lti)])
    discrete = domain == "dt"
    na = int(rng.integers(1, 4))
    nb = int(rng.integers(0, na + 1))
    if ka is None:
        ka = 0 if lti else int(rng.integers(1, 4))
    if kb is None:
        kb = 0 if lti else int(rng.integers(0, 4))
    # Zeros placed like the poles keep |B| away from zero on the grid as well as |A|.
    a_dc = np.atleast_1d(np.real(np.poly(_roots(rng, na, discrete))))[::-1]
    b_dc = rng.uniform(0.5, 2.0) * np.atleast_1d(np.real(np.poly(_roots(rng, nb, discrete))))[::-1]
    a = np.array([_coefficient_row(rng, c, ka, depth) for c in a_dc])
    b = np.array([_coefficient_row(rng, c, kb, depth) for c in b_dc])
    if discrete:
        N = int(rng.choice([16, 25, 32, 47, 64]))
        return lptv.Model(a, b, w0=2 * np.pi / N, ts=1.0)
    return lptv.Model(a, b, w0=float(rng.uniform(0.1, 0.5)))


def random_spectrum(seed, model, Lu=None, ncols=3):
    """One-sided input spectra (Lu+1, ncols) of real signals: DC (and a Nyquist line) real.

    Discrete time defaults to the whole one-sided grid 0..N//2; continuous time to 0..30.
    """
    rng = np.random.default_rng([seed, 7])
    if Lu is None:
        Lu = model.samples_per_period // 2 if model.discrete else 30
    U = rng.normal(size=(Lu + 1, ncols)) + 1j * rng.normal(size=(Lu + 1, ncols))
    U[0] = U[0].real
    if model.discrete and 2 * Lu == model.samples_per_period:
        U[Lu] = U[Lu].real
    return U


def skeel_condition(A):
    """|| |A^-1| |A| ||_inf of a dense matrix."""
    return float(np.max(np.sum(np.abs(np.linalg.inv(A)) @ np.abs(A), axis=1)))


@pytest.fixture(scope="session")
def make_model():
    return random_model


@pytest.fixture(scope="session")
def make_spectrum():
    return random_spectrum


@pytest.fixture(scope="session")
def kappa():
    return skeel_condition


# ==================================================================================================
# Identification: tests/python/test_identification_reference.py (the core against
# lptv.reference.identification, exact data, Monte Carlo). Tolerances of that file only.
# ==================================================================================================

# Noise statistics, J, e, var e, C, CJ_W and R^T R, core against reference, each relative to the
# magnitude of the terms it sums (so that cancellation counts against neither route): an entry is
# a sum of at most P (statistics) or (na+nb+2)(2K+1) <= 35 products, <= 35 eps = 8e-15 of its
# terms; C and CJ are positive semidefinite (|C_pq| <= sqrt(C_pp C_qq)), so norm-wise is
# entry-wise; Householder QR is backward stable, ||R^T R - Jx^T Jx|| <= c m n eps ||Jx||^2 with
# m n <= 500 * 20 rows x columns: 2e-12 in the worst case. Measured: 1e-16 .. 1e-15.
ID_STEP = 1e-11
# Estimates (theta, eta, cost, generalised singular values), core against reference: both are
# backward stable (QR/GSVD against SVD/pivoted Cholesky), so each is within ~ eps kappa of the
# exact estimate, kappa = sigma_max / (sigma_2 - sigma_1) of the (whitened, column-scaled)
# problem (Wedin's bound on the singular vector; see estimate_condition in the test file). The
# test problems keep kappa <= ID_COND_MAX (checked): 2.2e-16 * 1e5 = 2.2e-11 per route at the
# bound. WGTLS adds the stopping rule: each route stops within ~1e-12 of the same fixed point.
# Measured: 1e-15 .. 1e-13 (kappa 3 .. 1.2e4, the paper-like example under GTLS the largest).
ID_ESTIMATE = 1e-10
ID_COND_MAX = 1e5
# Noise-free data (FDS truncation 1e-13, FFT rounding 1e-16 relative): the estimate's error is
# that residue times the condition of the exact problem, sigma_max / sigma_{n-1} of the
# column-scaled Jx (checked <= ID_NOISELESS_COND_MAX: 1e-10 at the bound; measured <= 30).
ID_NOISELESS = 1e-9
ID_NOISELESS_COND_MAX = 1e3
# WGTLS cost against mean |e|^2/var e at the fixed point: the weights come from the previous
# iterate, within TOL = 1e-12 relative, and var e is at most ~1e2 times as sensitive.
ID_SELF_CHECK = 1e-8
# Monte Carlo: sample means compared within ID_MC_SIGMAS standard errors (estimated from the
# draws); over <= 60 rows and a few tests the chance of a false alarm is ~1e-5 (the draws are
# seeded, so a run is reproducible anyway). 2e4 draws resolve 3.5 % of the residue variance,
# well below the 30-90 % the correlation term changes it by (the test checks that it rejects
# the variance without it).
ID_MC_DRAWS = 20000
ID_MC_SIGMAS = 5.0
ID_FRACTION_DRAWS = 200000
# The expected fraction of residues above 0 dB: closed form (1 + 1/(c(P-1)))^-(P-1) against
# scipy.stats' F survival function, both to a few eps.
ID_FRACTION = 1e-12


@pytest.fixture(scope="session")
def id_tol():
    """The identification tolerances above as one namespace."""
    return SimpleNamespace(
        EPS=EPS, STEP=ID_STEP, ESTIMATE=ID_ESTIMATE, COND_MAX=ID_COND_MAX, NOISELESS=ID_NOISELESS,
        NOISELESS_COND_MAX=ID_NOISELESS_COND_MAX,
        SELF_CHECK=ID_SELF_CHECK, MC_DRAWS=ID_MC_DRAWS, MC_SIGMAS=ID_MC_SIGMAS,
        FRACTION_DRAWS=ID_FRACTION_DRAWS, FRACTION=ID_FRACTION)


# ==================================================================================================
# Floquet stability: tests/python/test_floquet.py. Tolerances of that file only.
# ==================================================================================================

# Hill's multipliers against the eigenvalues of the product of matrix exponentials
# (lptv.model.floquet.monodromy, sixth order), relative to ||Phi||_2: the product with 2000 steps is
# within ~1e-13 ||Phi|| of the exact Phi (the test checks ||Phi_2000 - Phi_4000|| <=
# FLOQUET_PRODUCT_STEP ||Phi||), eig(Phi) adds about eps ||Phi|| kappa_i with the eigenvalue
# condition numbers kappa_i <= FLOQUET_KAPPA_MAX (checked), and Hill's exponents carry at
# most their error_estimate (1e-13 .. 1e-5 relative, the large ones only for multipliers many
# orders below the largest, so below 1e-13 ||Phi|| in absolute terms). 1e-10 leaves two
# orders of margin; measured: 2e-15 .. 3e-14.
FLOQUET_VS_PRODUCT = 1e-10
FLOQUET_PRODUCT_STEP = 1e-12
FLOQUET_KAPPA_MAX = 1e3

# The monodromy of lptv.simulation.timedomain's CVODE shooting, in units of its rtol, relative to
# ||Phi||_2: CVODE keeps each step's local error below rtol |x| + atol; over one period of a
# modestly damped model (|mu| >= 0.05, so nothing decays below atol) the global error is a
# modest multiple of rtol. Measured 1-14 rtol over 8 models at rtol 1e-8, 1e-10, 1e-12.
FLOQUET_VS_CVODE_RTOLS = 1e3
FLOQUET_CVODE_RTOL = 1e-12

# LTI: ln(mu) = p T0 from Hill's block-diagonal matrix carries eps ||H|| T0 kappa (||H|| <= M w0
# + ||F|| ~ 30, T0 <= 63, kappa <= 10 for these poles): 4e-12; numpy.roots adds eps kappa.
# Relative error of each multiplier; measured <= 1e-13.
FLOQUET_LTI = 1e-11

# Discrete time, the core's product against NumPy's: both round each of the N <= 64 steps, so
# they differ by about the bound the core reports (error_estimate, kappa_i ||E|| / |mu_i|);
# twice it, plus 64 eps ||Phi|| for the two evaluations of a_n[k]. Measured <= 0.5 of the bound.
FLOQUET_DT_BOUND_FACTOR = 2.0


@pytest.fixture(scope="session")
def floquet_tol():
    """The Floquet tolerances above as one namespace."""
    return SimpleNamespace(
        EPS=EPS, VS_PRODUCT=FLOQUET_VS_PRODUCT, PRODUCT_STEP=FLOQUET_PRODUCT_STEP,
        KAPPA_MAX=FLOQUET_KAPPA_MAX, VS_CVODE_RTOLS=FLOQUET_VS_CVODE_RTOLS,
        CVODE_RTOL=FLOQUET_CVODE_RTOL, LTI=FLOQUET_LTI, DT_BOUND_FACTOR=FLOQUET_DT_BOUND_FACTOR)


# ==================================================================================================
# Floquet multipliers and frozen poles of the matrix system: tests/python/test_mimo_floquet.py.
# ==================================================================================================

# Hill's multipliers of the observer form against eig of the monodromy matrix from DOP853 at
# rtol MIMO_FLOQUET_IVP_RTOL (atol 1e-3 of it) of the state equations written out by hand,
# relative to ||Phi||_2. DOP853 keeps each step's local error below rtol |x| + atol; over one
# period of these systems (|mu| from 0.13 to 5) the global error is a modest multiple of rtol
# ||Phi||, and eig adds eps ||Phi|| kappa_i with kappa_i <= MIMO_FLOQUET_KAPPA_MAX (checked,
# measured <= 3.6); Hill's own error is below 1e-11 in ln(mu) (its error_estimate, measured
# <= 3e-13). 1e-10 is a hundred rtol; measured: 3.5e-14 .. 3.8e-13 over 35 systems.
MIMO_FLOQUET_IVP_RTOL = 1e-12
MIMO_FLOQUET_VS_IVP = 1e-10
MIMO_FLOQUET_KAPPA_MAX = 1e3
# The spectral radius must differ from 1 by this much for a verdict to be compared (a system on
# the tongue's edge is marginal, and both routes' errors could put it on either side); the
# systems of the tests are 2.6e-3 or more away.
MIMO_FLOQUET_MARGIN = 1e-4

# Discrete time, the core's product against NumPy's, in units of kappa_max ||Phi||_2: both round
# each of the N = 24 steps by a few eps ||G_k|| (||G_k|| of order 1 here), so the two Phi differ
# by about N eps prod ||G_k|| and the eigenvalues by kappa_i times that. Measured: 6e-17 ..
# 6.4e-16 over 20 systems; 1e-13 is 150 times that.
MIMO_FLOQUET_DT = 1e-13

# 1 x 1 models, the observer form against the SISO companion form: ln(mu) paired within twice
# the sum of both error estimates plus this (1 + |ln|mu||) (Hill's tol is 1e-11; the products
# are exact to rounding). Measured: the distance is at most 0.36 of the estimates' sum (1.75e-10
# against 6.2e-9 on the paper's model).
MIMO_FLOQUET_SISO = 1e-12

# Frozen poles against numpy.roots of det A(s) built by numpy.polymul, relative to max(1, |root|):
# the roots of a degree 3 .. 4 polynomial with well separated roots carry about 1e2 eps each,
# eig of the observer matrix the same. Measured: at most 1.9e-15 over 45 cases; 1e-12.
MIMO_FROZEN_POLES = 1e-12


# ==================================================================================================
# Several channels against one: tests/python/test_mimo_as_one_channel.py.
# ==================================================================================================

# A 1 x 1 fit by the route of several channels against the one-channel fit of the same arrays,
# rows from line 1 (row 1 reads line 0 and line 2 at K = 1): the same WGTLS, each iterated to a
# step of 1e-10 relative, so the estimates agree to well below that over their std (measured at
# most 6e-12 std over 5 seeds, K = 1 and 2). The std: the one-channel sandwich adds a second-order
# term (2e-6 .. 3e-5 of the std on these records), and on rows that read conjugate lines the
# route of several channels denoises its Jacobian with the circular residue covariance where the
# one channel's real likelihood has the exact one (against the one-channel first-order sandwich,
# lik.sandwich_covariance: 1e-14 on rows from K + 1, 1e-10 on rows that read line 0 only, 1e-6 ..
# 2.3e-5 on rows that read conjugate lines). Measured against the one-channel result: at most
# 3.7e-5; 1e-4 leaves a factor 3, and a pseudo-covariance left out or a line read unconjugated
# moves the std by far more (a row's variance, 1/24 of the information, is 4e-2).
MIMO_1X1_ETA = 1e-8
MIMO_1X1_STD = 1e-4

# The decoupled 2 x 2 fit against the one-channel fits of the same two orthogonal experiments:
# the 2 x 2 fit also estimates the couplings (true 0) from noisy regressors, so the two
# estimators differ by noise. Over 20 seeds (10 free parameters each) the diagonal entries
# differed by at most 1.49 one-channel std (rows from line 2) and 0.97 (rows from line 1), and
# the std ratio lay in 0.90-1.08 (from line 2) and 0.93-1.20 (from line 1); 2.5 std and 0.8-1.25
# hold the tests' seeds, and a wrong weighting or interval (a factor 2 in a variance: 0.71 or
# 1.41) fails.
MIMO_DECOUPLED_SIGMAS = 2.5
MIMO_DECOUPLED_STD_RATIO = (0.8, 1.25)

# The model scaled from the left (S A, S B) against the model itself: the same solution to the
# rounding of one 2 x 2 product per coefficient and of two FDS solves of condition below 10.
MIMO_SCALED_SAME_SYSTEM = 1e-10


# ==================================================================================================
# Batch runs and Monte Carlo studies: tests/python/test_batch.py and test_cli_batch.py.
# ==================================================================================================

# A study's statistics against the closed-form bound, within BATCH_MC_SIGMAS of their sampling
# error: the relative std of a sample variance of R normal draws is sqrt(2 / (R - 1)), that of a
# coverage sqrt(level (1 - level) / R), that of a mean the sample std / sqrt(R). Four sigmas over
# the ~10 numbers compared give a false alarm ~6e-4 (the draws are seeded: a run is reproducible).
BATCH_MC_SIGMAS = 4.0
# Per-line noise (co)variances against the mean periodogram of D draws: each |X_l|^2 is
# exponential (chi^2 with 1 dof at DC and Nyquist: sqrt(2) times the spread), so the mean has a
# relative std of sqrt(2 / D) at most; 5 sigmas over ~100 lines.
BATCH_NOISE_SIGMAS = 5.0


@pytest.fixture(scope="session")
def batch_tol():
    return SimpleNamespace(MC_SIGMAS=BATCH_MC_SIGMAS, NOISE_SIGMAS=BATCH_NOISE_SIGMAS)


@pytest.fixture(scope="session")
def dask_cluster():
    """A Dask LocalCluster of 2 worker processes with 1 thread each, started by the first test that
    asks for it and torn down at the end of the session (the workers inherit PYTHONPATH)."""
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, host="127.0.0.1")
    try:
        yield cluster
    finally:
        cluster.close()


# ==================================================================================================
# Nonlinear distortion: tests/python/test_distortion_core.py (the core's regression per output
# line against lptv.reference.distortion).
# ==================================================================================================

# Per line j a least-squares problem of M x q_j (M = 6, q_j <= 4): the core by a Jacobi SVD of
# X, the reference by LAPACK's gelsd and pinv(X^H X). Both are backward stable, so each G is
# within ~ c eps kappa ||y|| / sigma_min of the exact solution (kappa = cond X_j), the residual
# power within 2 ||r|| c eps kappa ||y||, the noise through |G|^2 var U likewise, and (X^H X)^-1
# within c eps kappa^2 / sigma_min^2 (the reference squares X). The test scales each difference
# by these bounds; c = 450 (TOL / eps) covers the growth factors of either route on matrices
# this small (M q <= 24 entries). The random-phase designs keep kappa <= DISTORTION_KAPPA_MAX
# (checked), so that no comparison rests on a near-singular line. Measured: at most 1.3 % of
# the bounds (kappa <= 8 on the paper's and the third-order design, M = 6).
DISTORTION_VS_REFERENCE = 1e-13
DISTORTION_KAPPA_MAX = 1e3
# Entry by entry, relative to each value, on those designs at their default Kh: the variances
# carry their line's relative error (measured <= 3e-13), the BLA's far branches, a thousandth of
# their line's coefficients, its absolute error (measured <= 3e-12).
DISTORTION_RELATIVE = 1e-10


# ==================================================================================================
# One record with its transient: tests/python/test_record_core.py (the core's lptv::fit_record
# against lptv.reference.record).
# ==================================================================================================

# The prediction A^-1 (B U - T) on the record's grid, the core (KLU on the whole grid) against
# the reference (SuperLU per residue class of the lines modulo L), relative to the largest line:
# the FDS_VS_REFERENCE argument, each a backward-stable LU with forward error ~ c eps kappa,
# kappa Skeel's condition number of A, which the test computes per class and keeps below
# RECORD_KAPPA_MAX: 2e3 x 2.2e-16 = 4.4e-13 per route at the bound. Measured: 3.5e-14 and
# 4.0e-14 on the discrete-time example (kappa 1.4e3), 4.8e-16 on the first-order one (3.3).
RECORD_PREDICTION = 1e-12
RECORD_KAPPA_MAX = 2e3
# The equation error's regression (M, e0), entry by entry relative to the magnitude of the
# terms of its row (sum over the parameters of |z^n X|): each entry is one product or a sum of
# two through Text, a few eps of the terms. Measured: below 1e-16.
RECORD_REGRESSION = 1e-14
# The estimates, core against reference, in units of each parameter's reported std. The two
# routes stop at different points of the same minimum: MINPACK when the actual and predicted
# decreases of the cost F (about 2 n = 1000 here) are below ftol F = 1e-12 F, i.e. a remaining
# step of sqrt(1e-12 F) = 3e-5 std (the cost's curvature is 1 per std^2: J^T J is the inverse
# covariance), and its trial costs carry the prediction's rounding, ~1e-11 F, so it cannot
# resolve steps below sqrt(1e-11 F) = 1e-4 std; the core stops when the predicted decrease is
# below 8 eps F (1.3e-6 std). The residual route chains three fits, each started from the last
# and weighted by its residual, which carries the difference along. 1e-3 std leaves a factor 10
# over the 1e-4 floor. Measured: at most 1.2e-5 std (eta), 1.5e-6 std (c).
RECORD_STD_UNITS = 1e-3
# What follows from RECORD_STD_UNITS = D: the prediction moves by at most D of its own std,
# below D times the noise level (measured 1.9e-6 of sqrt(noise_var)); the residual's variance
# |e|^2 by 2 |e| |de| <= 2 D relative, and the cost likewise (measured 4.8e-8 and 3.7e-10); the
# reported std, the inverse of J^T J at points D std apart, by the change of J over D std: one
# std is about 1e-4 of the coefficients' size (1.5e-5 to 3.9e-4 against 0.04 to 1.2 on the
# discrete-time example), so J moves by about 1e-4 D relative; 1e-3 D leaves a factor 10
# (measured 4e-9).
RECORD_NOISE_VAR = 2 * RECORD_STD_UNITS
RECORD_COST = 2 * RECORD_STD_UNITS
RECORD_COVARIANCE = 1e-3 * RECORD_STD_UNITS

# ==================================================================================================
# The reports' figures (test_report_figures.py).
# The measured Y/U drawn (dB and degrees) against NumPy's ratio of the periods' mean spectra: the
# same FFT lines, then a dB / degree round trip, whose rounding is eps times |dB| ln(10) / 20 (about
# 1e-14 at -60 dB). Measured: 8e-16.
REPORT_MEASURED = 1e-12
# The prediction drawn (the FDS, from the mean measured input) against CVODE's periodic steady
# state of the same model from the same input at its default rtol 1e-12, relative to each line:
# CVODE's error is a modest multiple of rtol of the output's peak, and the smallest excited line
# of the rig lies 46 dB (200 times) below it: about 2e-10 expected there; 1e-8 leaves a factor
# 50. Measured: 5e-11.
REPORT_PREDICTED = 1e-8
# Agreement "within the bands": the sum over n lines of |measured - predicted|^2 / var is a sum
# of n Exp(1) terms (Gamma(n)) when the model is right; the test asks for it below this quantile
# (the branch estimates: a chi-squared on n of their magnitudes).
REPORT_CHI_LEVEL = 0.999
# --scale b0=1 against --known b0=1: WGTLS's cost is invariant to a common factor of the
# parameters, so both fits have the same minimiser up to that factor and differ by the stopping
# rule (a relative step of 1e-10: 1e-10 of a value, far below 1e-6 of a std that is 1e-4 of it),
# and the covariance by the Jacobian of the division, exact to first order (the sandwich is first
# order itself) at the same point. Measured: 5e-11 std units, 1e-13 relative.
SCALE_VS_KNOWN_STD_UNITS = 1e-6
SCALE_VS_KNOWN_STD = 1e-8


# ------------------------------------------------------------------------- the suite's order

# make pytest runs the files on two workers, each file whole on one (--dist loadfile) in the
# order collected (--no-loadscope-reorder). The longest files go first (longest-processing-time
# scheduling: the last file to start is a short one, so the workers end together); the seconds
# each file took are in file_seconds.txt (written by `make pytest-order`, from a whole run's
# --durations=0), a file not listed there counting as that table's median.
def _file_seconds():
    from pathlib import Path

    table = {}
    path = Path(__file__).with_name("file_seconds.txt")
    if path.exists():
        for line in path.read_text().splitlines():
            parts = line.split()
            if len(parts) == 2 and not line.startswith("#"):
                table[parts[1]] = float(parts[0])
    return table


def pytest_collection_modifyitems(session, config, items):
    table = _file_seconds()
    if not table:
        return
    median = float(np.median(list(table.values())))
    first = {}
    for i, item in enumerate(items):
        first.setdefault(item.nodeid.split("::")[0], i)
    items.sort(key=lambda item: (-table.get(item.nodeid.split("::")[0].rsplit("/", 1)[-1], median),
                                 first[item.nodeid.split("::")[0]]))
