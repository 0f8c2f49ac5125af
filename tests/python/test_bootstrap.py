"""covariance='bootstrap' of lptv.identify (python/lptv/estimation/bootstrap.py): its draws have the data's
noise statistics, and its standard deviations agree with a Monte Carlo of the estimator."""
import numpy as np
import pytest

import lptv
from lptv.estimation.bootstrap import draw
from lptv.examples import noisy_periods


def _lti_case(P, seed):
    m = lptv.Model([[2.0], [1.0], [0.5]], [[1.0], [0.3]], w0=0.1)
    ms = lptv.multisine(range(1, 40), 128, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 128)
    u, y = noisy_periods(ms.signal, y1, P, 30, 20, seed=seed, correlation=0.4)
    return m, u, y


def _local_mean(v, w=5):
    v = np.asarray(v)
    return np.array([v[max(0, l - w): l + w + 1].mean() for l in range(v.size)])


def test_draws_have_the_smoothed_noise_statistics_of_the_data():
    """Over 4000 draws: the means scatter with the data's variances of the mean (and their
    input/output covariance) averaged over +-5 lines, and the drawn sample variances average to
    them (each within 5 % of its value: the relative sd of a mean of 4000 exponential-like terms
    is 1.6 %)."""
    m, u, y = _lti_case(4, 1)
    d0 = lptv.FrequencyData.from_periods(u, y, w0=0.1)
    d = lptv.FrequencyData(d0.U, d0.Y, _local_mean(d0.varU), _local_mean(d0.varY), _local_mean(d0.covYU),
                           w0=0.1, periods=4)   # what the draws must show
    draws_from = d0
    rng = np.random.default_rng(2)
    U0, Y0 = np.asarray(d.U), np.asarray(d.Y)
    draws = [draw(draws_from, U0, Y0, rng) for _ in range(4000)]
    dU = np.array([np.asarray(x.U) - U0 for x in draws])
    dY = np.array([np.asarray(x.Y) - Y0 for x in draws])
    lines = [0, 1, 5, 20, 64]
    for name, emp, ref in (("varU", np.mean(np.abs(dU) ** 2, 0), d.varU), ("varY", np.mean(np.abs(dY) ** 2, 0), d.varY),
                           ("cov", np.mean(dY * np.conj(dU), 0), d.covYU)):
        ref = np.asarray(ref)
        for l in lines:
            assert abs(emp[l] - ref[l]) < 0.05 * np.sqrt(np.asarray(d.varU)[l] * np.asarray(d.varY)[l]) + \
                0.05 * abs(ref[l]), (name, l)
    mean_var = np.mean([np.asarray(x.varY) for x in draws], 0)
    assert np.allclose(mean_var[lines], np.asarray(d.varY)[lines], rtol=0.05)
    assert all(x.periods == 4 for x in draws[:3]) and np.all(dU[:, 0].imag == 0)


@pytest.mark.parametrize("method", ["wgtls", "sml"])
def test_bootstrap_std_agrees_with_a_monte_carlo_of_the_estimator(method):
    """An LTI system at P = 4: the bootstrap's std (B = 200) against the std of 200 Monte Carlo
    estimates; each std is good to about 1/sqrt(2 x 200) = 5 %, the bootstrap's also carries the
    randomness of the one data set it starts from: within 25 % per parameter, 12 % in the median."""
    etas = []
    for s in range(200):
        _, u, y = _lti_case(4, 100 + s)
        # the bootstrap resamples the sample variances: its std is that route's estimator's
        etas.append(lptv.identify(u, y, na=2, nb=1, w0=0.1, method=method, noise="sample").eta)
    mc = np.std(np.array(etas), axis=0)
    _, u, y = _lti_case(4, 7)
    res = lptv.identify(u, y, na=2, nb=1, w0=0.1, method=method, covariance="bootstrap", bootstrap=200, seed=3)
    free = mc > 0
    ratio = res.parameter_std[free] / mc[free]
    assert np.all((ratio > 0.75) & (ratio < 1.25)), ratio
    assert abs(np.median(ratio) - 1) < 0.12, ratio
    assert res.model.covariance is res.covariance or np.array_equal(res.model.covariance, res.covariance)


def test_bootstrap_bad_arguments():
    m, u, y = _lti_case(4, 1)
    with pytest.raises(ValueError, match="covariance must be"):
        lptv.identify(u, y, na=2, nb=1, w0=0.1, covariance="jackknife")
    with pytest.raises(ValueError, match="bootstrap"):
        lptv.identify(u, y, na=2, nb=1, w0=0.1, covariance="bootstrap", bootstrap=5)
    with pytest.raises(ValueError, match="method 'wgtls' or 'sml'"):
        lptv.identify(u, y, na=2, nb=1, w0=0.1, method="ls", covariance="bootstrap")
    with pytest.raises(ValueError, match="one data set"):
        lptv.identify([(u, y), (u, y)], na=2, nb=1, w0=0.1, covariance="bootstrap")
