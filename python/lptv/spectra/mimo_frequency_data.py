"""The data of a fit with several inputs and outputs (METHOD.md section 19, eq. 19.10): the
periods' mean spectra of all channels and the (co)variances of those means, and the structure
(orders and harmonic counts of each entry) the estimators of :mod:`lptv.estimation.mimo_fit` read."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Tuple

import numpy as np

from .._validate import _array, as_int, check_finite
from ..model.siso import _ts, _w0


@dataclass(frozen=True)
class MimoFrequencyData:
    """Mean spectra and noise (co)variances of P periods of nu inputs and ny outputs.

    ``z_l = [Y_l; U_l]`` on lines 0..N//2 (``fft(x)[l] / N`` per channel, as for one input and
    output) and ``C[l]``, the covariance of the mean ``E{dz_l dz_l^H}`` (eq. 19.10), channels in
    the order y_1..y_ny, u_1..u_nu.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> rng = np.random.default_rng(0)
    >>> d = lptv.MimoFrequencyData.from_periods(rng.standard_normal((4, 32, 2)),
    ...                                         rng.standard_normal((4, 32, 3)), w0=1.0)
    >>> d.U.shape, d.Y.shape, d.C.shape, d.periods
    ((17, 2), (17, 3), (17, 5, 5), 4)
    """

    U: np.ndarray
    """Input spectra, shape (L+1, nu)."""
    Y: np.ndarray
    """Output spectra, shape (L+1, ny)."""
    C: np.ndarray
    """Covariance of the mean [Y; U] on each line, shape (L+1, ny+nu, ny+nu)."""
    periods: int
    w0: float
    ts: Optional[float] = None

    def __post_init__(self):
        U, Y, C = (np.asarray(_array(x, n)) for x, n in ((self.U, "U"), (self.Y, "Y"), (self.C, "C")))
        if U.ndim != 2 or min(U.shape) < 1:
            raise ValueError(f"U must have shape (L+1, nu), got {U.shape}")
        if Y.ndim != 2 or Y.shape[0] != U.shape[0] or Y.shape[1] < 1:
            raise ValueError(f"Y must have shape (L+1, ny) with the lines of U ({U.shape[0]}), got {Y.shape}")
        c = U.shape[1] + Y.shape[1]
        if C.shape != (U.shape[0], c, c):
            raise ValueError(f"C must have shape (L+1, ny+nu, ny+nu) = {(U.shape[0], c, c)}, got {C.shape}")
        for x, n in ((U, "U"), (Y, "Y"), (C, "C")):
            check_finite(x, n)
        if isinstance(self.periods, bool) or int(self.periods) != self.periods or self.periods < 0:
            raise ValueError(f"periods must be a non-negative integer, got {self.periods!r}")
        object.__setattr__(self, "U", U.astype(complex))
        object.__setattr__(self, "Y", Y.astype(complex))
        object.__setattr__(self, "C", C.astype(complex))

    n_inputs = property(lambda self: self.U.shape[1])
    n_outputs = property(lambda self: self.Y.shape[1])
    max_line = property(lambda self: self.U.shape[0] - 1)

    statistics = "given"
    """'periods', 'record' (METHOD.md section 20) or 'given'."""

    @classmethod
    def from_periods(cls, u, y, *, w0: float, ts: Optional[float] = None,
                     statistics: str = "periods") -> "MimoFrequencyData":
        """From P >= 2 periods: ``u`` of shape (P, N, nu), ``y`` of shape (P, N, ny).

        ``statistics='record'``: the covariances of lines 1 .. N/2 - 1 (N/2 too for odd N) from
        the whole record's P - 1 bins between the lines (METHOD.md section 20), as for one
        input and output (:meth:`lptv.FrequencyData.from_periods`)."""
        if not isinstance(statistics, str) or statistics not in ("periods", "record"):
            raise ValueError(f"statistics must be 'periods' or 'record', got {statistics!r}")
        u = _periods(u, "u")
        y = _periods(y, "y")
        if y.shape[:2] != u.shape[:2]:
            raise ValueError(f"y must have the periods and samples of u {u.shape[:2]} (shape (P, N, ny)), "
                             f"got shape {y.shape}")
        P, N = u.shape[:2]
        if P < 2:
            raise ValueError(f"u must hold P >= 2 periods for the noise (co)variances (shape (P, N, nu)), got {P}")
        z = np.concatenate([np.fft.rfft(y, axis=1), np.fft.rfft(u, axis=1)], axis=2) / N
        # deviations from the first period, so that a channel whose periods are identical (an
        # input measured without noise) has exactly zero (co)variances, not rounding
        w = z - z[0]
        wm = w.mean(axis=0)
        zm = z[0] + wm
        dz = w - wm
        C = np.einsum("plc,pld->lcd", dz, dz.conj()) / (P * (P - 1))
        ny = y.shape[2]
        if statistics == "record":
            zr = np.concatenate([np.fft.rfft(y.reshape(P * N, -1), axis=0),
                                 np.fft.rfft(u.reshape(P * N, -1), axis=0)], axis=1) / (P * N)
            last = N // 2 - 1 if N % 2 == 0 else N // 2
            qs = np.array([q for q in range(-((P + 1) // 2) + 1, P // 2 + 1) if q != 0])
            lines = np.arange(1, last + 1)
            zb = zr[lines[:, None] * P + qs[None, :]]          # (lines, P - 1, channels)
            C = C.copy()
            C[lines] = np.einsum("lqc,lqd->lcd", zb, zb.conj()) / (P - 1)
        out = cls(U=zm[:, ny:].copy(), Y=zm[:, :ny].copy(), C=C, periods=P, w0=_w0(w0), ts=_ts(ts))
        object.__setattr__(out, "statistics", statistics)
        object.__setattr__(out, "_spectra", tuple(z[:, :, c] for c in range(z.shape[2])))
        object.__setattr__(out, "_channel_names", tuple(f"output {i}" for i in range(ny))
                           + tuple(f"input {i}" for i in range(u.shape[2])))
        object.__setattr__(out, "_record", (u, y))
        return out

    def record_statistics(self) -> "MimoFrequencyData":
        """These data with the covariances from the whole record (``statistics='record'``)."""
        if self.statistics == "record":
            return self
        rec = getattr(self, "_record", None)
        if rec is None:
            raise ValueError("the record's statistics need the periods: make the data with "
                             "MimoFrequencyData.from_periods(u, y, ...)")
        return MimoFrequencyData.from_periods(rec[0], rec[1], w0=self.w0, ts=self.ts, statistics="record")


def _periods(x, name):
    arr = _array(x, name)
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} must be a real time signal, got complex values")
    if arr.ndim != 3:
        raise ValueError(f"{name} must have shape (P, N, channels): P periods of N samples of each channel, "
                         f"got shape {arr.shape}")
    if min(arr.shape) < 1:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    check_finite(arr, name)
    return np.ascontiguousarray(arr, dtype=float)


class MimoStructure:
    """Orders and harmonic counts of a matrix model, and its real parametrisation.

    Row-uniform (METHOD.md section 19): the entries of A_n in column q have the harmonic count
    ``ka[n, q]`` in every row, those of B_m in column r ``kb[m, r]``. Every output's equation
    then holds the same regressors phi_l (one per coefficient (side, order, column) and harmonic
    k), and output p's parameters are theta_p: e_{l,p} = phi_l^T theta_p. The real parameters of
    one row, xi_p, are per coefficient Re c_0, Re c_1, Im c_1, .., Re c_K, Im c_K (theta_p =
    T xi_p); xi stacks xi_1..xi_ny. The normalisation A_{na,0} = I (eq. 19.7) fixes Re c_0 of
    (a, na, q) in row p to delta_pq.
    """

    def __init__(self, na: int, nb: int, ka: np.ndarray, kb: np.ndarray, ny: int, nu: int, w0: float,
                 ts: Optional[float] = None):
        self.na, self.nb, self.ny, self.nu = int(na), int(nb), int(ny), int(nu)
        self.ka = np.asarray(ka, dtype=int).reshape(self.na + 1, self.ny)
        self.kb = np.asarray(kb, dtype=int).reshape(self.nb + 1, self.nu)
        self.w0 = float(w0)
        self.ts = float(ts) if ts else 0.0
        self.coefs: List[Tuple[bool, int, int, int]] = (
            [(True, n, q, int(self.ka[n, q])) for n in range(self.na + 1) for q in range(self.ny)]
            + [(False, m, r, int(self.kb[m, r])) for m in range(self.nb + 1) for r in range(self.nu)
               if self.kb[m, r] >= 0])     # kb = -1: an absent entry (the transient's columns, section 20)
        is_a, order, col, harm, cols, names = [], [], [], [], [], []
        fixed = []
        for ci, (a, n, c, K) in enumerate(self.coefs):
            base = len(is_a)
            for k in range(-K, K + 1):
                is_a.append(a)
                order.append(n)
                col.append(c)
                harm.append(k)
            if a and n == self.na:
                fixed.append(len(cols))
            cols.append({base + K: 1.0})
            names.append((ci, "re0"))
            for k in range(1, K + 1):
                cols.append({base + K + k: 1.0, base + K - k: 1.0})
                cols.append({base + K + k: 1j, base + K - k: -1j})
                names += [(ci, f"re{k}"), (ci, f"im{k}")]
        self.p_is_a = np.array(is_a, dtype=bool)
        self.p_order = np.array(order, dtype=int)
        self.p_col = np.array(col, dtype=int)
        self.p_k = np.array(harm, dtype=int)
        self.p_channel = np.where(self.p_is_a, self.p_col, self.ny + self.p_col)
        self.T = np.zeros((len(is_a), len(cols)), complex)
        for j, c in enumerate(cols):
            for i, v in c.items():
                self.T[i, j] = v
        self.fixed_row = np.array(fixed, dtype=int)         # positions in a row's xi_p, column q = 0..ny-1
        self._names = names
        self.K = int(max(self.ka.max(), self.kb.max()))

    n_phi = property(lambda self: self.T.shape[0])
    n_row = property(lambda self: self.T.shape[1])
    n_xi = property(lambda self: self.ny * self.T.shape[1])

    @property
    def fixed(self) -> np.ndarray:
        """Positions in xi of the normalised entries, row p column q at [p, q]."""
        return np.arange(self.ny)[:, None] * self.n_row + self.fixed_row[None, :]

    @property
    def free(self) -> np.ndarray:
        mask = np.ones(self.n_xi, dtype=bool)
        mask[self.fixed.ravel()] = False
        return np.flatnonzero(mask)

    @property
    def names(self) -> Tuple[str, ...]:
        """Names of xi's entries: 'a2[0,1].re0' is Re of harmonic 0 of [A_2]_{01}."""
        out = []
        for p in range(self.ny):
            for ci, part in self._names:
                a, n, c, _ = self.coefs[ci]
                out.append(f"{'a' if a else 'b'}{n}[{p},{c}].{part}")
        return tuple(out)

    def theta(self, xi) -> np.ndarray:
        """The complex parameters of each row, shape (n_phi, ny)."""
        return self.T @ np.asarray(xi, float).reshape(self.ny, self.n_row).T

    def xi_of(self, a, b) -> np.ndarray:
        """xi of coefficient arrays a (na'+1, ny, ny, 2Ka'+1) and b (nb'+1, ny, nu, 2Kb'+1), in
        this structure (entries outside it are ignored)."""
        a, b = np.asarray(a, complex), np.asarray(b, complex)
        out = np.zeros((self.ny, self.n_row))
        for p in range(self.ny):
            j = 0
            for is_a, n, c, K in self.coefs:
                arr = a if is_a else b
                Kx = (arr.shape[3] - 1) // 2

                def get(k):
                    return arr[n, p, c, Kx + k] if n < arr.shape[0] and abs(k) <= Kx else 0.0
                out[p, j] = get(0).real
                j += 1
                for k in range(1, K + 1):
                    out[p, j], out[p, j + 1] = get(k).real, get(k).imag
                    j += 2
        return out.ravel()

    def coefficients(self, xi):
        """(a, b) coefficient arrays of the model xi describes (the MimoModel layout)."""
        th = self.theta(xi)
        Ka, Kb = int(self.ka.max()), int(self.kb.max())
        a = np.zeros((self.na + 1, self.ny, self.ny, 2 * Ka + 1), complex)
        b = np.zeros((self.nb + 1, self.ny, self.nu, 2 * Kb + 1), complex)
        for i in range(self.n_phi):
            if self.p_is_a[i]:
                a[self.p_order[i], :, self.p_col[i], Ka + self.p_k[i]] = th[i]
            else:
                b[self.p_order[i], :, self.p_col[i], Kb + self.p_k[i]] = th[i]
        return a, b

    def line_variable(self, lines) -> np.ndarray:
        w = self.w0 * np.asarray(lines, float)
        return np.exp(1j * w * self.ts) if self.ts else 1j * w


def as_entry_counts(k, order: int, rows: int, cols: int, name: str) -> np.ndarray:
    """Harmonic counts of a matrix coefficient side: an int for every entry, one per order
    (order+1,), one per entry (rows, cols) for every order, or (order+1, rows, cols). Returned per
    order and column (order+1, cols): the structure must be row-uniform."""
    arr = _array(k, name)
    if np.iscomplexobj(arr) or not np.all(np.isfinite(arr)) or np.any(arr != np.round(arr)) or np.any(arr < 0):
        raise ValueError(f"{name} must hold non-negative integers, got {k!r}")
    arr = arr.astype(int)
    if arr.ndim == 0:
        arr = np.full((order + 1, rows, cols), int(arr))
    elif arr.ndim == 1 and arr.shape == (order + 1,):
        arr = np.broadcast_to(arr[:, None, None], (order + 1, rows, cols))
    elif arr.ndim == 2 and arr.shape == (rows, cols):
        arr = np.broadcast_to(arr[None], (order + 1, rows, cols))
    elif not (arr.ndim == 3 and arr.shape == (order + 1, rows, cols)):
        raise ValueError(f"{name} must be an int, one count per order ({order + 1},), one per entry "
                         f"({rows}, {cols}) or per order and entry ({order + 1}, {rows}, {cols}), "
                         f"got shape {arr.shape}")
    if np.any(arr > 4096):
        raise ValueError(f"{name}: a harmonic count must be at most 4096, got {int(arr.max())}")
    if np.any(arr != arr[:, :1, :]):
        raise ValueError(f"{name}: the structure must be row-uniform (every output's row of a coefficient "
                         "matrix with the same harmonic counts in each column), which the normalisation "
                         "A_na,0 = I needs (METHOD.md section 19)")
    return np.ascontiguousarray(arr[:, 0, :])


def as_order(x, name: str) -> int:
    return as_int(x, name, maximum=64)
