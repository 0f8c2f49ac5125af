"""The per-line regression of lptv.distortion in the compiled core (_core.distortion_lines)
against its NumPy twin lptv.reference.distortion (numpy.linalg.lstsq and pinv of X^H X per line,
the computation lptv.distortion had before), on the spectra of several seeds and systems, and
lptv.distortion as a whole against the reference on spectra from numpy.fft. Tolerances: conftest
(DISTORTION_VS_REFERENCE), scaled per line by the conditioning of its regression."""
import numpy as np
import pytest
from hypothesis import event, given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import lptv
from lptv import _core
from lptv.reference import distortion as ref
from lptv.reference.identification import frequency_data
from conftest import DISTORTION_KAPPA_MAX, DISTORTION_RELATIVE, DISTORTION_VS_REFERENCE as TOL
from test_bindings_hypothesis import ACCEPTED, FUZZ
from test_distortion import _realisations

CASES = [("paper", 4, 0, 0.0), ("paper", 4, 1, 0.0), ("paper", 4, 2, 0.02), ("paper", 8, 3, 0.02),
         ("third_order", 8, 4, 0.0), ("third_order", 8, 5, 0.1)]


def _spectra(d):
    return [np.array([s[i] for s in d.spectra]) for i in range(5)]   # U, Y, varU, varY, covYU


def _line_scales(U, Y, varU, covYU, excited, Kh):
    """Per output line j: kappa = cond(X_j), g = ||y_j|| / sigma_min(X_j) (a bound on ||G_j||),
    ||y_j|| and the largest var U, |cov YU| among the regressors (the noise's sensitivity to G)."""
    L = U.shape[1] - 1
    out = np.zeros((L, 5))
    for j in range(1, L + 1):
        cs = ref.regressors(excited, j, Kh)
        y = np.linalg.norm(Y[:, j])
        if cs.size == 0 or cs.size >= U.shape[0]:
            out[j - 1] = (1.0, 0.0, y, 0.0, 0.0)
            continue
        X = np.column_stack([U[:, c] if c > 0 else np.conj(U[:, -c]) for c in cs])
        s = np.linalg.svd(X, compute_uv=False)
        out[j - 1] = (s[0] / s[-1], y / s[-1], y, np.max(varU[:, np.abs(cs)]), np.max(np.abs(covYU[:, j])))
    return out


def _compare(core, r, U, Y, varU, varY, covYU, excited, Kh):
    """Each quantity within TOL times its first-order rounding bound (both routes are backward
    stable least-squares solutions of the same M x q problem): ||dG|| <~ eps kappa ||y|| /
    sigma_min; the residual power moves by 2 ||r|| ||dr||, ||dr|| <~ eps kappa ||y||; the noise by
    2 |G| |dG| var U + 2 |dG| |cov|; (X^H X)^-1 by eps kappa^2 / sigma_min^2, as NumPy forms
    X^H X (the core takes the SVD of X)."""
    M = U.shape[0]
    np.testing.assert_array_equal(np.asarray(core.dof), r.dof)
    np.testing.assert_array_equal(np.asarray(core.regressors), r.regressors)
    np.testing.assert_array_equal(np.asarray(core.lines), r.lines)
    sc = _line_scales(U, Y, varU, covYU, excited, Kh)
    kappa, g, ynorm, vu, cv = sc.T
    assert kappa.max() <= DISTORTION_KAPPA_MAX, kappa.max()
    ok = r.dof >= 1
    total, noise = np.asarray(core.total), np.asarray(core.noise)
    assert np.array_equal(np.isnan(total), ~ok) and np.array_equal(np.isnan(noise), ~ok)
    np.testing.assert_allclose(np.asarray(core.signal), r.signal, rtol=TOL, atol=0)
    rnorm = np.sqrt(np.where(ok, r.total, 0) * np.maximum(r.dof, 1))
    dG = TOL * kappa * g
    bound_total = 2 * rnorm * TOL * kappa * ynorm / np.maximum(r.dof, 1) + TOL * np.abs(r.total)
    bound_noise = 2 * vu * g * dG + 2 * cv * dG + TOL * np.abs(r.noise)
    err = {"total": np.abs(total - r.total)[ok] / bound_total[ok],
           "noise": np.abs(noise - r.noise)[ok] / bound_noise[ok]}
    # the BLA, entry (k, i) from output line j = excited[i] + k
    Kb = np.asarray(core.bla)
    Vb = np.asarray(core.bla_var)
    assert np.array_equal(np.isnan(Kb), np.isnan(r.bla)) and np.array_equal(np.isnan(Vb), np.isnan(r.bla_var))
    k, i = np.nonzero(np.isfinite(r.bla))
    jj = np.asarray(excited)[i] + k - Kh - 1
    err["bla"] = np.abs(Kb[k, i] - r.bla[k, i]) / dG[jj]
    s_min2 = np.where(g > 0, (g / np.maximum(ynorm, 1e-300)) ** 2, 0)   # 1 / sigma_min^2
    bound_var = TOL * kappa[jj] ** 2 * s_min2[jj] * r.total[jj] + r.bla_var[k, i] * bound_total[jj] / r.total[jj]
    err["bla_var"] = np.abs(Vb[k, i] - r.bla_var[k, i]) / bound_var
    for name, e in err.items():
        assert np.all(e <= 1.0), (name, float(np.max(e)))
    return {name: float(np.max(e)) for name, e in err.items()}


@pytest.mark.parametrize("system,P,seed,cubic", CASES)
def test_the_core_regression_agrees_with_the_numpy_reference(system, P, seed, cubic):
    m, ex, u, y = _realisations(system, 6, P, seed, cubic=cubic)
    d = lptv.distortion(u, y, w0=m.w0)
    U, Y, varU, varY, covYU = _spectra(d)
    args = (U, Y, varU, varY, covYU, [int(c) for c in d.excited], d.branches)
    core = _core.distortion_lines(*args)
    r = ref.distortion_lines(*args)
    _compare(core, r, *args)
    for name in ("bla", "bla_var", "total", "noise", "signal"):
        np.testing.assert_allclose(np.asarray(getattr(core, name)), getattr(r, name), rtol=DISTORTION_RELATIVE,
                                   atol=0, err_msg=name)
    # lptv.distortion reports the core's numbers unchanged
    np.testing.assert_array_equal(d.total, np.asarray(core.total))
    np.testing.assert_array_equal(d.bla_var, np.asarray(core.bla_var))
    # other branch counts: fewer (regressors of one excited line only) and more (lines without
    # a residual degree of freedom, NaN in both)
    for Kh in (0, 4, d.branches + 12):
        args = (U, Y, varU, varY, covYU, [int(c) for c in d.excited], Kh)
        _compare(_core.distortion_lines(*args), ref.distortion_lines(*args), *args)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_distortion_against_the_reference_from_numpy_fft(seed):
    """lptv.distortion (spectra by the core's FFT, regression by the core) against the reference
    regression on spectra from numpy.fft: the spectra differ by FFT rounding (the SIGNAL bound,
    relative to sum_l |X_l|), which the lines' regressions carry like their own rounding."""
    m, ex, u, y = _realisations("paper", 6, 4, seed, cubic=0.02 * (seed % 2))
    d = lptv.distortion(u, y, w0=m.w0)
    datas = [frequency_data(u[i], y[i]) for i in range(u.shape[0])]
    args = tuple(np.array([getattr(x, f) for x in datas]) for f in ("U", "Y", "varU", "varY", "covYU"))
    r = ref.distortion_lines(*args, d.excited, d.branches)

    class Result:   # the public result's fields under the core's names
        lines, signal, total, noise, dof, bla, bla_var = (d.lines, d.signal, d.total, d.noise, d.dof,
                                                          d.bla, d.bla_var)
        regressors = r.regressors
    _compare(Result, r, *args, d.excited, d.branches)
    assert np.all(d.kind[np.isin(d.lines, d.excited)] == "excited")


def test_rank_deficient_regressions_take_the_minimum_norm_solution():
    """Realisations with the same phases make X rank one: both routes return the minimum-norm
    least-squares solution (lstsq) and the pseudo-inverse of X^H X, at NumPy's cut-offs."""
    rng = np.random.default_rng(7)
    M, L = 5, 40
    U = np.zeros((M, L + 1), complex)
    ex = [10, 14, 18]
    U[:, ex] = np.exp(2j * np.pi * rng.random(3))           # the same in every realisation
    Y = U * 0.5 + 1e-3 * (rng.standard_normal((M, L + 1)) + 1j * rng.standard_normal((M, L + 1)))
    varU = np.full((M, L + 1), 1e-8)
    varY = np.full((M, L + 1), 1e-6)
    cov = np.zeros((M, L + 1), complex)
    core = _core.distortion_lines(U, Y, varU, varY, cov, ex, 4)
    r = ref.distortion_lines(U, Y, varU, varY, cov, ex, 4)
    np.testing.assert_array_equal(np.asarray(core.dof), r.dof)
    ok = np.isfinite(r.bla)
    scale = np.nanmax(np.abs(r.bla))
    assert np.max(np.abs(np.asarray(core.bla)[ok] - r.bla[ok])) < 1e3 * np.finfo(float).eps * scale
    np.testing.assert_allclose(np.asarray(core.total), r.total, rtol=1e-10)
    np.testing.assert_allclose(np.asarray(core.noise), r.noise, rtol=1e-10)
    np.testing.assert_allclose(np.asarray(core.bla_var)[ok], r.bla_var[ok], rtol=1e-8)


def test_bad_inputs_name_the_argument():
    M, L = 3, 8
    z = np.zeros((M, L + 1))
    good = dict(U=z + 0j, Y=z + 0j, varU=z, varY=z, covYU=z + 0j, excited=[2, 5], branches=1)
    _core.distortion_lines(**good)
    cases = [({"U": np.zeros((1, L + 1))}, "at least 2 realisations"),
             ({"Y": np.zeros((M, L))}, "Y must be 3 x 9"),
             ({"varY": -np.ones((M, L + 1))}, "varY must be >= 0"),
             ({"covYU": np.full((M, L + 1), np.nan)}, "covYU contains NaN"),
             ({"excited": []}, "no excited lines"),
             ({"excited": [5, 2]}, "ascending and distinct"),
             ({"excited": [0, 2]}, "line 0 is not a line 1..8"),
             ({"branches": 9}, "branches must be within 0..8")]
    for change, msg in cases:
        with pytest.raises(ValueError, match=msg):
            _core.distortion_lines(**{**good, **change})


@FUZZ
@given(M=st.integers(1, 6), L=st.integers(0, 12), data=st.data(),
       excited=st.lists(st.integers(-2, 14), max_size=4), branches=st.integers(-2, 14))
def test_random_inputs_give_a_result_or_value_error(M, L, data, excited, branches):
    """Random sizes, lines and values (now and then NaN, inf or a negative variance; magnitudes
    from subnormal to 1e100): the core either returns finite numbers wherever a line has a
    residual degree of freedom, with the reference's degrees of freedom, or raises ValueError
    (bad input) or NumericalError (a regression that overflows)."""
    def arr(dtype, nonneg=False):
        el = st.floats(0 if nonneg else -1e100, 1e100)
        x = data.draw(hnp.arrays(float, (M, L + 1), elements=el)).astype(dtype)
        if dtype is complex:
            x.imag = data.draw(hnp.arrays(float, (M, L + 1), elements=el))
        if x.size and data.draw(st.integers(0, 19)) == 0:   # now and then one bad value
            x.flat[data.draw(st.integers(0, x.size - 1))] = data.draw(st.sampled_from([np.nan, np.inf, -1.0]))
        return x
    args = (arr(complex), arr(complex), arr(float, True), arr(float, True), arr(complex), excited, branches)
    valid = sorted(set(e for e in excited if 1 <= e <= L))
    if valid and data.draw(st.integers(0, 3)) > 0:   # mostly lines and Kh that fit
        args = args[:5] + (valid, abs(branches) % (L + 1))
    try:
        d = _core.distortion_lines(*args)
    except ACCEPTED as e:
        event(type(e).__name__)
        return
    event("result")
    assert M >= 2 and L >= 1
    ok = np.asarray(d.dof) >= 1
    for name in ("total", "noise"):
        assert np.all(np.isfinite(np.asarray(getattr(d, name))[ok])), name
    assert np.all(np.isfinite(np.asarray(d.signal)))
    with np.errstate(all="ignore"):
        r = ref.distortion_lines(*args)
    np.testing.assert_array_equal(np.asarray(d.dof), r.dof)
