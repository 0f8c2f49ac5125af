"""Excitation design in plain NumPy/SciPy (METHOD.md section 2, "Designing the excitation").

An independent route for the compiled core's crest-factor minimisation: the signal and the
gradient of its L_p norm as direct sums of cosines (no FFT), minimised with SciPy's L-BFGS-B.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

__all__ = ["schroeder_phases", "lp_norm_log", "minimize_crest_factor", "signal"]


def schroeder_phases(amplitudes) -> np.ndarray:
    """phi_k = -2 pi sum_{i<k} (k - i) A_i^2 / sum A^2, as a double sum."""
    A = np.asarray(amplitudes, dtype=float)
    p = A**2 / np.sum(A**2)
    k = np.arange(A.size)
    return np.array([-2 * np.pi * sum((kk - i) * p[i] for i in range(kk)) for kk in k])


def _real_lines(lines, N):
    lines = np.asarray(lines)
    return (lines == 0) | ((N % 2 == 0) & (2 * lines == N))


def signal(lines, amplitudes, phases, N: int, oversample: int = 1) -> np.ndarray:
    """sum_l A_l cos(2 pi l n / M + phi_l) on M = N * oversample points (direct sum).

    DC and the Nyquist line of N are real lines: A cos(phi) (times cos(pi n / oversample)).
    """
    M = N * oversample
    n = np.arange(M)
    x = np.zeros(M)
    real = _real_lines(lines, N)
    for l, A, phi, r in zip(lines, amplitudes, phases, real):
        arg = 2 * np.pi * ((int(l) * n) % M) / M
        x += A * np.cos(phi) * np.cos(arg) if r else A * np.cos(arg + phi)
    return x


def lp_norm_log(lines, amplitudes, phases, N: int, oversample: int, p: int):
    """log of (mean x^p)^(1/p) and its gradient with respect to the phases (zero on real lines)."""
    M = N * oversample
    n = np.arange(M)
    x = signal(lines, amplitudes, phases, N, oversample).astype(np.longdouble)  # x^p up to 1e4932
    f = np.log(np.mean(x**p)) / p
    w = (x ** (p - 1) / np.sum(x**p)).astype(float)
    g = np.zeros(len(lines))
    for i, (l, A, phi, r) in enumerate(zip(lines, amplitudes, phases, _real_lines(lines, N))):
        if not r:
            g[i] = float(np.sum(w * -A * np.sin(2 * np.pi * ((int(l) * n) % M) / M + phi)))
    return float(f), g


def minimize_crest_factor(lines, amplitudes, phases, N: int, oversample: int = 1, max_p: int = 1024,
                          iterations_per_p: int = 100):
    """L-BFGS-B (SciPy) on the log L_p norm for p = 4, 8, ..., max_p; returns (phases, crest).

    The phases of the smallest crest factor among the stages' ends are returned.
    """
    lines = np.asarray(lines)
    amplitudes = np.asarray(amplitudes, dtype=float)
    ph = np.asarray(phases, dtype=float).copy()

    def crest(q):
        x = signal(lines, amplitudes, q, N, oversample)
        return float(np.abs(x).max() / np.sqrt(np.mean(x**2)))

    best = (crest(ph), ph.copy())
    p = 4
    while p <= max_p:
        # The objective scaled by the peak so x^p stays finite for large p.
        def fun(q, p=p):
            x = signal(lines, amplitudes, q, N, oversample)
            m = np.abs(x).max()
            f, g = lp_norm_log(lines, amplitudes / m, q, N, oversample, p)
            return f + np.log(m), g  # log of the norm is exact; its gradient does not see m
        r = minimize(fun, ph, jac=True, method="L-BFGS-B", options={"maxiter": iterations_per_p})
        ph = r.x
        c = crest(ph)
        if c < best[0]:
            best = (c, ph.copy())
        p *= 2
    return best[1], best[0]
