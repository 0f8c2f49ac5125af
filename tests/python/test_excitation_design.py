"""Excitation design: Schroeder phases, crest-factor minimisation and detection lines.

The core's objective and gradient are checked against direct sums of cosines (the reference,
no FFT) and against finite differences; its minimiser against SciPy's L-BFGS-B on the same
objective; the crest factors it reports against the signal rebuilt by the reference; the
detection lines by enumerating the nonlinear products and by simulating an LPTV system with a
static cubic after it.
"""
import itertools

import numpy as np
import pytest

import lptv
import lptv.examples as ex
from lptv import _core
from lptv.reference import excitation as rx


def crest(x):
    return float(np.abs(x).max() / np.sqrt(np.mean(x**2)))


def test_schroeder_phases_closed_form_and_general(seed, tol):
    F = 50
    k = np.arange(1, F + 1)
    phi = np.asarray(_core.schroeder_phases(np.ones(F)))
    # flat: -pi k (k - 1) / F, compared modulo 2 pi
    assert np.abs(np.angle(np.exp(1j * (phi + np.pi * k * (k - 1) / F)))).max() <= 1e3 * tol.EPS
    A = np.random.default_rng(seed).uniform(0.2, 2.0, 17)
    d = np.asarray(_core.schroeder_phases(A)) - rx.schroeder_phases(A)
    assert np.abs(np.angle(np.exp(1j * d))).max() <= 1e3 * tol.EPS


@pytest.mark.parametrize("N, oversample, lines", [
    (128, 1, np.arange(1, 51)),
    (100, 3, np.array([0, 3, 7, 10, 17, 50])),    # DC and the Nyquist line of N on a finer grid
    (64, 1, np.array([0, 5, 9, 32])),             # the grid's own Nyquist line
    (63, 3, np.arange(1, 21)),                    # an odd grid (the FFT's odd-length path)
])
@pytest.mark.parametrize("p", [4, 16, 256])
def test_objective_and_gradient_against_direct_sums(N, oversample, lines, p, seed):
    rng = np.random.default_rng(seed)
    A = rng.uniform(0.5, 2.0, lines.size)
    ph = rng.uniform(0, 2 * np.pi, lines.size)
    f, g = _core.lp_norm_log([int(l) for l in lines], A, ph, N, oversample, p)
    g = np.asarray(g)
    # The reference computes the norm as a plain mean of x^p in long double, the core on x / max|x|:
    # a few eps of log each; the gradient's sums of M terms, relative to its largest entry.
    f_ref, g_ref = rx.lp_norm_log(lines, A, ph, N, oversample, p)
    assert abs(f - f_ref) <= 1e-13 * max(1.0, abs(f_ref))
    assert np.abs(g - g_ref).max() <= 1e-11 * max(np.abs(g_ref).max(), 1e-3)
    real = (lines == 0) | (2 * lines == N)
    assert np.all(g[real] == 0)
    # central differences on one free phase; the objective's derivatives grow like p^n, so
    # h = 1e-3 / p keeps the truncation error h^2 f''' / 6 near 1e-7 |g|, the rounding
    # eps |f| / h below 1e-10
    i = int(np.flatnonzero(~real)[0])
    h = 1e-3 / p
    e = np.zeros(lines.size)
    e[i] = h
    fd = (_core.lp_norm_log([int(l) for l in lines], A, ph + e, N, oversample, p)[0]
          - _core.lp_norm_log([int(l) for l in lines], A, ph - e, N, oversample, p)[0]) / (2 * h)
    assert abs(fd - g[i]) <= 1e-6 * max(np.abs(g).max(), 1e-3)


def test_fifty_flat_lines_below_one_and_a_half():
    """The issue's figure: Schroeder ~1.7, the design <= 1.5, on the signal rebuilt independently."""
    lines = np.arange(1, 51)
    sch = lptv.schroeder_multisine(lines, 1024)
    ms, design = lptv.min_crest_multisine(lines, 1024, return_design=True)
    assert 1.65 < crest(rx.signal(lines, np.ones(50), sch.phases, 1024)) < 1.8
    assert design.oversample == 1  # 1024 points >= 16 per period of line 50
    x = rx.signal(lines, np.ones(50), ms.phases, 1024)
    assert abs(crest(x) - design.crest_factor) <= 1e-12
    assert abs(ms.crest_factor - design.crest_factor) <= 1e-12
    assert design.crest_factor <= 1.5
    assert design.initial_crest_factor == pytest.approx(sch.crest_factor, rel=1e-12)
    assert np.all(np.diff(design.best_per_p) <= 0)
    # the amplitude spectrum is untouched
    assert np.allclose(np.abs(ms.spectrum[lines]), 0.5, rtol=0, atol=1e-14)
    assert np.abs(np.delete(ms.spectrum, lines)).max() <= 1e-14


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_starts_reach_the_same_level(seed):
    lines = np.arange(1, 51)
    ms, d = lptv.min_crest_multisine(lines, 1024, start="random", seed=seed, return_design=True)
    assert d.initial_crest_factor > 2.0 and d.crest_factor <= 1.5


def test_core_against_scipy_minimiser():
    """The same objective minimised by SciPy's L-BFGS-B reaches the same crest factor (within 0.02)."""
    lines = np.arange(3, 63, 2)   # 30 odd lines
    A = np.linspace(1.0, 0.5, lines.size)
    phi0 = rx.schroeder_phases(A)
    ms, d = lptv.min_crest_multisine(lines, 512, amplitudes=A, return_design=True)
    _, c_ref = rx.minimize_crest_factor(lines, A, phi0, 512, oversample=d.oversample, max_p=256,
                                        iterations_per_p=60)
    x = rx.signal(lines, A, ms.phases, 512, d.oversample)
    assert abs(crest(x) - d.crest_factor) <= 1e-12
    assert d.crest_factor <= c_ref + 0.02


def test_oversampling_bounds_the_continuous_peak():
    lines = np.arange(1, 51)
    ms, d = lptv.min_crest_multisine(lines, 128, return_design=True)     # 2.6 points per top period
    assert d.oversample == 7                                             # 16 * 50 / 128 rounded up
    cont = crest(rx.signal(lines, np.ones(50), ms.phases, 128, 16))
    assert cont <= d.crest_factor * 1.02 and cont <= 1.5
    ms1, d1 = lptv.min_crest_multisine(lines, 128, oversample=1, return_design=True)
    assert d1.crest_factor == pytest.approx(ms1.crest_factor, rel=1e-12)
    # the samples' peak alone is lower than the continuous one it hides
    assert crest(rx.signal(lines, np.ones(50), ms1.phases, 128, 16)) > d1.crest_factor + 0.05


def test_real_lines_keep_their_phase():
    ms = lptv.min_crest_multisine([0, 3, 5, 8, 11, 16], 32, amplitudes=[1.0, 1, 1, 1, 1, 0.5])
    assert set(np.round(ms.phases[[0, 5]], 12)) <= {0.0, round(np.pi, 12)}
    assert ms.spectrum[0].imag == 0 and ms.spectrum[16].imag == 0


def test_realisations_share_the_amplitude_spectrum(seed):
    lines = np.arange(10, 250, 10)
    ms = lptv.multisine_realisations(lines, 1024, M=5, seed=seed)
    again = lptv.multisine_realisations(lines, 1024, M=5, seed=seed)
    assert all(np.array_equal(a.signal, b.signal) for a, b in zip(ms, again))
    for m in ms:
        assert np.allclose(np.abs(m.spectrum[lines]), 0.5, atol=1e-14)
    # phases differ between realisations (independent draws)
    assert min(np.abs(np.angle(np.exp(1j * (ms[i].phases - ms[j].phases)))).max()
               for i in range(5) for j in range(i)) > 0.5
    low = lptv.multisine_realisations(lines, 1024, M=3, seed=seed, low_crest=True)
    assert all(m.crest_factor < 1.7 for m in low)
    assert all(np.allclose(np.abs(m.spectrum[lines]), 0.5, atol=1e-14) for m in low)


@pytest.mark.parametrize("kind", ["odd", "odd-odd"])
@pytest.mark.parametrize("reach", [0, 2, 4])
def test_detection_lines_sort_the_distortion(kind, reach, seed):
    d = lptv.excitation_lines(1, 400, kind=kind, reach=reach, seed=seed)
    s = d.spacing
    assert s == 2 * reach + 1
    for arr in (d.excited, d.odd_detection, d.even_detection):
        assert np.all(arr % s == 0)
    groups = [set(d.excited), set(d.odd_detection), set(d.even_detection), set(d.sideband)]
    assert all(not (a & b) for a, b in itertools.combinations(groups, 2))
    # LPTV sidebands (0 < |k| <= K) of excited lines never reach a multiple of s
    for k in range(1, reach + 1):
        assert np.all((d.excited + k) % s != 0) and np.all((d.excited - k) % s != 0)
    # nonlinear products of degree 2 and 3 (sums of excited lines with signs) land on excited or
    # odd-detection lines (odd degree) and on even multiples (even degree)
    rng = np.random.default_rng(seed)
    exc = d.excited
    odd_or_exc = set(d.excited) | set(d.odd_detection)
    for _ in range(300):
        a, b, c = rng.choice(exc, 3)
        for sb, sc in itertools.product((1, -1), repeat=2):
            two = abs(a + sb * b)
            assert two % s == 0 and (two // s) % 2 == 0
            three = abs(a + sb * b + sc * c)
            assert three % s == 0 and (three // s) % 2 == 1
            if three <= 400:
                assert three in odd_or_exc
    if kind == "odd":   # one left out in each group of 3 odd multiples
        n_odd = d.excited.size + d.odd_detection.size
        assert d.odd_detection.size == n_odd // 3


def test_detection_lines_see_a_cubic_and_not_the_time_variation():
    """An LPTV system (third-order example, its sidebands below -48 dB beyond K = 2) followed by
    y + c y^3: on the odd detection lines the pure LPTV output is 90 dB below the excited lines,
    the cubic's distortion 30 dB below; the LPTV sidebands carry the time variation."""
    m = ex.third_order_model()
    N = ex.THIRD_ORDER_N
    d = lptv.excitation_lines(1, 140, kind="odd-odd", reach=2)
    ms = lptv.min_crest_multisine(d.excited, N)
    U = lptv.spectrum(ms.signal / np.std(ms.signal))
    y = lptv.time_signal(lptv.simulate(m, U), N)

    def power(Y, lines):
        return float(np.mean(np.abs(Y[lines]) ** 2))

    lin = lptv.spectrum(y)
    cub = lptv.spectrum(y + 0.05 * y**3)
    pe = power(lin, d.excited)
    assert power(lin, d.odd_detection) < 1e-9 * pe
    assert power(lin, d.sideband) > 1e-3 * pe
    assert power(cub, d.odd_detection) > 1e-5 * pe
    assert power(cub, d.odd_detection) > 1e4 * power(lin, d.odd_detection)
    assert d.role(int(d.odd_detection[0])) == "odd nonlinear"
    assert d.role(int(d.excited[0]) + 1) == "LPTV sideband"


def test_docstring_examples_run():
    import doctest
    import sys

    result = doctest.testmod(sys.modules["lptv.excitation.multisine"], optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 8 and result.failed == 0
