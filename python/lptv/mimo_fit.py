"""WGTLS and SML for several inputs and outputs (METHOD.md section 19, eqs. 19.11-19.15), NumPy
on the mean spectra and their (co)variances (:class:`lptv.MimoFrequencyData`).

The route (per experiment, rows l sorted, every line a row reads a measured line >= 1):

- regressors Phi (rows, n_phi), phi_l[(c, k)] = s_{l-k}^n X_{l-k,col(c)}, X = Y for an a
  coefficient and -U for a b coefficient, and their noise Cphi_l = E{conj(dphi_l) dphi_l^T}
  (nonzero only between entries of the same harmonic k, which read the same line);
- the residue e_l = Theta^T phi_l (ny), its per-line covariance C_{e,l} = Theta^T conj(Cphi_l)
  conj(Theta) (eq. 19.12, WGTLS's weights), and the full covariance C_E of all rows, banded
  (rows share lines when |l - l'| <= 2K), from the band blocks [AA_{l,i}, -BB_{l,i}];
- WGTLS: the d = ny^2 smallest generalised singular vectors of the whitened real Jacobian and
  CJ_W^{1/2} (column scaling, QR, Cholesky of CJ_W, SVD), then A_{na,0} = I;
- SML: Levenberg-Marquardt on e^H C_E^-1 e over the free parameters, gradient and Fisher
  information from the Jacobian at the denoised spectra (section 10's route in complex form).

The dense reference it is tested against is :mod:`lptv.reference.mimo_fit`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional, Sequence

import numpy as np
import scipy.linalg

from .mimo_data import MimoFrequencyData, MimoStructure

VARIANCE_FLOOR = 1e-14
"""Relative floor of the residue covariance's eigenvalues when it becomes a weight (as for one output)."""


class FitError(ValueError):
    """A fit that cannot be made on these data (the message says why)."""


def regressors(d: MimoFrequencyData, st: MimoStructure, rows, Y=None, U=None) -> np.ndarray:
    """Phi (rows, n_phi); Y, U replace the data's spectra (the denoised ones of SML)."""
    Y = d.Y if Y is None else Y
    U = d.U if U is None else U
    i = np.asarray(rows)[:, None] - st.p_k[None, :]
    f = st.line_variable(i) ** st.p_order[None, :]
    X = np.where(st.p_is_a[None, :], Y[i, np.minimum(st.p_col, Y.shape[1] - 1)[None, :]],
                 -U[i, np.minimum(st.p_col, U.shape[1] - 1)[None, :]])
    return f * X


def regressor_noise(d: MimoFrequencyData, st: MimoStructure, rows) -> np.ndarray:
    """Cphi (rows, n_phi, n_phi) = E{conj(dphi_l) dphi_l^T}."""
    rows = np.asarray(rows)
    n = st.n_phi
    out = np.zeros((rows.size, n, n), complex)
    i = rows[:, None] - st.p_k[None, :]
    f = st.line_variable(i) ** st.p_order[None, :] * np.where(st.p_is_a, 1.0, -1.0)[None, :]
    for k in np.unique(st.p_k):
        idx = np.flatnonzero(st.p_k == k)
        ch = st.p_channel[idx]
        C = d.C[rows - k][:, ch[None, :], ch[:, None]]          # [r, a, b] = C[c_b, c_a]
        out[:, idx[:, None], idx[None, :]] = np.conj(f[:, idx])[:, :, None] * f[:, idx][:, None, :] * C
    return out


def line_covariance(Cphi: np.ndarray, Theta: np.ndarray) -> np.ndarray:
    """C_{e,l} (rows, ny, ny), eq. 19.12."""
    return np.einsum("ap,rab,bq->rpq", Theta, np.conj(Cphi), np.conj(Theta), optimize=True)


def band_blocks(st: MimoStructure, Theta: np.ndarray, rows) -> np.ndarray:
    """G[r, K + k] = [AA_{l,l-k}, -BB_{l,l-k}] (rows, 2K+1, ny, ny+nu) for row l = rows[r]."""
    rows = np.asarray(rows)
    K = st.K
    G = np.zeros((rows.size, 2 * K + 1, st.ny, st.ny + st.nu), complex)
    s = st.line_variable(rows[:, None] - st.p_k[None, :]) ** st.p_order[None, :]   # (rows, n_phi)
    sign = np.where(st.p_is_a, 1.0, -1.0)
    for j in range(st.n_phi):
        G[:, K + st.p_k[j], :, st.p_channel[j]] += sign[j] * s[:, j, None] * Theta[j][None, :]
    return G


def full_covariance_band(d: MimoFrequencyData, st: MimoStructure, Theta, rows):
    """C_E of all rows' residues (scalar index ny r + p) in LAPACK's upper band storage, and its
    bandwidth: rows r < r' share the lines i = l - k = l' - k' (|l - l'| <= 2K)."""
    rows = np.asarray(rows)
    K, ny = st.K, st.ny
    R = rows.size
    G = band_blocks(st, Theta, rows)
    u = (2 * K + 1) * ny - 1
    ab = np.zeros((u + 1, R * ny), complex)
    ks = np.arange(-K, K + 1)
    Cl = d.C[rows[:, None] - ks[None, :]]                     # (R, 2K+1, c, c): line l - k
    for o in range(0, min(2 * K, R - 1) + 1):
        a = np.arange(R - o)
        dl = rows[a + o] - rows[a]
        blocks = np.zeros((a.size, ny, ny), complex)
        for kk in range(2 * K + 1):
            k2 = kk + dl                                      # l' - i = k + (l' - l)
            ok = k2 <= 2 * K
            if not np.any(ok):
                continue
            aa = a[ok]
            g1 = G[aa, kk]
            g2 = G[aa + o, k2[ok]]
            blocks[ok] += np.einsum("rpc,rcd,rqd->rpq", g1, Cl[aa, kk], np.conj(g2), optimize=True)
        for p in range(ny):
            for q in range(ny):
                i = a * ny + p
                j = (a + o) * ny + q
                keep = i <= j
                ab[u + i[keep] - j[keep], j[keep]] = blocks[keep, p, q]
    return ab, u


@dataclass
class Experiment:
    """One experiment's data with its rows and the terms that do not change with theta."""

    data: MimoFrequencyData
    rows: np.ndarray
    Phi: np.ndarray = field(init=False)
    Cphi: np.ndarray = field(init=False)
    Psi: np.ndarray = field(init=False)
    Cpsi: np.ndarray = field(init=False)

    def prepare(self, st: MimoStructure) -> "Experiment":
        self.Phi = regressors(self.data, st, self.rows)
        self.Cphi = regressor_noise(self.data, st, self.rows)
        self.Psi = self.Phi @ st.T
        self.Cpsi = np.einsum("ai,rab,bj->rij", np.conj(st.T), self.Cphi, st.T, optimize=True)
        return self


def _weights(C: np.ndarray) -> np.ndarray:
    """W_l = C_{e,l}^-1 with the eigenvalues floored at VARIANCE_FLOOR times the largest."""
    lam, V = np.linalg.eigh(C)
    top = lam.max()
    if not np.isfinite(top) or top <= 0:
        raise FitError("the residue covariance is not positive: the data carry no noise on the rows")
    lam = np.maximum(lam, VARIANCE_FLOOR * top)
    return np.einsum("rpi,ri,rqi->rpq", V, 1.0 / lam, np.conj(V))


def _whitened(ex: Experiment, st: MimoStructure, W: Optional[np.ndarray]):
    """The real Jacobian [Re; Im] of L_l^-1 e_l (W_l = L_l^-H L_l^-1) and CJ_W's contribution."""
    R, ny, nr = ex.rows.size, st.ny, st.n_row
    if W is None:
        W = Linv = np.broadcast_to(np.eye(ny), (R, ny, ny))
    else:
        Linv = np.conj(np.swapaxes(np.linalg.cholesky(W), 1, 2))    # M^H M = W, M = L^-1 for C_e = L L^H
    J = np.einsum("rqp,ri->rqpi", Linv, ex.Psi).reshape(R * ny, ny * nr)
    CJ = np.einsum("rpq,rij->piqj", W, ex.Cpsi, optimize=True).reshape(ny * nr, ny * nr).real
    return np.vstack([J.real, J.imag]), CJ


def _normalise(V: np.ndarray, st: MimoStructure) -> np.ndarray:
    """The element of span(V) (d columns) with A_{na,0} = I."""
    Nmat = V[st.fixed.ravel()]
    c = np.eye(st.ny).ravel()
    try:
        alpha = np.linalg.solve(Nmat, c)
    except np.linalg.LinAlgError:
        raise FitError("the normalisation A_na,0 = I cannot be applied: the estimated leading matrix's mean is "
                       "singular in the subspace of the smallest singular values (orders or harmonic counts "
                       "too high, or the inputs do not span nu directions on enough lines)") from None
    return V @ alpha


def gtls_subspace(Jx: np.ndarray, CJ: Optional[np.ndarray], d: int):
    """The d right generalised singular vectors of (Jx, CJ^{1/2}) of the smallest values, and all
    generalised singular values ascending (CJ None: the plain right singular vectors, TLS)."""
    n = Jx.shape[1]
    norms = np.linalg.norm(Jx, axis=0)
    sc = 1.0 / np.where(norms > 0, norms, 1.0)
    R = np.linalg.qr(Jx * sc, mode="r") if Jx.shape[0] > n else Jx * sc
    if CJ is None:
        _, s, Vt = np.linalg.svd(R)
        return sc[:, None] * Vt[-d:].T, s[::-1]
    Cs = CJ * np.outer(sc, sc)
    try:
        Lc = np.linalg.cholesky(0.5 * (Cs + Cs.T))
    except np.linalg.LinAlgError:
        raise FitError("the column covariance CJ_W is singular: some parameters' regressors carry no noise "
                       "(an input measured without noise); not built yet for several inputs and outputs") from None
    M = scipy.linalg.solve_triangular(Lc, R.T, lower=True).T          # R Lc^-T
    _, s, Vt = np.linalg.svd(M)
    Z = scipy.linalg.solve_triangular(Lc.T, Vt[-d:].T, lower=False)  # Lc^-T z
    return sc[:, None] * Z, s[::-1]


def wgtls(exps: Sequence[Experiment], st: MimoStructure, *, tol=1e-10, max_iter=50, method="wgtls"):
    """WGTLS with vector residues (METHOD.md section 19): xi, iterations, converged, singular values."""
    d = st.ny * st.ny
    noise_free = all(np.max(np.abs(ex.data.C)) == 0.0 for ex in exps)

    def solve(Ws):
        parts = [_whitened(ex, st, W) for ex, W in zip(exps, Ws)]
        Jx = np.vstack([p[0] for p in parts])
        CJ = None if noise_free else sum(p[1] for p in parts)
        V, s = gtls_subspace(Jx, CJ, d)
        return _normalise(V, st), s

    xi, s = solve([None] * len(exps))
    it, converged = 0, True
    if method == "wgtls" and not noise_free:
        converged = False
        for it in range(1, max_iter + 1):
            Th = st.theta(xi)
            Ws = [_weights(line_covariance(ex.Cphi, Th)) for ex in exps]
            prev = xi
            xi, s = solve(Ws)
            if np.linalg.norm(xi - prev) <= tol * np.linalg.norm(xi):
                converged = True
                break
    return xi, it, converged, s, noise_free


class Likelihood:
    """e^H C_E^-1 e over the experiments (eq. 19.13 with the rows' correlation), its gradient and
    Fisher information over the free parameters, from the Jacobian at the denoised spectra."""

    def __init__(self, exps: Sequence[Experiment], st: MimoStructure):
        self.exps, self.st = list(exps), st

    def evaluate(self, xi, derivatives=True):
        st = self.st
        Th = st.theta(xi)
        cost, grad, F = 0.0, 0.0, 0.0
        free = st.free
        for ex in self.exps:
            e = (ex.Phi @ Th).ravel()                               # scalar index ny r + p
            ab, _ = full_covariance_band(ex.data, st, Th, ex.rows)
            try:
                cf = scipy.linalg.cholesky_banded(ab, lower=False)
            except np.linalg.LinAlgError:
                raise FitError("the residue covariance of the rows is not positive definite") from None
            w = scipy.linalg.cho_solve_banded((cf, False), e)
            cost += float(np.real(np.vdot(e, w)))
            if not derivatives:
                continue
            J0 = self._jacobian0(ex, Th, w.reshape(-1, st.ny))[:, free]
            CiJ = scipy.linalg.cho_solve_banded((cf, False), J0)
            grad = grad + 2.0 * np.real(J0.conj().T @ w)
            F = F + 2.0 * np.real(J0.conj().T @ CiJ)
        return cost, grad, F

    def _jacobian0(self, ex: Experiment, Th, w):
        """d e / d xi at the denoised spectra z0_i = z_i - C_i sum_l G_{l,i}^H w_l."""
        st = self.st
        d = ex.data
        G = band_blocks(st, Th, ex.rows)                            # (R, 2K+1, ny, c)
        ks = np.arange(-st.K, st.K + 1)
        corr = np.zeros((d.max_line + 1, st.ny + st.nu), complex)
        gw = np.einsum("rkpc,rp->rkc", np.conj(G), w)               # G^H w per (row, line)
        np.add.at(corr, ex.rows[:, None] - ks[None, :], gw)
        z0 = np.concatenate([d.Y, d.U], axis=1) - np.einsum("lcd,ld->lc", d.C, corr)
        Psi0 = regressors(d, st, ex.rows, Y=z0[:, :st.ny], U=z0[:, st.ny:]) @ st.T
        R, ny, nr = ex.rows.size, st.ny, st.n_row
        J = np.zeros((R, ny, ny, nr), complex)
        for p in range(ny):
            J[:, p, p, :] = Psi0
        return J.reshape(R * ny, ny * nr)


def sml(exps: Sequence[Experiment], st: MimoStructure, xi0, *, tol=1e-10, max_iter=50):
    """Levenberg-Marquardt on the exact likelihood from xi0: xi, cost, F (free), steps, converged.

    A step whose predicted decrease of the cost is below 8 eps cost is not tried (the cost is at
    its minimum to rounding); the fit stops when an accepted step is below tol relative to the
    parameters, or when no damping lowers the cost."""
    lik = Likelihood(exps, st)
    free = st.free
    xi = np.array(xi0, float)
    cost, g, F = lik.evaluate(xi)
    mu, converged, steps = 1e-6, False, 0
    eps = np.finfo(float).eps
    while steps < max_iter:
        D = np.diag(np.maximum(np.diag(F), eps * np.max(np.diag(F))))
        try:
            step = -np.linalg.solve(F + mu * D, g)
        except np.linalg.LinAlgError:
            step = None
        if step is not None:
            pred = -(g @ step + 0.5 * step @ F @ step)
            if pred <= 8 * eps * max(cost, 1.0):
                converged = True
                break
            trial = xi.copy()
            trial[free] += step
            c_new = lik.evaluate(trial, derivatives=False)[0]
            if c_new < cost:
                xi = trial
                steps += 1
                mu = max(mu / 10.0, 1e-12)
                cost, g, F = lik.evaluate(xi)
                if np.linalg.norm(step) <= tol * np.linalg.norm(xi[free]):
                    converged = True
                    break
                continue
        mu *= 10.0
        if mu > 1e12:
            converged = True        # no step lowers the cost: a minimum to rounding
            break
    return xi, cost, F, steps, converged


def sandwich(exps: Sequence[Experiment], st: MimoStructure, xi) -> np.ndarray:
    """WGTLS's first-order covariance over the free parameters: H^-1 (1/2 Re J^H W C_E W J) H^-1,
    H = Re J^H W J, W block diagonal (C_{e,l}^-1), J at the denoised spectra."""
    Th = st.theta(xi)
    free = st.free
    H, Mt = 0.0, 0.0
    lik = Likelihood(exps, st)
    for ex in exps:
        e = (ex.Phi @ Th)
        ab, u = full_covariance_band(ex.data, st, Th, ex.rows)
        cf = scipy.linalg.cholesky_banded(ab, lower=False)
        w = scipy.linalg.cho_solve_banded((cf, False), e.ravel())
        J = lik._jacobian0(ex, Th, w.reshape(-1, st.ny))[:, free]
        W = _weights(line_covariance(ex.Cphi, Th))
        R, ny = ex.rows.size, st.ny
        WJ = np.einsum("rpq,rqj->rpj", W, J.reshape(R, ny, -1)).reshape(R * ny, -1)
        H = H + np.real(J.conj().T @ WJ)
        CE = _band_to_dense(ab, u)
        Mt = Mt + 0.5 * np.real(WJ.conj().T @ CE @ WJ)
    Hi = np.linalg.inv(H)
    return Hi @ Mt @ Hi


def _band_to_dense(ab, u):
    n = ab.shape[1]
    A = np.zeros((n, n), complex)
    for o in range(u + 1):
        i = np.arange(n - o)
        A[i, i + o] = ab[u - o, i + o]
    return A + np.triu(A, 1).conj().T


def fisher(exps: Sequence[Experiment], st: MimoStructure, xi) -> np.ndarray:
    """2 Re(J0^H C_E^-1 J0) over the free parameters (with noiseless spectra and true (co)variances:
    the Fisher information of eq. 19.15)."""
    return Likelihood(exps, st).evaluate(np.asarray(xi, float))[2]


def expand(cov_free: np.ndarray, st: MimoStructure) -> np.ndarray:
    """A covariance over the free parameters as one over xi (zero rows for the normalised entries)."""
    out = np.zeros((st.n_xi, st.n_xi))
    f = st.free
    out[np.ix_(f, f)] = cov_free
    return out


def prepare(datas: Sequence[MimoFrequencyData], st: MimoStructure, rows_list) -> List[Experiment]:
    return [Experiment(d, np.asarray(r, dtype=int)).prepare(st) for d, r in zip(datas, rows_list)]
