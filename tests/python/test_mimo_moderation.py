"""Moderated noise for several channels (METHOD.md section 19, "Moderated noise for several
channels"): the core's lptv::moderated_covariances against its NumPy twin
lptv.reference.moderation.moderated_covariances, the two-channel case against the single-channel
moderation, the moderated matrices against the true covariance of correlated coloured noise, and
identify's noise routes for several channels (the route chosen and said, a 1 x 1 fit equal to the
single-input single-output fit on the same route)."""
import warnings

import numpy as np
import pytest

import lptv
from lptv import _core
from lptv.spectra.mimo_frequency_data import MimoFrequencyData
from lptv.reference import moderation as ref


def _noise(L, P, c, seed, shape="coloured", spikes=(), mix=0.5):
    """MimoFrequencyData of P periods of pure noise on c channels (2 outputs first): the lines'
    complex Gaussian noise with a per-channel spectrum (white, coloured with a knee, or a rough
    log-uniform spread) and correlated between channels by a fixed mixing matrix; ``spikes``:
    lines whose output 0 variance is 100 times its neighbours'. Returns the data and the true
    covariance of the means (L+1, c, c)."""
    rng = np.random.default_rng(seed)
    l = np.arange(L + 1)
    if shape == "white":
        s = np.ones((L + 1, c))
    elif shape == "coloured":
        s = np.stack([(1 + q) / (1 + (l / (15.0 + 10 * q)) ** 2) + 0.02 for q in range(c)], 1)
    else:
        s = 10 ** rng.uniform(-2, 0, (L + 1, c))
    s = s.copy()
    for k in spikes:
        s[k, 0] *= 100
    M = np.eye(c) + mix * np.triu(rng.standard_normal((c, c)), 1)
    A = np.sqrt(s)[:, :, None] * M[None]                  # per line: the channels' mixing
    X = (rng.standard_normal((P, L + 1, c)) + 1j * rng.standard_normal((P, L + 1, c))) / np.sqrt(2)
    Z = np.einsum("lij,plj->pli", A, X)
    Z[:, 0], Z[:, -1] = Z[:, 0].real, Z[:, -1].real
    N = 2 * L
    sig = np.fft.irfft(Z * N, N, axis=1)
    true = np.einsum("lij,lkj->lik", A, A.conj()) / P
    return MimoFrequencyData.from_periods(sig[:, :, 2:], sig[:, :, :2], w0=1.0), true


CASES = [(200, 4, 3, "white", ()), (200, 8, 3, "coloured", (60, 140)), (120, 4, 4, "coloured", (30,)),
         (300, 2, 3, "coloured", ()), (200, 6, 5, "rough", ()), (40, 4, 3, "white", ()), (31, 4, 3, "white", ())]


@pytest.mark.parametrize("case", range(len(CASES)))
@pytest.mark.parametrize("seed", [0, 1])
def test_core_matches_reference(case, seed):
    """The same outliers, d0 within 1e-8 relative (the core's polygammas and F quantile against
    SciPy's, as for one channel), matrices and dof within 1e-10."""
    L, P, c, shape, spikes = CASES[case]
    d, _ = _noise(L, P, c, seed, shape, spikes)
    C = np.ascontiguousarray(d.C).reshape(-1, c)
    core = _core.moderated_covariances(C, 2, P, 10)
    r = ref.moderated_covariances(d.C, P, 2, 10)
    assert np.array_equal(np.asarray(core.outliers, int).reshape(-1), r.outliers)
    assert core.prior_dof == pytest.approx(r.prior_dof, rel=1e-8, abs=0)
    assert core.moderated == (r.prior_dof > 0)
    Cc = np.asarray(core.covariance).reshape(-1, c, c)
    scale = np.sqrt(np.einsum("lii,ljj->lij", r.C.real, r.C.real))
    assert np.all(np.abs(Cc - r.C) <= 1e-10 * scale + 1e-300)
    assert np.allclose(core.dof, r.dof, rtol=1e-10)
    assert np.allclose(core.own_weight, r.own_weight, rtol=1e-12)
    assert np.array_equal(np.asarray(core.neighbour, bool), r.neighbour)
    if L < 3 * 10 + 2 or P < 2:
        assert r.prior_dof == 0 and np.array_equal(Cc, d.C)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_two_channels_are_the_single_channel_moderation(seed):
    """c = 2 with C = [[varY, covYU], [conj covYU, varU]] is lptv::moderated_noise, both in the
    core and in the reference."""
    rng = np.random.default_rng(seed)
    P, N = 4 + 2 * seed, 600
    u = rng.standard_normal((P, N))
    e = rng.standard_normal((P, N + 8))
    y = 0.4 * u + np.array([np.convolve(x, [1.0, 0.7, 0.2], "same")[:N] for x in e])
    d = lptv.FrequencyData.from_periods(u + 0.1 * rng.standard_normal((P, N)), y, w0=1.0)
    one = lptv.moderated_noise(d)
    C = np.zeros((d.max_line + 1, 2, 2), complex)
    C[:, 0, 0], C[:, 1, 1], C[:, 0, 1] = d.varY, d.varU, d.covYU
    C[:, 1, 0] = np.conj(d.covYU)
    core = _core.moderated_covariances(C.reshape(-1, 2), 1, P, 10)
    Cc = np.asarray(core.covariance).reshape(-1, 2, 2)
    for got in (Cc, ref.moderated_covariances(C, P, 1, 10).C):
        assert np.allclose(got[:, 0, 0], one.data.varY, rtol=1e-12, atol=0)
        assert np.allclose(got[:, 1, 1], one.data.varU, rtol=1e-12, atol=0)
        assert np.all(np.abs(got[:, 0, 1] - one.data.covYU) <= 1e-12 * np.sqrt(one.data.varU * one.data.varY))
    assert core.prior_dof == one.prior_dof
    assert np.array_equal(core.dof, one.dof)
    assert np.array_equal(np.asarray(core.outliers).reshape(-1), one.outliers)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_moderated_matrices_near_the_true_covariance(seed):
    """Correlated coloured noise on 3 channels at P = 4: each line's own sample matrix is off by
    its Wishart spread (variances 0.58 rms relative); the moderated variances are within 0.2 rms
    (0.14-0.16 measured on six seeds), and the verdict's matrices (the prior's part at the
    neighbours' mean) have the mean of the lines' own variances to 1.5 % per channel (measured
    0.1-0.5 %: the shape factor follows the knee; the mean of the own ones is itself off the truth
    by its sampling error, 2.9 %, which both share), and the off-diagonal entries' error,
    relative to sqrt(C_pp C_qq), at most half the own one's."""
    L, P = 400, 4
    d, true = _noise(L, P, 3, seed, "coloured")
    mo = lptv.moderated_noise(d)
    assert isinstance(mo, lptv.spectra.mimo_moderation.MimoModeratedNoise)
    assert mo.prior_dof > 2 * (P - 1)
    inner = np.arange(1, L)
    tv = np.real(np.diagonal(true, axis1=1, axis2=2))[inner]
    own = np.real(np.diagonal(d.C, axis1=1, axis2=2))[inner] / tv - 1
    mod = np.real(np.diagonal(mo.data.C, axis1=1, axis2=2))[inner] / tv - 1
    assert np.sqrt(np.mean(own ** 2)) > 0.45
    assert np.sqrt(np.mean(mod ** 2)) < 0.2
    ub = np.real(np.diagonal(mo.unbiased_data().C, axis1=1, axis2=2))[inner] / tv - 1
    assert np.all(np.abs(ub.mean(axis=0) - own.mean(axis=0)) < 0.015), ub.mean(axis=0) - own.mean(axis=0)
    scale = np.sqrt(tv[:, :, None] * tv[:, None, :])
    off = ~np.eye(3, dtype=bool)
    e_own = np.abs(d.C[inner] - true[inner])[:, off] / scale[:, off]
    e_mod = np.abs(mo.data.C[inner] - true[inner])[:, off] / scale[:, off]
    assert np.sqrt(np.mean(e_mod ** 2)) < 0.5 * np.sqrt(np.mean(e_own ** 2))
    # every moderated matrix is a covariance matrix (Hermitian, positive semidefinite)
    Cm = mo.data.C
    assert np.allclose(Cm, np.conj(np.swapaxes(Cm, 1, 2)), rtol=0, atol=1e-15 * np.abs(Cm).max())
    assert np.linalg.eigvalsh(Cm[inner]).min() > 0
    # the verdict's matrices: the prior's part at the neighbours' mean (d0 / (d0 - 2) of data's)
    ub = mo.unbiased_data().C
    assert np.all(np.real(np.diagonal(ub, axis1=1, axis2=2))[inner] >= np.real(np.diagonal(Cm, axis1=1, axis2=2))[inner])


def test_spike_keeps_its_own_and_rough_noise_is_not_smooth():
    d, _ = _noise(300, 8, 3, 5, "coloured", spikes=(100,))
    mo = lptv.moderated_noise(d)
    assert 100 in mo.outliers
    assert np.array_equal(mo.data.C[100], d.C[100])
    ok, why = lptv.spectra.moderation.smooth_noise(mo)
    assert ok, why
    rough, _ = _noise(300, 8, 3, 5, "rough")
    ok, why = lptv.spectra.moderation.smooth_noise(lptv.moderated_noise(rough))
    assert not ok and "not smooth" in why


def _mimo_record(seed, P, N=256, level=0.02, colour=True):
    """One input, two outputs: a periodic coupling of two first-order outputs, the steady state by
    lptv's FDS (the fit is checked against solve_ivp records in test_mimo_fit.py), output noise
    white or coloured by a first-order filter, 1 % white noise on the input."""
    a = np.zeros((2, 2, 2, 3), complex)
    a[1, :, :, 1] = np.eye(2)
    a[0, :, :, 1] = [[1.0, 0.3], [-0.2, 2.0]]
    a[0, 0, 1, 2] = a[0, 0, 1, 0] = 0.1
    b = np.zeros((1, 2, 1, 1), complex)
    b[0, :, 0, 0] = [1.0, 0.5]
    m = lptv.MimoModel(a, b, w0=2 * np.pi / N)
    rng = np.random.default_rng(seed)
    ms = lptv.multisine(range(1, 60), N, seed=seed)
    Y = np.asarray(lptv.simulate(m, ms.spectrum[:, None], lines_out=N // 2)).reshape(N // 2 + 1, 2)
    y1 = np.fft.irfft(Y * N, N, axis=0)
    e = level * y1.std(axis=0) * rng.standard_normal((P, N + 50, 2))
    if colour:
        from scipy.signal import lfilter

        e = lfilter([1.0], [1.0, -0.7], e, axis=1)
    u = ms.periods(P)[:, :, None] + 0.01 * ms.signal.std() * rng.standard_normal((P, N, 1))
    return m, u, y1[None] + e[:, 50:]


def test_identify_takes_the_moderated_route_on_smooth_noise_and_says_why():
    m, u, y = _mimo_record(0, 8)
    kw = dict(na=1, nb=0, ka=[1, 0], kb=0, w0=m.w0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = lptv.identify(u, y, **kw)
    assert res.noise == "moderated" and res.noise_choice.startswith("moderated: the noise spectrum is smooth")
    assert len(res.moderation) == 1 and res.moderation[0].prior_dof > 14
    # the moderated periods: the covariance's factor (Pe - 1) / (Pe - 3) is near 1
    assert 1.0 < res.covariance_factor < 1.1
    assert res.model_ok
    # the true coefficients within 4.5 std (18 free parameters)
    truth = np.r_[[x for x in (1.0, 0.3, -0.2, 2.0)]]
    est = res.model.a[0, :, :, res.model.a.shape[-1] // 2].real.ravel()
    std = np.sqrt(np.diag(res.covariance))
    names = list(res.parameter_names)
    idx = [names.index(f"a0[{p},{q}].re0") for p in range(2) for q in range(2)]
    assert np.all(np.abs(est - truth) <= 4.5 * std[idx])
    sample = lptv.identify(u, y, noise="sample", **kw)
    assert sample.noise == "sample" and sample.noise_choice == "asked for"
    assert sample.covariance_factor == pytest.approx(7 / 5)
    # P = 3: too few periods for the automatic moderation
    m3, u3, y3 = _mimo_record(1, 3, colour=False)
    with pytest.warns(UserWarning, match="small-sample factor"):
        r3 = lptv.identify(u3, y3, **kw)
    assert r3.noise == "sample" and "3 periods" in r3.noise_choice
    asked = lptv.identify(u3, y3, noise="moderated", **kw)
    assert asked.noise == "moderated" and asked.noise_choice == "asked for"


def test_noise_argument_is_checked():
    m, u, y = _mimo_record(0, 4)
    with pytest.raises(ValueError, match="noise"):
        lptv.identify(u, y, na=1, nb=0, w0=m.w0, noise="smooth")
    with pytest.raises(ValueError, match="half_width"):
        lptv.moderated_noise(MimoFrequencyData.from_periods(u, y, w0=m.w0), half_width=0)


@pytest.mark.parametrize("seed", [0, 1])
def test_one_by_one_equals_siso_on_the_moderated_route(seed):
    """A 1 x 1 fit moderates as the single-input single-output fit does: the same estimate and,
    for SML, the same covariance (the same moderated variances, the same periods worth)."""
    m = lptv.Model([[0.5, 2.0, 0.5], [0.0, 1.0, 0.0]], [[0.0, 1.0, 0.0]], w0=2 * np.pi / 256)
    ms = lptv.multisine(range(2, 60), 256, seed=seed)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    rng = np.random.default_rng(seed)
    P = 6
    u = ms.periods(P) + 0.02 * rng.standard_normal((P, 256))
    y = np.tile(y1, (P, 1)) + 0.02 * rng.standard_normal((P, 256))
    kw = dict(na=1, nb=0, ka=1, kb=0, w0=m.w0, method="sml", tol=1e-13, max_iter=200, noise="moderated")
    siso = lptv.identify(u, y, **kw)
    mimo = lptv.identify(u[:, :, None], y[:, :, None], **kw)
    assert siso.noise == mimo.noise == "moderated"
    assert np.abs(mimo.eta - siso.eta).max() <= 1e-8 * np.abs(siso.eta).max() + 1e-6 * siso.parameter_std.min()
    assert np.allclose(mimo.covariance, siso.covariance, rtol=1e-6, atol=1e-12)
