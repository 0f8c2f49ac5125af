"""What the figures share: new figures with fixed margins, log axes, frequency axes."""
from __future__ import annotations

from typing import Optional

import numpy as np

# Margins of a new figure in inches: room for the tick labels and the axis label on the left,
# the x label below and a title above. Fixed margins instead of matplotlib's constrained layout,
# which measures every text of every axes before drawing (it was half of the identify report's
# figure time); every figure here keeps its texts within these margins.
MARGINS = dict(left=0.85, right=0.2, bottom=0.55, top=0.42, hspace=0.55, wspace=0.75)


def _figure(figsize=(6.4, 4.0), rows: int = 1, cols: int = 1, *, sharex=False, width_ratios=None,
            height_ratios=None, **margins):
    """A new figure (not through pyplot) and its ``rows`` x ``cols`` axes (a 2-D array), with the
    fixed :data:`MARGINS` (in inches; keywords override them)."""
    from matplotlib.figure import Figure

    m = {**MARGINS, **margins}
    w, h = figsize
    fig = Figure(figsize=figsize)
    # hspace / wspace are fractions of the mean axes' height / width
    ax_h = (h - m["bottom"] - m["top"] - (rows - 1) * m["hspace"]) / rows
    ax_w = (w - m["left"] - m["right"] - (cols - 1) * m["wspace"]) / cols
    fig.subplots_adjust(left=m["left"] / w, right=1 - m["right"] / w, bottom=m["bottom"] / h,
                        top=1 - m["top"] / h, hspace=m["hspace"] / max(ax_h, 0.1),
                        wspace=m["wspace"] / max(ax_w, 0.1))
    axes = fig.subplots(rows, cols, sharex=sharex, squeeze=False, width_ratios=width_ratios,
                        height_ratios=height_ratios)
    for ax in axes.flat:      # at most 6 ticks a side: each tick is a text to lay out and draw
        ax.locator_params(nbins=5)
    return fig, axes


def _axes(ax, figsize=(6.4, 4.0)):
    if ax is not None:
        return ax
    return _figure(figsize)[1][0, 0]


def _log_x(ax):
    """A logarithmic frequency axis with ticks at 1, 2, 5 times the powers of ten, labelled in
    plain numbers (0.5, 1, 2, 5, 10, ...) rather than in powers of ten, and no minor ticks (each
    tick is a text to lay out and a grid line to draw)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    ax.set_xscale("log")
    ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.grid(True, which="major", alpha=0.3)


def _z_of(level: float) -> float:
    """The two-sided standard normal quantile of a confidence level (the standard library's:
    scipy.stats costs half a second to import)."""
    from statistics import NormalDist

    return NormalDist().inv_cdf(0.5 + level / 2.0)


def _series(x, name, n=None, ndim=1):
    """A numeric array of the given dimension (and length n along its first axis) to plot; NaN
    and inf are allowed (a pole at infinity, a line without data)."""
    from .._validate import _array

    a = _array(x, name)
    if a.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-D, got shape {a.shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} must have one value per line or time ({n}), got {a.shape[0]}")
    return a


def _options(w0=None, hz=False):
    from .._validate import as_bool, as_float

    as_bool(hz, "hz")
    if w0 is not None and w0 != 0:
        as_float(w0, "w0", minimum=0.0, open_min=True, what="a finite positive angular frequency (rad/s)")


def _freq_axis(lines, w0, hz):
    """x values and label of a frequency axis: line * w0 in rad/s (or Hz), else the line number."""
    _options(w0, hz)
    lines = _series(lines, "lines")
    if not w0:
        return lines, "line (multiple of the fundamental)"
    if hz:
        return lines * w0 / (2 * np.pi), "frequency (Hz)"
    return lines * w0, "angular frequency (rad/s)"


def _db(x):
    x = np.abs(np.asarray(x))
    with np.errstate(divide="ignore"):
        return 20 * np.log10(np.where(x > 0, x, np.nan))
