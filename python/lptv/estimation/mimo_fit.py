"""WGTLS and SML for several inputs and outputs (METHOD.md section 19, eqs. 19.11-19.15): the
arguments for the C++ core's route (``lptv::mimo_wgtls``, ``mimo_sml``, ``mimo_fisher``,
``mimo_sandwich``, ``mimo_residues`` in cpp/src/mimo_estimators.cpp) and its results.

The route, per experiment (rows l sorted, every line a row reads a measured line >= 1):
regressors phi_l shared by every output's equation and their noise Cphi_l (nonzero only between
entries of the same harmonic, which read the same line); the residue e_l = Theta^T phi_l, its
per-line covariance C_{e,l} (eq. 19.12, WGTLS's weights) and the rows' full covariance C_E
(a Hermitian band: rows share lines when |l - l'| <= 2K); WGTLS: the ny^2 smallest generalised
singular vectors of the whitened real Jacobian and CJ_W^{1/2}, then A_{na,0} = I; SML:
Levenberg-Marquardt on e^H C_E^-1 e, gradient and Fisher information from the Jacobian at the
denoised spectra. The dense reference it is tested against is :mod:`lptv.reference.mimo_fit`.
"""
from __future__ import annotations

from typing import List, Sequence

import numpy as np

from .. import _core
from ..spectra.mimo_frequency_data import MimoFrequencyData, MimoStructure


class FitError(ValueError):
    """A fit that cannot be made on these data (the message says why)."""


def core_structure(st: MimoStructure):
    return _core.MimoStructure(st.ny, st.nu, np.ascontiguousarray(st.ka, dtype=np.int32),
                               np.ascontiguousarray(st.kb, dtype=np.int32), st.w0, st.ts)


def core_data(datas: Sequence[MimoFrequencyData], rows_list) -> List[tuple]:
    """The core's (Y, U, C as ((L+1)(ny+nu), ny+nu), rows) per experiment."""
    out = []
    for d, r in zip(datas, rows_list):
        c = d.n_outputs + d.n_inputs
        out.append((np.asarray(d.Y, complex), np.asarray(d.U, complex),
                    np.ascontiguousarray(d.C, dtype=complex).reshape(-1, c), [int(x) for x in r]))
    return out


def _call(f, *args):
    try:
        return f(*args)
    except _core.NumericalError as err:
        raise FitError(str(err)) from None


def fit(data, cst, method, *, tol=1e-10, max_iter=50, covariance=True):
    """One fit in the core: (xi, iterations, converged, singular values, noise_free, SML's cost or
    None, the covariance over the free entries or None, residues (rows, ny), C_{e,l} (rows, ny, ny))."""
    r = _call(_core.mimo_fit, data, cst, method, float(tol), int(max_iter), bool(covariance))
    est = r.estimate
    res = np.asarray(r.residues)
    Ce = np.asarray(r.residue_covariance).reshape(res.shape[0], res.shape[1], res.shape[1])
    cov = np.asarray(r.covariance) if r.covariance.size else None
    cost = float(est.cost) if method == "sml" and not est.noise_free else None
    return (np.asarray(est.xi), est.iterations, est.converged, np.asarray(est.singular_values), est.noise_free,
            cost, cov, res, Ce)


def wgtls(data, cst, *, tol=1e-10, max_iter=50, method="wgtls"):
    """WGTLS (or GTLS) with vector residues: xi, iterations, converged, singular values, noise_free."""
    r = _call(_core.mimo_wgtls, data, cst, float(tol), int(max_iter), method == "wgtls")
    return np.asarray(r.xi), r.iterations, r.converged, np.asarray(r.singular_values), r.noise_free


def sml(data, cst, xi0, *, tol=1e-10, max_iter=50):
    """Levenberg-Marquardt on the exact likelihood from xi0: xi, cost, F (free), steps, converged."""
    r = _call(_core.mimo_sml, data, cst, np.asarray(xi0, float), float(tol), int(max_iter))
    return np.asarray(r.xi), float(r.cost), np.asarray(r.information), r.iterations, r.converged


def fisher(data, cst, xi) -> np.ndarray:
    """2 Re(J0^H C_E^-1 J0) over the free entries (eq. 19.15 at noiseless spectra and true (co)variances)."""
    return np.asarray(_call(_core.mimo_fisher, data, cst, np.asarray(xi, float)))


def sandwich(data, cst, xi) -> np.ndarray:
    """WGTLS's first-order covariance over the free entries."""
    return np.asarray(_call(_core.mimo_sandwich, data, cst, np.asarray(xi, float)))


def residues(data, cst, xi):
    """e_l (rows, ny) and C_{e,l} (rows, ny, ny) over all experiments' rows."""
    es, cs = [], []
    for d in data:
        e, C = _call(_core.mimo_residues, d, cst, np.asarray(xi, float))
        e = np.asarray(e)
        es.append(e)
        cs.append(np.asarray(C).reshape(e.shape[0], e.shape[1], e.shape[1]))
    return np.vstack(es), np.concatenate(cs)


def expand(cov_free: np.ndarray, st: MimoStructure) -> np.ndarray:
    """A covariance over the free parameters as one over xi (zero rows for the normalised entries)."""
    out = np.zeros((st.n_xi, st.n_xi))
    f = st.free
    out[np.ix_(f, f)] = cov_free
    return out


def transient_orders(st: MimoStructure) -> np.ndarray:
    """The powers of the record's transient term (METHOD.md section 20, eq. 20.5): s^0 .. s^(n-1)
    in continuous time, z^1 .. z^n in discrete time, n = max(na, nb)."""
    n = max(st.na, st.nb)
    return np.arange(1, n + 1) if st.ts else np.arange(n)


class Transient:
    """The fit with the record's transient term of each experiment and output (METHOD.md section
    20, "The record's transient in the fit"): the experiments' spectra with one noise-free input
    more per experiment, 1 on every line of its own experiment and 0 in the others, whose B
    entries (no harmonics) at the transient's powers are its real coefficients; every other
    input keeps its own orders (the absent entries kb = -1 of the core's structure)."""

    def __init__(self, st: MimoStructure, n_experiments: int):
        self.orders = transient_orders(st)
        self.n_experiments = E = int(n_experiments)
        nb = max(st.nb, int(self.orders.max()))
        kb = -np.ones((nb + 1, st.nu + E), dtype=int)
        kb[:st.nb + 1, :st.nu] = st.kb
        kb[np.ix_(self.orders, np.arange(st.nu, st.nu + E))] = 0
        self.base = st
        self.st = MimoStructure(st.na, nb, st.ka, kb, st.ny, st.nu + E, st.w0, st.ts or None)
        pos = {n: i for i, n in enumerate(self.st.names)}
        self.keep = np.array([pos[n] for n in st.names])
        self.nuisance = np.array([[[pos[f"b{m}[{p},{st.nu + e}].re0"] for m in self.orders] for p in range(st.ny)]
                                  for e in range(E)])
        fpos = {int(i): k for k, i in enumerate(self.st.free)}
        self.free_keep = np.array([fpos[int(i)] for i in self.keep[st.free]])

    @property
    def n_parameters(self) -> int:
        """The real coefficients the transient adds: experiments x outputs x powers."""
        return int(self.nuisance.size)

    def data(self, datas: Sequence[MimoFrequencyData], rows_list) -> List[tuple]:
        """The core's spectra with the transient's inputs (noise-free: zero (co)variances)."""
        out = []
        E = self.n_experiments
        for e, (Y, U, C, rows) in enumerate(core_data(datas, rows_list)):
            L1, nu = U.shape
            ny = Y.shape[1]
            c = ny + nu
            Ua = np.zeros((L1, nu + E), complex)
            Ua[:, :nu] = U
            Ua[:, nu + e] = 1.0
            Ca = np.zeros((L1, c + E, c + E), complex)
            Ca[:, :c, :c] = C.reshape(L1, c, c)
            out.append((Y, Ua, Ca.reshape(-1, c + E), rows))
        return out

    def structure(self):
        return core_structure(self.st)

    def reduce(self, xi_aug: np.ndarray, free_cov_aug: np.ndarray = None):
        """The model's xi and its free covariance (the transient's coefficients profiled out: the
        block of the joint covariance), and the coefficients (experiments, outputs, powers)."""
        xi = np.asarray(xi_aug)[self.keep]
        cov = None if free_cov_aug is None else free_cov_aug[np.ix_(self.free_keep, self.free_keep)]
        return xi, cov, np.asarray(xi_aug)[self.nuisance]
