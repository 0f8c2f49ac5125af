"""Sample maximum likelihood (METHOD.md section 6, "beyond the paper").

The SML cost V(theta) = sum_l |e_l(theta)|^2 / var e_l(theta) over the rows is minimised by
Levenberg-Marquardt from the WGTLS estimate. With noise variances estimated from P periods it
is the efficient estimator for this noise model (Schoukens, Pintelon, Vandersteen and Guillaume,
"Frequency-domain system identification using non-parametric noise models estimated from a small
number of data sets", Automatica 33(6), 1997), and its Jacobian gives the parameter covariance.

The residue e = J theta and J do not depend on theta; var e_l = theta^H C_l theta does, with
d var e_l / d eta = 2 Re(conj(G_l) T), G_l = C_l theta (``_core.residue_variance_gradient``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core


@dataclass(frozen=True)
class SmlFit:
    theta: np.ndarray
    xi: np.ndarray
    iterations: int
    converged: bool
    cost: float            # V / rows: the mean squared normalised residue
    covariance_xi: np.ndarray  # of the free entries of xi (all but the normalised one)
    free: np.ndarray       # indices of the free entries of xi


def _xi_from_theta(Text, theta):
    """theta = Text xi with real xi: least squares on the stacked real and imaginary parts."""
    M = np.vstack([Text.real, Text.imag])
    rhs = np.concatenate([theta.real, theta.imag])
    return np.linalg.lstsq(M, rhs, rcond=None)[0]


def sml_refine(data, par, rows, theta0, *, periods=0, tol=1e-10, max_iter=100) -> SmlFit:
    """Levenberg-Marquardt on the SML cost from ``theta0`` (normalised as the core does)."""
    Text = np.asarray(par.Text)
    norm = par.norm_index
    free = np.array([j for j in range(Text.shape[1]) if j != norm])
    xi = _xi_from_theta(Text, np.asarray(theta0))
    xi = xi / xi[norm]
    J = np.asarray(_core.jacobian(data._cpp, par, rows))       # rows x n_theta, data only
    JT = J @ Text[:, free]

    def evaluate(xi):
        theta = Text @ xi
        e = J @ theta
        v = np.asarray(_core.residue_variance(data._cpp, par, rows, theta))
        if np.any(v <= 0):
            raise ValueError("data: the residue variance is zero on some rows; the SML cost is "
                             "undefined without noise (use method='wgtls')")
        return theta, e, v

    def residual_and_jacobian(xi):
        theta, e, v = evaluate(xi)
        G = np.asarray(_core.residue_variance_gradient(data._cpp, par, rows, theta))
        dv = 2.0 * (G.conj() @ Text[:, free]).real              # rows x n_free
        s = np.sqrt(v)
        r = e / s
        dr = JT / s[:, None] - (e / (2.0 * v * s))[:, None] * dv
        return (np.concatenate([r.real, r.imag]), np.vstack([dr.real, dr.imag]))

    R, D = residual_and_jacobian(xi)
    V = float(R @ R)
    lam = 1e-3
    converged = False
    it = 0
    for it in range(1, max_iter + 1):
        H = D.T @ D
        g = D.T @ R
        improved = False
        while lam < 1e12:
            step = np.linalg.solve(H + lam * np.diag(np.diag(H)), -g)
            trial = xi.copy()
            trial[free] += step
            try:
                R_t, D_t = residual_and_jacobian(trial)
            except ValueError:
                lam *= 10
                continue
            V_t = float(R_t @ R_t)
            if V_t <= V:
                improved = True
                break
            lam *= 10
        if not improved:
            converged = True  # no step lowers the cost: a minimum to rounding
            break
        rel_cost = (V - V_t) / max(V, 1e-300)
        rel_step = np.linalg.norm(step) / max(np.linalg.norm(xi[free]), 1e-300)
        xi, R, D, V = trial, R_t, D_t, V_t
        lam = max(lam / 10, 1e-12)
        if rel_cost < tol and rel_step < np.sqrt(tol):
            converged = True
            break
    # Each normalised residue is circular with unit variance: its real and imaginary parts
    # have variance 1/2, so Cov(xi_free) = (D^T D)^-1 / 2 to first order. Noise variances
    # estimated from P periods inflate it by (P - 2)/(P - 3) (Schoukens et al. 1997).
    cov = np.linalg.inv(D.T @ D) / 2.0
    if periods and periods > 3:
        cov *= (periods - 2) / (periods - 3)
    theta = Text @ xi
    return SmlFit(theta=theta, xi=xi, iterations=it, converged=converged, cost=V / len(rows),
                  covariance_xi=cov, free=free)
