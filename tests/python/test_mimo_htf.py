"""lptv.mimo_htf_estimate (METHOD.md eq. 19.8): the HTF matrix from nu experiments against lptv.htf
on noise-free data, and its first-order variance against a Monte Carlo of output noise."""
import numpy as np
import pytest

import lptv

from test_mimo_model import two_mass

LINES = np.array([20, 40, 60])
N, P, K = 256, 4, 2


def experiments(design, E, seed=5):
    m = two_mass()
    d = lptv.mimo_multisines(LINES, N, 2, design=design, n_experiments=E, seed=seed)
    Y = lptv.simulate(m, d.spectra.transpose(1, 2, 0))                     # (lines, ny, E)
    y = np.stack([np.stack([lptv.time_signal(Y[:, p, e], N) for p in range(2)], axis=1) for e in range(E)])
    return m, d, np.repeat(d.signals[:, None], P, axis=1), np.repeat(y[:, None], P, axis=1)


@pytest.mark.parametrize("design, E", [("hadamard", 2), ("random", 3)])
def test_noise_free_against_htf(design, E):
    m, d, u, y = experiments(design, E)
    est = lptv.mimo_htf_estimate(u, y, LINES, K)
    G = lptv.htf(m, 90, LINES)
    assert est.G.shape == (3, 5, 2, 2)
    for i, l in enumerate(LINES):
        ref = G[90 + l + est.branches, :, i, :]
        np.testing.assert_allclose(est.G[i], ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    assert np.all(est.variance == 0) or np.abs(est.variance).max() < 1e-25
    if design == "hadamard":
        np.testing.assert_allclose(est.condition, 1.0, rtol=1e-12)


def test_variance_against_monte_carlo():
    """Output noise of std 1e-3 per sample: the reported variance (from P = 4 periods) averaged over
    the runs against the runs' own spread of G; 400 runs give each entry's Monte Carlo variance to
    about 7 % (800 real degrees of freedom), so each ratio must lie within 0.75-1.33 and their
    median within 0.9-1.1."""
    m, d, u, y0 = experiments("hadamard", 2)
    rng = np.random.default_rng(0)
    Gs, Vs = [], []
    for _ in range(400):
        est = lptv.mimo_htf_estimate(u, y0 + 1e-3 * rng.standard_normal(y0.shape), LINES, K)
        Gs.append(est.G)
        Vs.append(est.variance)
    Gs, Vs = np.array(Gs), np.array(Vs)
    ratio = np.mean(Vs, axis=0) / np.var(Gs, axis=0)
    assert 0.75 < ratio.min() and ratio.max() < 1.33, (ratio.min(), ratio.max())
    assert 0.9 < np.median(ratio) < 1.1
    # the orthogonal design: sigma^2 / (E |U|^2) per entry, the output noise of a line being sigma^2 / (N P)
    expect = (1e-3 ** 2 / (N * P)) / (2 * 0.5 ** 2)
    np.testing.assert_allclose(np.median(np.mean(Vs, axis=0)), expect, rtol=0.05)


@pytest.mark.parametrize("kwargs, match", [
    (dict(lines=[20, 23]), "apart"),
    (dict(K=-1), "K"),
])
def test_bad_arguments(kwargs, match):
    m, d, u, y = experiments("hadamard", 2)
    kw = dict(u=u, y=y, lines=LINES, K=K)
    kw.update(kwargs)
    with pytest.raises(ValueError, match=match):
        lptv.mimo_htf_estimate(**kw)
    with pytest.raises(ValueError, match="E >= nu"):
        lptv.mimo_htf_estimate(u[:1], y[:1], LINES, K)
    with pytest.raises(ValueError, match="y must have"):
        lptv.mimo_htf_estimate(u, y[:, :2], LINES, K)
