"""The Floquet exponents of an estimate with their uncertainty (METHOD.md section 22).

:func:`lptv.floquet` of an identification result comes here: the covariance C of the free real
parameters eta is carried to the exponents to first order, J C J^T with J = d lambda / d eta
(one output: the core's eigenvalue derivative of Hill's matrix or of the monodromy product,
``_core.floquet_sensitivity``; several outputs: central differences of the core's exponents), or
by the parametric bootstrap (``method='bootstrap'``: draws from N(eta, C)). A result is read by
its attributes (model, eta_names, eta, covariance), so that this module imports no result type.
"""
from __future__ import annotations

import re
from typing import Optional, Tuple

import numpy as np

from .. import _core
from .mimo import MimoModel
from .siso import Model

_SISO = re.compile(r"([ab])(\d+)\.(re|im)(\d+)")
_MIMO = re.compile(r"([ab])(\d+)\[(\d+),(\d+)\]\.(re|im)(\d+)")

FIRST_ORDER_SEPARATION = 3.0
"""Two exponents closer than this many std of their distance make first order fail (section 22)."""
MAX_CONDITION = 1e8
"""An eigenvalue condition number above this is a repeated exponent: no first-order derivative."""


def source(obj):
    """(model, names, eta, covariance) of an identification result; ValueError without covariance."""
    if not all(hasattr(obj, a) for a in ("model", "eta_names", "eta", "covariance")) or \
            not isinstance(obj.model, (Model, MimoModel)):
        raise ValueError(f"model must be an lptv.Model, an lptv.MimoModel or an identification result, "
                         f"got {type(obj).__name__}")
    if obj.covariance is None:
        why = obj._no_covariance()[0] if hasattr(obj, "_no_covariance") else "the result has no covariance"
        raise ValueError(f"floquet: no intervals without a covariance: {why}")
    names = tuple(obj.eta_names)
    cov = np.asarray(obj.covariance, float)
    if cov.shape != (len(names), len(names)):
        raise ValueError(f"floquet: the covariance's shape {cov.shape} does not match the {len(names)} parameters")
    return obj.model, names, np.asarray(obj.eta, float), cov


def model_from_eta(model, names, eta):
    """A copy of ``model`` with the real parameters ``names`` set to ``eta``."""
    a, b = model.a.copy(), model.b.copy()
    mimo = isinstance(model, MimoModel)
    for name, value in zip(names, eta):
        m = (_MIMO if mimo else _SISO).fullmatch(name)
        if m is None:
            raise ValueError(f"not a parameter name of this model: {name!r}")
        side, n = m.group(1), int(m.group(2))
        part, k = m.group(m.lastindex - 1), int(m.group(m.lastindex))
        arr, K = (a, model.ka) if side == "a" else (b, model.kb)
        idx = (n, int(m.group(3)), int(m.group(4))) if mimo else (n,)
        c = arr[idx + (K + k,)]
        c = complex(value, c.imag) if part == "re" else complex(c.real, value)
        arr[idx + (K + k,)] = c
        if k:
            arr[idx + (K - k,)] = np.conj(c)
    return type(model)(a, b, w0=model.w0, ts=model.ts)


def _siso_jacobian(model: Model, names, opt):
    """(floquet core result, J complex (n, n_eta), condition numbers) by the core's derivative."""
    s = _core.floquet_sensitivity(model._cpp, **opt)
    Ka = model.ka
    n = len(s.gradient)
    J = np.zeros((n, len(names)), complex)
    for j, name in enumerate(names):
        m = _SISO.fullmatch(name)
        if m is None:
            raise ValueError(f"not a parameter name like 'a0.re1': {name!r}")
        if m.group(1) == "b":
            continue
        order, part, k = int(m.group(2)), m.group(3), int(m.group(4))
        for i, g in enumerate(s.gradient):
            g = np.asarray(g)
            if k == 0:
                J[i, j] = g[order, Ka] if part == "re" else 0.0
            elif part == "re":
                J[i, j] = g[order, Ka + k] + g[order, Ka - k]
            else:
                J[i, j] = 1j * (g[order, Ka + k] - g[order, Ka - k])
    return s.floquet, J, np.asarray(s.condition, float)


def _wrap(im, w0):
    r = im - w0 * np.round(im / w0)
    return np.where(r <= -0.5 * w0, r + w0, np.where(r > 0.5 * w0, r - w0, r))


def match(reference, lam, w0):
    """The order of ``lam`` that pairs it with ``reference`` (by the distance modulo j w0,
    the Hungarian assignment), and ``lam`` put on the branches of ``reference``."""
    from scipy.optimize import linear_sum_assignment

    ref, lam = np.asarray(reference), np.asarray(lam)
    fin_r, fin_l = np.isfinite(ref.real), np.isfinite(lam.real)
    dre = np.where(fin_r[:, None] & fin_l[None, :], ref.real[:, None] - lam.real[None, :], 0.0)
    dre = np.where(fin_r[:, None] == fin_l[None, :], dre, 1e300)
    dim = _wrap(ref.imag[:, None] - lam.imag[None, :], w0)
    _, col = linear_sum_assignment(np.hypot(dre, dim))
    out = lam[col]
    # on the reference's branch: Im continued from the reported exponent, not wrapped
    return out.real + 1j * (ref.imag - _wrap(ref.imag - out.imag, w0))


def _mimo_jacobian(model: MimoModel, names, cov, opt):
    """Central differences of the core's exponents (several outputs; METHOD.md section 22)."""
    f = _core.floquet_mimo(model._cpp, **opt)
    lam0 = np.asarray(f.exponents)
    eta0 = np.array([_value(model, nm) for nm in names])
    J = np.zeros((lam0.size, len(names)), complex)
    for j, name in enumerate(names):
        if cov[j, j] <= 0:
            continue
        h = 1e-6 * max(abs(eta0[j]), 1e-3)
        lp, lm = [], []
        for sign, store in ((1, lp), (-1, lm)):
            e = eta0.copy()
            e[j] += sign * h
            mm = model_from_eta(model, (name,), e[j:j + 1])
            store.append(match(lam0, np.asarray(_core.floquet_mimo(mm._cpp, **opt).exponents), model.w0))
        J[:, j] = (lp[0] - lm[0]) / (2 * h)
    return f, J, np.full(lam0.size, np.nan)


def _value(model, name):
    m = _MIMO.fullmatch(name)
    if m is None:
        raise ValueError(f"not a parameter name like 'a0[0,1].re1': {name!r}")
    arr, K = (model.a, model.ka) if m.group(1) == "a" else (model.b, model.kb)
    c = arr[int(m.group(2)), int(m.group(3)), int(m.group(4)), K + int(m.group(6))]
    return c.real if m.group(5) == "re" else c.imag


def first_order(obj, opt):
    """(core Floquet result, exponents (n,), covariance (2n, 2n) of [Re l0, Im l0, Re l1, ...],
    condition numbers)."""
    model, names, eta, cov = source(obj)
    if isinstance(model, MimoModel):
        f, J, cond = _mimo_jacobian(model, names, cov, opt)
    else:
        f, J, cond = _siso_jacobian(model, names, opt)
    lam = np.asarray(f.exponents)
    Jr = np.empty((2 * lam.size, len(names)))
    Jr[0::2], Jr[1::2] = J.real, J.imag
    Jr[~np.isfinite(Jr)] = 0.0
    C = Jr @ cov @ Jr.T
    return f, lam, 0.5 * (C + C.T), cond


def bootstrap(obj, opt, draws: int, seed):
    """(core Floquet result, exponents, draws (B, n) on the estimate's branches)."""
    model, names, eta, cov = source(obj)
    route = _core.floquet_mimo if isinstance(model, MimoModel) else _core.floquet
    f = route(model._cpp, **opt)
    lam = np.asarray(f.exponents)
    w, V = np.linalg.eigh(0.5 * (cov + cov.T))
    L = V * np.sqrt(np.maximum(w, 0.0))
    rng = np.random.default_rng(seed)
    out = np.empty((draws, lam.size), complex)
    for i in range(draws):
        e = eta + L @ rng.standard_normal(eta.size)
        m = model_from_eta(model, names, e)
        out[i] = match(lam, np.asarray(route(m._cpp, **opt).exponents), model.w0)
    return f, lam, out


def stable_probability(re, C_re) -> float:
    """P(every Re lambda < 0) under N(re, C_re) of the distinct decay rates (section 22)."""
    from .._dist import norm_sf

    fin = np.isfinite(re)
    re, C_re = re[fin], C_re[np.ix_(fin, fin)]
    if re.size == 0:
        return 1.0
    s = np.sqrt(np.maximum(np.diag(C_re), 0.0))
    if np.all(s == 0):
        return float(np.all(re < 0))
    if re.size == 1:
        return float(norm_sf(re[0] / s[0]))
    from scipy.stats import multivariate_normal

    keep = s > 0
    if np.any(re[~keep] >= 0):
        return 0.0
    re, C_re = re[keep], C_re[np.ix_(keep, keep)]
    if re.size == 1:
        return float(norm_sf(re[0] / np.sqrt(C_re[0, 0])))
    # Genz's quasi-Monte Carlo, seeded so that one estimate gives one probability
    p = multivariate_normal.cdf(np.zeros(re.size), mean=re, cov=C_re, allow_singular=True, abseps=1e-6,
                                releps=1e-6, rng=np.random.default_rng(0))
    return float(np.clip(p, 0.0, 1.0))


def distinct_rates(lam, w0) -> np.ndarray:
    """Indices of one exponent per decay rate: the complex pairs' member with Im > 0 and every
    exponent of a real multiplier (Im = 0 or w0/2)."""
    return np.flatnonzero(lam.imag >= 0)


def first_order_notes(lam, C, cond, w0) -> Tuple[str, ...]:
    """The sentences saying where first order does not hold (section 22); empty when it does."""
    notes = []
    n = lam.size
    for i in range(n):
        if np.isfinite(cond[i]) and cond[i] > MAX_CONDITION:
            notes.append(f"exponent {i} ({_fmt(lam[i])}) is ill-conditioned (condition {cond[i]:.3g}): a repeated "
                         f"exponent, whose first-order interval does not hold; use method='bootstrap'")
        if np.sqrt(max(C[2 * i + 1, 2 * i + 1], 0.0)) > w0 / 6:
            notes.append(f"exponent {i}: the std of Im is above w0/6, so its branch is ambiguous")
    for i in range(n):
        for j in range(i + 1, n):
            if not (np.isfinite(lam[i].real) and np.isfinite(lam[j].real)):
                continue
            d = np.array([lam[i].real - lam[j].real, float(_wrap(lam[i].imag - lam[j].imag, w0))])
            bi, bj = slice(2 * i, 2 * i + 2), slice(2 * j, 2 * j + 2)
            Cd = C[bi, bi] + C[bj, bj] - C[bi, bj] - C[bj, bi]
            dist = float(np.hypot(*d))
            sd = float(np.sqrt(max(d @ Cd @ d, 0.0))) / dist if dist > 0 else float(np.sqrt(max(np.trace(Cd), 0.0)))
            if dist <= FIRST_ORDER_SEPARATION * sd or dist == 0.0:
                what = ("a pair about to become real multipliers" if abs(lam[i] - np.conj(lam[j])) < 1e-12 * (1 + abs(lam[i]))
                        else "two exponents that may meet")
                notes.append(f"exponents {i} and {j} ({_fmt(lam[i])}, {_fmt(lam[j])}): {what} (distance {dist:.3g}, "
                             f"{dist / sd if sd > 0 else 0:.2g} std of it): the first-order intervals do not hold "
                             f"there; use method='bootstrap'")
    return tuple(notes)


def _fmt(z) -> str:
    return f"{z.real:.4g}{z.imag:+.4g}j"
