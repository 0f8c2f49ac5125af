"""METHOD.md section 17 in NumPy and SciPy: one record with its transient.

The independent route :func:`lptv._core.fit_record` (behind :func:`lptv.identify_record`) is
tested against. It was the computation of ``lptv.identify_record`` before the core had it, with
the core's two parts replaced: the parametrisation is :class:`lptv.reference.identification.
Parametrisation`, and A^-1 on the record's grid is a dense LU per residue class of the lines
modulo L (harmonic k moves a line by k L, so the classes do not couple: L systems of N0 lines,
each a band that wraps around its corners, factorised by SuperLU (``scipy.sparse.linalg.splu``),
where the core factorises the whole grid at once with KLU). The fit is SciPy's
MINPACK Levenberg-Marquardt (``least_squares(method="lm")``) where the core has its own; the
continuous-time grid (the signed lines -M..M, ``_CtGrid``) is one sparse matrix factorised by
SuperLU, where the core runs its continuous-time FDS with KLU; the
start is ``numpy.linalg.lstsq``. Nothing here calls ``lptv._core``; the local polynomial method
(``noise="lpm"``, NumPy only, not in the core) is ``lptv.estimation.one_record.local_polynomial_noise``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse
import scipy.sparse.linalg
from scipy.optimize import least_squares

from .identification import Parametrisation


@dataclass(frozen=True)
class RecordFit:
    """The fields of the core's ``RecordFit`` (and of ``lptv.RecordResult``) this route gives."""

    eta: np.ndarray             # xi with xi[norm_index] = 1
    theta: np.ndarray
    covariance: np.ndarray      # of eta, n_xi x n_xi (zero at norm_index)
    transient: np.ndarray       # c_1..c_n
    transient_std: np.ndarray
    start: np.ndarray           # [free eta, c] of the equation error
    lines: np.ndarray
    periods: int
    noise_var: np.ndarray
    noise_dof: int
    Y: np.ndarray
    Y_fit: np.ndarray
    cost: float
    dof: int
    converged: bool
    iterations: int             # MINPACK's function evaluations of the last fit


class _Grid:
    """The record's DFT grid (N = L N0 lines) and the band operators of a coefficient set on it."""

    def __init__(self, N, L):
        self.N, self.L = N, L
        self.x = np.exp(2j * np.pi * np.arange(N) / N)          # z_m (discrete time)

    def apply(self, coef, X):
        """sum_p sum_k coef[p, K+k] x_{l-kL}^p X_{l-kL} on the full grid."""
        K = (coef.shape[1] - 1) // 2
        out = np.zeros(self.N, dtype=complex)
        for p in range(coef.shape[0]):
            xp = self.x**p * X
            for k in range(-K, K + 1):
                c = coef[p, K + k]
                if c != 0:
                    out += c * np.roll(xp, k * self.L)
        return out

    def transient_basis(self, n):
        """n columns: z^1..z^n (section 17)."""
        return np.stack([self.x**j for j in range(1, n + 1)], axis=1)

    def spectrum(self, X):
        return X

    def index(self, lines):
        return lines

    def factor(self, a):
        """LU factors of A (a: (na+1, 2K+1), harmonic k at column K + k) per residue class r of
        the lines modulo L: the lines r + m L, m = 0..N0-1, couple only among themselves, line
        r + m L to r + (m - k) L through harmonic k."""
        N, L = self.N, self.L
        N0 = N // L
        K = (a.shape[1] - 1) // 2
        m = np.arange(N0)
        lu = []
        for r in range(L):
            lines = r + L * m
            rows, cols, vals = [], [], []
            for k in range(-K, K + 1):
                src = (m - k) % N0                              # class index of line l - k L
                z = self.x[lines[src]]
                rows.append(m)
                cols.append(src)
                vals.append(sum(a[n, K + k] * z**n for n in range(a.shape[0])))
            A = scipy.sparse.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                        shape=(N0, N0))
            lu.append(scipy.sparse.linalg.splu(A))
        return lu

    def solve(self, lu, R):
        """A^-1 R for full-grid right-hand sides R (N rows, columns)."""
        R = np.asarray(R, dtype=complex)
        out = np.empty_like(R)
        N0 = self.N // self.L
        for r in range(self.L):
            lines = r + self.L * np.arange(N0)
            out[lines] = lu[r].solve(np.ascontiguousarray(R[lines]))
        return out


class _CtGrid:
    """A continuous-time record's grid: the signed lines -M..M, M = (N - 1) // 2, at index l + M,
    x_l = j l w0 / L; spectra beyond the grid are taken as zero (as the FDS does)."""

    def __init__(self, N, L, w0):
        self.N, self.L = N, L
        self.M = (N - 1) // 2
        self.line = np.arange(-self.M, self.M + 1)
        self.G = self.line.size
        self.x = 1j * self.line * (w0 / L)

    def spectrum(self, X):
        """The DFT (index l mod N) on the grid."""
        return X[self.line % self.N]

    def index(self, lines):
        return np.asarray(lines) + self.M

    def _shift(self, v, s):
        """out[g] = v[g - s], zero where g - s leaves the grid."""
        out = np.zeros_like(v)
        if s >= 0:
            out[s:] = v[:self.G - s]
        else:
            out[:self.G + s] = v[-s:]
        return out

    def apply(self, coef, X):
        K = (coef.shape[1] - 1) // 2
        out = np.zeros(self.G, dtype=complex)
        for p in range(coef.shape[0]):
            xp = self.x**p * X
            for k in range(-K, K + 1):
                c = coef[p, K + k]
                if c != 0:
                    out += c * self._shift(xp, k * self.L)
        return out

    def transient_basis(self, n):
        """n columns: (j w_l ts)^0..(j w_l ts)^(n-1), j w_l ts = j 2 pi l / N."""
        v = 2j * np.pi * self.line / self.N
        return np.stack([v**j for j in range(n)], axis=1)

    def factor(self, a):
        K = (a.shape[1] - 1) // 2
        g = np.arange(self.G)
        rows, cols, vals = [], [], []
        for k in range(-K, K + 1):
            src = g - k * self.L
            ok = (src >= 0) & (src < self.G)
            z = self.x[src[ok]]
            rows.append(g[ok])
            cols.append(src[ok])
            vals.append(sum(a[n, K + k] * z**n for n in range(a.shape[0])))
        A = scipy.sparse.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                    shape=(self.G, self.G))
        return scipy.sparse.linalg.splu(A)

    def solve(self, lu, R):
        return lu.solve(np.ascontiguousarray(np.asarray(R, dtype=complex)))


MIN_SHARE = 0.05


def _residual_variance(e2, width, J):
    """Each line's |Y - Y_hat|^2 over its share 1 - h_l of the noise the fit leaves (h_l the mean
    leverage of its Re and Im rows in the weighted Jacobian J, [Re rows; Im rows]; the share at
    least MIN_SHARE), averaged over the fitted lines within +-width positions (fewer at the ends)."""
    n = e2.size
    U, s, _ = np.linalg.svd(J, full_matrices=False)
    cut = (s[0] if s.size else 0.0) * np.finfo(float).eps * max(J.shape)
    h2 = np.sum(U[:, s > cut] ** 2, axis=1)
    e2 = e2 / np.maximum(1.0 - 0.5 * (h2[:n] + h2[n:]), MIN_SHARE)
    cum = np.concatenate([[0.0], np.cumsum(e2)])
    i = np.arange(n)
    lo, hi = np.maximum(0, i - width), np.minimum(n, i + width + 1)
    var = (cum[hi] - cum[lo]) / (hi - lo)
    return np.maximum(var, 1e-300)


def identify_record(u, y, *, na, nb, ka, kb, w0, ts, lines=None, transient=True, noise="residual",
                    noise_width=10, lpm_branches=None, lpm_degree=2, max_iterations=100, continuous=False,
                    transient_degree=None) -> RecordFit:
    """The arguments of :func:`lptv.identify_record` (``ka``, ``kb``: one count per coefficient),
    assumed valid (this route is for comparisons, not for users' data)."""
    u = np.asarray(u, dtype=float)
    y = np.asarray(y, dtype=float)
    N = u.size
    n0 = int(round(2 * np.pi / (w0 * ts)))
    L = N // n0
    ka_l, kb_l = [int(k) for k in ka], [int(k) for k in kb]
    par = Parametrisation(na, nb, ka_l, kb_l, (), w0, 0.0 if continuous else ts)
    if lines is None:
        lines = np.arange(1, (N - 1) // 8 + 1) if continuous else np.arange(1, N // 2)
    else:
        lines = np.unique(np.asarray(lines))
    grid = _CtGrid(N, L, w0) if continuous else _Grid(N, L)
    U = np.fft.fft(u) / N
    Y = np.fft.fft(y) / N
    kmax = max(ka_l + kb_l)
    if continuous:
        nT = (max(na, nb) + 2 if transient_degree is None else transient_degree + 1) if transient else 0
    else:
        nT = max(na, nb) if transient else 0
    norm = par.norm_index
    free = [i for i in range(par.n_xi) if i != norm]
    n_eta = len(free)

    if isinstance(noise, str) and noise == "lpm":
        from ..estimation.one_record import local_polynomial_noise        # NumPy only: not in the core
        branches = kmax + 1 if lpm_branches is None else int(lpm_branches)
        var, noise_dof = local_polynomial_noise(U, Y, L, lines, branches=branches, degree=lpm_degree)
    elif isinstance(noise, str):
        var, noise_dof = np.ones(lines.size), 0
    else:
        var = np.broadcast_to(np.asarray(noise, dtype=float), lines.shape).copy()
        noise_dof = 0

    Ka, Kb = max(ka_l), max(kb_l)
    U, Y = grid.spectrum(U), grid.spectrum(Y)
    fit_lines, lines = lines, grid.index(lines)    # positions on the grid

    def arrays(theta):
        a = np.zeros((na + 1, 2 * Ka + 1), dtype=complex)
        b = np.zeros((nb + 1, 2 * Kb + 1), dtype=complex)
        for (is_a, order, k), v in zip(par.params, theta):
            if is_a:
                a[order, Ka + k] = v
            else:
                b[order, Kb + k] = v
        return a, b

    Text = par.Text
    dirs = [arrays(Text[:, i]) for i in free]
    a_norm, b_norm = arrays(Text[:, norm])
    V = grid.transient_basis(nT) if nT else np.zeros((Y.size, 0))

    def theta_of(eta):
        xi = np.zeros(par.n_xi)
        xi[free] = eta
        xi[norm] = 1.0
        return Text @ xi

    # start: the equation error E = A Y - B U + T, linear in eta and c, by weighted least squares
    E0 = grid.apply(a_norm, Y) - grid.apply(b_norm, U)
    cols = [grid.apply(ad, Y) - grid.apply(bd, U) for ad, bd in dirs]
    Mf = np.stack(cols, axis=1) if cols else np.zeros((Y.size, 0))
    Mf = np.concatenate([Mf, V], axis=1)
    sc = 1.0 / np.sqrt(var)
    Mr = np.concatenate([(Mf[lines] * sc[:, None]).real, (Mf[lines] * sc[:, None]).imag])
    br = -np.concatenate([(E0[lines] * sc).real, (E0[lines] * sc).imag])
    x0, *_ = np.linalg.lstsq(Mr, br, rcond=None)
    w = 1.0 / np.sqrt(var / 2.0)          # Re and Im of V_l each have variance var / 2

    def predict(x):
        a, b = arrays(theta_of(x[:n_eta]))
        lu = grid.factor(a)
        R = grid.apply(b, U) - V @ x[n_eta:]
        return a, b, lu, grid.solve(lu, R)

    def residual(x):
        *_, Yh = predict(x)
        d = (Y - Yh)[lines] * w
        return np.concatenate([d.real, d.imag])

    def jacobian(x):
        a, b, lu, Yh = predict(x)
        R = np.stack([grid.apply(bd, U) - grid.apply(ad, Yh) for ad, bd in dirs]
                     + [-V[:, j] for j in range(nT)], axis=1)
        D = grid.solve(lu, R)[lines] * w[:, None]         # dY/dx on the fitted lines
        return -np.concatenate([D.real, D.imag])

    def fit(x_start):
        return least_squares(residual, x_start, jac=jacobian, method="lm",
                             max_nfev=max_iterations * (x_start.size + 1), xtol=1e-12, ftol=1e-12, gtol=1e-12)

    sol = fit(x0)
    if isinstance(noise, str) and noise == "residual":
        # the residual's local mean square, each line's over its share 1 - h_l, then the fit again
        for _ in range(2):
            *_, Yh = predict(sol.x)
            var = _residual_variance(np.abs((Y - Yh)[lines]) ** 2, noise_width, sol.jac)
            w = 1.0 / np.sqrt(var / 2.0)
            sol = fit(sol.x)
        noise_dof = 2 * noise_width + 1
    x = sol.x
    J = sol.jac
    try:
        cov = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(J.T @ J)
    std = np.sqrt(np.clip(np.diag(cov), 0, None))
    *_, Yh = predict(x)
    eta = np.zeros(par.n_xi)
    eta[free] = x[:n_eta]
    eta[norm] = 1.0
    cov_eta = np.zeros((par.n_xi, par.n_xi))
    cov_eta[np.ix_(free, free)] = cov[:n_eta, :n_eta]
    return RecordFit(
        eta=eta, theta=theta_of(x[:n_eta]), covariance=cov_eta, transient=x[n_eta:].copy(),
        transient_std=std[n_eta:], start=x0, lines=fit_lines, periods=L, noise_var=var, noise_dof=int(noise_dof),
        Y=Y[lines], Y_fit=Yh[lines], cost=float(np.sum(sol.fun**2)), dof=int(2 * lines.size - x.size),
        converged=bool(sol.success), iterations=int(sol.nfev))
