"""Property tests of the input handling: random shapes, dtypes and values into lptv.Model,
lptv.simulate and lptv.multisine give either a correct result or ValueError / NumericalError,
never another exception, a crash, or NaN in the output."""
import os
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import lptv

# Deterministic (derandomize) so that a run in CI is reproducible; modest counts keep the file
# at a few seconds. LPTV_FUZZ_EXAMPLES raises the count (make sanitize runs this file under
# ASan + UBSan with 5000 examples per test).
FUZZ_EXAMPLES = int(os.environ.get("LPTV_FUZZ_EXAMPLES", "150"))
FUZZ = settings(max_examples=FUZZ_EXAMPLES, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow])

ACCEPTED = (ValueError, lptv.NumericalError)

# Magnitudes up to 1e100: wide enough for every scaling a user might try, and far from the
# overflow of |s|^n sums (the band entries of a third-order model at line 100 stay below 1e110).
FLOATS = st.floats(min_value=-1e100, max_value=1e100, allow_nan=False, allow_infinity=False)
SPECIAL = st.sampled_from([np.nan, np.inf, -np.inf, 0.0, -0.0, 1e-300, 5e-324])
REALS = st.one_of(FLOATS, SPECIAL)

NUMERIC_DTYPES = [np.float64, np.float32, np.float16, np.complex128, np.complex64, np.int64,
                  np.int8, np.uint8, np.bool_]


def arrays_of_any_kind(max_dims=3, max_side=5):
    """Arrays of numeric dtypes with special values, strings, objects, and plain lists."""
    shapes = hnp.array_shapes(min_dims=0, max_dims=max_dims, min_side=0, max_side=max_side)
    numeric = st.sampled_from(NUMERIC_DTYPES).flatmap(
        lambda dt: hnp.arrays(dt, shapes, elements=_elements(dt)))
    strings = hnp.arrays(hnp.unicode_string_dtypes(max_len=3), shapes)
    objects = hnp.arrays(object, shapes, elements=st.one_of(st.none(), REALS, st.text(max_size=2)))
    lists = st.lists(REALS, max_size=6)
    return st.one_of(numeric, numeric, numeric, strings, objects, lists)


def _elements(dt):
    if np.issubdtype(dt, np.complexfloating):
        part = st.floats(width=32 if dt == np.complex64 else 64)
        return st.builds(complex, part, part)
    if np.issubdtype(dt, np.floating):
        width = np.dtype(dt).itemsize * 8
        return st.floats(width=width)  # NaN, inf and subnormals included
    return None  # hypothesis' default for integers and booleans


@st.composite
def symmetric_coefficients(draw, max_order=3, max_k=3):
    """Valid coefficient arrays (conjugate-symmetric, finite): the inputs that must succeed."""
    order = draw(st.integers(0, max_order))
    K = draw(st.integers(0, max_k))
    re = draw(hnp.arrays(np.float64, (order + 1, K + 1), elements=FLOATS))
    im = draw(hnp.arrays(np.float64, (order + 1, K), elements=FLOATS))
    c = np.zeros((order + 1, 2 * K + 1), complex)
    c[:, K] = re[:, 0]
    c[:, K + 1:] = re[:, 1:] + 1j * im
    c[:, :K] = np.conj(c[:, K + 1:][:, ::-1])
    return c


COEFFICIENTS = st.one_of(symmetric_coefficients(), symmetric_coefficients(), arrays_of_any_kind())
W0 = st.one_of(st.floats(1e-3, 1e3), SPECIAL, st.just(-1.0))
TS = st.one_of(st.none(), st.just(0.0), st.floats(1e-3, 10.0), SPECIAL,
               st.sampled_from([1.0, 0.5]))


def assert_finite(x):
    x = np.asarray(x)
    assert x.dtype.kind in "fc" and np.all(np.isfinite(x))


@FUZZ
@given(a=COEFFICIENTS, b=COEFFICIENTS, w0=W0, ts=TS, grid=st.booleans())
def test_model_construction(a, b, w0, ts, grid):
    if grid and ts not in (None, 0.0) and np.isfinite(ts) and ts > 0:
        # Often make w0 and ts fit a grid, so discrete-time models get built too.
        w0 = 2 * np.pi / (ts * 16)
    try:
        m = lptv.Model(a, b, w0=w0, ts=ts)
    except ACCEPTED as e:
        assert str(e)
        event(f"rejected: {type(e).__name__}")
        return
    event("accepted")
    assert_finite(m.a)
    assert_finite(m.b)
    assert m.a.shape == (m.na + 1, 2 * m.ka + 1) and m.b.shape == (m.nb + 1, 2 * m.kb + 1)
    assert np.array_equal(m.a[:, m.ka:][:, ::-1], np.conj(m.a[:, :m.ka + 1]))
    assert m.w0 > 0 and np.isfinite(m.w0)
    t = np.array([0.0, 0.37, -2.5])
    assert_finite(m.a_at(t))
    assert_finite(m.b_at(t))
    try:
        back = lptv.Model.from_dict(m.to_dict())
    except ValueError as e:
        # A description is refused only when its leading coefficient a_na(t) (nearly) vanishes
        # within the period: confirmed here on a grid 16 times finer than the check's own.
        assert "leading coefficient" in str(e), e
        assert _leading_nearly_vanishes(m), e
        event("description refused: leading coefficient vanishes")
    else:
        assert back == m
    assert repr(m).startswith("lptv.Model(")


def _leading_nearly_vanishes(m) -> bool:
    if m.discrete:
        t = np.arange(m.samples_per_period) * m.ts
    else:
        t = np.linspace(0.0, m.period, 4096 * (m.ka + 1) + 1)
    v = np.abs(m.a_at(t)[:, m.na])
    return bool(v.min() <= 0.05 * v.max())


MODELS = {
    "ct-lti": lptv.Model([2.0, 3.0, 1.0], [1.0, 0.5], w0=0.3),
    "ct-lptv": lptv.Model(np.array([[0.1 - 0.1j, 2, 0.1 + 0.1j], [0, 3, 0], [0.05j, 1, -0.05j]]),
                          [[0.2, 1.0, 0.2]], w0=0.3),
    "dt-even": lptv.Model(np.array([[0.05j, 0.4, -0.05j], [0, 1, 0]]), [[1.0], [0.5]],
                          w0=2 * np.pi / 8, ts=1.0),
    "dt-odd": lptv.Model([[0.3], [1.0]], [[1.0]], w0=2 * np.pi / 7, ts=1.0),
}

SMALL_INT = st.one_of(st.none(), st.integers(-2, 12))


@st.composite
def spectra(draw):
    """Mostly plausible spectra (1-D or 2-D, finite, DC usually real) with occasional flaws."""
    shape = draw(st.one_of(st.tuples(st.integers(1, 6)),
                           st.tuples(st.integers(1, 6), st.integers(1, 3))))
    dtype = draw(st.sampled_from([np.complex128, np.float64, np.int64]))
    value = {np.int64: st.integers(-5, 5), np.float64: st.floats(-1e6, 1e6),
             np.complex128: st.builds(complex, st.floats(-1e6, 1e6), st.floats(-1e6, 1e6))}
    U = draw(hnp.arrays(dtype, shape, elements=value[dtype]))
    if draw(st.integers(0, 4)):  # four times in five
        U[0] = U[0].real
        if U.shape[0] == 5:  # the Nyquist line of the 8-sample model
            U[4] = U[4].real
    return U


@FUZZ
@given(name=st.sampled_from(sorted(MODELS)), U=st.one_of(spectra(), arrays_of_any_kind(max_side=6)),
       lines_out=SMALL_INT, guard=SMALL_INT, solver=st.sampled_from(["auto", "klu", "umfpack"]))
def test_simulate_inputs(name, U, lines_out, guard, solver):
    model = MODELS[name]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", lptv.TruncationWarning)
            Y = lptv.simulate(model, U, lines_out=lines_out, guard=guard, solver=solver)
    except ACCEPTED as e:
        assert str(e)
        event(f"rejected: {type(e).__name__}")
        return
    event("accepted")
    Ua = np.asarray(U)
    assert_finite(Y)
    rows = Ua.shape[0] if lines_out is None else lines_out + 1
    assert Y.shape == ((rows,) if Ua.ndim == 1 else (rows, Ua.shape[1]))


@FUZZ
@given(name=st.sampled_from(sorted(MODELS)),
       U=hnp.arrays(np.complex128, st.tuples(st.integers(1, 5), st.integers(1, 3)),
                    elements=st.complex_numbers(max_magnitude=1e3, allow_nan=False,
                                                allow_infinity=False)))
def test_simulate_valid_inputs_succeed(name, U):
    # Real DC (and Nyquist) lines: every such input must give a finite output.
    model = MODELS[name]
    U = U.copy()
    U[0] = U[0].real
    if model.discrete:
        half = model.samples_per_period // 2
        U = U[: half + 1]
        if model.samples_per_period % 2 == 0 and U.shape[0] == half + 1:
            U[half] = U[half].real
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lptv.TruncationWarning)
        Y = lptv.simulate(model, U)
    assert_finite(Y)
    assert Y.shape == U.shape


# n_samples >= 2: a one-sample period crashes the FFT (see test_errors.py,
# test_length_one_and_zero_periods_do_not_crash), which would end this whole run.
N_SAMPLES = st.one_of(st.integers(2, 64), st.integers(-3, 0), st.sampled_from([2.0, 16.0, 7.5]))
LINES = st.one_of(st.lists(st.integers(-3, 40), max_size=6), arrays_of_any_kind(max_dims=2),
                  st.lists(st.sampled_from([1.0, 2.0, 2.5, np.nan, np.inf]), min_size=1,
                           max_size=3))
AMPLITUDES = st.one_of(REALS, arrays_of_any_kind(max_dims=2))


# lines = inf is cast to int with a RuntimeWarning before it is rejected (test_errors.py,
# lines-inf); the rejection itself is what this test checks.
@pytest.mark.filterwarnings("ignore:invalid value encountered in cast:RuntimeWarning")
@FUZZ
@given(lines=LINES, n_samples=N_SAMPLES, amplitudes=AMPLITUDES, seed=st.integers(0, 2 ** 32))
def test_multisine_inputs(lines, n_samples, amplitudes, seed):
    try:
        ms = lptv.multisine(lines, n_samples, amplitudes=amplitudes, seed=seed)
    except ACCEPTED as e:
        assert str(e)
        event(f"rejected: {type(e).__name__}")
        return
    event("accepted")
    N = ms.n_samples
    assert ms.signal.shape == (N,) and ms.spectrum.shape == (N // 2 + 1,)
    assert_finite(ms.signal)
    assert_finite(ms.spectrum)
    assert_finite(ms.phases)
    # Only excited lines carry anything.
    others = np.setdiff1d(np.arange(N // 2 + 1), ms.lines)
    assert np.all(ms.spectrum[others] == 0)


# ------------------------------------------------------------ sizes, lines and orders from users

# Integers a user may type where the core holds a C int: beyond the largest grid (2^26 lines each
# side), at and beyond INT_MAX, beyond 64 bits, and far negative. Valid but huge sizes (a grid of
# 2^26 lines takes gigabytes) are not drawn: every value here must be refused.
HUGE = st.sampled_from([2**26 + 65, 2**27 + 2, 2**30, 2**31 - 2, 2**31 - 1, 2**31, 2**32 + 1,
                        2**63 - 1, 2**63, 2**64, -2**31 + 1, -2**31, -2**31 - 1, -2**63])


def sizes(lo, hi):
    return st.one_of(st.integers(lo, hi), st.integers(lo, hi), HUGE)


def quiet(call):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call()


def _example_periods(P=4, N=64, ts=None):
    """P noisy periods of a first-order LPTV system (a1(t) = 1 + 0.2 cos t) under a multisine."""
    m = lptv.Model(np.array([[0.05, 2.0, 0.05], [0.1, 1.0, 0.1]]), [[1.0]], w0=1.0,
                   ts=None if ts is None else 2 * np.pi / N)
    ms = lptv.multisine(range(1, N // 2 - 4, 2), N, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), N)
    rng = np.random.default_rng(3)
    return (ms.periods(P) + 1e-3 * rng.standard_normal((P, N)),
            np.tile(y1, (P, 1)) + 1e-3 * rng.standard_normal((P, N)))


U_P, Y_P = _example_periods()
DATA = lptv.FrequencyData.from_periods(U_P, Y_P, w0=1.0)

ROWS = st.one_of(st.none(), st.just("excited"),
                 st.lists(sizes(-3, 40), min_size=1, max_size=12),
                 st.builds(lambda a, n, extra: list(range(a, a + n)) + extra, st.integers(-2, 30),
                           st.integers(1, 30), st.lists(HUGE, max_size=2)),
                 st.lists(st.sampled_from([3.0, 4.0, 2.5, 1e300, -1e300, np.nan]), min_size=1,
                          max_size=4))
COUNTS = st.one_of(sizes(0, 3), st.lists(sizes(0, 3), min_size=1, max_size=4))


def assert_identified(res):
    assert_finite(res.model.a)
    assert_finite(res.model.b)
    assert np.all(np.isfinite(res.residue))


@FUZZ
@given(na=sizes(0, 3), nb=sizes(0, 2), ka=COUNTS, kb=COUNTS, lines=ROWS,
       method=st.sampled_from(lptv.METHODS),
       max_iter=st.one_of(st.integers(0, 4), st.sampled_from([-1, 2**31, 2**63])))
def test_identify_sizes_and_lines(na, nb, ka, kb, lines, method, max_iter):
    try:
        res = quiet(lambda: lptv.identify(U_P, Y_P, na=na, nb=nb, ka=ka, kb=kb, w0=1.0,
                                          lines=lines, method=method, max_iter=max_iter))
    except ACCEPTED as e:
        assert str(e)
        event(f"rejected: {type(e).__name__}")
        return
    event("accepted")
    assert_identified(res)


@st.composite
def frequency_data(draw):
    """Spectra and variances of any shape and dtype (mostly of one consistent length), and
    periods of any size."""
    n = draw(st.integers(0, 40))
    consistent = hnp.arrays(np.float64, n, elements=st.floats(0, 10))
    parts = [draw(st.one_of(consistent, consistent, consistent, arrays_of_any_kind(max_dims=2)))
             for _ in range(4)]
    periods = draw(st.one_of(sizes(0, 8), st.sampled_from([2.5, np.nan, -1.0])))
    return parts, periods


@FUZZ
@given(fd=frequency_data(), method=st.sampled_from(lptv.METHODS), na=sizes(0, 2),
       K=st.integers(0, 2))
def test_frequency_data_inputs(fd, method, na, K):
    (U, Y, varU, varY), periods = fd
    try:
        data = lptv.FrequencyData(U, Y, varU, varY, w0=1.0, periods=periods)
    except ACCEPTED as e:
        assert str(e)
        event("rejected: FrequencyData")
        return
    assert data.periods == periods and data.periods >= 0
    try:
        res = quiet(lambda: lptv.identify(data, na=na, nb=0, ka=K, method=method, max_iter=3))
    except ACCEPTED as e:
        assert str(e)
        event(f"identify rejected: {type(e).__name__}")
        return
    event("accepted")
    assert_identified(res)


GRID_MODELS = dict(MODELS, **{
    # samples per period far beyond the largest grid: every grid of it must be refused
    f"dt-N{N}": lptv.Model([[0.3], [1.0]], [[1.0]], w0=2 * np.pi / N, ts=1.0)
    for N in (2**27 + 3, 2**31 - 1)})


@FUZZ
@given(name=st.sampled_from(sorted(GRID_MODELS)), L=sizes(-2, 40),
       lines=st.one_of(st.none(), st.lists(sizes(-45, 45), max_size=4)),
       lines_out=st.one_of(st.none(), sizes(-2, 40)), guard=st.one_of(st.none(), sizes(-2, 40)),
       max_guard=st.one_of(st.none(), st.integers(-2, 200), st.sampled_from([2**31, 2**63])),
       call=st.sampled_from(["band_matrices", "htf", "simulate"]))
def test_grid_sizes(name, L, lines, lines_out, guard, max_guard, call):
    model = GRID_MODELS[name]
    try:
        if call == "band_matrices":
            A, B = lptv.band_matrices(model, L)
            n = model.samples_per_period if model.discrete else 2 * L + 1
            assert A.shape == (n, n) and B.shape == (n, n)
            assert_finite(A.data)
        elif call == "htf":
            G = lptv.htf(model, L, lines)
            n = model.samples_per_period if model.discrete else 2 * L + 1
            assert G.shape == (n, n if lines is None else len(lines))
            assert_finite(G)
        else:
            U = np.ones(4 if lines_out is None or model.discrete else 3)
            Y = quiet(lambda: lptv.simulate(model, U, lines_out=lines_out, guard=guard,
                                            max_guard=max_guard))
            assert Y.shape == (U.size if lines_out is None else lines_out + 1,)
            assert_finite(Y)
    except ACCEPTED as e:
        assert str(e)
        event(f"rejected: {call}")
        return
    event(f"accepted: {call}")


# Periods beyond the largest multisine (2^27 + 1 samples, one grid of 2^26 lines each side).
HUGE_PERIODS = HUGE.filter(lambda n: n > 2**27 + 1 or n < 0)


@FUZZ
@given(lines=st.lists(sizes(-3, 40), max_size=5),
       n_samples=st.one_of(st.integers(-2, 100), st.integers(-2, 100), HUGE_PERIODS),
       X=st.lists(st.floats(-10, 10), min_size=1, max_size=5))
def test_multisine_and_time_signal_sizes(lines, n_samples, X):
    try:
        ms = lptv.multisine(lines, n_samples, seed=0)
    except ACCEPTED as e:
        assert str(e)
        event("multisine rejected")
    else:
        event("multisine accepted")
        assert ms.signal.shape == (n_samples,)
        assert_finite(ms.signal)
    try:
        x = lptv.time_signal(X, n_samples)
    except ACCEPTED as e:
        assert str(e)
        event("time_signal rejected")
    else:
        event("time_signal accepted")
        assert x.shape == (n_samples,)
        assert_finite(x)
