"""The nonparametric HTF matrix from E >= nu experiments (METHOD.md section 19, eq. 19.8): on each
excited line l and branch k, G_k(w_l) = YY_{l+k} UU_l^+ from the experiments' period means, with
its variance from the noise (co)variances of all channels (eq. 19.10). NumPy on the periods'
spectra; a first route, before the core has one."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import _array, as_int, as_lines, check_finite


@dataclass(frozen=True)
class MimoHtfEstimate:
    """Result of :func:`mimo_htf_estimate`."""

    lines: np.ndarray
    """Excited input lines l."""
    branches: np.ndarray
    """Branches k = -K..K."""
    G: np.ndarray
    """G_k(w_l), shape (len(lines), 2K+1, ny, nu): output p on line l + k per unit input r on line l
    (NaN where l + k lies outside 0..N/2)."""
    variance: np.ndarray
    """First-order variance of each entry of G (same shape)."""
    condition: np.ndarray
    """2-norm condition number of the nu x E input matrix UU_l on each excited line."""
    P: int
    """Periods per experiment."""


def _spectra(x, name, n_channels=None):
    arr = _array(x, name)
    if arr.ndim != 4:
        raise ValueError(f"{name} must be 4-D (experiments, periods, samples, channels), got shape {arr.shape}")
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} must be real, got complex values")
    if min(arr.shape) < 1:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    check_finite(arr, name)
    return np.fft.rfft(arr.astype(float), axis=2) / arr.shape[2]


def mimo_htf_estimate(u, y, lines, K: int) -> MimoHtfEstimate:
    """The HTF matrix G_k(w_l), |k| <= K, on the excited lines from E >= nu experiments.

    Parameters
    ----------
    u : array_like, shape (E, P, N, nu)
        P periods of N samples of the nu inputs in each of E experiments (after transients).
    y : array_like, shape (E, P, N, ny)
        The outputs of the same periods.
    lines : sequence of int
        The excited lines; they must be more than 2 K apart, so that output line l + k holds
        input line l's contribution only (METHOD.md eq. 19.8).
    K : int
        Branches -K..K.

    Returns
    -------
    MimoHtfEstimate

    Notes
    -----
    With P >= 2 the (co)variances of the period means C_z (eq. 19.10) give the variance of G to
    first order: dG = sum_e d_e w_e^T, w_e row e of UU_l^+ and d_e = dY_e(l+k) - G dU_e(l), so
    var G[p, r] = sum_e |w_e[r]|^2 (C_Y(l+k) + G C_U(l) G^H - C_YU(l) G^H - G C_UY(l))_e[p, p],
    the cross terms only for k = 0 (the one branch whose output line is the input's line; the
    input noise of line l enters every branch through G C_U G^H). With P = 1 the variance is NaN.
    """
    U = _spectra(u, "u")
    Y = _spectra(y, "y")
    E, P, H, nu = U.shape
    if Y.shape[:3] != (E, P, H):
        raise ValueError(f"y must have the experiments, periods and samples of u {tuple(_array(u, 'u').shape[:3])}, "
                         f"got shape {tuple(_array(y, 'y').shape[:3])}")
    ny = Y.shape[3]
    if E < nu:
        raise ValueError(f"u: {E} experiments cannot determine the HTF matrix of {nu} inputs (E >= nu needed)")
    N = _array(u, "u").shape[2]
    K = as_int(K, "K", maximum=N // 4)
    ln = np.asarray(as_lines(lines, "lines", maximum=N // 2), dtype=int)
    if ln.size > 1 and np.min(np.diff(np.sort(ln))) <= 2 * K:
        raise ValueError(f"lines must be more than 2 K = {2 * K} apart, so that each output line has one "
                         f"contributor, got a spacing of {int(np.min(np.diff(np.sort(ln))))}")
    Um, Ym = U.mean(axis=1), Y.mean(axis=1)
    if P >= 2:
        dz = np.concatenate([Y, U], axis=3) - np.concatenate([Ym, Um], axis=2)[:, None]
        Cz = np.einsum("eplc,epld->elcd", dz, dz.conj()) / (P * (P - 1))
    else:
        Cz = np.full((E, H, ny + nu, ny + nu), np.nan, complex)
    ks = np.arange(-K, K + 1)
    G = np.full((ln.size, ks.size, ny, nu), np.nan, complex)
    var = np.full(G.shape, np.nan)
    cond = np.empty(ln.size)
    for i, l in enumerate(ln):
        UU = Um[:, l, :].T                                     # nu x E
        cond[i] = np.linalg.cond(UU)
        W = np.linalg.pinv(UU)                                 # E x nu: row e is w_e
        for j, k in enumerate(ks):
            m = l + k
            if not 0 <= m < H:
                continue
            g = Ym[:, m, :].T @ W                              # ny x nu
            G[i, j] = g
            CY = Cz[:, m, :ny, :ny]
            C = CY + np.einsum("pr,ers,qs->epq", g, Cz[:, l, ny:, ny:], g.conj())
            if k == 0:
                cross = np.einsum("eps,qs->epq", Cz[:, l, :ny, ny:], g.conj())
                C = C - cross - np.conj(np.swapaxes(cross, 1, 2))
            var[i, j] = np.einsum("er,ep->pr", np.abs(W) ** 2, np.real(np.diagonal(C, axis1=1, axis2=2)))
    return MimoHtfEstimate(lines=ln, branches=ks, G=G, variance=var, condition=cond, P=P)
