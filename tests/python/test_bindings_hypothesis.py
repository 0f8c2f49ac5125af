"""Property tests of the input handling: random shapes, dtypes and values into lptv.Model,
lptv.simulate and lptv.multisine give either a correct result or ValueError / NumericalError,
never another exception, a crash, or NaN in the output."""
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import lptv

# Deterministic (derandomize) so that a run in CI is reproducible; modest counts keep the file
# at a few seconds.
FUZZ = settings(max_examples=150, deadline=None, derandomize=True, database=None,
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
    assert lptv.Model.from_dict(m.to_dict()) == m
    assert repr(m).startswith("lptv.Model(")


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
