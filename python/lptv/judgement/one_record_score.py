"""Score tests of a one-record fit for one more harmonic per coefficient (METHOD.md section 17,
"Score tests for one more harmonic per coefficient").

For each coefficient the model is extended by the next harmonic of that coefficient alone; the
output-error residual's Jacobian at the fit over the fitted parameters (J) and the two new ones
(J_c) is taken by central differences of the core's prediction; the share of the scaled residual
that J_c explains beyond J is the score statistic, judged as F(2, dof - 2) against the rest.
"""
from __future__ import annotations

from typing import List, NamedTuple, Tuple

import numpy as np

from .. import _core

STEP = 1e-6
"""Relative step of the central differences."""


def _columns(par, U, L, eta_free, c, ts, t_degree, idx, which):
    """d Y_hat[idx] / d x_j (complex) for the free parameters j in ``which`` (indices into
    [eta_free, c]) by central differences."""
    x0 = np.concatenate([eta_free, c])
    ne = eta_free.size
    cols = []
    for j in which:
        h = STEP * max(1.0, abs(x0[j]))
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        yp = np.asarray(_core.record_prediction(par, U, L, xp[:ne], xp[ne:], ts, t_degree))[idx]
        ym = np.asarray(_core.record_prediction(par, U, L, xm[:ne], xm[ne:], ts, t_degree))[idx]
        cols.append((yp - ym) / (2 * h))
    return np.stack(cols, axis=1) if cols else np.zeros((idx.size, 0), complex)


def _real(Z, scale):
    return np.concatenate([Z.real, Z.imag], axis=0) * np.concatenate([scale, scale])[:, None]


class ScoreParts(NamedTuple):
    """What the score tests of one fit are built from (:func:`score_parts`)."""

    J: np.ndarray
    """The scaled real Jacobian over the free parameters and the transient's (rows as the cost)."""
    r: np.ndarray
    """The scaled real residual (cost = r^T r)."""
    Q: np.ndarray
    """An orthonormal basis of J's columns."""
    dof: int
    cost: float
    coefficients: list
    """(label, harmonic, J_c') per coefficient: J_c' the new harmonic's two columns less their
    projection on J."""


def score_parts(na, nb, ka, kb, w0, ts_par, U, residual, L, lines, eta, c, var, ts, t_degree,
                continuous) -> ScoreParts:
    """The Jacobians and the residual of :func:`harmonic_score_tests` (same arguments)."""
    lines = np.asarray(lines)
    N = U.size
    idx = lines + (N - 1) // 2 if continuous else lines
    scale = np.sqrt(2.0 / np.asarray(var, float))
    r = np.concatenate([residual.real, residual.imag]) * np.concatenate([scale, scale])
    par = _core.Parametrisation(na, nb, list(ka), list(kb), [], float(w0), float(ts_par))
    free = list(par.free_indices)
    eta_free = np.asarray(eta, float)[free]
    c = np.asarray(c, float)
    J = _real(_columns(par, U, L, eta_free, c, ts, t_degree, idx, range(eta_free.size + c.size)), scale)
    Q, R = np.linalg.qr(J)
    keep = np.abs(np.diag(R)) > 1e-10 * max(np.abs(np.diag(R)).max(initial=0.0), 1e-300)
    Q = Q[:, keep]
    dof = r.size - Q.shape[1]
    cost = float(r @ r)
    names = list(par.eta_names)
    value = dict(zip(names, np.asarray(eta, float)))
    coefs = []
    for is_a, n in [(True, n) for n in range(na + 1)] + [(False, m) for m in range(nb + 1)]:
        kae, kbe = list(ka), list(kb)
        if is_a:
            kae[n] += 1
        else:
            kbe[n] += 1
        pe = _core.Parametrisation(na, nb, kae, kbe, [], float(w0), float(ts_par))
        fe = list(pe.free_indices)
        ne = list(pe.eta_names)
        x = np.array([value.get(ne[i], 0.0) for i in fe])
        label = f"{'a' if is_a else 'b'}{n}"
        K = (kae if is_a else kbe)[n]
        new = [j for j, i in enumerate(fe) if ne[i] in (f"{label}.re{K}", f"{label}.im{K}")]
        Jc = _real(_columns(pe, U, L, x, c, ts, t_degree, idx, new), scale)
        Jc = Jc - Q @ (Q.T @ Jc)
        coefs.append((label, K, Jc))
    return ScoreParts(J, r, Q, dof, cost, coefs)


def score_estimates(parts: ScoreParts) -> dict:
    """Per coefficient's label: the one-step estimate of the new harmonic (Re, Im) from the
    residual, (J_c'^T J_c')^+ J_c'^T r (what the extended fit would move it to, to first order)."""
    return {label: np.linalg.pinv(Jc) @ parts.r for label, _, Jc in parts.coefficients}


def harmonic_score_tests(na, nb, ka, kb, w0, ts_par, U, residual, L, lines, eta, c, var, ts, t_degree,
                         continuous, *, parts=None, sigma=None, draws=()) -> List[Tuple[str, float, int, int, float]]:
    """(coefficient and harmonic, F, 2, dof - 2, p-value) per coefficient a_0..a_na, b_0..b_nb.

    ``eta``: the fit's real parameters (all, as ``fit.eta``), ``c`` its transient coefficients,
    ``residual`` Y - Y_hat on ``lines``, ``var`` the noise variance per line the cost divides by;
    ``parts``: :func:`score_parts` of these, when already made.

    With a noisy input (METHOD.md section 17, "A noisy input: the covariance and the verdict"):
    ``sigma`` the scaled residual's covariance (real rows as the cost's, the input noise's
    share included) and ``draws`` the :func:`score_estimates` of the refits with more noise
    added to the input. The test is then the Wald form of the score: the one-step estimate d of
    the new harmonic less the refits' mean shift (the bias the input noise causes), against its
    covariance G^-1 J_c'^T sigma J_c' G^-1 (G = J_c'^T J_c') plus the shifts' covariance over the
    draws; d^T V^-1 d / rank over the residual's scale r^T r / tr((I - P_J) sigma) is F(rank,
    dof - rank)."""
    from .._dist import f_sf

    if parts is None:
        parts = score_parts(na, nb, ka, kb, w0, ts_par, U, residual, L, lines, eta, c, var, ts, t_degree,
                            continuous)
    r, Q, dof, cost = parts.r, parts.Q, parts.dof, parts.cost
    out = []
    if sigma is not None:
        level = cost / max(float(np.trace(sigma)) - float(np.sum(Q * (sigma @ Q))), 1e-300)
    for label, K, Jc in parts.coefficients:
        if sigma is not None:
            Jp = np.linalg.pinv(Jc)
            rank = int(np.linalg.matrix_rank(Jc, tol=1e-8 * max(np.linalg.norm(Jc), 1e-300)))
            if rank == 0 or dof - rank <= 0:
                continue
            d = Jp @ r
            V = Jp @ sigma @ Jp.T
            if len(draws):
                shifts = np.array([e[label] for e in draws]) - d
                d = d - shifts.mean(axis=0)
                if len(draws) > 1:
                    V = V + np.cov(shifts, rowvar=False, ddof=1).reshape(V.shape) / len(draws)
            T = float(d @ np.linalg.pinv(V, hermitian=True) @ d)
            F = (T / rank) / level
            out.append((f"{label} harmonic {K}", float(F), rank, int(dof - rank), float(f_sf(F, rank, dof - rank))))
            continue
        Qc, Rc = np.linalg.qr(Jc)
        rank = int(np.sum(np.abs(np.diag(Rc)) > 1e-8 * max(np.linalg.norm(Jc), 1e-300)))
        if rank == 0 or dof - rank <= 0:
            continue
        Qc = Qc[:, :rank]
        S = float(np.sum((Qc.T @ r) ** 2))
        rest = max(cost - S, 1e-300)
        F = (S / rank) / (rest / (dof - rank))
        out.append((f"{label} harmonic {K}", float(F), rank, int(dof - rank), float(f_sf(F, rank, dof - rank))))
    return out
