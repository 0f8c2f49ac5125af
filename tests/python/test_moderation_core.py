"""lptv.moderated_noise in the compiled core (_core.moderated_noise) against its NumPy and SciPy
twin lptv.reference.moderation (the computation lptv.moderated_noise had before), on white,
coloured, rough and exactly smooth noise, a narrowband outlier, correlated input and output noise,
few lines, and P = 2, 4, 8, 32; and the core's special functions against SciPy's.

Both routes take the same window sums (running sums in the same order), so the outlier rule sees
the same numbers; what differs is the core's own polygammas and F quantile against SciPy's, the
mean of the squared residuals (NumPy sums pairwise) and the last bits of the arithmetic. Hence:
the same outliers, d0 within 1e-8 relative (or both at the cap), the moderated variances and the
degrees of freedom within 1e-10 relative, covYU within 1e-10 of sqrt(varU varY)."""
import numpy as np
import pytest
from scipy import special, stats

import lptv
from lptv import _core
from lptv.reference import moderation as ref
from test_moderation import _data

L_DEFAULT = 300


def _coloured(L):
    l = np.arange(L + 1)
    return 1e-2 / (1 + (l / 40.0) ** 2), 1e-3 * (1 + (l / 80.0) ** 4) / (1 + (l / 20.0) ** 2)


def _case(name):
    rng = np.random.default_rng(11)
    L = L_DEFAULT
    if name == "white-P4":
        return _data(np.full(L + 1, 0.01), np.full(L + 1, 0.01), 4, 0), 10
    if name == "white-P2":
        return _data(np.full(L + 1, 0.01), np.full(L + 1, 0.03), 2, 1), 10
    if name == "coloured-P8":
        return _data(*_coloured(L), 8, 2), 10
    if name == "coloured-P32-W4":
        return _data(*_coloured(L), 32, 3), 4
    if name.startswith("spread-"):    # a log-normal spread about a smooth trend: d0 finite, not small
        P, sigma = {"spread-P2": (2, 0.5), "spread-P4": (4, 0.3), "spread-P32": (32, 0.12)}[name]
        tu, ty = _coloured(L)
        e = np.exp(sigma * rng.standard_normal((2, L + 1)))
        return _data(tu * e[0], ty * e[1], P, 16 + P, rho=0.3), 10
    if name == "rough-P8":
        v = 10 ** rng.uniform(-3, -1, (2, L + 1))
        return _data(v[0], v[1], 8, 6), 10
    if name == "rough-P4-W25":
        v = 10 ** rng.uniform(-4, -1, (2, L + 1))
        return _data(v[0], v[1], 4, 4), 25
    if name == "outlier-P4":
        vy = np.full(L + 1, 0.01)
        vy[150] = 2.0
        vy[40] = 0.5
        return _data(np.full(L + 1, 0.01), vy, 4, 7), 10
    if name == "correlated-P4":
        return _data(np.full(L + 1, 0.01), np.full(L + 1, 0.02), 4, 8, rho=0.6), 10
    if name == "correlated-coloured-P8":
        return _data(*_coloured(L), 8, 9, rho=-0.8), 6
    if name == "few-lines-P4":       # 33 >= 3 x 10 + 2: just enough lines
        return _data(np.full(34, 0.01), np.full(34, 0.01), 4, 10), 10
    if name == "noise-free-input-P4":  # varU = 0: only the output's variances count
        d = _data(np.full(L + 1, 0.01), np.full(L + 1, 0.01), 4, 12)
        return lptv.FrequencyData(d.U, d.Y, np.zeros(L + 1), d.varY, w0=1.0, periods=4), 10
    if name == "exactly-smooth-P4":  # no spread about the trend: d0 at its cap
        d = _data(np.full(L + 1, 0.01), np.full(L + 1, 0.01), 4, 13)
        return lptv.FrequencyData(d.U, d.Y, np.full(L + 1, 0.01), np.full(L + 1, 0.02), w0=1.0, periods=4), 10
    if name == "too-few-lines-P4":   # unchanged
        return _data(np.full(21, 0.01), np.full(21, 0.01), 4, 14), 10
    if name == "not-from-periods":   # unchanged
        d = _data(np.full(L + 1, 0.01), np.full(L + 1, 0.01), 4, 15)
        return lptv.FrequencyData(d.U, d.Y, d.varU, d.varY, w0=1.0), 10
    raise KeyError(name)


CASES = ["white-P4", "white-P2", "spread-P2", "spread-P4", "spread-P32", "coloured-P8", "coloured-P32-W4", "rough-P8", "rough-P4-W25", "outlier-P4",
         "correlated-P4", "correlated-coloured-P8", "few-lines-P4", "noise-free-input-P4", "exactly-smooth-P4",
         "too-few-lines-P4", "not-from-periods"]


def _rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    same = (a == b)        # equal infinities (and zeros) included
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(same, 0.0, np.abs(a - b) / np.abs(b))


@pytest.mark.parametrize("name", CASES)
def test_core_agrees_with_the_reference(name):
    d, W = _case(name)
    core, r = lptv.moderated_noise(d, W), ref.moderated_noise(d, W)
    assert core.half_width == r.half_width == W
    np.testing.assert_array_equal(core.outliers, r.outliers)
    if r.prior_dof == 0:
        assert core.prior_dof == 0 and core.data is d and r.data is d
        assert core.own_weight is None and core.neighbour is None
    elif r.prior_dof == ref.MAX_PRIOR_DOF:
        assert core.prior_dof == lptv.spectra.moderation.MAX_PRIOR_DOF == r.prior_dof
    else:
        assert abs(core.prior_dof - r.prior_dof) <= 1e-8 * r.prior_dof, (core.prior_dof, r.prior_dof)
    assert np.max(_rel(core.dof, r.dof)) <= 1e-10
    for f in ("varU", "varY"):
        assert np.max(_rel(getattr(core.data, f), getattr(r.data, f))) <= 1e-10, f
    scale = np.sqrt(np.asarray(r.data.varU) * np.asarray(r.data.varY))
    dc = np.abs(np.asarray(core.data.covYU) - np.asarray(r.data.covYU))
    assert np.all(dc <= 1e-10 * scale)
    assert core.data.periods == r.data.periods and core.data.w0 == r.data.w0 and core.data.ts == r.data.ts
    np.testing.assert_array_equal(core.data.U, r.data.U)
    np.testing.assert_array_equal(core.data.Y, r.data.Y)
    np.testing.assert_array_equal(core.source_varU, r.source_varU)
    np.testing.assert_array_equal(core.source_varY, r.source_varY)
    if r.own_weight is not None:
        assert np.max(_rel(core.own_weight, r.own_weight)) <= 1e-10
        np.testing.assert_array_equal(core.neighbour, r.neighbour)
    lines = np.unique(np.r_[0, 1, 2, np.asarray(r.outliers), d.max_line // 2 + np.arange(-3, 4), d.max_line - 1,
                            d.max_line])
    C, Cr = core.error_covariance(lines), r.error_covariance(lines)
    assert C.shape == Cr.shape == (lines.size, lines.size)
    assert np.max(np.abs(C - Cr)) <= 1e-12 * max(np.max(np.abs(Cr)), 1e-300)


def test_the_cases_reach_every_branch():
    """The cases above cover moderation with and without outliers, d0 below and at its cap, and
    the unchanged returns (a guard that the comparison is not vacuous)."""
    got = {name: ref.moderated_noise(*_case(name)) for name in CASES}
    assert {40, 150} <= set(got["outlier-P4"].outliers.tolist())
    assert got["exactly-smooth-P4"].prior_dof == ref.MAX_PRIOR_DOF
    assert 0 < got["rough-P8"].prior_dof < 20
    for name in ("spread-P2", "spread-P4", "spread-P32", "correlated-coloured-P8", "few-lines-P4"):
        assert 5 < got[name].prior_dof < 1e4, (name, got[name].prior_dof)
    assert got["too-few-lines-P4"].prior_dof == 0 and got["not-from-periods"].prior_dof == 0
    assert got["few-lines-P4"].prior_dof > 0


def test_polygammas_agree_with_scipy():
    for x in np.r_[np.logspace(-3, 6, 181), np.arange(1, 64) / 2.0]:
        for n, f in ((0, _core.digamma), (1, _core.trigamma), (2, _core.tetragamma)):
            want = float(special.polygamma(n, x))
            if n == 0 and abs(x - 1.4616321449683622) < 0.05:
                continue    # digamma's root: relative error has no meaning there
            assert abs(f(x) - want) <= 1e-12 * abs(want), (n, x, f(x), want)


def test_inverse_trigamma_agrees_with_the_reference():
    for x in np.logspace(-7, 8, 61):
        y, want = _core.trigamma_inverse(x), ref._trigamma_inverse(x)
        assert abs(y - want) <= 1e-9 * want, (x, y, want)


def test_f_quantile_agrees_with_scipy():
    """The quantiles the outlier rule takes (d = 2 (P - 1), n d for n = 1..2 W neighbours) and a
    few others."""
    for P in (2, 3, 4, 8, 16, 32):
        d = 2.0 * (P - 1)
        for n in (1, 2, 3, 5, 10, 19, 20, 40, 50):
            want = float(stats.f.isf(1e-3, d, n * d))
            assert abs(_core.f_upper_quantile(1e-3, d, n * d) - want) <= 1e-9 * want, (P, n)
    for p, d1, d2 in ((0.5, 1.0, 1.0), (0.05, 3.5, 7.25), (1e-6, 6.0, 12.0), (0.9, 4.0, 10.0), (0.01, 200.0, 5.0)):
        want = float(stats.f.isf(p, d1, d2))
        assert abs(_core.f_upper_quantile(p, d1, d2) - want) <= 1e-9 * want, (p, d1, d2)


def test_core_rejects_what_the_wrapper_would():
    d, _ = _case("white-P4")
    with pytest.raises(ValueError, match="half_width"):
        _core.moderated_noise(d._cpp, 0)
    mod = lptv.moderated_noise(d)
    with pytest.raises(ValueError, match="lines"):
        mod.error_covariance([d.max_line + 1])


@pytest.mark.parametrize("seed", range(4))
def test_the_core_s_trend_residuals_are_the_smoothness_check_s(seed):
    """The residuals of the log variances about their local quadratic trend that the core's
    moderation keeps (ModeratedNoise.trend_residual_u/_y, the fit behind its shape factors) against
    the NumPy route of the smoothness check (_trend_residuals), on white and shaped noise with and
    without outlying lines: the same lines left out (NaN), values within 1e-12 (log variances of
    size <= 30, a 3 x 3 least-squares fit on offsets scaled to -1..1: about 1e-14 measured)."""
    from lptv.spectra.moderation import _trend_residuals, moderated_noise

    rng = np.random.default_rng(seed)
    N = (256, 1000, 2048, 4096)[seed]
    shape = 1 + 0.5 * np.sin(np.arange(N) / 40) if seed % 2 else 1.0
    u = rng.standard_normal((8, N)) * shape
    y = u + 0.1 * rng.standard_normal((8, N))
    if seed >= 2:
        y[:, ::17] *= 20          # narrowband lines: outliers of the moderation
    mo = moderated_noise(lptv.FrequencyData.from_periods(u, y, w0=1.0))
    keep = np.ones(mo.data.max_line - 1, bool)
    if np.size(mo.outliers):
        keep[np.asarray(mo.outliers) - 1] = False
    for src, core in ((mo.source_varU, mo._core.trend_residual_u), (mo.source_varY, mo._core.trend_residual_y)):
        r = _trend_residuals(np.asarray(src)[1:-1], keep, mo.half_width)
        core = np.asarray(core)
        assert core.shape == r.shape
        assert np.array_equal(np.isnan(core), np.isnan(r))
        assert np.isfinite(r).sum() > r.size // 2
        np.testing.assert_allclose(core[np.isfinite(r)], r[np.isfinite(r)], rtol=0, atol=1e-12)
