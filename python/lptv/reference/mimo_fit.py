"""METHOD.md section 19's estimators in plain, dense NumPy/SciPy: the vector residue (19.11) as
a dense linear map of all measured lines, its covariance (19.12) and that of all rows, WGTLS
with vector residues and A_na,0 = I, SML on the exact likelihood, the covariances and the CRB.

The independent route :mod:`lptv.estimation.mimo_fit` is tested against. It shares the conventions (listed
here) but none of the code: the residue is e = G(xi) z with G built entry by entry for every
row, output, line and channel; the Jacobian's column j is G(e_j) z; the noise of every row is
G Cz G^H over the whole stacked noise vector; CJ_W is tr(W G_j' Cz G_j^H) for every pair of
parameters; WGTLS is a generalised symmetric eigenproblem (scipy.linalg.eigh) of the tall real
Jacobian's Gram matrix and CJ_W, not a QR, Cholesky and SVD; SML minimises the cost by
Gauss-Newton steps on the gradient 2 Re(e_j^H w) - w^H dC_j w (dC_j the derivative of the
covariance) with the dense Fisher information as the Hessian, not the production's
denoised-spectra route.

Conventions (shared): spectra on lines 0..L (``fft(x)[l] / N``); C[l] the covariance of the
mean of [Y_l; U_l] (outputs first); xi stacks each output's row of real parameters, a row being
the coefficients (a, n, q) for n = 0..na, q = 0..ny-1, then (b, m, r), each as Re c_0, Re c_1,
Im c_1, .., Re c_K, Im c_K with K = ka[n, q] (kb[m, r]); the normalised entries are Re c_0 of
(a, na, q) in row p, equal to delta_pq. Nothing here calls ``lptv._core`` or the production
modules.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

__all__ = ["Structure", "residue_map", "residue", "jacobian", "line_covariances", "row_covariance",
           "wgtls", "sml", "fisher", "sandwich", "crb"]


class Structure:
    """na, nb, ka (na+1, ny) and kb (nb+1, nu) per order and column (kb = -1: no entry), w0, ts;
    the parameter list."""

    def __init__(self, na, nb, ka, kb, w0, ts=None):
        self.ka, self.kb = np.atleast_2d(np.asarray(ka, int)), np.atleast_2d(np.asarray(kb, int))
        self.na, self.nb = int(na), int(nb)
        self.ny, self.nu = self.ka.shape[1], self.kb.shape[1]
        self.w0, self.ts = float(w0), float(ts or 0.0)
        self.coefs = [("a", n, q, self.ka[n, q]) for n in range(self.na + 1) for q in range(self.ny)] + \
                     [("b", m, r, self.kb[m, r]) for m in range(self.nb + 1) for r in range(self.nu)
                      if self.kb[m, r] >= 0]   # kb = -1: the entry absent
        self.row = sum(2 * K + 1 for *_, K in self.coefs)
        self.K = int(max(self.ka.max(), self.kb.max()))
        fixed = []
        j = 0
        for side, n, c, K in self.coefs:
            if side == "a" and n == self.na:
                fixed.append(j)
            j += 2 * K + 1
        self.fixed = np.array([[p * self.row + fixed[q] for q in range(self.ny)] for p in range(self.ny)])
        self.free = np.array([i for i in range(self.ny * self.row) if i not in set(self.fixed.ravel())])

    def s(self, i):
        return np.exp(1j * self.w0 * i * self.ts) if self.ts else 1j * self.w0 * i

    def coefficients(self, xi):
        """a[n][p][q] and b[m][p][r] as dicts {k: complex} from the real vector xi."""
        xi = np.asarray(xi, float)
        a, b = {}, {}
        for p in range(self.ny):
            j = p * self.row
            for side, n, c, K in self.coefs:
                d = {0: complex(xi[j])}
                for k in range(1, K + 1):
                    d[k] = complex(xi[j + 2 * k - 1], xi[j + 2 * k])
                    d[-k] = d[k].conjugate()
                (a if side == "a" else b)[(n, p, c)] = d
                j += 2 * K + 1
        return a, b


def residue_map(st: Structure, xi, rows, n_lines):
    """G (len(rows) ny, n_lines (ny + nu)): e = G z, z = [Y_i; U_i] stacked over lines 0..n_lines-1."""
    a, b = st.coefficients(xi)
    nc = st.ny + st.nu
    G = np.zeros((len(rows) * st.ny, n_lines * nc), complex)
    for r, l in enumerate(rows):
        for p in range(st.ny):
            for (n, pp, q), d in a.items():
                if pp != p:
                    continue
                for k, v in d.items():
                    i = l - k
                    G[r * st.ny + p, i * nc + q] += v * st.s(i) ** n
            for (m, pp, c), d in b.items():
                if pp != p:
                    continue
                for k, v in d.items():
                    i = l - k
                    G[r * st.ny + p, i * nc + st.ny + c] -= v * st.s(i) ** m
    return G


def _z(Y, U):
    return np.concatenate([Y, U], axis=1).ravel()


def _cz(C):
    return scipy.linalg.block_diag(*C)


def residue(st, xi, rows, Y, U):
    return residue_map(st, xi, rows, Y.shape[0]) @ _z(Y, U)


def jacobian(st, rows, Y, U):
    """d e / d xi (e is linear and homogeneous in xi): column j is G(e_j) z."""
    n = st.ny * st.row
    z = _z(Y, U)
    return np.column_stack([residue_map(st, np.eye(n)[j], rows, Y.shape[0]) @ z for j in range(n)])


def row_covariance(st, xi, rows, C):
    """E{e e^H} of all rows (every correlation through shared lines)."""
    G = residue_map(st, xi, rows, C.shape[0])
    return G @ _cz(C) @ G.conj().T


def line_covariances(st, xi, rows, C):
    """C_{e,l} of eq. 19.12: the diagonal blocks of the rows' covariance."""
    CE = row_covariance(st, xi, rows, C)
    ny = st.ny
    return np.array([CE[r * ny:(r + 1) * ny, r * ny:(r + 1) * ny] for r in range(len(rows))])


def _normalised(st, V):
    Nm = V[st.fixed.ravel()]
    return V @ np.linalg.solve(Nm, np.eye(st.ny).ravel())


def _block_diag_weights(Cl):
    return scipy.linalg.block_diag(*[np.linalg.inv(c) for c in Cl])


def wgtls(st, experiments, tol=1e-10, max_iter=50):
    """experiments: list of (Y, U, C, rows). GTLS with unit weights, then W_l = C_{e,l}^-1 of the
    last estimate, until the relative change is below tol."""
    n = st.ny * st.row
    d = st.ny * st.ny
    maps = [[residue_map(st, np.eye(n)[j], rows, Y.shape[0]) for j in range(n)] for Y, U, C, rows in experiments]

    def solve(Ws):
        H = np.zeros((n, n))
        CJ = np.zeros((n, n))
        for (Y, U, C, rows), Gs, W in zip(experiments, maps, Ws):
            z, Cz = _z(Y, U), _cz(C)
            J = np.column_stack([g @ z for g in Gs])
            H += np.real(J.conj().T @ W @ J)
            P = np.array([W @ g @ Cz for g in Gs])
            M = np.array(Gs)
            CJ += np.real(np.einsum("kaz,jaz->jk", P, M.conj()))
        CJ = 0.5 * (CJ + CJ.T)
        try:
            lam, V = scipy.linalg.eigh(H, CJ)
        except np.linalg.LinAlgError:
            # CJ singular (an input without noise): the pencil reversed, CJ v = mu H v with H
            # positive definite; the smallest ratios are the largest mu (mu = 0: no noise)
            mu, V = scipy.linalg.eigh(CJ, H)
            V, lam = V[:, ::-1], 1.0 / mu[::-1]
        return _normalised(st, V[:, :d]), lam

    Ws = [np.eye(len(e[3]) * st.ny) for e in experiments]
    xi, lam = solve(Ws)
    for it in range(1, max_iter + 1):
        Ws = [_block_diag_weights(line_covariances(st, xi, rows, C)) for Y, U, C, rows in experiments]
        prev = xi
        xi, lam = solve(Ws)
        if np.linalg.norm(xi - prev) <= tol * np.linalg.norm(xi):
            break
    return xi, lam


def _cost_grad(st, xi, experiments):
    n = st.ny * st.row
    V, g = 0.0, np.zeros(n)
    for Y, U, C, rows in experiments:
        z, Cz = _z(Y, U), _cz(C)
        G = residue_map(st, xi, rows, Y.shape[0])
        e = G @ z
        CE = G @ Cz @ G.conj().T
        w = np.linalg.solve(CE, e)
        V += float(np.real(np.vdot(e, w)))
        for j in st.free:       # the gradient over the free entries (0 at the fixed ones)
            Gj = residue_map(st, np.eye(n)[j], rows, Y.shape[0])
            dC = Gj @ Cz @ G.conj().T
            dC = dC + dC.conj().T
            g[j] += 2 * np.real(np.vdot(Gj @ z, w)) - np.real(np.vdot(w, dC @ w))
    return V, g


def sml(st, experiments, xi0, tol=1e-8, max_iter=50):
    """Minimise sum e^H C_E^-1 e over the free entries of xi from xi0 by Gauss-Newton: the step
    F^-1 g with F the reference's own Fisher information (:func:`fisher`, the cost's Hessian to
    first order) and g the cost's exact gradient (:func:`_cost_grad`, C_E's dependence on xi
    included), halved until the cost does not rise. Stops when the step is below ``tol`` of every
    free entry's standard deviation sqrt((F^-1)_jj), or when no halving lowers the cost (a minimum
    to rounding). The minimum is the cost's, whatever the route to it: the production's
    Levenberg-Marquardt on the whitened band is a different computation of the same optimum.
    Returns (xi, info) with info's 'iterations' and 'converged'."""
    free = np.asarray(st.free)
    xi = np.array(xi0, float)
    V, g = _cost_grad(st, xi, experiments)
    for it in range(1, max_iter + 1):
        F = fisher(st, xi, experiments)
        step = np.linalg.solve(F, g[free])
        std = np.sqrt(np.diag(np.linalg.inv(F)))
        t = 1.0
        while t >= 1e-10:
            xn = xi.copy()
            xn[free] -= t * step
            Vn, gn = _cost_grad(st, xn, experiments)
            if Vn <= V:
                break
            t /= 2
        else:
            return xi, dict(iterations=it, converged=True)      # no step lowers the cost
        xi, V, g = xn, Vn, gn
        if np.max(np.abs(t * step) / std) < tol:
            return xi, dict(iterations=it, converged=True)
    return xi, dict(iterations=max_iter, converged=False)


def _denoised_jacobian(st, xi, Y, U, C, rows):
    """d e / d xi at the spectra the model explains exactly nearest the data: z0 = z - Cz G^H C_E^-1 e."""
    z, Cz = _z(Y, U), _cz(C)
    G = residue_map(st, xi, rows, Y.shape[0])
    CE = G @ Cz @ G.conj().T
    z0 = z - Cz @ G.conj().T @ np.linalg.solve(CE, G @ z)
    Z0 = z0.reshape(Y.shape[0], -1)
    return jacobian(st, rows, Z0[:, :st.ny], Z0[:, st.ny:]), CE


def fisher(st, xi, experiments):
    """2 Re(J0^H C_E^-1 J0) over the free entries, summed over the experiments."""
    F = 0.0
    for Y, U, C, rows in experiments:
        J, CE = _denoised_jacobian(st, xi, Y, U, C, rows)
        J = J[:, st.free]
        F = F + 2 * np.real(J.conj().T @ np.linalg.solve(CE, J))
    return F


def sandwich(st, xi, experiments):
    """WGTLS's first-order covariance H^-1 (1/2 Re J^H W C_E W J) H^-1, H = Re J^H W J."""
    H, Mt = 0.0, 0.0
    for Y, U, C, rows in experiments:
        J, CE = _denoised_jacobian(st, xi, Y, U, C, rows)
        J = J[:, st.free]
        W = _block_diag_weights(line_covariances(st, xi, rows, C))
        H = H + np.real(J.conj().T @ W @ J)
        Mt = Mt + 0.5 * np.real(J.conj().T @ W @ CE @ W @ J)
    Hi = np.linalg.inv(H)
    return Hi @ Mt @ Hi


def crb(st, xi_true, experiments):
    """F^-1 at the noiseless spectra with the true (co)variances of the means."""
    return np.linalg.inv(fisher(st, xi_true, experiments))
