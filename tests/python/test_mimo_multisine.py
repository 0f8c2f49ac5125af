"""lptv.mimo_multisines (METHOD.md section 19, the experiment design): the orthogonal pattern,
the input matrices UU_l it gives, their noise gain against random phases, and the HTF matrix
G_k(w_l) = YY_{l+k} UU_l^+ (eq. 19.8) from simulated experiments against lptv.htf."""
import numpy as np
import pytest

import lptv

from test_mimo_model import two_mass

LINES = np.arange(5, 100, 10)


@pytest.mark.parametrize("nu, E, real", [(1, 1, True), (2, 2, True), (3, 3, False), (3, 4, True), (2, 5, False)])
def test_orthogonal_pattern(nu, E, real):
    d = lptv.mimo_multisines(LINES, 256, nu, n_experiments=E, amplitudes=0.8, seed=3)
    assert d.signals.shape == (E, 256, nu) and d.spectra.shape == (E, 129, nu)
    assert d.n_inputs == nu and d.n_experiments == E
    T = d.pattern
    assert T.shape == (nu, E) and np.isrealobj(T.real) and (np.all(T.imag == 0) == real)
    np.testing.assert_allclose(T @ T.conj().T, E * np.eye(nu), atol=1e-12)
    for l in LINES:
        UU = d.input_matrix(l)
        np.testing.assert_allclose(UU @ UU.conj().T, E * 0.4 ** 2 * np.eye(nu), atol=1e-12)
    np.testing.assert_allclose(d.noise_gain(), 1 / (E * 0.4 ** 2), rtol=1e-10)
    # the signals are the spectra's (numpy.fft), and nothing off the excited lines
    S = np.fft.rfft(d.signals, axis=1) / 256
    np.testing.assert_allclose(S, d.spectra, atol=1e-13)
    off = np.setdiff1d(np.arange(129), LINES)
    assert np.abs(d.spectra[:, off]).max() < 1e-13


def test_random_design_is_never_better():
    """Hadamard's inequality: diag((UU UU^H)^-1) >= 1 / diag(UU UU^H) = the orthogonal design's gain."""
    h = lptv.mimo_multisines(LINES, 256, 2, seed=0)
    gains = np.concatenate([lptv.mimo_multisines(LINES, 256, 2, design="random", seed=s).noise_gain()
                            for s in range(20)])
    assert np.all(gains >= h.noise_gain()[0, 0] * (1 - 1e-12))
    # nu = E = 2: the gain is 1 / sin^2(Delta / 2) times the orthogonal one, median 2 (METHOD.md)
    assert 1.5 < np.median(gains / h.noise_gain()[0, 0]) < 2.7


def test_amplitudes_per_input_and_sign_pattern():
    amp = np.vstack([np.full(LINES.size, 1.0), np.linspace(0.5, 2, LINES.size)])
    d = lptv.mimo_multisines(LINES, 256, 2, amplitudes=amp, seed=1)
    np.testing.assert_allclose(np.abs(d.spectra[0][LINES]), amp.T / 2, rtol=1e-12)
    # a sign pattern: experiment 2's second input is the first experiment's negated
    np.testing.assert_allclose(d.signals[1, :, 1], -d.signals[0, :, 1], atol=1e-13)
    np.testing.assert_allclose(d.signals[1, :, 0], d.signals[0, :, 0], atol=1e-13)


@pytest.mark.parametrize("design, E", [("hadamard", 2), ("random", 3)])
def test_htf_matrix_from_experiments(design, E):
    """Excited lines 20 apart: output line l + k (|k| <= 2) holds input line l's contribution only
    (the others', from branches |k| >= 18, are below 1e-15 of it), so YY_{l+k} UU_l^+ is G_k(w_l)."""
    m = two_mass()
    lines = np.array([20, 40, 60])
    d = lptv.mimo_multisines(lines, 256, 2, design=design, n_experiments=E, seed=5)
    Y = lptv.simulate(m, d.spectra.transpose(1, 2, 0))         # (lines, ny, E)
    L = 90
    G = lptv.htf(m, L, lines)                                  # (grid, ny, len(lines), nu)
    for j, l in enumerate(lines):
        UUp = np.linalg.pinv(d.input_matrix(l))
        for k in range(-2, 3):
            Gk = Y[l + k] @ UUp
            np.testing.assert_allclose(Gk, G[L + l + k, :, j, :], rtol=0, atol=1e-10 * np.abs(G[L + l, :, j, :]).max())


@pytest.mark.parametrize("kwargs, match", [
    (dict(n_inputs=3, lines=[0, 5]), "DC and the Nyquist line"),
    (dict(n_inputs=2, n_experiments=1), "n_experiments"),
    (dict(n_inputs=2, design="zigzag"), "design"),
    (dict(n_inputs=2, amplitudes=np.ones((3, LINES.size))), "amplitudes"),
])
def test_bad_arguments(kwargs, match):
    kw = dict(lines=LINES, n_samples=256, seed=0)
    kw.update(kwargs)
    with pytest.raises(ValueError, match=match):
        lptv.mimo_multisines(**kw)
