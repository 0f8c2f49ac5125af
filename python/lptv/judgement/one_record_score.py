"""Score tests of a one-record fit for one more harmonic per coefficient (METHOD.md section 17,
"Score tests for one more harmonic per coefficient").

For each coefficient the model is extended by the next harmonic of that coefficient alone; the
output-error residual's Jacobian at the fit over the fitted parameters (J) and the two new ones
(J_c) is taken by central differences of the core's prediction; the share of the scaled residual
that J_c explains beyond J is the score statistic, judged as F(2, dof - 2) against the rest.
"""
from __future__ import annotations

from typing import List, Tuple

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


def harmonic_score_tests(na, nb, ka, kb, w0, ts_par, U, residual, L, lines, eta, c, var, ts, t_degree,
                         continuous) -> List[Tuple[str, float, int, int, float]]:
    """(coefficient and harmonic, F, 2, dof - 2, p-value) per coefficient a_0..a_na, b_0..b_nb.

    ``eta``: the fit's real parameters (all, as ``fit.eta``), ``c`` its transient coefficients,
    ``residual`` Y - Y_hat on ``lines``, ``var`` the noise variance per line the cost divides by."""
    from .._dist import f_sf

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
    out = []
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
