"""A fit that did not converge, or whose output does not respond to the inputs, is never called
consistent (its verdict says NOT DETERMINED and why); the same fits converged and responding are."""
import warnings

import numpy as np
import pytest

import lptv


def _one_input_two_outputs(dead: bool, seed: int = 1):
    """y_1 and y_2 of a 1-input 2-output LTI system (the docs' small system), by NumPy's FFT of its
    exact frequency response; with ``dead`` the second output is noise alone (a dead sensor)."""
    N, P, w0 = 128, 6, 0.1
    lines = np.arange(1, 40)
    rng = np.random.default_rng(seed)
    U = np.zeros(N // 2 + 1, complex)
    U[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    s = 1j * w0 * np.arange(N // 2 + 1)
    # (s I + A0) Y = B U with A0 = [[2, 0.5], [0, 3]], B = [1, 1]
    y2 = U / (s + 3.0)
    y1 = (U - 0.5 * y2) / (s + 2.0)
    u1 = np.fft.irfft(U, N) * N / 2
    Y = np.stack([np.fft.irfft(y1, N), np.fft.irfft(y2, N)], axis=-1) * N / 2
    if dead:
        Y[:, 1] = 0.0
    u = u1[None, :, None] + 1e-3 * rng.standard_normal((P, N, 1))
    y = Y[None] + 1e-3 * rng.standard_normal((P, N, 2))
    return u, y, w0


def test_an_output_that_does_not_respond_is_not_determined():
    u, y, w0 = _one_input_two_outputs(dead=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        live = lptv.identify(u, y, na=1, nb=0, w0=w0)
    assert live.model_ok and live.undetermined is None
    assert live.verdict.startswith("the model is consistent")
    u, y, w0 = _one_input_two_outputs(dead=True)
    with pytest.warns(UserWarning, match="output 1 does not respond"):
        dead = lptv.identify(u, y, na=1, nb=0, w0=w0)
    assert "output 1 does not respond" in dead.undetermined
    assert not dead.verdict.startswith("the model is consistent") and "output 1 does not respond" in dead.verdict
    assert "output 0" not in dead.undetermined


def test_pure_noise_outputs_are_said_at_most_at_the_tests_size():
    """Outputs of noise alone are found silent unless one of their rows passes the 1 % Bonferroni
    point, which happens for at most about 1 % of them (80 here); a responding output never is."""
    from lptv.estimation.mimo_identify import silent_outputs

    said, live = 0, 0
    rows = [np.arange(2, 40)]
    for seed in range(40):
        rng = np.random.default_rng(100 + seed)
        u, y, w0 = _one_input_two_outputs(dead=False, seed=seed)
        noise = 1e-3 * rng.standard_normal(y.shape)
        said += len(silent_outputs([lptv.MimoFrequencyData.from_periods(u, noise, w0=w0)], rows))
        live += len(silent_outputs([lptv.MimoFrequencyData.from_periods(u, y, w0=w0)], rows))
    assert said >= 78 and live == 0


def test_a_fit_that_did_not_converge_is_not_consistent():
    u, y, w0 = _one_input_two_outputs(dead=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stopped = lptv.identify(u, y, na=1, nb=0, w0=w0, method="sml", max_iter=1)
        full = lptv.identify(u, y, na=1, nb=0, w0=w0, method="sml")
    assert full.converged and full.verdict.startswith("the model is consistent")
    assert not stopped.converged
    assert stopped.verdict.startswith("NOT DETERMINED") and "did not converge in 1 iterations" in stopped.verdict
    # one channel alike
    ms = lptv.multisine(range(1, 30), 64, seed=3)
    m = lptv.Model([2.0, 3.0, 1.0], [1.0], w0=0.3)
    y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), ms.n_samples)
    rng = np.random.default_rng(4)
    uu = ms.periods(6) + 1e-3 * rng.standard_normal((6, 64))
    yy = np.tile(y0, (6, 1)) + 1e-3 * rng.standard_normal((6, 64))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = lptv.identify(uu, yy, na=2, nb=0, w0=0.3, method="sml", max_iter=1)
        done = lptv.identify(uu, yy, na=2, nb=0, w0=0.3, method="sml")
    assert done.converged and done.verdict.startswith("the model is consistent")
    assert not one.converged and one.verdict.startswith("NOT DETERMINED") and "did not converge" in one.verdict
