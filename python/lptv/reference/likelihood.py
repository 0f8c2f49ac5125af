"""METHOD.md section 10 in plain NumPy/SciPy: the exact likelihood of LPTV rows and the CRB.

The residue rows of an LPTV model share noisy lines (rows l and l' whenever |l - l'| <= 2K) and
the rows near DC use a line together with its conjugate, so the real residue

    r = [Re e_l1, Im e_l1, Re e_l2, Im e_l2, ...]   (rows in the order given)

is correlated across rows and not circular. Here everything is written out densely: the real
noise vector n of the measured lines, its covariance Cov(n), the real map M(theta) with
r = M x (x the measured spectra in the layout of n), S = M Cov(n) M^T (eq. 16) and the cost
V = r^T S^-1 r (eq. 17) by a dense Cholesky factorisation. The gradient is the direct formula
with dS/dxi; the minimiser is Newton's method on that gradient with a finite-difference
Hessian. None of it is the compiled core's route (banded Cholesky, "denoised data" gradient,
Gauss-Newton), so the two can be tested against each other.

Conventions are those of :mod:`lptv.reference.identification` (theta, xi = Text-coordinates,
norm_index, rows >= 1, line -m = conj of line m, X_l = fft(x)[l] / N). The noise vector holds
4 entries per measured line m = 0..Lmax, [Re dY_m, Im dY_m, Re dU_m, Im dU_m]; at DC only the
real parts carry noise (a real signal's mean is real).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from .identification import Data, Parametrisation, band_rows, line_variable

__all__ = [
    "noise_vector_covariance", "data_vector", "residue_map", "residue_covariance", "exact_cost",
    "exact_cost_gradient", "fisher_information", "crb", "sml_estimate", "xi_of_theta",
    "crb_experiments", "sml_estimate_experiments", "sandwich_terms", "exact_cost_experiments", "denoised",
    "second_order_terms", "second_order_meat",
]


# -- the real noise vector and the real residue map ------------------------------------------

def noise_vector_covariance(data: Data) -> np.ndarray:
    """Cov(n), n = [Re dY_m, Im dY_m, Re dU_m, Im dU_m] for m = 0..Lmax: block diagonal, 4 x 4.

    A circular line (E{dX dX} = 0) splits each (co)variance evenly over the real and
    imaginary parts: with c = E{dY conj(dU)}, E{Re dY Re dU} = E{Im dY Im dU} = Re c / 2 and
    E{Im dY Re dU} = -E{Re dY Im dU} = Im c / 2. The DC line is real: full variances on the
    real parts, nothing on the imaginary ones.
    """
    L = data.max_line
    C = np.zeros((4 * (L + 1), 4 * (L + 1)))
    for m in range(L + 1):
        cy, cu, c = float(data.varY[m]), float(data.varU[m]), complex(data.covYU[m])
        if m == 0:
            block = np.array([[cy, 0, c.real, 0], [0, 0, 0, 0],
                              [c.real, 0, cu, 0], [0, 0, 0, 0]])
        else:
            block = 0.5 * np.array([[cy, 0, c.real, -c.imag],
                                    [0, cy, c.imag, c.real],
                                    [c.real, c.imag, cu, 0],
                                    [-c.imag, c.real, 0, cu]])
        C[4 * m:4 * m + 4, 4 * m:4 * m + 4] = block
    return C


def data_vector(data: Data) -> np.ndarray:
    """x = [Re Y_m, Im Y_m, Re U_m, Im U_m] for m = 0..Lmax (the layout of the noise vector)."""
    return np.column_stack([data.Y.real, data.Y.imag, data.U.real, data.U.imag]).ravel()


def _real_block(a: complex, i: int) -> np.ndarray:
    """The real 2 x 2 map [Re X, Im X] of line |i| -> [Re, Im] of a X_i.

    i > 0: a X; i < 0: a conj(X) (the conjugate line); i = 0: X real (the Im column unused).
    """
    if i > 0:
        return np.array([[a.real, -a.imag], [a.imag, a.real]])
    if i < 0:
        return np.array([[a.real, a.imag], [a.imag, -a.real]])
    return np.array([[a.real, 0.0], [a.imag, 0.0]])


def residue_map(data: Data, par: Parametrisation, rows, theta) -> np.ndarray:
    """M (2|R| x 4(Lmax+1)) with r = M x: e_l = sum_i A_{l,i} Y_i - B_{l,i} U_i, i = l-k.

    Built entry by entry from the band rows A, B. A row near DC may meet line m both directly
    and as the conjugate line -m: the two blocks add. M is linear in theta (over the reals).
    """
    rows = np.asarray(rows)
    L, K = data.max_line, par.K
    lines = rows[:, None] - np.arange(-K, K + 1)[None, :]
    if rows.size and (rows.min() < 1 or np.abs(lines).max() > L):
        raise ValueError(f"rows must be >= 1 and use lines within -{L}..{L}")
    A, B = band_rows(par, theta, rows)
    M = np.zeros((2 * rows.size, 4 * (L + 1)))
    for r in range(rows.size):
        for c in range(2 * K + 1):
            i = int(lines[r, c])
            m = abs(i)
            M[2 * r:2 * r + 2, 4 * m:4 * m + 2] += _real_block(complex(A[r, c]), i)
            M[2 * r:2 * r + 2, 4 * m + 2:4 * m + 4] += _real_block(complex(-B[r, c]), i)
    return M


def residue_covariance(data: Data, par: Parametrisation, rows, theta) -> np.ndarray:
    """S = M Cov(n) M^T (eq. 16), dense."""
    M = residue_map(data, par, rows, theta)
    S = M @ noise_vector_covariance(data) @ M.T
    return 0.5 * (S + S.T)


# -- the exact cost and its gradient ---------------------------------------------------------

def _basis_maps(data: Data, par: Parametrisation, rows) -> np.ndarray:
    """dM_j = M(Text[:, j]) for every column of Text: M(Text xi) = sum_j xi_j dM_j."""
    return np.array([residue_map(data, par, rows, par.Text[:, j]) for j in range(par.n_xi)])


def _cost_and_gradient(M, dM, C, x):
    """V = r^T S^-1 r and dV_j = 2 r^T S^-1 dr_j - q^T dS_j q, q = S^-1 r, written out.

    dS_j = dM_j C M^T + M C dM_j^T is formed explicitly (the direct formula of section 10).
    """
    S = M @ C @ M.T
    S = 0.5 * (S + S.T)
    r = M @ x
    factor = scipy.linalg.cho_factor(S, lower=True)  # raises LinAlgError if S is not PD
    q = scipy.linalg.cho_solve(factor, r)
    V = float(r @ q)
    CMt = C @ M.T
    g = np.empty(len(dM))
    for j, dMj in enumerate(dM):
        dS = dMj @ CMt
        dS = dS + dS.T
        g[j] = 2.0 * q @ (dMj @ x) - q @ dS @ q
    return V, g


def exact_cost(data: Data, par: Parametrisation, rows, theta) -> float:
    """V = r^T S^-1 r (eq. 17) with a dense Cholesky factorisation of S."""
    M = residue_map(data, par, rows, theta)
    S = residue_covariance(data, par, rows, theta)
    r = M @ data_vector(data)
    return float(r @ scipy.linalg.cho_solve(scipy.linalg.cho_factor(S, lower=True), r))


def exact_cost_gradient(data: Data, par: Parametrisation, rows, theta) -> np.ndarray:
    """dV/dxi_j (all n_xi entries, the normalised one included) at theta = Text xi."""
    M = residue_map(data, par, rows, theta)
    return _cost_and_gradient(M, _basis_maps(data, par, rows), noise_vector_covariance(data),
                              data_vector(data))[1]


# -- Fisher information and the Cramer-Rao bound ---------------------------------------------

def _free(par: Parametrisation) -> np.ndarray:
    return np.array([j for j in range(par.n_xi) if j != par.norm_index], dtype=int)


def fisher_information(data: Data, par: Parametrisation, rows, theta) -> np.ndarray:
    """F = J^T S^-1 J over the free xi entries, J[:, j] = M(Text[:, j]) x on the data given.

    With noiseless spectra and the true noise (co)variances F^-1 is the Cramer-Rao bound.
    """
    x = data_vector(data)
    J = np.column_stack([residue_map(data, par, rows, par.Text[:, j]) @ x for j in _free(par)])
    S = residue_covariance(data, par, rows, theta)
    F = J.T @ scipy.linalg.cho_solve(scipy.linalg.cho_factor(S, lower=True), J)
    return 0.5 * (F + F.T)


def crb(data: Data, par: Parametrisation, rows, theta) -> np.ndarray:
    """Covariance bound of eta (n_eta x n_eta): F^-1 on the free entries; the normalised
    parameter (when nothing is known) gets a zero row and column."""
    return _eta_covariance(par, np.linalg.inv(fisher_information(data, par, rows, theta)))


def crb_experiments(datas, par: Parametrisation, rows_list, theta) -> np.ndarray:
    """The bound of several independent experiments (METHOD.md section 14): the noise vector is
    the experiments' noise vectors one after the other, so Cov(n) and S are block diagonal and
    F = J^T S^-1 J is the sum of the experiments' informations."""
    F = sum(fisher_information(d, par, r, theta) for d, r in zip(datas, rows_list))
    return _eta_covariance(par, np.linalg.inv(F))


def _eta_covariance(par: Parametrisation, cov_free) -> np.ndarray:
    free = _free(par)
    cov = np.zeros((par.n_xi, par.n_xi))
    cov[np.ix_(free, free)] = cov_free
    # With a known part, xi = [eta, 1]: the last (known) column is the normalised one.
    return cov[:par.n_eta, :par.n_eta]


# -- the sample maximum likelihood estimate --------------------------------------------------

def xi_of_theta(par: Parametrisation, theta) -> np.ndarray:
    """Real xi with theta = Text xi: least squares on the stacked real and imaginary parts."""
    theta = np.asarray(theta, complex)
    A = np.vstack([par.Text.real, par.Text.imag])
    return np.linalg.lstsq(A, np.concatenate([theta.real, theta.imag]), rcond=None)[0]


def sml_estimate(data: Data, par: Parametrisation, rows, theta0, *, tol: float = 1e-13,
                 max_iter: int = 100) -> dict:
    """Minimise V (eq. 17) over the free entries of xi, xi[norm_index] = 1, from theta0: see
    :func:`sml_estimate_experiments`, here with one experiment."""
    return sml_estimate_experiments([data], par, [rows], theta0, tol=tol, max_iter=max_iter)


def exact_cost_experiments(datas, par: Parametrisation, rows_list, theta) -> float:
    """V of several independent experiments: S block diagonal, so the costs add."""
    return float(sum(exact_cost(d, par, r, theta) for d, r in zip(datas, rows_list)))


def denoised(data: Data, par: Parametrisation, rows, theta) -> Data:
    """The data nearest to the measured ones in the noise metric that the model explains exactly:
    x0 = x - Cov(n) M^T S^-1 r (the noiseless spectra the likelihood eliminates), with the same
    (co)variances. ``fisher_information(denoised(...))`` is the information at the estimate."""
    rows = np.asarray(rows)
    M = residue_map(data, par, rows, theta)
    C = noise_vector_covariance(data)
    S = residue_covariance(data, par, rows, theta)
    x = data_vector(data)
    x0 = (x - C @ M.T @ np.linalg.solve(S, M @ x)).reshape(-1, 4)
    return Data(U=x0[:, 2] + 1j * x0[:, 3], Y=x0[:, 0] + 1j * x0[:, 1], varU=data.varU,
                varY=data.varY, covYU=data.covYU, periods=data.periods)


def sandwich_terms(data: Data, par: Parametrisation, rows, theta, weights):
    """The two terms of the WGTLS covariance (first order in the noise), densely: with J the real
    Jacobian dr/dxi (free entries) evaluated at the data x0 = x - Cov(n) M^T S^-1 r that the model
    explains exactly, and W = diag(w_l, w_l) per row, H = J^T W J and the meat J^T W S W J.
    Over independent experiments both add; the covariance is H^-1 meat H^-1."""
    rows = np.asarray(rows)
    S = residue_covariance(data, par, rows, theta)
    x0 = data_vector(denoised(data, par, rows, theta))
    J = np.column_stack([residue_map(data, par, rows, par.Text[:, j]) @ x0 for j in _free(par)])
    W = np.repeat(np.asarray(weights, float), 2)
    WJ = W[:, None] * J
    return J.T @ WJ, WJ.T @ S @ WJ


def second_order_terms(data: Data, par: Parametrisation, rows, theta, weights) -> dict:
    """The pieces of the second-order noise of WGTLS's estimating equation (METHOD.md section 10),
    densely, over the complex noise of the signed lines i (line -m the conjugate of line m,
    independent of it for circular noise; the DC line taken as circular too):
    nu_i = [dY_i, dU_i], E{nu_i nu_i^H} = [[var Y, cov YU], [conj cov YU, var U]] (conjugated on a
    negative line). With the complex maps e = M nu (the residue), dJ[:, q] = D_q nu (column q of
    the Jacobian), S = M Sigma M^H, w the row weights and Q_q = sum_l w_l conj(dJ_lq) e_l,
    R = sum_l w_l |e_l|^2, Isserlis' theorem gives

        E{Q_q conj(Q_q2)} = sum_{l,l'} w_l w_l' [conj(D_q) conj(Sigma) D_q2^T]_{l l'} S_{l l'}
        E{Q_q Q_q2}       = sum_{l,l'} w_l w_l' G_q[l, l'] G_q2[l', l],  G_q = conj(D_q) conj(Sigma) M^T
        Cov(Q_q, R)       = sum_{l,l'} w_l w_l' G_q[l, l'] S_{l l'}
        Var(R)            = sum_{l,l'} w_l w_l' |S_{l l'}|^2

    (centred), and in real xi coordinates (q = Re(Text^H Q)): 'qq' = Re(Text^H E{Q Q^H} Text
    + Text^H E{Q Q^T} conj(Text)) / 2, 'qr' = Re(Text^H Cov(Q, R)), 'rr' = Var(R) and
    'cj' = Re(Text^H C Text), C = sum_l w_l E{dJ_l^H dJ_l}."""
    rows = np.asarray(rows)
    K = par.K
    k = np.arange(-K, K + 1)
    lines = rows[:, None] - k[None, :]                      # signed line of each band entry
    signed = np.arange(lines.min(), lines.max() + 1)
    pos = {int(i): j for j, i in enumerate(signed)}
    ns = signed.size
    R = rows.size
    Sig = np.zeros((2 * ns, 2 * ns), complex)
    for j, i in enumerate(signed):
        m = abs(int(i))
        c = complex(data.covYU[m]) if i >= 0 else complex(np.conj(data.covYU[m]))
        Sig[2 * j:2 * j + 2, 2 * j:2 * j + 2] = [[data.varY[m], c], [np.conj(c), data.varU[m]]]
    A, B = band_rows(par, theta, rows)
    Mc = np.zeros((R, 2 * ns), complex)
    for r in range(R):
        for c in range(2 * K + 1):
            j = pos[int(lines[r, c])]
            Mc[r, 2 * j] += A[r, c]
            Mc[r, 2 * j + 1] -= B[r, c]
    n_theta = len(par.params)
    D = np.zeros((n_theta, R, 2 * ns), complex)
    for q, (is_a, n, kq) in enumerate(par.params):
        i = rows - kq
        f = (1.0 if is_a else -1.0) * line_variable(par, i) ** n
        for r in range(R):
            D[q, r, 2 * pos[int(i[r])] + (0 if is_a else 1)] = f[r]
    w = np.asarray(weights, float)
    S = Mc @ Sig @ Mc.conj().T
    Om = np.outer(w, w) * S
    Z = np.einsum("qls,st->qlt", D.conj(), Sig.conj())      # conj(D_q) conj(Sigma)
    OD = np.einsum("lm,qms->qls", Om, D)                   # Omega D_q2
    Gamma = np.einsum("qls,pls->qp", Z, OD)
    G = np.einsum("qls,ms->qlm", Z, Mc)                    # E{conj(dJ_lq) e_m}
    Pi = np.einsum("qlm,pml,l,m->qp", G, G, w, w)
    tau = np.einsum("qls,ls->q", Z, Om @ Mc)
    Cc = np.einsum("qls,pls->qp", Z * w[None, :, None], D)
    T = par.Text
    qq = 0.5 * (T.conj().T @ Gamma @ T + T.conj().T @ Pi @ T.conj()).real
    return dict(qq=0.5 * (qq + qq.T), qr=(T.conj().T @ tau).real,
                rr=float(np.sum(np.outer(w, w) * np.abs(S) ** 2)), cj=(T.conj().T @ Cc @ T).real)


def second_order_meat(terms: dict, par: Parametrisation, theta) -> np.ndarray:
    """Cov(q - lambda CJ_W xi) over the free entries of xi, lambda = R / (xi^T CJ_W xi): with
    v = CJ_W xi / (xi^T CJ_W xi), Cov(q) - c v^T - v c^T + Var(R) v v^T, c = Cov(q, R). The terms
    of independent experiments add first (one lambda for all)."""
    xi = xi_of_theta(par, theta)  # theta = Text xi, at the scale theta has
    cx = terms["cj"] @ xi
    v = cx / (xi @ cx)
    M = terms["qq"] - np.outer(terms["qr"], v) - np.outer(v, terms["qr"]) + terms["rr"] * np.outer(v, v)
    free = _free(par)
    M = M[np.ix_(free, free)]
    return 0.5 * (M + M.T)


def sml_estimate_experiments(datas, par: Parametrisation, rows_list, theta0, *, tol: float = 1e-13,
                             max_iter: int = 100) -> dict:
    """Minimise V (eq. 17) over the free entries of xi, xi[norm_index] = 1, from theta0.

    Newton's method: the exact gradient above and a Hessian from its central differences
    (symmetrised), damped Levenberg-style (H + lam diag|H|) whenever H is not positive definite
    or the step raises V.

    Stopping rule: stop when the undamped Newton step is below tol relative to ||xi||. With an
    accurate Hessian the Newton step is the distance to the minimiser up to a factor
    1 + O(||H^-1 dH||): central differences with h = 1e-5 |xi_j| leave dH at ~1e-10 of H and
    ||H^-1 dH|| below ~1e-6 on the test problems, so the returned point is within about
    tol ||xi|| of the stationary point of V, and each iteration shrinks the error by that
    factor (quadratic convergence until then). A cost test could not do this: near the
    minimum V changes by ~ step^2, so V alone resolves xi only to sqrt(eps) ~ 1e-8. The
    gradient is accurate to ~eps cond(S) of its terms, which sets the floor of the Newton
    step; tol = 1e-13 lies above that floor on well-posed problems (measured from WGTLS:
    relative steps 1e-3, 1e-5, 1e-9, then 1e-16 where it stops). Near the floor V
    differences are rounding noise, so a step that raises V by no more than 100 eps |V| is
    still taken.
    """
    norm, free = par.norm_index, _free(par)
    # Per experiment: Cov(n), x and the basis maps. S is block diagonal over the experiments
    # (independent noise), so V and its gradient are the sums of the experiments' own.
    parts = [(noise_vector_covariance(d), data_vector(d), _basis_maps(d, par, np.asarray(r)))
             for d, r in zip(datas, rows_list)]
    xi = xi_of_theta(par, theta0)
    xi = xi / xi[norm]

    def evaluate(z):
        V, g = 0.0, 0.0
        for C, x, dM in parts:
            Ve, ge = _cost_and_gradient(np.tensordot(z, dM, axes=1), dM, C, x)
            V, g = V + Ve, g + ge
        return V, g

    def hessian(z):
        H = np.empty((free.size, free.size))
        for c, j in enumerate(free):
            h = 1e-5 * max(abs(z[j]), 1e-3 * np.max(np.abs(z)))
            zp, zm = z.copy(), z.copy()
            zp[j] += h
            zm[j] -= h
            H[:, c] = (evaluate(zp)[1][free] - evaluate(zm)[1][free]) / (2 * h)
        return 0.5 * (H + H.T)

    V, g = evaluate(xi)
    lam, converged, it = 0.0, False, 0
    for it in range(1, max_iter + 1):
        H = hessian(xi)
        D = np.diag(np.abs(np.diag(H)))
        try:
            newton = -scipy.linalg.cho_solve(scipy.linalg.cho_factor(H), g[free])
            if np.linalg.norm(newton) <= tol * np.linalg.norm(xi):
                converged = True
                break
        except np.linalg.LinAlgError:
            lam = max(lam, 1e-6)
        accepted = False
        while lam <= 1e12:
            try:
                step = -scipy.linalg.cho_solve(scipy.linalg.cho_factor(H + lam * D), g[free])
                trial = xi.copy()
                trial[free] += step
                V_t, g_t = evaluate(trial)
            except np.linalg.LinAlgError:
                V_t = np.inf
            if V_t <= V + 100 * np.finfo(float).eps * abs(V):
                accepted = True
                break
            lam = max(10 * lam, 1e-6)
        if not accepted:
            break  # no step lowers V: leave converged False, the caller sees it
        xi, V, g = trial, V_t, g_t
        lam = lam / 10 if lam > 1e-9 else 0.0
    return dict(theta=par.Text @ xi, xi=xi, cost=V, iterations=it, converged=converged)
