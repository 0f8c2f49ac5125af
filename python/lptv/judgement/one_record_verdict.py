"""The verdict of a one-record fit (METHOD.md section 17, "The verdict of one record").

The fit's noise level comes from its own residual, which a wrong structure inflates: the cost
ratio cannot judge the model. What a wrong structure leaves, and noise does not, is a residual
that the input explains: an order too few leaves dG(w_l) U_l, a missing harmonic k of a
coefficient leaves dG_k(w_l) U_{l - k L} (the input shifted by k w0 on the record's grid). The
test regresses the normalised residual on the input and its shifts, k = -(K + 1) .. K + 1, in
short windows of lines (each dG locally constant), and compares the share the regressors
explain with the share they leave, as an F ratio: scale-free, so it needs no noise level.

Under a right structure and an exact input the residual is the output noise (less its
projection on the parameters' directions, which only lowers the statistic), independent of the
input: each window's explained sum of squares is a chi-square of 2 r degrees of freedom (r the
window's rank) and its remainder one of 2 (W - r), so the pooled ratio is F(2 sum r, 2 sum (W - r))
and the test has at most its nominal size. The shifts are then tested one by one (Holm) to name
what is missing.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Tuple

import numpy as np

ALPHA = 0.01
"""The verdict's size: the probability of rejecting a right structure (at most)."""


@dataclass(frozen=True)
class RecordVerdict:
    """The cross-correlation test of a one-record fit's residual with the input and its shifts."""

    statistic: float
    """The pooled F ratio (about 1 or below for a right structure)."""
    dof: Tuple[int, int]
    p_value: float
    shifts: Tuple[int, ...]
    """The harmonics k of the regressors U_{l - k L}."""
    shift_p_values: Tuple[float, ...]
    """Each shift's own test (its column's share), before Holm's correction."""
    window: int
    alpha: float
    model_errors: Tuple[str, ...]
    score_tests: Tuple = ()
    """(coefficient and harmonic, F, d1, d2, p-value) of each score test for one more harmonic of
    one coefficient (METHOD.md section 17); combined with the windowed test by Holm at alpha."""

    @property
    def model_ok(self) -> bool:
        return not self.model_errors


def _window(n_regressors: int) -> int:
    # 4 lines per regressor (at least 15): enough remainder degrees of freedom per window, and
    # windows short against the change of dG over the record's grid
    return max(15, 4 * n_regressors)


def record_verdict(U, residual, lines, L, kmax, alpha: float = ALPHA, scores=()) -> RecordVerdict:
    """The verdict of a one-record fit from the record's full DFT ``U`` (N lines), the
    normalised residual on ``lines`` and the model's largest harmonic count ``kmax``;
    ``scores``: the score tests of :func:`lptv.record_score.harmonic_score_tests`, combined with
    the windowed test's pooled p-value by Holm's method at ``alpha``."""
    from .._dist import f_sf

    N = U.size
    lines = np.asarray(lines)
    e = np.asarray(residual, dtype=complex)
    shifts = tuple(range(-(kmax + 1), kmax + 2))
    X = np.stack([U[(lines - k * L) % N] for k in shifts], axis=1)
    q = len(shifts)
    W = _window(q)
    n_win = lines.size // W
    s_expl = s_rest = 0.0
    d_expl = d_rest = 0
    drop, seen = np.zeros(q), np.zeros(q, int)
    for w in range(n_win):
        sl = slice(w * W, (w + 1) * W)
        Xw, ew = X[sl], e[sl]
        scale = np.linalg.norm(Xw, axis=0)
        keep = scale > 1e-12 * max(scale.max(), 1e-300)
        if not keep.any():
            continue
        Xk = Xw[:, keep] / scale[keep]
        Q, R = np.linalg.qr(Xk)
        rank = int(np.sum(np.abs(np.diag(R)) > 1e-10 * np.abs(R[0, 0])))
        if rank == 0 or rank >= W:
            continue
        # the window's fit, its projection, and each column's share (dropping it)
        coef, *_ = np.linalg.lstsq(Xk, ew, rcond=1e-10)
        fitted = Xk @ coef
        rest = ew - fitted
        s_expl += float(np.vdot(fitted, fitted).real)
        s_rest += float(np.vdot(rest, rest).real)
        d_expl += 2 * rank
        d_rest += 2 * (W - rank)
        idx = np.flatnonzero(keep)
        for j, col in enumerate(idx):
            others = np.delete(Xk, j, axis=1)
            if others.shape[1]:
                c2, *_ = np.linalg.lstsq(others, ew, rcond=1e-10)
                r2 = ew - others @ c2
            else:
                r2 = ew
            drop[col] += float(np.vdot(r2, r2).real) - float(np.vdot(rest, rest).real)
            seen[col] += 1
    scores = tuple(scores)
    if d_expl == 0 or d_rest == 0 or s_rest <= 0:
        return RecordVerdict(np.nan, (d_expl, d_rest), np.nan, shifts, tuple([np.nan] * q), W, alpha,
                             ("the verdict needs at least one window of "
                              f"{W} lines where the input is nonzero",), scores)
    F = (s_expl / d_expl) / (s_rest / d_rest)
    p = float(f_sf(F, d_expl, d_rest))
    per = [float(f_sf((drop[j] / (2 * seen[j])) / (s_rest / d_rest), 2 * seen[j], d_rest)) if seen[j] else np.nan
           for j in range(q)]
    return _holm_verdict(F, (d_expl, d_rest), p, shifts, per, W, alpha, scores)


INPUT_NSR_MAX = 0.02
"""With a noisy input: a regressor column enters a window's test only where the input's noise is at
most this share of its power there (its mean over the window's lines, the noise's known
s_u^2 / N per line taken off): where the noise dominates, the column is the noise itself, which
the residual holds through the model's gain, and the refits' doubling of it is no longer linear."""


def window_estimates(U, residual, lines, L, kmax):
    """Per window of :func:`record_verdict`: the least-squares coefficients of the normalised
    residual on the input and its shifts (all columns), for the refits of a noisy input."""
    N = U.size
    lines = np.asarray(lines)
    e = np.asarray(residual, dtype=complex)
    shifts = tuple(range(-(kmax + 1), kmax + 2))
    X = np.stack([U[(lines - k * L) % N] for k in shifts], axis=1)
    W = _window(len(shifts))
    return [np.linalg.lstsq(X[w * W:(w + 1) * W], e[w * W:(w + 1) * W], rcond=1e-10)[0]
            for w in range(lines.size // W)]


def noisy_input_verdict(U, residual, lines, L, kmax, *, sigma, level, dof, noise_power, draws,
                        alpha: float = ALPHA, scores=()) -> RecordVerdict:
    """The windowed test of :func:`record_verdict` with a noisy input of known level (METHOD.md
    section 17, "A noisy input: the covariance and the verdict"): per window the coefficients b
    of the normalised residual on the input and its shifts, less the refits' mean shift
    (``draws``: :func:`window_estimates` of each refit, fitted on the input with more noise
    added), against their covariance A sigma_w A^T (A the real least-squares operator, sigma_w
    the residual's covariance on the window's lines, the input noise's share included) plus the
    shifts' over the draws; the Wald statistics summed over the windows, over the residual's
    ``level``, are F(d1, dof). A column enters only where the input's noise-to-signal power
    (``noise_power`` = s_u^2 / N per line) is at most INPUT_NSR_MAX. ``sigma``: the covariance
    of the normalised residual's real rows (Re of all lines, then Im)."""
    from .._dist import f_sf

    N = U.size
    lines = np.asarray(lines)
    n = lines.size
    e = np.asarray(residual, dtype=complex)
    shifts = tuple(range(-(kmax + 1), kmax + 2))
    X = np.stack([U[(lines - k * L) % N] for k in shifts], axis=1)
    q = len(shifts)
    W = _window(q)
    n_win = n // W
    T = 0.0
    d1 = 0
    per_T, per_d = np.zeros(q), np.zeros(q, int)
    for w in range(n_win):
        rows = np.arange(w * W, (w + 1) * W)
        Xw, ew = X[rows], e[rows]
        power = np.mean(np.abs(Xw) ** 2, axis=0)
        keep = (power - noise_power) > noise_power / INPUT_NSR_MAX
        if not keep.any():
            continue
        A = np.linalg.pinv(Xw[:, keep], rcond=1e-10)
        rank = int(np.linalg.matrix_rank(Xw[:, keep]))
        if rank == 0 or rank >= W:
            continue
        b = A @ ew
        Ar = np.block([[A.real, -A.imag], [A.imag, A.real]])
        ridx = np.concatenate([rows, n + rows])
        V = Ar @ sigma[np.ix_(ridx, ridx)] @ Ar.T
        br = np.concatenate([b.real, b.imag])
        if len(draws):
            d = np.array([np.concatenate([dk[w][keep].real, dk[w][keep].imag]) for dk in draws]) - br
            br = br - d.mean(axis=0)
            if len(draws) > 1:
                V = V + np.cov(d, rowvar=False, ddof=1).reshape(V.shape) / len(draws)
        T += float(br @ np.linalg.pinv(V, hermitian=True) @ br)
        d1 += 2 * rank
        m = int(keep.sum())
        for j, col in enumerate(np.flatnonzero(keep)):
            sub = [j, m + j]
            T_j = float(br[sub] @ np.linalg.pinv(V[np.ix_(sub, sub)], hermitian=True) @ br[sub])
            per_T[col] += T_j
            per_d[col] += 2
    scores = tuple(scores)
    if d1 == 0 or dof <= 0:
        return RecordVerdict(np.nan, (d1, dof), np.nan, shifts, tuple([np.nan] * q), W, alpha,
                             ("the verdict needs at least one window of "
                              f"{W} lines where the input stands above its noise",), scores)
    F = (T / d1) / level
    p = float(f_sf(F, d1, dof))
    per = [float(f_sf((per_T[j] / per_d[j]) / level, int(per_d[j]), dof)) if per_d[j] else np.nan for j in range(q)]
    return _holm_verdict(F, (d1, dof), p, shifts, per, W, alpha, scores)


def _holm_verdict(F, dofs, p, shifts, per, W, alpha, scores) -> RecordVerdict:
    """Holm's method over the windowed test's pooled p-value and the score tests, and the names
    of what the rejected ones point to."""
    d_expl, d_rest = dofs
    q = len(shifts)
    # Holm over the windowed test and the score tests: the smallest p against alpha / m, ...
    ps = [p] + [t[4] for t in scores]
    m = len(ps)
    passed = set()
    for rank_i, i in enumerate(np.argsort(ps)):
        if not ps[i] < alpha / (m - rank_i):
            break
        passed.add(int(i))
    errors = []
    for i in sorted(passed - {0}):
        name, Fc, d1, d2, pc = scores[i - 1]
        coef, k = name.split(" harmonic ")
        errors.append(f"the residual follows harmonic {k} of {coef} (a score test: F = {Fc:.3g} "
                      f"on {d1} and {d2} degrees of freedom, p = {pc:.2g}; Holm at {alpha:g} over {m} tests): "
                      "that harmonic is missing in the coefficient")
    if 0 in passed:
        errors.append(f"the residual is explained by the input (F = {F:.3g} on {d_expl} and {d_rest} degrees of "
                      f"freedom, p = {p:.2g} < {alpha:g}): the structure misses what the data show")
        # Holm over the shifts: name those that stand out
        order = np.argsort(np.nan_to_num(per, nan=1.0))
        for rank_j, j in enumerate(order):
            if per[j] >= alpha / (q - rank_j):
                break
            k = shifts[j]
            if k == 0:
                errors.append(f"on the same line (k = 0, p = {per[j]:.2g}): dynamics the model lacks (an order "
                              "too few, or the mean system's shape)")
            else:
                errors.append(f"on the input shifted by {k:+d} w0 (p = {per[j]:.2g}): a harmonic {abs(k)} missing "
                              "in a coefficient")
    return RecordVerdict(float(F), (d_expl, d_rest), p, shifts, tuple(per), W, alpha, tuple(errors), scores)
