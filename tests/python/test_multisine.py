"""Multisines and the spectrum <-> time-signal conversions against numpy.fft and direct sums."""
import numpy as np
import pytest

import lptv
import lptv.examples as ex
from lptv import reference as ref

CASES = [  # (lines, N): even and odd N, with DC and with the Nyquist line
    (np.arange(10, 241, 10), 2048),
    (np.array([1, 2, 3, 5, 8, 13]), 63),
    (np.array([0, 4, 7, 32]), 64),
    (np.arange(1, 500, 3), 4096),
]


def cosine_sum(lines, amplitudes, phases, N):
    """sum_l A_l cos(2 pi l t / N + phi_l), the phase reduced exactly as (l t) mod N."""
    t = np.arange(N)
    x = np.zeros(N)
    for l, A, phi in zip(lines, amplitudes, phases):
        x += A * np.cos(2 * np.pi * ((int(l) * t) % N) / N + phi)
    return x


@pytest.mark.parametrize("lines, N", CASES)
def test_multisine_spectrum_and_signal(lines, N, seed, tol):
    rng = np.random.default_rng(seed)
    amplitudes = rng.uniform(0.5, 2.0, lines.size)
    ms = lptv.multisine(lines, N, amplitudes=amplitudes, seed=seed)
    assert ms.spectrum.shape == (N // 2 + 1,) and ms.signal.shape == (N,)
    assert np.array_equal(ms.lines, lines) and np.array_equal(ms.amplitudes, amplitudes)
    X = ms.spectrum
    # Cosine amplitude A: |X_l| = A/2 with phase phi on a line with a conjugate partner; the
    # self-conjugate lines (DC, Nyquist) hold the whole real value A cos(phi).
    self_conj = (lines == 0) | (2 * lines == N)
    inner = lines[~self_conj]
    assert np.all(np.abs(np.abs(X[inner]) - amplitudes[~self_conj] / 2)
                  <= tol.ROUNDING * amplitudes[~self_conj])
    assert np.all(np.abs(np.angle(X[inner] * np.exp(-1j * ms.phases[~self_conj]))) <= tol.ROUNDING)
    assert np.all(X[lines[self_conj]].imag == 0)
    assert np.all(np.abs(X[lines[self_conj]].real - amplitudes[self_conj] * np.cos(ms.phases[self_conj]))
                  <= tol.ROUNDING * amplitudes[self_conj])
    assert np.all(X[np.setdiff1d(np.arange(N // 2 + 1), lines)] == 0)
    # One period equals the sum of cosines.
    scale = amplitudes.sum()
    assert np.abs(ms.signal - cosine_sum(lines, amplitudes, ms.phases, N)).max() <= tol.SIGNAL * scale
    # The reference builds the spectrum the other way round (time samples, then fft).
    X_ref = ref.multisine_spectrum(lines, amplitudes, ms.phases, N)
    assert np.abs(X - X_ref).max() <= tol.SIGNAL * scale


def test_phases_uniform_in_range(tol):
    ms = lptv.multisine(np.arange(1, 2001), 4096, seed=3)
    assert ms.phases.min() >= 0 and ms.phases.max() < 2 * np.pi
    # 2000 uniform phases: the mean is pi to within 5 standard errors (2 pi / sqrt(12 * 2000)).
    assert abs(ms.phases.mean() - np.pi) <= 5 * 2 * np.pi / np.sqrt(12 * 2000)


@pytest.mark.parametrize("lines, N", CASES)
def test_crest_factor(lines, N, seed, tol):
    ms = lptv.multisine(lines, N, seed=seed)
    x = ms.signal
    expected = np.max(np.abs(x)) / np.sqrt(np.mean(x ** 2))
    assert ms.crest_factor == pytest.approx(expected, rel=tol.ROUNDING, abs=0)
    assert ref.crest_factor(x) == pytest.approx(expected, rel=tol.ROUNDING, abs=0)
    # A random-phase multisine of many lines is neither a single cosine (sqrt 2) nor a pulse.
    if lines.size > 10:
        assert np.sqrt(2) < ms.crest_factor < np.sqrt(2 * lines.size)


def test_seeding_is_reproducible():
    lines = np.arange(1, 50)
    a = lptv.multisine(lines, 256, seed=42)
    b = lptv.multisine(lines, 256, seed=42)
    assert np.array_equal(a.phases, b.phases) and np.array_equal(a.signal, b.signal)
    c = lptv.multisine(lines, 256, seed=43)
    assert not np.allclose(a.phases, c.phases)
    # A Generator is used as given (its state advances), an int seeds a fresh one.
    g1, g2 = np.random.default_rng(42), np.random.default_rng(42)
    assert np.array_equal(lptv.multisine(lines, 256, seed=g1).phases, a.phases)
    assert np.array_equal(lptv.multisine(lines, 256, seed=g2).phases, a.phases)
    assert np.array_equal(lptv.multisine(lines, 256, seed=g1).phases,
                          lptv.multisine(lines, 256, seed=g2).phases)
    # No seed: fresh entropy each call.
    assert not np.array_equal(lptv.multisine(lines, 256).phases,
                              lptv.multisine(lines, 256).phases)


def test_scalar_amplitude_and_periods():
    ms = lptv.multisine([3, 5], 32, amplitudes=2.5, seed=0)
    assert np.array_equal(ms.amplitudes, [2.5, 2.5])
    P = ms.periods(3)
    assert P.shape == (3, 32) and np.array_equal(P[2], ms.signal)


@pytest.mark.parametrize("N", [2, 3, 7, 64, 1023, 4096])
def test_spectrum_matches_numpy(N, seed, tol):
    x = np.random.default_rng(seed).normal(size=N)
    X = lptv.spectrum(x)
    X_ref = np.fft.fft(x)[: N // 2 + 1] / N
    assert X.shape == X_ref.shape
    assert np.abs(X - X_ref).max() <= tol.SIGNAL * np.abs(x).sum() / N
    assert np.array_equal(ref.spectrum(x), X_ref)


@pytest.mark.parametrize("N", [2, 3, 7, 64, 1023, 4096])
def test_time_signal_matches_numpy_and_round_trips(N, seed, tol):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=N)
    X = np.fft.fft(x)[: N // 2 + 1] / N
    x_back = lptv.time_signal(X, N)
    scale = np.abs(X).sum()
    assert np.abs(x_back - x).max() <= tol.SIGNAL * scale
    assert np.abs(ref.time_signal(X, N) - x).max() <= tol.SIGNAL * scale
    assert np.abs(lptv.time_signal(lptv.spectrum(x), N) - x).max() <= tol.SIGNAL * scale
    # Fewer lines than N//2 + 1: the missing ones are zero.
    L = N // 4
    Xs = X[: L + 1]
    assert np.abs(lptv.time_signal(Xs, N) - ref.time_signal(Xs, N)).max() <= tol.SIGNAL * scale
    assert np.abs(ref.time_signal(Xs, N) - np.fft.irfft(Xs, n=N) * N).max() <= tol.SIGNAL * scale


def test_paper_multisine_has_unit_rms(seed, tol):
    ms = ex.paper_multisine(seed)
    assert np.sqrt(np.mean(ms.signal ** 2)) == pytest.approx(1.0, rel=tol.SIGNAL, abs=0)
    assert np.array_equal(ms.lines, ex.PAPER_EXCITED)
