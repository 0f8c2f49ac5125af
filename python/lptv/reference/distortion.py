"""METHOD.md section 16 in plain NumPy: per output line, the regression of M random-phase
realisations' Y_j on the excited lines within +-Kh (their conjugates near DC), its residual
variance, the noise of a period mean and the best linear time-periodic approximation.

The independent route :func:`lptv._core.distortion_lines` is tested against: a Python loop over
the lines with ``numpy.linalg.lstsq`` and ``numpy.linalg.pinv`` of X^H X where the core takes one
Jacobi SVD of X per line. It was the computation of :func:`lptv.distortion` before the core had
it. Nothing here calls ``lptv._core``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DistortionLines:
    """The fields of the core's ``DistortionLines``; per output line 1..L unless stated."""

    lines: np.ndarray
    signal: np.ndarray       # mean over the realisations of |Y_j|^2
    total: np.ndarray        # residual variance s_j^2 (NaN where M - q_j < 1)
    noise: np.ndarray        # noise variance of a period mean, input noise through the BLA
    dof: np.ndarray          # M - q_j
    regressors: np.ndarray   # q_j
    bla: np.ndarray          # (2 Kh + 1, n_excited): branch k (row Kh + k) at each excited line
    bla_var: np.ndarray      # s_j^2 [(X^H X)^-1]_cc


def regressors(excited, j: int, branches: int) -> np.ndarray:
    """The regressors of output line j: excited lines c (c > 0) and conjugates -c with
    |j - c| <= Kh, the excited lines first."""
    excited = np.asarray(excited, int)
    src = np.concatenate([excited, -excited])
    return src[np.abs(j - src) <= branches]


def distortion_lines(U, Y, varU, varY, covYU, excited, branches: int) -> DistortionLines:
    """U, Y, varU, varY, covYU: (M, L + 1), realisation m's period means and their noise
    (co)variances on lines 0..L; excited: ascending lines in 1..L; branches: Kh."""
    U, Y, cov = (np.asarray(x, complex) for x in (U, Y, covYU))
    varU, varY = (np.asarray(x, float) for x in (varU, varY))
    excited = np.asarray(excited, int)
    Kh = int(branches)
    M, L = U.shape[0], U.shape[1] - 1
    Ufull = lambda c: U[:, c] if c >= 0 else np.conj(U[:, -c])           # noqa: E731
    lines = np.arange(1, L + 1)
    n = lines.size
    total = np.full(n, np.nan)
    noise = np.full(n, np.nan)
    dof = np.zeros(n, int)
    nreg = np.zeros(n, int)
    bla = np.full((2 * Kh + 1, excited.size), np.nan + 0j)
    bla_var = np.full((2 * Kh + 1, excited.size), np.nan)
    ex_index = {int(c): i for i, c in enumerate(excited)}
    for i, j in enumerate(lines):
        cs = regressors(excited, int(j), Kh)
        q = cs.size
        nreg[i] = q
        dof[i] = M - q
        if M - q < 1:
            continue
        yj = Y[:, j]
        if q:
            X = np.column_stack([Ufull(int(c)) for c in cs])        # (M, q)
            G, *_ = np.linalg.lstsq(X, yj, rcond=None)
            r = yj - X @ G
        else:
            X, G, r = None, np.zeros(0, complex), yj - 0.0
        s2 = float(np.sum(np.abs(r) ** 2) / (M - q))
        # noise of one realisation's period mean: output, plus the input noise through G
        nv = varY[:, j].copy()
        for g, c in zip(G, cs):
            c = int(c)
            nv = nv + np.abs(g) ** 2 * varU[:, abs(c)]
            if c == j:
                nv = nv - 2 * np.real(np.conj(g) * cov[:, j])
        total[i], noise[i] = s2, float(np.mean(nv))
        if q:
            Ci = np.linalg.pinv(X.conj().T @ X)
            for g, c, v in zip(G, cs, np.real(np.diag(Ci)) * s2):
                c = int(c)
                if c > 0:
                    bla[Kh + (j - c), ex_index[c]] = g
                    bla_var[Kh + (j - c), ex_index[c]] = v
    signal = np.mean(np.abs(Y[:, 1:]) ** 2, axis=0)
    return DistortionLines(lines=lines, signal=signal, total=total, noise=noise, dof=dof,
                           regressors=nreg, bla=bla, bla_var=bla_var)
