"""Every bad input raises ValueError, every numerical failure lptv.NumericalError, each with a
message naming the argument (or the line) and what is wrong. Nothing crashes, nothing returns NaN."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lptv

NaN, INF = np.nan, np.inf


def lti(w0=1.0, ts=None):
    return lptv.Model([[1.0], [1.0]], [[1.0]], w0=w0, ts=ts)


def dt_model(N=8):
    return lptv.Model([[0.5], [1.0]], [[1.0]], w0=2 * np.pi / N, ts=1.0)


LPTV_A = np.array([[0.1j, 1, -0.1j], [0, 1, 0]])


def check(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


def cases(table):
    """(id, call, match[, xfail reason]) rows -> pytest params; a reason marks a known bug."""
    return [pytest.param(call, match, id=name,
                         marks=pytest.mark.xfail(strict=True, reason=bug[0]) if bug else ())
            for name, call, match, *bug in table]


# ---------------------------------------------------------------------------- NaN and inf

NONFINITE = [
    ("a-nan", lambda: lptv.Model([[NaN], [1.0]], [[1.0]], 1.0), r"^a contains NaN or inf"),
    ("a-inf-harmonic", lambda: lptv.Model([[INF, 1, INF], [0, 1, 0]], [[1.0]], 1.0),
     r"^a contains NaN or inf \(first at index \(0, 0\)\)"),
    ("a-complex-nan", lambda: lptv.Model([[complex(1, NaN)], [1.0]], [[1.0]], 1.0),
     r"^a contains NaN or inf"),
    ("b-nan", lambda: lptv.Model([[1.0], [1.0]], [[1.0], [NaN]], 1.0),
     r"^b contains NaN or inf \(first at index \(1, 0\)\)"),
    ("b-minus-inf", lambda: lptv.Model([[1.0], [1.0]], [[-INF]], 1.0), r"^b contains NaN or inf"),
    ("w0-nan", lambda: lptv.Model([[1.0], [1.0]], [[1.0]], NaN), r"^w0 must be a finite positive"),
    ("w0-inf", lambda: lptv.Model([[1.0], [1.0]], [[1.0]], INF), r"^w0 must be a finite positive"),
    ("ts-nan", lambda: lptv.Model([[1.0], [1.0]], [[1.0]], 1.0, ts=NaN), r"^ts must be finite"),
    ("ts-inf", lambda: lptv.Model([[1.0], [1.0]], [[1.0]], 1.0, ts=INF), r"^ts must be finite"),
    ("U-nan", lambda: lptv.simulate(lti(), [1.0, NaN, 0.5]),
     r"^U contains NaN or inf \(first at index \(1, 0\)\)"),
    ("U-inf-2d", lambda: lptv.simulate(lti(), np.array([[1.0, 1], [1j, INF]])),
     r"^U contains NaN or inf \(first at index \(1, 1\)\)"),
    ("U-complex-inf", lambda: lptv.simulate(dt_model(), [1.0, complex(0, INF)]),
     r"^U contains NaN or inf"),
    ("t-nan-a_at", lambda: lti().a_at([0.0, NaN]), r"^t contains NaN or inf"),
    ("t-inf-b_at", lambda: lti().b_at([INF]), r"^t contains NaN or inf"),
    ("t-nan-frozen", lambda: lti().frozen(NaN), r"^t contains NaN or inf"),
    ("amplitudes-nan", lambda: lptv.multisine([1, 2], 16, amplitudes=[1.0, NaN]),
     r"^amplitudes contains NaN or inf \(first at index \(1,\)\)"),
    ("amplitudes-inf-scalar", lambda: lptv.multisine([1, 2], 16, amplitudes=INF),
     r"^amplitudes contains NaN or inf"),
    ("x-nan-spectrum", lambda: lptv.spectrum([0.0, NaN]), r"^x contains NaN or inf"),
    ("tol-nan", lambda: lptv.simulate(lti(), [1.0, 1.0], tol=NaN), r"^tol must be positive"),
    ("X-nan-time_signal", lambda: lptv.time_signal([1.0, NaN], 8), r"^X contains NaN or inf"),
    ("X-object-time_signal", lambda: lptv.time_signal(np.array([1.0, None], object), 8),
     r"^X must be numeric"),
]


@pytest.mark.parametrize("call, match", cases(NONFINITE))
def test_nonfinite_rejected(call, match):
    check(call, ValueError, match)


# Integer arguments given NaN, inf, a fraction or a negative number: ValueError naming the
# argument, not OverflowError from int(inf), "cannot convert float NaN to integer", or silent
# truncation of 2.5 to 2.
def _simulate_lptv(**kw):
    return lptv.simulate(lptv.Model(LPTV_A, [[1.0]], 1.0), [1.0, 1.0], **kw)


INTEGER_CASES = []
for name, arg, call in [
    ("simulate", "lines_out", lambda v: lptv.simulate(lti(), [1.0, 1.0], lines_out=v)),
    ("simulate", "guard", lambda v: lptv.simulate(lti(), [1.0, 1.0], guard=v)),
    ("simulate", "max_guard", lambda v: _simulate_lptv(max_guard=v)),
    ("multisine", "n_samples", lambda v: lptv.multisine([1], v)),
    ("time_signal", "n_samples", lambda v: lptv.time_signal([1.0, 0.5], v)),
]:
    values = [("nan", NaN), ("inf", INF), ("fraction", 2.5)]
    if arg != "max_guard":  # a negative max_guard is documented nowhere, either way
        values.append(("negative", -3))
    for label, value in values:
        INTEGER_CASES.append(pytest.param(call, value, arg, id=f"{name}-{arg}-{label}"))


@pytest.mark.parametrize("call, value, arg", INTEGER_CASES)
def test_integer_arguments_rejected(call, value, arg):
    check(lambda: call(value), ValueError, rf"^{arg} must be")


# --------------------------------------------------------------------- shapes and dtypes

SHAPES_DTYPES = [
    ("a-3d", lambda: lptv.Model(np.ones((2, 1, 1)), [[1.0]], 1.0), r"^a must be 2-D"),
    ("a-even-columns", lambda: lptv.Model(np.ones((2, 2)), [[1.0]], 1.0),
     r"^a must have an odd number of columns 2K\+1"),
    ("b-even-columns", lambda: lptv.Model([[1.0], [1.0]], np.ones((1, 4)), 1.0),
     r"^b must have an odd number of columns"),
    ("a-no-rows", lambda: lptv.Model(np.zeros((0, 1)), [[1.0]], 1.0),
     r"^a must have at least one row"),
    ("a-ragged", lambda: lptv.Model([[1.0, 2.0, 3.0], [1.0]], [[1.0]], 1.0),
     r"^a must be array-like"),
    ("a-string", lambda: lptv.Model("abc", [[1.0]], 1.0), r"^a must be numeric, got dtype <U3"),
    ("a-strings", lambda: lptv.Model([["1"], ["2"]], [[1.0]], 1.0), r"^a must be numeric"),
    ("b-object", lambda: lptv.Model([[1.0], [1.0]], np.array([[1.0], [None]], object), 1.0),
     r"^b must be numeric, got dtype object"),
    ("a-datetime", lambda: lptv.Model(np.array([1, 2], "M8[s]"), [[1.0]], 1.0),
     r"^a must be numeric"),
    ("a-timedelta", lambda: lptv.Model(np.array([1, 2], "m8[s]"), [[1.0]], 1.0),
     r"^a must be numeric"),
    ("U-3d", lambda: lptv.simulate(lti(), np.ones((3, 2, 2))),
     r"^U must be 1-D \(lines\) or 2-D \(lines, inputs\), got shape \(3, 2, 2\)"),
    ("U-scalar", lambda: lptv.simulate(lti(), 1.0), r"^U must be 1-D"),
    ("U-empty", lambda: lptv.simulate(lti(), []), r"^U must not be empty"),
    ("U-no-columns", lambda: lptv.simulate(lti(), np.ones((3, 0))), r"^U must not be empty"),
    ("U-string", lambda: lptv.simulate(lti(), ["1", "2"]), r"^U must be numeric"),
    ("U-object", lambda: lptv.simulate(lti(), np.array([1.0, None], object)),
     r"^U must be numeric, got dtype object"),
    ("t-2d", lambda: lti().a_at(np.zeros((2, 2))), r"^t must be 1-D"),
    ("t-complex", lambda: lti().a_at([1j]), r"^t must be real"),
    ("t-string", lambda: lti().b_at(["0"]), r"^t must be numeric"),
    ("amplitudes-2d", lambda: lptv.multisine([1, 2], 16, amplitudes=np.ones((2, 1))),
     r"^amplitudes must be 1-D"),
    ("amplitudes-length", lambda: lptv.multisine([1, 2], 16, amplitudes=[1.0, 2.0, 3.0]),
     r"^amplitudes must be a scalar or have one entry per line \(2\), got 3"),
    ("amplitudes-complex", lambda: lptv.multisine([1, 2], 16, amplitudes=[1j, 1.0]),
     r"^amplitudes must be real"),
    ("amplitudes-string", lambda: lptv.multisine([1, 2], 16, amplitudes="a"),
     r"^amplitudes must be numeric"),
    ("lines-2d", lambda: lptv.multisine([[1, 2]], 16), r"^lines must be 1-D"),
    ("lines-fraction", lambda: lptv.multisine([1.5], 16), r"^lines must be integers"),
    ("lines-string", lambda: lptv.multisine(["1"], 16), r"^lines must be integers"),
    ("lines-object", lambda: lptv.multisine(np.array([1, None], object), 16),
     r"^lines must be integers"),
    ("lines-empty", lambda: lptv.multisine([], 16), r"^lines must not be empty"),
    ("lines-inf", lambda: lptv.multisine([2.0, np.inf], 16), r"^lines must be integers"),
    ("lines-above-nyquist", lambda: lptv.multisine([3, 9], 16),
     r"^lines must lie in 0\.\.8 \(n_samples//2\)"),
    ("lines-negative", lambda: lptv.multisine([-1], 16), r"^lines must lie in 0\.\.8"),
    ("lines-repeated", lambda: lptv.multisine([2, 2], 16), r"^lines must be distinct"),
    ("n_samples-zero", lambda: lptv.multisine([0], 0), r"^n_samples must be a positive integer"),
    ("X-too-long", lambda: lptv.time_signal(np.ones(6), 8), r"^X must have between 1 and"),
    ("x-empty", lambda: lptv.spectrum([]), r"^x must have at least 1"),
]


@pytest.mark.parametrize("call, match", cases(SHAPES_DTYPES))
def test_shapes_and_dtypes_rejected(call, match):
    check(call, ValueError, match)


# ------------------------------------------------------------------- model consistency

def test_coefficients_not_conjugate_symmetric():
    a = np.array([[0.1, 1, 0.2], [0, 1, 0]])
    check(lambda: lptv.Model(a, [[1.0]], 1.0), ValueError,
          r"^a is not conjugate-symmetric: row 0, harmonic 1")
    b = np.array([[0.1j, 1, 0.1j]])
    check(lambda: lptv.Model([[1.0], [1.0]], b, 1.0), ValueError,
          r"^b is not conjugate-symmetric: row 0, harmonic 1")


def test_harmonic_zero_not_real():
    check(lambda: lptv.Model([[1.0 + 0.5j], [1.0]], [[1.0]], 1.0), ValueError,
          r"^a is not conjugate-symmetric: row 0, harmonic 0")


def test_leading_coefficient_identically_zero():
    check(lambda: lptv.Model([[1.0], [0.0]], [[1.0]], 1.0), ValueError,
          r"^a: the leading coefficient a_na\(t\) is identically zero")


@pytest.mark.parametrize("which", ["a", "b"])
def test_harmonics_do_not_fit_discrete_grid(which):
    wide = np.zeros((2, 7))
    wide[:, 3] = 1.0  # 3 harmonics need 7 samples per period
    a, b = (wide, [[1.0]]) if which == "a" else ([[0.5], [1.0]], wide)
    check(lambda: lptv.Model(a, b, w0=2 * np.pi / 6, ts=1.0), ValueError,
          r"^harmonic counts do not fit the grid: 3 harmonics need at least 7 samples per "
          r"period, the model has 6")


def test_sample_period_not_a_whole_grid():
    check(lambda: lptv.Model([[0.5], [1.0]], [[1.0]], w0=1.0, ts=1.0), ValueError,
          r"^w0 and ts do not fit a grid: 2\*pi/\(w0\*ts\) = 6\.28319 samples per parameter "
          r"period is not an integer")


@pytest.mark.parametrize("w0", [0.0, -1.0])
def test_nonpositive_w0(w0):
    check(lambda: lptv.Model([[1.0], [1.0]], [[1.0]], w0), ValueError,
          r"^w0 must be a finite positive angular frequency")


def test_negative_ts():
    check(lambda: lptv.Model([[1.0], [1.0]], [[1.0]], 1.0, ts=-0.1), ValueError, r"^ts must be")


# ----------------------------------------------------------------------- simulate inputs

def test_complex_dc_input():
    check(lambda: lptv.simulate(lti(), np.array([[1.0, 1 + 0.5j], [1, 1]])), ValueError,
          r"^U: line 0 \(DC\) must be real for a real input signal, column 1")


def test_complex_dc_input_discrete():
    check(lambda: lptv.simulate(dt_model(), [0.5j, 1.0]), ValueError, r"^U: line 0 \(DC\)")


def test_complex_nyquist_input():
    check(lambda: lptv.simulate(dt_model(8), [1.0, 1, 1, 1, 1j]), ValueError,
          r"^U: the Nyquist line N/2 must be real")


def test_input_beyond_discrete_grid():
    check(lambda: lptv.simulate(dt_model(8), np.ones(6)), ValueError,
          r"^U has lines 0\.\.5 but the discrete-time grid of 8 samples per period has one-sided "
          r"lines 0\.\.4")


def test_lines_out_beyond_discrete_grid():
    check(lambda: lptv.simulate(dt_model(8), np.ones(3), lines_out=5), ValueError,
          r"^lines_out must be <= N/2 = 4")


def test_not_a_model():
    check(lambda: lptv.simulate("model", np.ones(3)), ValueError,
          r"^model must be an lptv.Model, got str")
    check(lambda: lptv.htf(lti()._cpp, 3), ValueError, r"^model must be an lptv.Model")


def test_unknown_solver():
    check(lambda: lptv.simulate(lti(), np.ones(3), solver="lu"), ValueError,
          r"^solver must be 'auto', 'band', 'klu' or 'umfpack', got 'lu'")
    check(lambda: lptv.htf(lti(), 3, solver="dense"), ValueError, r"^solver must be")


@pytest.mark.parametrize("tol_value", [0.0, -1e-12, INF])
def test_bad_tolerance(tol_value):
    check(lambda: lptv.simulate(lti(), np.ones(3), tol=tol_value), ValueError,
          r"^tol must be positive")


def test_htf_bad_lines_and_grid():
    check(lambda: lptv.htf(lti(), 3, [0, 5]), ValueError,
          r"^lines: input line 5 is outside the grid -3\.\.3")
    check(lambda: lptv.htf(lti(), -1), ValueError, r"^L must be a non-negative integer")
    check(lambda: lptv.band_matrices(lti(), -2), ValueError, r"^L must be a non-negative integer")


def test_crest_factor_of_zero_signal():
    check(lambda: lptv.multisine([1, 2], 16, amplitudes=0.0).crest_factor, ValueError,
          r"^crest factor of a zero signal is undefined")


# ------------------------------------------------------------------ numerical failures

SOLVERS = ["klu", "umfpack"]
CT_SOLVERS = SOLVERS + ["band"]


@pytest.mark.parametrize("solver", CT_SOLVERS)
def test_pole_on_a_continuous_grid_line(solver):
    # s^2 + 4 with w0 = 1: poles at +-2j, lines +-2; A(2j) is exactly zero in floating point.
    model = lptv.Model([[4.0], [0.0], [1.0]], [[1.0]], w0=1.0)
    match = r"^A is singular at line -?2 \(a zero pivot: the system has a pole on that line"
    check(lambda: lptv.simulate(model, np.ones(4), solver=solver), lptv.NumericalError, match)
    check(lambda: lptv.htf(model, 5, [1], solver=solver), lptv.NumericalError, match)


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("line", [0, 3, 6, 12])
def test_pole_on_a_discrete_grid_line(solver, line):
    # Poles exp(+-j theta) on the unit circle at line 3 or 6 of 24, at DC ((z - 1)^2) and at
    # Nyquist ((z + 1)^2): lines where z^2 - 2 cos(theta) z + 1 rounds to exactly zero.
    N = 24
    theta = 2 * np.pi * line / N
    model = lptv.Model([[1.0], [-2 * np.cos(theta)], [1.0]], [[1.0]], w0=2 * np.pi / N, ts=1.0)
    check(lambda: lptv.simulate(model, np.ones(N // 2 + 1), solver=solver), lptv.NumericalError,
          rf"^A is singular at line ({line}|{(N - line) % N})\b")


@pytest.mark.parametrize("solver", CT_SOLVERS)
def test_pole_on_a_continuous_grid_line_up_to_rounding(solver):
    # s^2 + 0.04 with w0 = 0.1: poles at +-0.2j = line +-2, but (0.2j)^2 + 0.04 = -6.9e-18.
    model = lptv.Model([[0.04], [0.0], [1.0]], [[1.0]], w0=0.1)
    check(lambda: lptv.simulate(model, np.ones(5), solver=solver), lptv.NumericalError,
          r"line -?2\b")


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("line", [1, 5])
def test_pole_on_a_discrete_grid_line_up_to_rounding(solver, line):
    # As above on the unit circle: at lines 1 and 5 of 24 the quadratic misses zero by ~1e-16.
    N = 24
    theta = 2 * np.pi * line / N
    model = lptv.Model([[1.0], [-2 * np.cos(theta)], [1.0]], [[1.0]], w0=2 * np.pi / N, ts=1.0)
    check(lambda: lptv.simulate(model, np.ones(N // 2 + 1), solver=solver), lptv.NumericalError,
          rf"line ({line}|{N - line})\b")


# ------------------------------------------------------------------------- no crashes

def run_isolated(code):
    """Run code in a fresh interpreter: a crash there fails one test, not the whole run."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=120)


@pytest.mark.parametrize("code", [
    pytest.param("r = lptv.spectrum([2.5]); assert r.tolist() == [2.5]", id="spectrum-N1"),
    pytest.param("r = lptv.time_signal([2.5], 1); assert r.tolist() == [2.5]",
                 id="time_signal-N1"),
    pytest.param("ms = lptv.multisine([0], 1, seed=0); assert ms.signal.shape == (1,)",
                 id="multisine-N1"),
    pytest.param("""
        try:
            lptv.time_signal([1.0], 0)
        except ValueError as e:
            assert "n_samples" in str(e)
        else:
            raise AssertionError("no error")
        """, id="time_signal-N0"),
])
def test_length_one_and_zero_periods_do_not_crash(code):
    r = run_isolated("import lptv\n" + textwrap.dedent(code))
    assert r.returncode == 0, f"exit code {r.returncode}: {r.stderr[-500:]}"


def test_band_solver_refused_on_the_discrete_grid():
    check(lambda: lptv.simulate(dt_model(), [1.0, 0.5], solver="band"), ValueError,
          r"^solver: the band solver needs the continuous-time grid")


def test_a_row_near_int_max_is_refused_not_read_out_of_bounds():
    """lines=[2**31 - 1, ...] with K = 1 wrapped around in 32-bit arithmetic and passed the check
    (then read out of bounds: a segfault). Run in a subprocess so a regression fails this test,
    not the session."""
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent("""
        import numpy as np, lptv
        m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
        ms = lptv.multisine(range(1, 60), 256, seed=0)
        y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
        u, y = ms.periods(4), np.tile(y1, (4, 1))
        rng = np.random.default_rng(1)
        u, y = u + 1e-3 * rng.standard_normal(u.shape), y + 1e-3 * rng.standard_normal(y.shape)
        for method in ("wgtls", "ls", "sml"):
            try:
                lptv.identify(u, y, na=1, nb=0, ka=1, w0=0.1, lines=[2**31 - 1] + list(range(2, 40)),
                              method=method)
            except ValueError as e:
                assert "2147483647" in str(e) and "lines" in str(e), e
            else:
                raise AssertionError("accepted")
        print("ok")
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and p.stdout.strip() == "ok", (p.returncode, p.stderr[-2000:])


@pytest.mark.parametrize("kw, match", [
    (dict(na=6000, nb=0), "6001 free parameters for 256 real equations"),
    (dict(na=1, nb=0, ka=2**31 - 1), "8589934590 free parameters"),
    (dict(na=5, nb=0, ka=10, kb=10, lines=range(11, 20)), "146 free parameters for 18 real equations"),
])
def test_structures_too_large_for_the_data_are_refused_before_allocating(kw, match):
    """Equations against unknowns in 64-bit arithmetic before the parametrisation is built (na=6000
    allocated 1.2 GB before this check; a harmonic count near INT_MAX grew without bound)."""
    import resource

    m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
    ms = lptv.multisine(range(1, 60), 256, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    rng = np.random.default_rng(1)
    u = ms.periods(4) + 1e-3 * rng.standard_normal((4, 256))
    y = np.tile(y1, (4, 1)) + 1e-3 * rng.standard_normal((4, 256))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(ValueError, match=match):
        lptv.identify(u, y, w0=0.1, **kw)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100_000  # KB: < 100 MB


def test_a_parametrisation_beyond_the_size_limit_says_how_much_memory():
    from lptv import _core

    with pytest.raises(ValueError, match="complex parameters .* GB"):
        _core.Parametrisation(2, 0, [1500, 1500, 1500], [0], [], 0.1, 0.0)


@pytest.mark.parametrize("call, match", [
    (lambda M: lptv.htf(M, 2**30), "L must be at most 67108864"),
    (lambda M: lptv.band_matrices(M, 2**31 - 1), "too large .* GB"),
    (lambda M: lptv.simulate(M, np.ones(10), lines_out=2**31 - 2), "too large .* GB"),
    (lambda M: lptv.Model([[1.0], [1.0]], [[1.0]], w0=1e-9, ts=0.73).samples_per_period,
     "more than a grid can hold"),
])
def test_grids_beyond_int_range_are_refused_before_allocating(call, match):
    """2 L + 1 and the guard on top of a grid are ints in the core, and 8.6e9 samples per period
    were cast to int: each is now a ValueError before anything is allocated."""
    M = lptv.Model([[1.0, 2.0, 1.0], [0.0, 1.0, 0.0]], [[0.0, 1.0, 0.0]], w0=0.1)
    with pytest.raises(ValueError, match=match):
        call(M)


# ------------------------------------------------- sizes from users beyond the grids and C ints

def _data_256():
    """The 256-sample record of the tests above: 1 / (s + 2), w0 = 0.1, 4 noisy periods."""
    m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
    ms = lptv.multisine(range(1, 60), 256, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    rng = np.random.default_rng(1)
    return (ms.periods(4) + 1e-3 * rng.standard_normal((4, 256)),
            np.tile(y1, (4, 1)) + 1e-3 * rng.standard_normal((4, 256)))


# A discrete-time model of 2^31 - 1 samples per period (w0 ts = 2 pi / (2^31 - 1)).
def _dt_huge():
    return lptv.Model([[0.3], [1.0]], [[1.0]], w0=2 * np.pi / (2**31 - 1), ts=1.0)


@pytest.mark.parametrize("call, match", [
    pytest.param(lambda M: lptv.simulate(M, np.ones(10), guard=2**31 - 1),
                 r"grid of lines -2147483656\.\.2147483656 is too large .* GB", id="guard-int-max"),
    pytest.param(lambda M: lptv.simulate(_dt_huge(), np.ones(3)),
                 "the model's 2147483647 samples per period is too large .* GB", id="dt-simulate"),
    pytest.param(lambda M: lptv.band_matrices(_dt_huge()),
                 "the model's 2147483647 samples per period is too large .* GB", id="dt-band"),
    pytest.param(lambda M: lptv.htf(_dt_huge(), 0, lines=[0]),
                 "the model's 2147483647 samples per period is too large", id="dt-htf-lines"),
    pytest.param(lambda M: lptv.htf(_dt_huge(), 0),
                 "the model's 2147483647 samples per period is too large", id="dt-htf-default"),
    pytest.param(lambda M: lptv.multisine([1], 2**31 - 1),
                 r"n_samples = 2147483647 is too large \(at most 134217729.* GB", id="multisine"),
    pytest.param(lambda M: lptv.time_signal([1.0], 2**31 - 1),
                 r"n_samples = 2147483647 is too large \(at most 134217729.* GB", id="time_signal"),
])
def test_sizes_beyond_the_largest_grid_are_refused_before_allocating(call, match):
    """A fixed guard near INT_MAX overflowed band + guard (an int) into a negative L; a discrete
    grid or a multisine period of 2^31 - 1 samples was allocated (std::bad_alloc, or with the
    default input lines of htf a Python list of 2^31 entries)."""
    import resource

    M = lptv.Model([[1.0, 2.0, 1.0], [0.0, 1.0, 0.0]], [[0.0, 1.0, 0.0]], w0=0.1)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(ValueError, match=match):
        call(M)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100_000  # KB: < 100 MB


def test_the_largest_multisine_period_is_the_largest_grid():
    # The bound of n_samples is the continuous grid's 2^26 lines each side, not less: a period of
    # 2^27 + 1 samples has its lines 0..2^26 on that grid; one sample more does not.
    with pytest.raises(ValueError, match="n_samples = 134217730 is too large"):
        lptv.multisine([1], 2 * 2**26 + 2)
    with pytest.raises(ValueError, match="lines must lie in 0..67108864"):
        lptv.multisine([2**26 + 1], 2 * 2**26 + 1)


@pytest.mark.parametrize("kw, match", [
    (dict(max_iter=2**31), "^max_iter must be at most 2147483647, got 2147483648$"),
    (dict(ka=2**31), "^ka must be at most 2147483647, got 2147483648$"),
    (dict(kb=[2**31]), r"^kb must be at most 2147483647, got 2147483648 \(an entry of kb\)$"),
    (dict(na=2**31 - 1), "^na = 2147483647 and nb = 0 give 2147483649 coefficients"),
    (dict(lines=[2**63] + list(range(2, 40))),
     r"^lines must be at most 2147483647, got 9223372036854775808 \(an entry of lines\)$"),
    (dict(lines=[3.0, 1e300]), r"^lines must be at most 2147483647, got 1e\+300 \(an entry of lines\)$"),
    (dict(lines=[-2**40, 3]), r"^lines must be a non-negative integer, got -1099511627776 \(an entry of lines\)$"),
    (dict(ka=2**31 - 1, lines="excited"),
     r"^lines='excited': no excited line lies within the usable rows 2147483648\.\.-2147483519$"),
])
def test_counts_and_lines_beyond_int_are_value_errors_naming_the_argument(kw, match):
    """They reached the compiled core as Python ints it cannot hold: a TypeError listing the
    binding's signatures instead of the argument at fault; na = 2^31 - 1 built per-coefficient
    lists of 2^31 entries, ka = 2^31 - 1 with lines='excited' an array of 2^32 offsets."""
    u, y = _data_256()
    args = dict(dict(na=1, nb=0, w0=0.1), **kw)
    with pytest.raises(ValueError, match=match):
        lptv.identify(u, y, **args)


@pytest.mark.parametrize("periods, match", [
    (-1, "^periods must be a non-negative integer, got -1$"),
    (2.5, "^periods must be an integer, got 2.5$"),
    (2**40, "^periods must be at most 2147483647, got 1099511627776$"),
])
def test_frequency_data_periods_must_be_a_count(periods, match):
    # -1 and 2.5 were accepted (2.5 truncated to 2), 2^40 was a TypeError of the binding.
    ones = np.ones(8)
    with pytest.raises(ValueError, match=match):
        lptv.FrequencyData(ones, ones, ones, ones, w0=1.0, periods=periods)
    assert lptv.FrequencyData(ones, ones, ones, ones, w0=1.0, periods=3.0).periods == 3


def test_multisine_lines_beyond_int64_are_reported_as_given():
    # [2**63, -1] is a float64 array; its cast to int wrapped 2**63 to -2**63 in the message.
    with pytest.raises(ValueError, match=r"^lines must lie in 0..8 \(n_samples//2\), got -1..9223372036854775808$"):
        lptv.multisine([2**63, -1], 16)


@pytest.mark.parametrize("a", [
    [[1.0e308], [1.0]],
    [[0.1 + 0.2j, 1.5e308, 0.1 - 0.2j], [0.0, 1.0, 0.0]],
    [[1.5e308 - 1.0e308j, 0.5, 1.5e308 + 1.0e308j], [0.0, 1.0, 0.0]],
], ids=["mean", "harmonic-0", "harmonic-1"])
def test_coefficients_near_the_largest_double_stay_finite(a):
    # The exact symmetrisation took (x + conj(y)) / 2, and x + x overflowed to inf: a model with
    # an infinite coefficient, silently.
    a = np.array(a, dtype=complex)
    m = lptv.Model(a, [[1.0]], w0=1.0)
    assert np.all(np.isfinite(m.a))
    np.testing.assert_array_equal(m.a, a)  # already symmetric: kept bit for bit
