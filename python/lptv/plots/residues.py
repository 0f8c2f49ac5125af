"""The verdict's residue tests, each on its own statistic against its own threshold."""
from __future__ import annotations

from typing import Optional

import numpy as np

from ._base import MARGINS, _axes, _db, _figure, _freq_axis, _log_x, _options, _series, _z_of  # noqa: F401


def residue_tests(res, *, fig=None):
    """The verdict's residue tests (:attr:`lptv.IdentificationResult.residue_tests`) as horizontal
    bars, each on its own statistic against its own threshold, under the short names of
    :func:`residue_test_label` (the reports' tables use them too): the sums of normal scores (z,
    standard normal without a model error; two-sided over all rows with signal, one-sided per
    group of rows at one distance d from the excited lines) in the upper panel, the score tests of
    one more harmonic per coefficient (an F statistic with its own degrees of freedom) in the
    lower one. A test's threshold is where its statistic reaches the level Holm's method gives
    it, alpha / (number of tests not yet rejected before it) (overall size ``alpha``, 1 %); it
    rejects (red) when it and every test with a smaller p-value reach theirs.

    Returns the figure.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import system_measurements
    >>> d = system_measurements("third_order", seed=1, periods=8)
    >>> res = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], lines=d["lines"])
    >>> fig = lptv.plots.residue_tests(res)
    >>> [ax.get_xlabel().split(":")[0] for ax in fig.axes]
    ['z', 'F of the score test for one more harmonic on the coefficient']
    """
    tests = getattr(res, "residue_tests", None)
    if tests is None:
        raise ValueError("res: the fit has no residue tests (no noise in the data, or no data kept)")
    thresholds = residue_test_thresholds(tests)
    groups = [[i for i, t in enumerate(tests.tests) if t.kind != "score"],
              [i for i, t in enumerate(tests.tests) if t.kind == "score"]]
    groups = [g for g in groups if g]
    # horizontal bars, one row per test: the names read in full and each threshold marks its own row
    heights = [len(g) + 0.6 for g in groups]
    if fig is None:
        fig, axes = _figure((6.4, 1.35 + 0.3 * sum(heights) + 0.55 * (len(groups) - 1)), len(groups), 1,
                            left=1.95, top=0.5, bottom=0.5, hspace=0.55, height_ratios=heights)
    else:
        axes = fig.subplots(len(groups), 1, squeeze=False, height_ratios=heights)
    for ax, idx in zip(axes[:, 0], groups):
        score = tests.tests[idx[0]].kind == "score"
        y = np.arange(len(idx))[::-1]
        stat = np.array([tests.tests[i].statistic for i in idx])
        ax.barh(y, stat, height=0.6, color=["C3" if tests.tests[i].rejects else "C0" for i in idx])
        for yi, i in zip(y, idx):
            for thr in thresholds[i]:
                if thr is not None:
                    ax.vlines(thr, yi - 0.42, yi + 0.42, color="k", ls="--", lw=1.2)
        ax.set_yticks(y, [f"{residue_test_label(tests.tests[i])} ({tests.tests[i].rows.size} rows)" for i in idx],
                      fontsize="small")
        ax.set_ylim(-0.6, len(idx) - 0.4)
        marks = [v for i in idx for v in thresholds[i] if v is not None]
        if score:
            ax.set_xlabel("F of the score test for one more harmonic on the coefficient", fontsize="small")
            top = max(float(np.max(stat)), max(marks))
            if top > 30 * max(marks):      # a rejected structure's F of 10^5 would hide the thresholds
                from matplotlib.ticker import FuncFormatter

                ax.set_xscale("log")
                ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
                ax.set_xlim(0.5 * min(float(np.min(stat[stat > 0], initial=1.0)), min(marks)), 2 * top)
            else:
                ax.set_xlim(0, 1.1 * top)
        else:
            ax.set_xlabel("z: sum of the rows' normal scores over its std (N(0, 1) without a model error)",
                          fontsize="small")
            lo = min(0.0, float(np.min(stat)), min(marks))
            hi = max(0.0, float(np.max(stat)), max(marks))
            pad = 0.08 * (hi - lo)
            ax.set_xlim(lo - pad, hi + pad)
            ax.axvline(0.0, color="k", lw=0.8)
        ax.grid(True, axis="x", alpha=0.3)
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fig.legend(handles=[Line2D([], [], color="k", ls="--", lw=1.1,
                               label=f"each test's threshold (Holm, overall {100 * tests.alpha:g} %)"),
                        Patch(color="C0", label="not rejected"), Patch(color="C3", label="rejects")],
               # a constrained layout (a figure passed in) makes room above the axes for it
               loc="outside upper center" if type(fig.get_layout_engine()).__name__ == "ConstrainedLayoutEngine"
               else "upper center", ncol=3, fontsize="small", frameon=False, borderaxespad=0.2)
    return fig


def residue_test_label(test) -> str:
    """The short name of a residue test (a :class:`lptv.verdict.ResidueTest`) that the reports'
    table and :func:`residue_tests` share: 'all rows' (every row with signal), 'd = 3' (the rows 3
    lines from the nearest excited line), 'a0: +1 harmonic' (the score test of one more harmonic
    on a_0)."""
    import re

    if test.kind == "score":
        m = re.search(r"on (\w+)$", test.name)
        return f"{m.group(1) if m else test.name}: +1 harmonic"
    if test.name == "rows with signal":
        return "all rows"
    m = re.match(r"rows (\d+) lines? from", test.name)
    return f"d = {m.group(1)}" if m else test.name


def residue_test_thresholds(tests):
    """Per test of a :class:`lptv.verdict.ResidueTests`, its thresholds ``(lower, upper)`` on its own
    statistic (None where a side is not tested): the values at which its p-value reaches the level
    Holm's step-down method gives it, alpha / (k - r) for the test of rank r (0 for the smallest
    p-value) among k. A z test (a sum of normal scores): one-sided per offset group (upper), two-sided over all
    rows with signal; a score test: the F(2, nu) quantile, nu recovered from the test's F value and
    p-value (the F(2, nu) tail is (1 + 2 F / nu)^(-nu / 2), monotone in nu; nu infinite is the
    chi-squared limit exp(-F))."""
    from statistics import NormalDist

    k = len(tests.tests)
    ranks = np.argsort(np.argsort([t.p_value for t in tests.tests], kind="stable"), kind="stable")
    out = []
    for t, r in zip(tests.tests, ranks):
        q = tests.alpha / (k - r)
        if t.kind == "score":
            nu = _f2_dof(t.statistic, t.p_value)
            out.append((None, -np.log(q) if nu is None else nu / 2 * (q ** (-2 / nu) - 1)))
        elif t.name == "rows with signal":
            zq = NormalDist().inv_cdf(1 - q / 2)
            out.append((-zq, zq))
        else:
            out.append((None, NormalDist().inv_cdf(1 - q)))
    return out


def _f2_dof(F: float, p: float):
    """nu with P(F(2, nu) > F) = p; None for the chi-squared limit (p at or below exp(-F))."""
    if not (F > 0 and 0 < p < 1) or np.log(p) <= -F * (1 - 1e-12):
        return None
    g = lambda nu: -nu / 2 * np.log1p(2 * F / nu) - np.log(p)     # decreasing in nu
    lo, hi = 1e-6, 1.0
    while g(hi) > 0:
        hi *= 2
        if hi > 1e12:
            return None
    for _ in range(200):
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if g(mid) > 0 else (lo, mid)
        if hi / lo < 1 + 1e-13:
            break
    return float(np.sqrt(lo * hi))
