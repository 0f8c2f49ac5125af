"""METHOD.md sections 4-7 in plain NumPy/SciPy: noise model, residue, Jacobian, estimators.

The independent route the compiled identification core is tested against. It uses the same
conventions as the core (listed below) so that every intermediate result can be compared, but
shares none of its code or its algorithms: the Jacobian is built densely and vectorised over
rows, the noise terms are quadratic forms with explicit per-line covariance matrices instead of
the core's grouped closed form, the estimators work on the tall real Jacobian itself (no QR
reduction), and GTLS is an SVD after whitening by a pivoted Cholesky factor, with the noise-free
directions eliminated, instead of LAPACK's GSVD.

Conventions (shared with the core):

- spectra X_l = fft(x)[l] / N on lines 0..N//2; a line l < 0 is the conjugate line:
  X_{-m} = conj(X_m), var X_{-m} = var X_m, covYU_{-m} = conj(covYU_m);
- theta (complex): a_0..a_na then b_0..b_nb, each coefficient's harmonics -K_n..K_n with its own
  count K_n, known coefficients included;
- theta = T eta + d: per free coefficient the real unknowns Re c_0, Re c_1, Im c_1, ...,
  Re c_K, Im c_K; known coefficients make d. xi is the homogeneous vector theta = Text xi with
  Text = [T, d] (or T when nothing is known); the estimate is scaled so that xi[norm_index] = 1;
- rows are lines l >= 1, by default K+1 .. Lmax-K with K the largest harmonic count.

Nothing here calls ``lptv._core``: the inputs are NumPy arrays (a core object's arrays may be
read, e.g. ``Data.of(core_data)``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np
import scipy.linalg
import scipy.linalg.lapack
import scipy.stats

__all__ = [
    "Data", "frequency_data", "Parametrisation", "default_rows", "line_values", "line_noise",
    "line_variable", "jacobian", "residue", "band_rows", "residue_variance", "column_covariance",
    "real_column_covariance", "real_jacobian", "solve_ls", "solve_tls", "solve_gtls", "estimate",
    "normalized_residue", "expected_fraction_above_0db", "theta_of_coefficients", "estimate_experiments",
]

# Relative floor of the residue variance when it becomes the WGTLS weight (as in the core):
# rows whose residue carries (numerically) no noise get a large finite weight.
VARIANCE_FLOOR = 1e-14


# -- section 4: nonparametric noise model ---------------------------------------------------

@dataclass(frozen=True)
class Data:
    """Mean spectra on lines 0..Lmax and the (co)variances of the means."""

    U: np.ndarray
    Y: np.ndarray
    varU: np.ndarray
    varY: np.ndarray
    covYU: np.ndarray  # E{dY conj(dU)} of the means
    periods: int = 0

    @property
    def max_line(self) -> int:
        return self.U.size - 1

    @classmethod
    def of(cls, obj) -> "Data":
        """Copy the arrays of any object with the fields U, Y, varU, varY, covYU (and periods)."""
        return cls(U=np.array(obj.U, complex), Y=np.array(obj.Y, complex),
                   varU=np.array(obj.varU, float), varY=np.array(obj.varY, float),
                   covYU=np.array(obj.covYU, complex), periods=int(getattr(obj, "periods", 0)))


def frequency_data(u, y) -> Data:
    """Sample means of the per-period spectra and the (co)variances of those means (section 4).

    u, y: P x N, one period per row. var X_l = 1/(P(P-1)) sum_p |X^[p]_l - X_l|^2 is the variance
    of the mean (Pintelon & Schoukens 2001, eq. 2-31), likewise covYU with (dY) conj(dU).
    """
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    P, N = u.shape
    Up = np.fft.fft(u, axis=1)[:, : N // 2 + 1] / N
    Yp = np.fft.fft(y, axis=1)[:, : N // 2 + 1] / N
    U, Y = Up.mean(axis=0), Yp.mean(axis=0)
    dU, dY = Up - U, Yp - Y
    scale = 1.0 / (P * (P - 1))
    return Data(U=U, Y=Y, varU=scale * np.sum(np.abs(dU) ** 2, axis=0),
                varY=scale * np.sum(np.abs(dY) ** 2, axis=0),
                covYU=scale * np.sum(dY * np.conj(dU), axis=0), periods=P)


def line_values(X, lines) -> np.ndarray:
    """X on any lines: X_{-m} = conj(X_m) (real signals)."""
    lines = np.asarray(lines)
    v = np.asarray(X)[np.abs(lines)]
    return np.where(lines < 0, np.conj(v), v)


def line_noise(data: Data, lines):
    """Per-line covariance of z = [dY_i, dU_i]: E{z z^H} = [[varY, covYU], [conj covYU, varU]].

    Returns an array (..., 2, 2) over ``lines``; the conjugate line -m has the conjugate matrix.
    """
    lines = np.asarray(lines)
    m = np.abs(lines)
    cyu = line_values(data.covYU, lines)
    S = np.empty(lines.shape + (2, 2), complex)
    S[..., 0, 0] = data.varY[m]
    S[..., 1, 1] = data.varU[m]
    S[..., 0, 1] = cyu
    S[..., 1, 0] = np.conj(cyu)
    return S


# -- section 5: parameters ------------------------------------------------------------------

class Parametrisation:
    """theta (complex, every harmonic of every coefficient) and its real parametrisation.

    Parameters mirror the core's: ``known`` is a sequence of (is_a, order, Fourier row of 2K+1
    values), K that coefficient's own harmonic count. ``ts`` = 0 or None: continuous time.
    """

    def __init__(self, na: int, nb: int, ka: Sequence[int], kb: Sequence[int],
                 known: Sequence[Tuple[bool, int, Sequence[complex]]] = (), w0: float = 1.0,
                 ts: Optional[float] = 0.0):
        self.na, self.nb = int(na), int(nb)
        self.ka, self.kb = [int(v) for v in ka], [int(v) for v in kb]
        assert len(self.ka) == self.na + 1 and len(self.kb) == self.nb + 1
        self.w0 = float(w0)
        self.ts = float(ts) if ts else 0.0
        self.known = {(bool(a), int(n)): np.asarray(c, complex) for a, n, c in known}
        # theta order: a_0 .. a_na, then b_0 .. b_nb; inside each, k = -K .. K.
        self.params: List[Tuple[bool, int, int]] = [
            (is_a, n, k)
            for is_a, counts in ((True, self.ka), (False, self.kb))
            for n, K in enumerate(counts)
            for k in range(-K, K + 1)]
        index = {p: i for i, p in enumerate(self.params)}
        self._index = index
        cols, d = [], np.zeros(len(self.params), complex)
        self.norm_index = -1
        for is_a, counts in ((True, self.ka), (False, self.kb)):
            for n, K in enumerate(counts):
                if (is_a, n) in self.known:
                    row = self.known[(is_a, n)]
                    for k in range(-K, K + 1):
                        d[index[(is_a, n, k)]] = row[K + k]
                    continue
                if is_a and n == self.na:
                    self.norm_index = len(cols)  # Re a_{na,0}
                col = np.zeros(len(self.params), complex)
                col[index[(is_a, n, 0)]] = 1.0
                cols.append(col)
                for k in range(1, K + 1):
                    # c_k = x + j y and c_-k = x - j y keep the coefficient real in time.
                    re = np.zeros(len(self.params), complex)
                    im = np.zeros(len(self.params), complex)
                    re[index[(is_a, n, k)]], re[index[(is_a, n, -k)]] = 1.0, 1.0
                    im[index[(is_a, n, k)]], im[index[(is_a, n, -k)]] = 1j, -1j
                    cols += [re, im]
        self.T = np.column_stack(cols) if cols else np.zeros((len(self.params), 0), complex)
        self.d = d
        self.has_known = bool(self.known)
        if self.has_known:
            # The known part fixes the scale: its column is the one set to 1.
            self.Text = np.column_stack([self.T, d])
            self.norm_index = self.T.shape[1]
        else:
            self.Text = self.T
        self.K = max(self.ka + self.kb)
        # Per-parameter attributes as arrays, for the vectorised Jacobian.
        self.p_is_a = np.array([p[0] for p in self.params])
        self.p_order = np.array([p[1] for p in self.params])
        self.p_k = np.array([p[2] for p in self.params])

    n_theta = property(lambda self: len(self.params))
    n_eta = property(lambda self: self.T.shape[1])
    n_xi = property(lambda self: self.Text.shape[1])

    def theta_index(self, is_a: bool, order: int, k: int) -> int:
        return self._index.get((bool(is_a), int(order), int(k)), -1)

    def theta_from_xi(self, xi) -> np.ndarray:
        """theta of the normalised xi (xi / xi[norm_index])."""
        return self.Text @ (np.asarray(xi, float) / xi[self.norm_index])

    def eta_from_xi(self, xi) -> np.ndarray:
        x = np.asarray(xi, float) / xi[self.norm_index]
        return x[: self.n_eta]


def theta_of_coefficients(par: Parametrisation, a, b) -> np.ndarray:
    """theta from coefficient arrays a (na+1, 2Ka+1) and b (nb+1, 2Kb+1), harmonic k in column
    Ka + k (Kb + k), as ``Model.a`` and ``Model.b`` hold them."""
    a, b = np.asarray(a, complex), np.asarray(b, complex)
    Ka, Kb = (a.shape[1] - 1) // 2, (b.shape[1] - 1) // 2
    return np.array([a[n, Ka + k] if is_a else b[n, Kb + k] for is_a, n, k in par.params])


def default_rows(par: Parametrisation, max_line: int) -> np.ndarray:
    """Rows K+1 .. Lmax-K: every line a row needs is a measured positive line (section 5)."""
    return np.arange(par.K + 1, max_line - par.K + 1)


def line_variable(par: Parametrisation, lines) -> np.ndarray:
    """s_i = j i w0 (continuous) or z_i = exp(j i w0 ts) (discrete, forward shift)."""
    w = par.w0 * np.asarray(lines, float)
    return np.exp(1j * w * par.ts) if par.ts else 1j * w


# -- section 5: Jacobian and residue --------------------------------------------------------

def jacobian(data: Data, par: Parametrisation, rows) -> np.ndarray:
    """J[r, p] = s_i^n Y_i for p = (a, n, k), -s_i^m U_i for p = (b, m, k), with i = rows[r] - k."""
    i = np.asarray(rows)[:, None] - par.p_k[None, :]
    X = np.where(par.p_is_a[None, :], line_values(data.Y, i), -line_values(data.U, i))
    return line_variable(par, i) ** par.p_order[None, :] * X


def residue(data: Data, par: Parametrisation, rows, theta) -> np.ndarray:
    """e = J theta = A(theta) Y - B(theta) U on the rows."""
    return jacobian(data, par, rows) @ np.asarray(theta, complex)


def band_rows(par: Parametrisation, theta, rows):
    """A_{l,i}, B_{l,i} (eq. 5) for i = l - k, k = -K..K: two arrays (rows, 2K+1), column K + k.

    A_{l,i} = sum_n a_{n,l-i} s_i^n, i.e. the entries of row l of the band matrices.
    """
    rows = np.asarray(rows)
    K = par.K
    k = np.arange(-K, K + 1)
    s = line_variable(par, rows[:, None] - k[None, :])
    A = np.zeros(s.shape, complex)
    B = np.zeros(s.shape, complex)
    for t, (is_a, n, kp) in zip(np.asarray(theta, complex), par.params):
        (A if is_a else B)[:, K + kp] += t * s[:, K + kp] ** n
    return A, B


def residue_variance(data: Data, par: Parametrisation, rows, theta) -> np.ndarray:
    """var e_l (eq. 15) as the quadratic form g Sigma_i g^H with g = [A_li, -B_li] per line i.

    The noise of different lines is independent. A row near DC uses both X_m and X_-m =
    conj(X_m), whose cross term E{dX_m conj(dX_-m)} = E{dX_m dX_m} vanishes for circular noise,
    and line 0 (real noise) at most once, so this holds on every row >= 1; the residue there is
    just not circular.
    """
    rows = np.asarray(rows)
    A, B = band_rows(par, theta, rows)
    k = np.arange(-par.K, par.K + 1)
    S = line_noise(data, rows[:, None] - k[None, :])  # (rows, 2K+1, 2, 2)
    g = np.stack([A, -B], axis=-1)                      # e noise = sum_i g_i . z_i
    v = np.einsum("rka,rkab,rkb->r", g, S, np.conj(g))
    return v.real


def column_covariance(data: Data, par: Parametrisation, rows, weights) -> np.ndarray:
    """C = sum_l w_l E{dJ_l^H dJ_l} (section 6), from explicit linear maps of the noise.

    Row l uses the lines i = l - k, k = -K..K; with z_l = [dY_i, dU_i]_{k=-K..K} its noise is
    dJ_l^T = M_l z_l, M_l[p, (k_p, Y or U)] = +-s_i^n. Then E{conj(dJ_p) dJ_q} =
    (conj(M_l Sigma_l M_l^H))_{pq} with Sigma_l = E{z_l z_l^H}, block diagonal over the lines
    (independent lines) with the 2 x 2 blocks of ``line_noise``.
    """
    rows = np.asarray(rows)
    K = par.K
    nk = 2 * K + 1
    k = np.arange(-K, K + 1)
    S = line_noise(data, rows[:, None] - k[None, :])          # (rows, 2K+1, 2, 2)
    M = np.zeros((rows.size, par.n_theta, nk, 2), complex)     # noise entry (line k, Y/U)
    ip = rows[:, None] - par.p_k[None, :]
    f = line_variable(par, ip) ** par.p_order[None, :]
    for p, (is_a, n, kp) in enumerate(par.params):
        M[:, p, K + kp, 0 if is_a else 1] = f[:, p] if is_a else -f[:, p]
    # einsum without BLAS: these small products are slower threaded on a busy machine.
    MS = np.einsum("rpja,rjab->rpjb", M, S).reshape(rows.size, par.n_theta, -1)
    Mf = M.reshape(rows.size, par.n_theta, -1)
    C = np.einsum("r,rpx,rqx->pq", np.asarray(weights, float), MS, np.conj(Mf))
    return np.conj(C)


def real_column_covariance(data: Data, par: Parametrisation, rows, weights) -> np.ndarray:
    """CJ_W = Re(Text^H C Text).

    Exact, no circularity needed: for one row with g = dJ_l Text (xi is real),
    E{Re(g)^T Re(g) + Im(g)^T Im(g)} = Re E{g^H g}.
    """
    C = column_covariance(data, par, rows, weights)
    CJ = (par.Text.conj().T @ C @ par.Text).real
    return 0.5 * (CJ + CJ.T)


def real_jacobian(data: Data, par: Parametrisation, rows, weights=None) -> np.ndarray:
    """Jx = [Re(J Text); Im(J Text)], both halves of row l scaled by sqrt(w_l) (section 5)."""
    JT = jacobian(data, par, rows) @ par.Text
    if weights is not None:
        JT = JT * np.sqrt(np.asarray(weights, float))[:, None]
    return np.vstack([JT.real, JT.imag])


# -- section 6: estimators ------------------------------------------------------------------

def solve_ls(Jx, norm_index: int):
    """Equation error: xi[norm_index] = 1, the rest by linear least squares (SVD-based lstsq)."""
    n = Jx.shape[1]
    rest = [j for j in range(n) if j != norm_index]
    z = np.linalg.lstsq(Jx[:, rest], -Jx[:, norm_index], rcond=None)[0]
    x = np.empty(n)
    x[norm_index] = 1.0
    x[rest] = z
    return x, np.empty(0), float(np.sum((Jx @ x) ** 2))


def solve_tls(Jx):
    """Right singular vector of the smallest singular value: min ||Jx x||, ||x|| = 1."""
    _, s, Vt = np.linalg.svd(Jx, full_matrices=False)
    return Vt[-1], s[::-1], float(s[-1] ** 2)


def solve_gtls(Jx, CJ):
    """min ||Jx x||^2 / (x^T CJ x) as a whitened SVD, CJ possibly singular (section 6).

    Columns are first scaled to unit norm (the ratio is invariant to it). A pivoted Cholesky
    factorisation (LAPACK dpstrf, rank decided at n eps max diag, i.e. within the rounding of CJ
    itself) gives P^T CJ P = [L11; L21] [L11; L21]^T with L11 r x r. With x' = P^T x split as
    (x1, x2) the denominator is ||z||^2, z = L11^T x1 + L21^T x2, and the numerator
    ||W z + G x2||^2, W = A1 L11^-T, G = A2 - W L21^T. The directions x2 carry no noise
    (e.g. the b-columns of an exactly known input): the ratio has no denominator there, so x2 is
    eliminated by least squares, projecting span(G) out of W, and the ratio becomes the Rayleigh
    quotient of the projected W: its smallest right singular vector. A singular CJ gives r < n
    finite generalised singular values (the GSVD's infinite ones are the eliminated x2).

    Returns (x, finite generalised singular values ascending, cost = smallest value squared).
    """
    n = Jx.shape[1]
    norms = np.linalg.norm(Jx, axis=0)
    scale = 1.0 / np.where(norms > 0, norms, 1.0)
    A = Jx * scale
    Cs = CJ * np.outer(scale, scale)
    c, piv, r, info = scipy.linalg.lapack.dpstrf(Cs, lower=1)
    if info < 0 or r == 0:
        raise np.linalg.LinAlgError("GTLS: pivoted Cholesky of the column covariance failed")
    perm = piv - 1
    L11 = np.tril(c[:r, :r])
    L21 = c[r:, :r]
    Ap = A[:, perm]
    W = scipy.linalg.solve_triangular(L11, Ap[:, :r].T, lower=True).T   # A1 L11^-T
    Wp = W
    if r < n:
        G = Ap[:, r:] - W @ L21.T
        Q, _ = np.linalg.qr(G)
        Wp = W - Q @ (Q.T @ W)
    _, s, Vt = np.linalg.svd(Wp, full_matrices=False)
    z = Vt[-1]
    x2 = np.linalg.lstsq(G, -(W @ z), rcond=None)[0] if r < n else np.empty(0)
    x1 = scipy.linalg.solve_triangular(L11.T, z - L21.T @ x2, lower=False)
    x = np.empty(n)
    x[perm] = np.concatenate([x1, x2])
    return scale * x, s[::-1], float(s[-1] ** 2)


def estimate(data: Data, par: Parametrisation, rows, method: str = "wgtls", tol: float = 1e-10,
             max_iter: int = 50) -> dict:
    """LS, TLS, GTLS or WGTLS (eq. 14); the same fields and stopping rule as the core's estimate.

    WGTLS starts from GTLS with unit weights, then repeats: w_l = 1 / var e_l(theta) (floored at
    VARIANCE_FLOOR * max var e), GTLS on the weighted Jacobian with CJ_W built with the same w,
    until ||theta_new - theta|| / ||theta_new|| < tol or max_iter weighted solves.
    """
    return estimate_experiments([data], par, [rows], method, tol, max_iter)


def estimate_experiments(datas: Sequence[Data], par: Parametrisation, rows_list, method: str = "wgtls",
                         tol: float = 1e-10, max_iter: int = 50) -> dict:
    """:func:`estimate` on several independent experiments of one system (METHOD.md section 14).

    Experiment e contributes its own rows, built from its own spectra: the real Jacobian is the
    experiments' Jacobians one above the other, CJ_W the sum of their column covariances (the
    noise of different experiments is independent, so the expectations add), and each row's
    WGTLS weight 1 / var e_l comes from its own experiment's noise (the floor from the largest
    variance over all rows).
    """
    rows_list = [np.asarray(r) for r in rows_list]
    pairs = list(zip(datas, rows_list))
    out = dict(iterations=0, converged=True, cost_history=[], noise_free=False)

    def finish(solved):
        x, values, cost = solved
        out.update(theta=par.theta_from_xi(x), eta=par.eta_from_xi(x), singular_values=values,
                   cost=cost)

    def stacked_jacobian(weights=None):
        return np.vstack([real_jacobian(d, par, r, None if weights is None else w)
                          for (d, r), w in zip(pairs, weights or [None] * len(pairs))])

    def summed_cj(weights):
        return sum(real_column_covariance(d, par, r, w) for (d, r), w in zip(pairs, weights))

    Jx = stacked_jacobian()
    if method == "ls":
        finish(solve_ls(Jx, par.norm_index))
        return out
    if method == "tls":
        finish(solve_tls(Jx))
        return out
    if method not in ("gtls", "wgtls"):
        raise ValueError(f"unknown method {method!r}")
    CJ = summed_cj([np.ones(r.size) for r in rows_list])
    if np.max(np.abs(CJ)) == 0.0:
        # No noise: no weight to apply; TLS is exact on noise-free data.
        out["noise_free"] = True
        finish(solve_tls(Jx))
        return out
    finish(solve_gtls(Jx, CJ))
    if method == "gtls":
        return out
    out["converged"] = False
    for it in range(1, max_iter + 1):
        v = [residue_variance(d, par, r, out["theta"]) for d, r in pairs]
        vmax = max(x.max() for x in v)
        if not (all(np.all(np.isfinite(x)) for x in v) and vmax > 0):
            raise np.linalg.LinAlgError(
                f"WGTLS: the residue variance is not positive at iteration {it}")
        w = [1.0 / np.maximum(x, VARIANCE_FLOOR * vmax) for x in v]
        prev = out["theta"]
        finish(solve_gtls(stacked_jacobian(w), summed_cj(w)))
        out["iterations"] = it
        out["cost_history"].append(out["cost"])
        if np.linalg.norm(out["theta"] - prev) / np.linalg.norm(out["theta"]) < tol:
            out["converged"] = True
            break
    return out


# -- section 7: validation ------------------------------------------------------------------

def normalized_residue(data: Data, par: Parametrisation, rows, theta):
    """e_l, var e_l and r_l = |e_l| / sqrt(var e_l)."""
    e = residue(data, par, rows, theta)
    v = residue_variance(data, par, rows, theta)
    return e, v, np.abs(e) / np.sqrt(v)


def expected_fraction_above_0db(n_rows: int, n_free: int, periods: int) -> float:
    """P(r_l > 1) for a correct model (section 7).

    |e|^2 / var e is Exp(1) = chi2_2 / 2 with known variances; with variances from P periods the
    estimated variance is var chi2_{2(P-1)} / (2(P-1)), independent of the mean, so the ratio is
    F(2, 2(P-1)). Fitting n_free parameters to 2 n_rows real equations shrinks |e|^2 by
    c = 1 - n_free / (2 n_rows): P(c F > 1) = P(F > 1/c).
    """
    c = 1.0 - n_free / (2.0 * n_rows)
    if periods and periods >= 2:
        return float(scipy.stats.f.sf(1.0 / c, 2, 2 * (periods - 1)))
    return float(scipy.stats.chi2.sf(2.0 / c, 2))
