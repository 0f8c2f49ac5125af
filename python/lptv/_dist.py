"""The few distribution functions the verdicts and intervals need, from scipy.special: the same
values as scipy.stats's (which computes them with these functions), without scipy.stats's import
(0.4-0.6 s, more than a fit and its report). tests/python/test_dist.py compares them."""
from __future__ import annotations

import numpy as np
from scipy import special


def norm_ppf(p):
    return special.ndtri(p)


def norm_sf(x):
    return special.ndtr(-np.asarray(x, dtype=float))


def f_sf(x, d1, d2):
    return special.fdtrc(d1, d2, x)


def f_cdf(x, d1, d2):
    return special.fdtr(d1, d2, x)


def f_isf(q, d1, d2):
    """x with P(F(d1, d2) > x) = q: P(F > x) = I_w(d2/2, d1/2), w = d2 / (d2 + d1 x)."""
    w = special.betaincinv(np.asarray(d2, float) / 2.0, np.asarray(d1, float) / 2.0, q)
    return np.asarray(d2, float) * (1.0 - w) / (np.asarray(d1, float) * w)


def chi2_sf(x, k):
    return special.chdtrc(k, x)


def t_ppf(p, df):
    return special.stdtrit(df, p)


def gamma_sf(x, a):
    return special.gammaincc(a, x)


def gamma_median(a, scale=1.0):
    return special.gammaincinv(a, 0.5) * scale


def gamma_pdf(x, a, scale=1.0):
    z = np.asarray(x, dtype=float) / scale
    return np.exp(special.xlogy(a - 1.0, z) - z - special.gammaln(a)) / scale
