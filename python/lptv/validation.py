"""Validation (METHOD.md section 7): normalised residues, frozen poles and zeros."""
from __future__ import annotations

import numpy as np

from . import _core
from ._validate import as_int, as_lines, as_real_1d
from .model import Model


def _structure_of(model: Model):
    return _core.Parametrisation(_core.Structure.of(model._cpp))


def normalized_residue(model: Model, data, lines, *, _par=None, _theta=None):
    """Residue e_l, its variance and |e_l| / sqrt(var e_l) of ``model`` on ``data`` at the rows ``lines``.

    Returns
    -------
    e, var_e, r : ndarrays over the rows
    """
    from .data import FrequencyData

    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model, got {type(model).__name__}")
    if not isinstance(data, FrequencyData):
        raise ValueError(f"data must be an lptv.FrequencyData, got {type(data).__name__}")
    rows = as_lines(lines, "lines")
    par = _par if _par is not None else _structure_of(model)
    theta = _theta if _theta is not None else par.theta_from_model(model._cpp)
    par.check_rows(rows, data.max_line)
    e = np.asarray(_core.residue(data._cpp, par, rows, theta))
    var_e = np.asarray(_core.residue_variance(data._cpp, par, rows, theta))
    if np.any(var_e <= 0):
        raise ValueError("data: the residue variance is zero on some rows (noise-free data); "
                         "normalised residues are undefined")
    return e, var_e, np.abs(e) / np.sqrt(var_e)


def expected_fraction_above_0db(n_rows: int, n_free: int, periods: int):
    """Expected fraction of normalised residues above 0 dB and a 3-sigma band.

    With variances from P periods |e|^2/var e ~ F(2, 2(P-1)), so P(r > 1) =
    (1 + 1/(P-1))^-(P-1); fitting n parameters to 2|R| real equations shrinks |e|^2 by
    c = 1 - n/(2|R|), giving P(r > 1) = (1 + 1/(c (P-1)))^-(P-1) (exp(-1/c) for known
    variances, ``periods`` = 0). The band is +-3 binomial standard deviations over the rows.

    Examples
    --------
    >>> import lptv
    >>> p, (lo, hi) = lptv.expected_fraction_above_0db(243, 34, 8)
    >>> round(p, 3), round(lo, 3), round(hi, 3)
    (0.368, 0.275, 0.461)
    """
    n_rows = as_int(n_rows, "n_rows", minimum=1)
    n_free = as_int(n_free, "n_free")
    periods = as_int(periods, "periods")
    if periods == 1:
        raise ValueError("periods must be 0 (known variances) or >= 2, got 1")
    if n_free >= 2 * n_rows:
        raise ValueError(f"n_free must be below the 2 n_rows = {2 * n_rows} real equations of the rows, got {n_free}")
    p, band = _core.expected_fraction_above_0db(n_rows, n_free, periods)
    return p, tuple(band)


def _frozen_roots(coef_at, t, order, what):
    t = as_real_1d(t, "t")
    vals = coef_at(t)  # (len t, order+1), lowest power first
    out = np.full((t.size, order), complex(np.inf, 0.0))
    for i in range(t.size):
        p = vals[i, ::-1]
        r = np.roots(p)  # drops leading zeros: those roots went to infinity
        r = np.sort_complex(r)
        out[i, order - r.size:] = r if r.size else out[i, order - r.size:]
    return out


def frozen_poles(model: Model, t) -> np.ndarray:
    """Roots of sum_n a_n(t) s^n (z^n in discrete time) at each t: array (len(t), na).

    They say nothing about the stability of the time-varying system. Where a_na(t)
    vanishes a pole goes to infinity (reported as inf).

    Examples
    --------
    >>> import lptv
    >>> m = lptv.Model([[1.0], [1.0], [1.0]], [[1.0]], w0=1.0)
    >>> lptv.frozen_poles(m, [0.0]).round(3)
    array([[-0.5-0.866j, -0.5+0.866j]])
    """
    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model, got {type(model).__name__}")
    return _frozen_roots(model.a_at, t, model.na, "poles")


def frozen_zeros(model: Model, t) -> np.ndarray:
    """Roots of sum_m b_m(t) s^m at each t: array (len(t), nb)."""
    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model, got {type(model).__name__}")
    return _frozen_roots(model.b_at, t, model.nb, "zeros")
