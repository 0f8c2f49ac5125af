"""Frozen poles and HTF branches of an estimate with their uncertainty (METHOD.md section 22):
the covariance of the free real parameters carried to first order, J C J^T (frozen poles: the
root's derivative in closed form; HTF branches: central differences of ``Model.freqresp``)."""
from __future__ import annotations

from dataclasses import dataclass
import numpy as np

from .._validate import as_real_1d
from .parameters import _parse, _source, _z, perturbed_model

__all__ = ["FrozenPoles", "HtfBand", "frozen_poles_of", "htf_band"]


@dataclass(frozen=True)
class FrozenPoles:
    """What :func:`lptv.frozen_poles` returns for an identification result."""

    t: np.ndarray
    """The times (s) (discrete time: sample times)."""
    poles: np.ndarray
    """(len t, na): the roots of sum_n a_n(t) s^n (z^n), as for a model."""
    std: np.ndarray
    """(len t, na, 2): the first-order std of Re and Im of each pole."""

    def confidence_interval(self, level: float = 0.95) -> np.ndarray:
        """(len t, na, 2, 2): ``[..., 0, :]`` the interval of Re p, ``[..., 1, :]`` of Im p."""
        z = _z(level)
        mid = np.stack([self.poles.real, self.poles.imag], axis=-1)
        return np.stack([mid - z * self.std, mid + z * self.std], axis=-1)


def frozen_poles_of(res, t=None, *, roots) -> FrozenPoles:
    """The frozen poles of ``res.model`` at ``t`` (default: 64 times over one period) with their
    std: dp = -dA(t, p) / A'(t, p), dA / d a_{n,h} = e^{j h w0 t} p^n (METHOD.md section 22).
    ``roots(model, t)`` gives the poles (validation.frozen_poles, passed in to keep the imports
    one way)."""
    model, names, eta, cov = _source(res)
    if cov is None:
        raise ValueError("frozen_poles: no std without a covariance (fit with covariance='analytic')")
    if t is None:
        t = np.arange(64) * (model.period / 64)
    t = as_real_1d(t, "t")
    P = roots(model, t)
    std = np.zeros(P.shape + (2,))
    for it, ti in enumerate(t):
        coef = model.a_at(np.array([ti]))[0]            # a_n(t), lowest first
        dcoef = np.polyder(coef[::-1])
        for i, p in enumerate(P[it]):
            if not np.isfinite(p):
                std[it, i] = np.inf
                continue
            dA = np.polyval(dcoef, p)
            g = np.zeros((2, len(names)))
            for j, name in enumerate(names):
                side, n, part, k = _parse(name)
                if side == "b":
                    continue
                e = np.exp(1j * k * model.w0 * ti)
                basis = (e + np.conj(e) if k else 1.0) if part == "re" else 1j * (e - np.conj(e))
                dp = -basis * p ** n / dA
                g[:, j] = dp.real, dp.imag
            V = g @ cov @ g.T
            std[it, i] = np.sqrt(np.maximum(np.diag(V), 0.0))
    return FrozenPoles(t=t, poles=P, std=std)


@dataclass(frozen=True)
class HtfBand:
    """What :meth:`IdentificationResult.htf_band` returns: the model's HTF branches at lines with
    their first-order covariance."""

    lines: np.ndarray
    w: np.ndarray
    """w_l = l w0 (rad/s) of the input lines."""
    branches: np.ndarray
    """The branch indices k; G_k(w_l) maps input line l to output line l + k."""
    G: np.ndarray
    """(len branches, len lines) complex."""
    covariance: np.ndarray
    """(len branches, len lines, 2, 2): the covariance of (Re G, Im G)."""
    level: float

    @property
    def std_abs(self) -> np.ndarray:
        """First-order std of |G_k| (Re(conj(G) dG) / |G|)."""
        u = np.stack([self.G.real, self.G.imag], axis=-1) / np.maximum(np.abs(self.G), 1e-300)[..., None]
        return np.sqrt(np.maximum(np.einsum("...i,...ij,...j->...", u, self.covariance, u), 0.0))

    @property
    def std_phase(self) -> np.ndarray:
        """First-order std of arg G_k in rad (Im(dG / G))."""
        u = np.stack([-self.G.imag, self.G.real], axis=-1) / np.maximum(np.abs(self.G), 1e-300)[..., None] ** 2
        return np.sqrt(np.maximum(np.einsum("...i,...ij,...j->...", u, self.covariance, u), 0.0))

    def magnitude_band(self) -> np.ndarray:
        """(len branches, len lines, 2): |G| -+ z std_abs at the band's level (low clipped at 0)."""
        z = _z(self.level)
        m = np.abs(self.G)
        return np.stack([np.maximum(m - z * self.std_abs, 0.0), m + z * self.std_abs], axis=-1)

    def contains(self, G) -> np.ndarray:
        """Whether each value of ``G`` (same shape as ``self.G``) lies in the level's ellipse
        (x - G)^T Cov^-1 (x - G) <= chi2_2(level) around the estimate."""
        G = np.asarray(G, complex)
        if G.shape != self.G.shape:
            raise ValueError(f"G must have shape {self.G.shape}, got {G.shape}")
        d = np.stack([(G - self.G).real, (G - self.G).imag], axis=-1)
        q = np.einsum("...i,...ij,...j->...", d, np.linalg.pinv(self.covariance), d)
        return q <= -2.0 * np.log(1.0 - self.level)   # chi2_2 quantile


def _branches(model, w, ks) -> np.ndarray:
    """G_k(w) for each k of ``ks``, shape (len(ks), w.size): one harmonic balance for every
    branch where the model has one (a one-channel LPTV model), else branch by branch."""
    if hasattr(model, "_branches") and not model.is_lti:
        return model._branches(w, [int(k) for k in ks])
    return np.stack([model.freqresp(w, branch=int(k)) for k in ks])


def htf_band(res, lines=None, branches=(0,), *, level: float = 0.95) -> HtfBand:
    """The HTF branches G_k(j w_l) of ``res.model`` at the input ``lines`` (default: the fit's
    excited lines, |U_l|^2 > 100 var U_l) with their covariance (METHOD.md section 22)."""
    from .._validate import as_int

    model, names, eta, cov = _source(res)
    if cov is None:
        raise ValueError("htf_band: no band without a covariance (fit with covariance='analytic')")
    _z(level)
    if lines is None:
        d = getattr(res, "data", None)
        if d is None:
            raise ValueError("htf_band: lines must be given (the result keeps no data)")
        U, vU = np.asarray(d.U), np.asarray(d.varU)
        lines = np.flatnonzero(np.abs(U) ** 2 > 100 * np.maximum(vU, 1e-300))
        lines = lines[lines > 0]
    lines = np.asarray(lines)
    if lines.ndim != 1 or lines.size == 0 or not np.issubdtype(lines.dtype, np.integer) or np.any(lines < 1):
        raise ValueError(f"lines must be a non-empty 1-D array of positive integers, got {lines!r}")
    ks = np.array([as_int(k, "branches", minimum=-4096) for k in np.atleast_1d(branches)])
    w = lines * model.w0
    G = _branches(model, w, ks)
    Jr = np.zeros(G.shape + (2, len(names)))
    for j, name in enumerate(names):
        if cov[j, j] <= 0:
            continue
        h = 1e-6 * max(abs(eta[j]), 1e-3)
        mp, mm = perturbed_model(model, name, h), perturbed_model(model, name, -h)
        dG = (_branches(mp, w, ks) - _branches(mm, w, ks)) / (2 * h)
        Jr[..., 0, j], Jr[..., 1, j] = dG.real, dG.imag
    C = np.einsum("...ip,pq,...jq->...ij", Jr, cov, Jr)
    return HtfBand(lines=lines, w=w, branches=ks, G=G, covariance=C, level=float(level))
