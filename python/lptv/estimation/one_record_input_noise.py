"""One record with a noisy input: the residue's covariance the input noise adds, the weights and
the sandwich covariance built from it (METHOD.md section 17, "A noisy input: the covariance").

The record's prediction is linear in the input: Y_hat(U) = H U - A^-1 T, H = A^-1 B on the
record's grid (the model's HTF branches G_k(l) = H[l, l - k L]). With the measured input
U = U0 + N_u the residue at the true model holds -H N_u besides the output noise. For white input
noise n(t) of variance s_u^2, N_u = F n / N, so the residue's input-noise part on the fitted lines
is -M n with M = (H F / N)[lines, :]: column t of M is the prediction (without the transient)
for a unit impulse of the input at sample t. The model is periodic in N0 samples, so the impulse
at t + q N0 gives column t times exp(-j 2 pi l q / L): N0 predictions build M.
"""
from __future__ import annotations

import numpy as np

from .. import _core


def input_noise_operator(par, L, eta_free, ts, t_degree, idx, lines, N):
    """M (n_lines, N) complex: the residue's input-noise part on ``lines`` is -M n, n the input's
    noise samples. ``idx`` the lines' positions in the core's prediction vector."""
    N0 = N // L
    m = np.arange(N)
    none = np.zeros(0)
    head = np.empty((idx.size, N0), complex)
    for t in range(N0):
        Ut = np.exp(-2j * np.pi * m * t / N) / N
        head[:, t] = np.asarray(_core.record_prediction(par, Ut, L, eta_free, none, ts, t_degree))[idx]
    phase = np.exp(-2j * np.pi * np.asarray(lines) / L)
    return np.concatenate([head * (phase ** q)[:, None] for q in range(L)], axis=1)


def stacked(M):
    """[Re M; Im M]: the real rows of the residue (Re parts of all lines, then Im parts)."""
    return np.concatenate([M.real, M.imag], axis=0)


def smooth(x, width):
    """The mean over the fitted lines within +-width positions (fewer at the ends), as the core's
    residual noise level averages."""
    x = np.asarray(x, float)
    c = np.concatenate([[0.0], np.cumsum(x)])
    i = np.arange(x.size)
    lo, hi = np.maximum(0, i - width), np.minimum(x.size - 1, i + width)
    return (c[hi + 1] - c[lo]) / (hi - lo + 1)


OUTPUT_FLOOR = 0.01
"""The output noise's variance per line is kept at least this share of the residual's level when
the input noise's share is taken off it (the two are told apart by the model, not the data)."""


def split_noise(var, Mr, s_u, width, residual_route):
    """(output noise variance, input-noise variance per line): the fit's level ``var`` holds both
    on the residual route (its average over +-width lines); a given level is the output's alone."""
    n = var.size
    cu = s_u ** 2 * (np.sum(Mr[:n] ** 2, axis=1) + np.sum(Mr[n:] ** 2, axis=1))
    if residual_route:
        out = np.maximum(var - smooth(cu, width), OUTPUT_FLOOR * var)
    else:
        out = np.asarray(var, float).copy()
    return out, cu


def residue_covariance(out_var, Mr, s_u):
    """The real-stacked residue's covariance: output noise (circular, half its variance in each of
    Re and Im) plus the input noise's s_u^2 Mr Mr^T."""
    C = s_u ** 2 * (Mr @ Mr.T)
    d = np.concatenate([out_var, out_var]) / 2
    C[np.diag_indices_from(C)] += d
    return C


def sandwich(J, Sigma):
    """(J^T J)^-1 J^T Sigma J (J^T J)^-1 for the scaled real Jacobian J (rows as the cost) and the
    scaled residue's covariance Sigma; the pseudo-inverse where J is rank-deficient."""
    B = np.linalg.pinv(J.T @ J)
    return B @ (J.T @ Sigma @ J) @ B
