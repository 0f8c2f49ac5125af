"""lptv._dist's distribution functions against scipy.stats's, over the ranges lptv uses."""
import numpy as np
import pytest
from scipy import stats

from lptv import _dist

P = np.array([1e-12, 1e-6, 1e-3, 0.025, 0.5, 0.975, 0.999])
X = np.array([1e-3, 0.1, 1.0, 3.0, 10.0, 40.0])
DOF = [1, 2, 3.5, 6, 30, 400, 1e4]


def close(a, b):
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-300)


def test_normal():
    close(_dist.norm_ppf(P), stats.norm.ppf(P))
    close(_dist.norm_sf(X), stats.norm.sf(X))


@pytest.mark.parametrize("d1", [1, 2, 4, 20])
@pytest.mark.parametrize("d2", DOF)
def test_f(d1, d2):
    close(_dist.f_sf(X, d1, d2), stats.f.sf(X, d1, d2))
    close(_dist.f_cdf(X, d1, d2), stats.f.cdf(X, d1, d2))
    q = P[(P < 0.5) & (P >= 1e-6)]        # scipy.stats takes 1 - q: below 1e-6 it is the less precise
    np.testing.assert_allclose(_dist.f_isf(q, d1, d2), stats.f.isf(q, d1, d2), rtol=1e-8)


@pytest.mark.parametrize("k", DOF)
def test_chi2_t_gamma(k):
    close(_dist.chi2_sf(X, k), stats.chi2.sf(X, k))
    np.testing.assert_allclose(_dist.t_ppf(P, k), stats.t.ppf(P, k), rtol=1e-9)
    close(_dist.gamma_sf(X, k), stats.gamma.sf(X, k))
    law = stats.gamma(k, scale=1.0 / k)
    np.testing.assert_allclose(_dist.gamma_median(k, 1.0 / k), law.median(), rtol=1e-10)
    np.testing.assert_allclose(_dist.gamma_pdf(X / 10, k, 1.0 / k), law.pdf(X / 10), rtol=1e-9, atol=1e-300)
