"""Noise variances moderated across neighbouring lines (lptv.moderated_noise, METHOD.md section 7).

The distributional claims are checked on noise whose variance is known line by line: the
moderated variance of a line is then judged against the true one, and a mean's |X|^2 over its
moderated variance must follow F(2, dof) when the model of the rule (a smooth trend, a scaled
inverse chi-square spread about it) holds."""
import numpy as np
import pytest
from scipy import stats

import lptv


def _data(var_u, var_y, P, seed, rho=0.0):
    """FrequencyData of P periods of pure noise with the given variances of one period's line
    (lines 1..L), output correlated with the input by rho: the spectra are the noise's means."""
    rng = np.random.default_rng(seed)
    L = var_y.size - 1
    N = 2 * L
    def noise(var):
        X = (rng.standard_normal((P, L + 1)) + 1j * rng.standard_normal((P, L + 1))) * np.sqrt(var / 2)
        return X
    Eu, Ey = noise(np.ones(L + 1)), noise(np.ones(L + 1))
    Ey = rho * Eu + np.sqrt(1 - rho ** 2) * Ey
    Eu, Ey = Eu * np.sqrt(var_u), Ey * np.sqrt(var_y)
    Eu[:, 0], Ey[:, 0] = Eu[:, 0].real, Ey[:, 0].real
    Eu[:, -1], Ey[:, -1] = Eu[:, -1].real, Ey[:, -1].real
    # time signals whose spectra (lptv.spectrum's scaling) are these lines
    u = np.array([lptv.time_signal(x, N) for x in Eu])
    y = np.array([lptv.time_signal(x, N) for x in Ey])
    return lptv.FrequencyData.from_periods(u, y, w0=1.0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_smooth_noise_is_moderated_to_near_its_true_variance(seed):
    """White noise at P = 4: the sample variance of one line is off by its chi-square_6 / 6 spread
    (relative error 0.58 rms); moderated over +-10 lines the error is that of about 20 lines'
    pool, below 0.25 rms, and d0 is large."""
    L = 400
    d = _data(np.full(L + 1, 0.01), np.full(L + 1, 0.04), 4, seed)
    mod = lptv.moderated_noise(d)
    inner = np.arange(1, L)
    truth_y = 0.04 / 4                   # the variance of the mean of 4 periods
    own = d.varY[inner] / truth_y - 1
    moderated = np.asarray(mod.data.varY)[inner] / truth_y - 1
    assert np.sqrt(np.mean(own ** 2)) > 0.45
    assert np.sqrt(np.mean(moderated ** 2)) < 0.25
    assert mod.prior_dof > 20
    assert np.median(mod.dof[inner]) > 40
    assert mod.dof[0] == 3 and mod.dof[L] == 3


def test_moderated_statistic_follows_F_with_the_stated_degrees_of_freedom():
    """Noise whose variance follows a smooth trend (two decades over the band) times a scaled
    inverse chi-square spread with 30 degrees of freedom, P = 4, over 40 data sets: the means'
    |X|^2 over their moderated variance, mapped through F(2, dof), are uniform: the fractions
    beyond the 90 %, 99 % points are 10 %, 1 % within 4 binomial standard errors (n = 40 x 598
    lines, rows of one data set sharing a prior: the bounds are generous by a factor 2)."""
    L = 300
    l = np.arange(L + 1)
    trend = 0.01 * 10 ** (2 * l / L)
    u90, u99, n = 0, 0, 0
    d0s = []
    for seed in range(40):
        rng = np.random.default_rng(1000 + seed)
        spread = 30 / rng.chisquare(30, (2, L + 1))
        d = _data(trend * spread[0], trend * spread[1], 4, seed)
        mod = lptv.moderated_noise(d)
        d0s.append(mod.prior_dof)
        inner = np.setdiff1d(np.arange(1, L), mod.outliers)
        for X, v in ((d.U, mod.data.varU), (d.Y, mod.data.varY)):
            z = np.abs(np.asarray(X)[inner]) ** 2 / np.asarray(v)[inner]
            p = stats.f.sf(z, 2, mod.dof[inner])
            u90 += np.sum(p < 0.10)
            u99 += np.sum(p < 0.01)
            n += inner.size
    assert 10 < np.median(d0s) < 120, d0s          # the spread's 30, from one data set each
    se90, se99 = np.sqrt(0.09 / n), np.sqrt(0.0099 / n)
    assert abs(u90 / n - 0.10) < 8 * se90, u90 / n
    assert abs(u99 / n - 0.01) < 8 * se99, u99 / n


@pytest.mark.parametrize("shape", ["slope", "roll-off"])
def test_a_sloping_or_bending_noise_spectrum_is_moderated_without_bias(shape):
    """The neighbours' arithmetic mean of a spectrum that slopes in log is biased up by the
    exponential's convexity: at 0.43 dB a line (a second-order roll-off near 40 lines) the mean
    over +-10 lines is 1 + 0.1^2 x 38.5 / 2 = 1.19 times the line's variance (and the roll-off
(1 + l / 10)^-6 bends as well: 0.12 to 0.05 nepers a line over lines 40-120). The shape factor
    of the local log-quadratic trend (METHOD.md section 7) removes it: over 40 data sets at
    P = 4 the moderated variances of the lines away from the ends average within 3 % of the true
    ones (sampling error of that mean about 0.5 %), where the plain mean is 10 % or more off."""
    L = 300
    l = np.arange(L + 1, dtype=float)
    trend = np.exp(-0.1 * l) if shape == "slope" else (1.0 + l / 10.0) ** -6
    inner = np.arange(40, L - 20) if shape == "slope" else np.arange(40, 120)
    ratio, plain = [], []
    for seed in range(40):
        d = _data(np.full(L + 1, 1.0), trend, 4, 300 + seed)
        mod = lptv.moderated_noise(d)
        assert mod.prior_dof > 20
        ratio.append(np.asarray(mod.data.varY)[inner] / (trend[inner] / 4))
        n = 20
        plain.append(np.array([(np.sum(d.varY[i - 10:i + 11]) - d.varY[i]) / n for i in inner])
                     / (trend[inner] / 4))
    bias = float(np.mean(ratio)) - 1
    assert abs(bias) < 0.03, bias
    assert float(np.mean(plain)) - 1 > 0.10         # what the shape factor corrects


def test_rough_noise_keeps_each_line_near_its_own_variance():
    """Variances drawn independently per line over two decades: the neighbours know nothing,
    d0 comes out small and the line's own variance dominates: the spread's log-variance variance
    (2 ln 10)^2 / 12 = 1.77 is trigamma(0.7), d0 = 1.4, raised a little by the lines flagged as
    above their neighbours (left out of the spread); the own weight d / (d + d0) stays above 2/3
    for d = 2 (P - 1) = 14."""
    L = 300
    rng = np.random.default_rng(5)
    v = 10 ** rng.uniform(-3, -1, (2, L + 1))
    d = _data(v[0], v[1], 8, 6)
    mod = lptv.moderated_noise(d)
    assert mod.prior_dof < 7
    inner = np.arange(1, L)
    assert np.median(mod.dof[inner]) < 20
    w = np.asarray(mod.data.varY)[inner] / d.varY[inner]
    assert np.median(np.abs(w - 1)) < 0.3


def test_a_narrowband_disturbance_keeps_its_own_variance():
    """One line with 200 times the noise of its neighbours (a disturbance between the grid's
    lines): flagged, its variance kept as measured, and left out of its neighbours' prior."""
    L = 300
    vy = np.full(L + 1, 0.01)
    vy[150] = 2.0
    d = _data(np.full(L + 1, 0.01), vy, 4, 7)
    mod = lptv.moderated_noise(d)
    assert 150 in mod.outliers
    assert mod.data.varY[150] == d.varY[150]
    assert mod.dof[150] == 6
    assert mod.data.varY[149] < 5 * np.median(d.varY)
    assert mod.prior_dof > 20


def test_correlated_input_and_output_noise_keeps_a_valid_covariance():
    L = 200
    d = _data(np.full(L + 1, 0.01), np.full(L + 1, 0.02), 4, 8, rho=0.6)
    mod = lptv.moderated_noise(d)
    m = mod.data
    assert np.all(np.abs(m.covYU) ** 2 <= m.varU * m.varY * (1 + 1e-12))
    inner = np.arange(1, L)
    rho = np.abs(np.asarray(m.covYU)[inner]) / np.sqrt(np.asarray(m.varU)[inner] * np.asarray(m.varY)[inner])
    assert abs(np.median(rho) - 0.6) < 0.1


def test_data_that_cannot_be_moderated_are_returned_unchanged():
    d = _data(np.full(21, 0.01), np.full(21, 0.01), 4, 9)        # 20 lines < 3 x 10 + 2
    mod = lptv.moderated_noise(d)
    assert mod.prior_dof == 0 and mod.data is d
    assert np.all(mod.dof[1:-1] == 6)
    given = lptv.FrequencyData(d.U, d.Y, d.varU, d.varY, w0=1.0)     # periods = 0
    assert lptv.moderated_noise(given).prior_dof == 0


@pytest.mark.parametrize("args, message", [
    (("not data",), "data must be an lptv.FrequencyData"),
    ((None, 0), "half_width"),
    ((None, 2.5), "half_width"),
])
def test_bad_arguments_name_themselves(args, message):
    d = _data(np.full(101, 0.01), np.full(101, 0.01), 4, 10)
    args = tuple(d if a is None else a for a in args)
    with pytest.raises(ValueError, match=message):
        lptv.moderated_noise(*args)


# ------------------------------------------------------------------ fits weighed by moderated noise

def _system(name="discrete", seed=3, P=4):
    from lptv.examples import system_measurements
    return system_measurements(name, seed=seed, periods=P)


def _fit(d, **kw):
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["lines"], **kw)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_identify_with_moderated_noise_weighs_by_it_and_reports_its_periods(seed):
    """noise='moderated': the fit uses the moderated (co)variances (res.data holds them, with the
    periods they are worth), agrees with the sample-weighted fit within their uncertainty, and
    its verdict reads the fit's own moderation (not a second one)."""
    d = _system(seed=seed)
    ref = _fit(d, method="sml", noise="sample")
    res = _fit(d, method="sml", noise="moderated")
    assert res.noise == "moderated" and ref.noise == "sample" and ref.moderation == ()
    mo = res.moderation[0]
    assert isinstance(mo, lptv.ModeratedNoise)
    assert np.array_equal(res.data.varY, mo.data.varY)
    assert res.data.periods == round(1 + np.median(mo.dof[1:-1]) / 2) > 4
    free = res.parameter_std > 0
    z = (res.eta - ref.eta)[free] / np.hypot(res.parameter_std, ref.parameter_std)[free]
    assert np.max(np.abs(z)) < 3.5, z
    assert res.residue_tests is not None and res.model_ok


def test_the_verdict_of_a_moderated_fit_does_not_moderate_again(monkeypatch):
    import lptv.spectra.moderation
    d = _system(seed=4)
    res = _fit(d, method="wgtls", noise="moderated")
    calls = []
    real = lptv.spectra.moderation.moderated_noise
    monkeypatch.setattr(lptv.spectra.moderation, "moderated_noise", lambda *a, **k: calls.append(1) or real(*a, **k))
    assert res.residue_tests is not None
    assert calls == []
    ref = _fit(d, method="wgtls")
    assert ref.residue_tests is not None and calls == [1]


def test_moderated_noise_with_several_experiments():
    d1, d2 = _system(seed=5), _system(seed=6, P=6)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify([(d1["u"], d1["y"]), (d2["u"], d2["y"])], **d1["structure"], w0=d1["w0"],
                            ts=d1["ts"], method="sml", noise="moderated")
    assert len(res.moderation) == 2 and all(isinstance(m, lptv.ModeratedNoise) for m in res.moderation)
    assert res.experiments[0].periods > 4 and res.experiments[1].periods > 6
    assert res.residue_tests is not None


def test_docstring_examples_run():
    import doctest

    import lptv.spectra.moderation

    result = doctest.testmod(lptv.spectra.moderation, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


def test_plot_shows_own_and_moderated_variances_and_the_kept_lines():
    pytest.importorskip("matplotlib")
    import lptv.plots

    L = 300
    vy = np.full(L + 1, 0.01)
    vy[150] = 2.0
    d = _data(np.full(L + 1, 0.01), vy, 4, 7)
    mod = lptv.moderated_noise(d)
    ax = lptv.plots.moderated_noise(mod, hz=True)
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert labels[:2] == ["output: each line's own", "output: moderated"]
    assert "kept their own (above their neighbours)" in labels
    own = ax.get_lines()[0].get_ydata()
    assert np.allclose(own, 10 * np.log10(d.varY[1:L]))
    assert ax.get_xlabel() == "frequency (Hz)"
    with pytest.raises(ValueError, match="mod must be an lptv.ModeratedNoise"):
        lptv.plots.moderated_noise(d)


def test_summary_says_the_noise_was_moderated():
    d = _system(seed=7)
    res = _fit(d, method="sml", noise="moderated")
    text = res.summary()
    assert f"noise: moderated across neighbouring lines, worth about {res.data.periods} periods per line" in text
    assert "noise: moderated" not in _fit(d, method="sml", noise="sample").summary()


# ------------------------------------------------------------------ the default route, noise='auto'

def _rough_periods(P, seed):
    """The discrete-time example's noise-free periods plus noise whose variance is drawn per line
    over two decades (independently: no neighbour knows a line's variance)."""
    from lptv.examples import system_measurements
    d = system_measurements("discrete", seed=seed, periods=P)
    N = d["u0"].size
    L = N // 2
    rng = np.random.default_rng(seed)
    v = 1e-6 * 10 ** rng.uniform(0, 2, (2, L + 1))
    def noise(var):
        X = (rng.standard_normal((P, L + 1)) + 1j * rng.standard_normal((P, L + 1))) * np.sqrt(var / 2) * N
        X[:, 0], X[:, -1] = X[:, 0].real, X[:, -1].real
        return np.array([np.fft.irfft(x, N) for x in X])
    return dict(d, u=d["u0"] + noise(v[0]), y=d["y0"] + noise(v[1]))


@pytest.mark.parametrize("seed", [1, 2])
def test_the_default_route_moderates_smooth_noise_and_says_why(seed):
    d = _system(seed=seed, P=4)          # white noise
    res = _fit(d, method="sml")
    assert res.noise == "moderated"
    assert res.noise_choice.startswith("moderated: the noise spectrum is smooth across lines")
    assert "noise route (noise='auto'): moderated" in res.summary()
    asked = _fit(d, method="sml", noise="moderated")
    np.testing.assert_array_equal(res.eta, asked.eta)
    assert asked.noise_choice == "asked for"


@pytest.mark.parametrize("seed", [1, 2])
def test_the_default_route_keeps_the_sample_variances_of_rough_noise(seed):
    d = _rough_periods(8, seed)
    res = _fit(d, method="wgtls")
    assert res.noise == "sample", res.noise_choice
    assert "not smooth across lines" in res.noise_choice
    np.testing.assert_array_equal(res.eta, _fit(d, method="wgtls", noise="sample").eta)


def test_the_default_route_keeps_the_sample_variances_below_four_periods_and_for_the_bootstrap():
    res = _fit(_system(seed=5, P=3), method="wgtls")
    assert res.noise == "sample" and "3 periods" in res.noise_choice
    res = _fit(_system(seed=5, P=4), method="wgtls", covariance="bootstrap", bootstrap=20)
    assert res.noise == "sample" and "bootstrap" in res.noise_choice
    with pytest.raises(ValueError, match="noise must be one of"):
        _fit(_system(seed=5, P=4), noise="smooth")


def test_the_smoothness_check_names_its_numbers():
    from lptv.spectra.moderation import smooth_noise
    L = 300
    rng = np.random.default_rng(5)
    v = 10 ** rng.uniform(-3, -1, (2, L + 1))
    ok, why = smooth_noise(lptv.moderated_noise(_data(v[0], v[1], 8, 6)))
    assert not ok and "d0 =" in why and "< the lines' own 14" in why
    ok, why = smooth_noise(lptv.moderated_noise(_data(np.full(L + 1, 0.01), np.full(L + 1, 0.04), 4, 0)))
    assert ok and ">= 6" in why
    with pytest.raises(ValueError, match="mo must be an lptv.ModeratedNoise"):
        smooth_noise("x")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_smoothness_check_finds_bumps_a_few_lines_wide(seed):
    """Noise whose variance has 20 bumps about three lines wide (a factor up to 5) on a flat floor:
    scattered about no smooth trend, neighbouring lines' residuals correlate and the check fails
    by that criterion; the same noise without the bumps passes."""
    from lptv.spectra.moderation import smooth_noise
    L = 300
    l = np.arange(L + 1)
    rng = np.random.default_rng(seed)
    bumps = 1 + sum(4 * np.exp(-0.5 * ((l - c) / 1.5) ** 2) for c in rng.uniform(20, 280, 20))
    ok, why = smooth_noise(lptv.moderated_noise(_data(np.full(L + 1, 0.01), 0.01 * bumps, 8, 40 + seed)))
    assert not ok and "bumps a few lines wide" in why, why
    ok, why = smooth_noise(lptv.moderated_noise(_data(np.full(L + 1, 0.01), np.full(L + 1, 0.01), 8, 40 + seed)))
    assert ok and "correlate by" in why, why
