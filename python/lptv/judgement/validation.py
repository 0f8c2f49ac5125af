"""Validation (METHOD.md section 7): normalised residues, frozen poles and zeros."""
from __future__ import annotations

import numpy as np

from .. import _core
from .._validate import as_int, as_lines, as_real_1d
from ..model.mimo import MimoModel
from ..model.siso import Model


def _structure_of(model: Model):
    return _core.Parametrisation(_core.Structure.of(model._cpp))


def normalized_residue(model: Model, data, lines, *, _par=None, _theta=None):
    """Residue e_l, its variance and |e_l| / sqrt(var e_l) of ``model`` on ``data`` at the rows ``lines``.

    Returns
    -------
    e, var_e, r : ndarrays over the rows
    """
    from ..spectra.frequency_data import FrequencyData

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


def frozen_poles(model, t=None) -> np.ndarray:
    """Roots of sum_n a_n(t) s^n (z^n in discrete time) at each t: array (len(t), na).

    Of an identification result: a :class:`lptv.judgement.uncertainty.FrozenPoles` with the
    poles of its model and their first-order std (METHOD.md section 22); ``t`` defaults to 64
    times over the period there.

    They say nothing about the stability of the time-varying system (:func:`lptv.floquet`
    does). Where a_na(t) vanishes a pole goes to infinity (reported as inf).

    For an :class:`lptv.MimoModel` (METHOD.md section 19): the roots of
    det sum_n A_n(t) s^n, sum_p d_p of them (d_p the row degrees, the highest order in row p
    of A), as the eigenvalues of the frozen observer-form state matrix S - R L^{-1} E1 (the
    block companion matrix when every row has degree na). Where the leading row coefficient
    matrix L(t) is singular, poles go to infinity (inf, sorted first as for one output).

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model([[1.0], [1.0], [1.0]], [[1.0]], w0=1.0)
    >>> lptv.frozen_poles(m, [0.0]).round(3)
    array([[-0.5-0.866j, -0.5+0.866j]])

    Two masses with M = I, C = 0.2 I and K = [[2, -1], [-1, 2]]: det(M s^2 + C s + K) has the
    roots of s^2 + 0.2 s + 1 and s^2 + 0.2 s + 3.

    >>> mm = lptv.MimoModel.mechanical(np.eye(2), 0.2 * np.eye(2), [[2.0, -1.0], [-1.0, 2.0]],
    ...                                np.eye(2), w0=1.0)
    >>> p = lptv.frozen_poles(mm, [0.0])[0]
    >>> p.real.round(3), np.sort(p.imag).round(3)
    (array([-0.1, -0.1, -0.1, -0.1]), array([-1.729, -0.995,  0.995,  1.729]))
    """
    if isinstance(model, MimoModel):
        return _frozen_poles_mimo(model, as_real_1d(t, "t"))
    if not isinstance(model, Model) and isinstance(getattr(model, "model", None), Model) \
            and hasattr(model, "covariance"):
        from .uncertainty import frozen_poles_of  # a result: the poles with their std

        return frozen_poles_of(model, t, roots=frozen_poles)
    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model or lptv.MimoModel, got {type(model).__name__}")
    if t is None:
        raise ValueError("t must be given for a model (the times of the frozen poles)")
    return _frozen_roots(model.a_at, t, model.na, "poles")


def _frozen_poles_mimo(model: MimoModel, t: np.ndarray) -> np.ndarray:
    ny = model.n_outputs
    d = model.na_entries.max(axis=1)  # row degrees; -1: a zero row
    if np.any(d < 0):
        raise ValueError(f"model: row {int(np.argmax(d < 0))} of A(t, s) is zero at every order (det A(t, s) "
                         "vanishes identically); every row must hold a nonzero coefficient")
    off = np.concatenate([[0], np.cumsum(d)])
    n = int(off[-1])
    out = np.full((t.size, n), complex(np.inf, 0.0))
    A = model.a_at(t)  # (len t, na+1, ny, ny)
    E1 = np.zeros((ny, n))
    for p in range(ny):
        if d[p] > 0:
            E1[p, off[p]] = 1.0
    for i in range(t.size):
        L = np.array([A[i, d[p], p, :] for p in range(ny)])
        # frozen: the right-form coefficients are the A_n themselves; state rows w_{p,1..d_p}
        S = np.zeros((n, n))
        R = np.zeros((n, ny))
        for p in range(ny):
            for j in range(1, d[p] + 1):
                r = off[p] + j - 1
                if j < d[p]:
                    S[r, r + 1] = 1.0
                R[r] = A[i, d[p] - j, p, :]
        sv = np.linalg.svd(L, compute_uv=False)
        if sv[-1] > 1e-12 * max(sv[0], np.abs(A[i]).max()):
            roots = np.linalg.eigvals(S - R @ np.linalg.solve(L, E1))
        else:  # the pencil of [[S, -R], [E1, -L]] and diag(I, 0): the lost poles are infinite
            from scipy.linalg import eigvals

            Fd = np.block([[S, -R], [E1, -L]])
            Ed = np.zeros((n + ny, n + ny))
            Ed[:n, :n] = np.eye(n)
            roots = eigvals(Fd, Ed)
            roots = roots[np.isfinite(roots)]
            roots = roots[np.argsort(np.abs(roots))[:n]]
        roots = np.sort_complex(roots)
        out[i, n - roots.size:] = roots
    return out


def frozen_zeros(model: Model, t) -> np.ndarray:
    """Roots of sum_m b_m(t) s^m at each t: array (len(t), nb)."""
    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model, got {type(model).__name__}")
    return _frozen_roots(model.b_at, t, model.nb, "zeros")
