"""Parameters with their uncertainty: the table of estimates, standard deviations and intervals,
amplitude and phase of every harmonic of an LPTV model, and for an LTI model the transfer
function, poles, natural frequencies and damping ratios with their standard deviations.

The covariance is that of the free real parameters ``eta`` (:attr:`IdentificationResult.covariance`,
kept by :meth:`Model.save`); derived quantities get theirs by a first-order propagation
``J C J^T`` with the Jacobian ``J`` in closed form (amplitude, phase) or by central differences
(poles and what follows from them).
"""
from __future__ import annotations

import re
from typing import List, Optional

import numpy as np

_NAME = re.compile(r"([ab])(\d+)\.(re|im)(\d+)")


def _source(obj):
    """(model, eta names, eta values, covariance or None) of a result or a model. A result is
    anything with a model, eta_names, eta and covariance (lptv.identify's, identify_record's):
    read by its attributes, so that this module imports no result type (which imports it)."""
    from ..model.siso import Model

    if not isinstance(obj, Model) and all(hasattr(obj, a) for a in ("model", "eta_names", "eta", "covariance")) \
            and isinstance(obj.model, Model):
        return obj.model, tuple(obj.eta_names), np.asarray(obj.eta, float), obj.covariance
    if isinstance(obj, Model):
        names = tuple(obj.eta_names)
        eta = np.array([_value(obj, n) for n in names]) if names else np.zeros(0)
        return obj, names, eta, obj.covariance
    raise ValueError(f"obj must be an IdentificationResult or an lptv.Model, got {type(obj).__name__}")


def _value(model, name):
    side, n, part, k = _parse(name)
    arr, K = (model.a, model.ka) if side == "a" else (model.b, model.kb)
    c = arr[n, K + k]
    return c.real if part == "re" else c.imag


def _parse(name):
    m = _NAME.fullmatch(name)
    if not m:
        raise ValueError(f"not a parameter name like 'a0.re1': {name!r}")
    return m.group(1), int(m.group(2)), m.group(3), int(m.group(4))


def _z(level):
    from .._dist import norm_ppf
    from .._validate import as_float

    level = as_float(level, "level", minimum=0.0, maximum=1.0, open_min=True, open_max=True)
    return float(norm_ppf(0.5 + level / 2.0))


def parameter_table(obj, level: float = 0.95) -> List[dict]:
    """One row per estimated parameter: ``name``, ``value``, ``std``, ``low``, ``high`` (the
    two-sided ``level`` interval ``value +- z std``), ``kind``; for harmonic k >= 1 of an LPTV
    coefficient also the rows ``a0.amp1`` (amplitude 2|c_k| of ``2 |c_k| cos(k w0 t + phase)``) and
    ``a0.phase1`` (degrees). The normalised parameter has ``std`` 0 and ``kind`` 'normalised'.
    Without a covariance (LS, TLS, GTLS) ``std``, ``low``, ``high`` are None.

    Parameters
    ----------
    obj : IdentificationResult or Model
        A model loaded from a file written by ``lptv identify`` or :meth:`Model.save` keeps its
        covariance.
    level : float

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2)
    >>> ms = lptv.multisine(range(1, 60), 256, seed=0)
    >>> y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    >>> rng = np.random.default_rng(1)
    >>> u = ms.periods(8) + 1e-3 * rng.standard_normal((8, 256))
    >>> y = np.tile(y1, (8, 1)) + 1e-3 * rng.standard_normal((8, 256))
    >>> res = lptv.identify(u, y, na=1, nb=0, w0=0.1, method="sml")
    >>> row = lptv.parameter_table(res)[0]
    >>> row["name"], round(row["value"], 2), bool(row["low"] < 2.0 < row["high"])
    ('a0.re0', 2.0, True)
    """
    model, names, eta, cov = _source(obj)
    z = _z(level)
    std = None if cov is None else np.sqrt(np.maximum(np.diag(cov), 0.0))
    rows = []

    def row(name, value, s, kind, unit=""):
        lo = hi = None
        if s is not None:
            lo, hi = value - z * s, value + z * s
        rows.append({"name": name, "value": float(value), "std": None if s is None else float(s),
                     "low": lo, "high": hi, "kind": kind, "unit": unit})

    index = {n: i for i, n in enumerate(names)}
    for i, name in enumerate(names):
        s = None if std is None else std[i]
        kind = "normalised" if s == 0.0 else "estimate"
        row(name, eta[i], s, kind)
        side, n, part, k = _parse(name)
        if part == "im" and k >= 1:
            ir = index.get(f"{side}{n}.re{k}")
            if ir is None:
                continue
            re_, im_ = eta[ir], eta[i]
            mag = np.hypot(re_, im_)
            amp, ph = 2 * mag, np.degrees(np.arctan2(im_, re_))
            s_amp = s_ph = None
            if cov is not None and mag > 0:
                C = cov[np.ix_([ir, i], [ir, i])]
                J = np.array([[2 * re_ / mag, 2 * im_ / mag],
                              [np.degrees(-im_ / mag ** 2), np.degrees(re_ / mag ** 2)]])
                V = J @ C @ J.T
                s_amp, s_ph = np.sqrt(max(V[0, 0], 0.0)), np.sqrt(max(V[1, 1], 0.0))
            row(f"{side}{n}.amp{k}", amp, s_amp, "derived")
            row(f"{side}{n}.phase{k}", ph, s_ph, "derived", "deg")
    return rows


# ------------------------------------------------------------------------------ LTI


def _poles_of(a_desc, ts):
    p = np.roots(a_desc)
    return p


def _pole_quantities(a, ts):
    """Poles (upper half plane and real ones) of the ascending real coefficients a, with the
    continuous-time equivalents' natural frequency and damping."""
    p = np.roots(np.asarray(a, float)[::-1])
    p = p[p.imag >= -1e-12 * np.maximum(np.abs(p), 1.0)]
    p = p[np.lexsort((p.imag, p.real))]
    s = np.log(p.astype(complex)) / ts if ts else p.astype(complex)
    wn = np.abs(s)
    with np.errstate(invalid="ignore", divide="ignore"):
        zeta = np.where(wn > 0, -s.real / wn, np.nan)
    return p, wn, zeta


def lti_table(obj, level: float = 0.95) -> dict:
    """The transfer function, poles, natural frequencies and damping ratios of an LTI model, with
    their standard deviations and ``level`` intervals where the covariance is known.

    Returns a dict with ``num``, ``den`` (descending powers, scipy.signal order), their ``num_std``,
    ``den_std`` (0 for the normalised and the known coefficients) and ``poles``: one dict per real
    pole and per complex pair (the member with Im >= 0) with ``pole``, ``std_re``, ``std_im``,
    ``wn`` (rad/s), ``wn_std``, ``f_hz``, ``f_std``, ``zeta``, ``zeta_std``, ``zeta_low``,
    ``zeta_high``, ``wn_low``, ``wn_high``. In discrete time ``wn`` and ``zeta`` are those of the
    continuous-time equivalent ``s = log(z) / ts``. The propagation is first order, by central
    differences of the poles over the parameters.

    Examples
    --------
    >>> import lptv
    >>> t = lptv.lti_table(lptv.Model.from_tf([1.0], [1.0, 4.0, 100.0]))
    >>> p = t["poles"][0]
    >>> round(p["wn"], 6), round(p["zeta"], 6), p["wn_std"] is None
    (10.0, 0.2, True)
    """
    model, names, eta, cov = _source(obj)
    if not model.is_lti:
        raise ValueError("lti_table: the model is time-varying; use Model.to_tf(t) for a frozen system")
    a = model.a[:, 0].real.copy()
    b = model.b[:, 0].real.copy()
    ts = model.ts
    z = _z(level)
    p0, wn0, zeta0 = _pole_quantities(a, ts)
    f0 = np.concatenate([p0.real, p0.imag, wn0, zeta0])
    n_p = p0.size
    out = {"num": b[::-1].tolist(), "den": a[::-1].tolist(), "num_std": None, "den_std": None,
           "ts": ts, "level": float(level)}
    Vf = None
    if cov is not None and names:
        sa, sb = np.zeros(a.size), np.zeros(b.size)
        J = np.zeros((f0.size, len(names)))
        for i, name in enumerate(names):
            side, n, part, k = _parse(name)
            if part != "re" or k != 0:
                continue
            (sa if side == "a" else sb)[n] = np.sqrt(max(cov[i, i], 0.0))
            if side != "a":
                continue
            h = 1e-6 * max(abs(a[n]), 1e-3)
            cols = []
            for sgn in (1.0, -1.0):
                ap = a.copy()
                ap[n] += sgn * h
                p, wn, zeta = _pole_quantities(ap, ts)
                if p.size != n_p:
                    break
                order = [int(np.argmin(np.abs(p - q))) for q in p0]
                p, wn, zeta = p[order], wn[order], zeta[order]
                cols.append(np.concatenate([p.real, p.imag, wn, zeta]))
            if len(cols) == 2:
                J[:, i] = (cols[0] - cols[1]) / (2 * h)
        Vf = J @ cov @ J.T
        out["num_std"], out["den_std"] = sb[::-1].tolist(), sa[::-1].tolist()
    poles = []
    for j in range(n_p):
        sd = (lambda q: None) if Vf is None else (lambda q: float(np.sqrt(max(Vf[q, q], 0.0))))
        d = {"pole": complex(p0[j]), "std_re": sd(j), "std_im": sd(n_p + j),
             "wn": float(wn0[j]), "wn_std": sd(2 * n_p + j), "f_hz": float(wn0[j] / (2 * np.pi)),
             "zeta": float(zeta0[j]), "zeta_std": sd(3 * n_p + j)}
        d["f_std"] = None if d["wn_std"] is None else d["wn_std"] / (2 * np.pi)
        for q in ("wn", "zeta"):
            s = d[f"{q}_std"]
            d[f"{q}_low"] = None if s is None else d[q] - z * s
            d[f"{q}_high"] = None if s is None else d[q] + z * s
        poles.append(d)
    out["poles"] = poles
    return out


def _num(v, s=None):
    if s is None:
        return f"{v:.6g}"
    return f"{v:.6g} +- {s:.2g}"


def format_parameter_table(obj, level: float = 0.95, units: Optional[dict] = None) -> str:
    """:func:`parameter_table` (and for an LTI model :func:`lti_table`) as aligned text;
    ``units`` ({'a0': 'N/m', ...}) names each coefficient's unit after its interval."""
    rows = parameter_table(obj, level)
    for r in rows:
        r["unit"] = r["unit"] or (units or {}).get(r["name"].split(".")[0], "")
    pct = f"{100 * level:g} %"
    lines = [f"  {'parameter':12s} {'value':>12s} {'std':>10s}   {pct + ' interval':>27s}"]
    for r in rows:
        if r["std"] is None:
            lines.append(f"  {r['name']:12s} {r['value']:12.6g}")
        elif r["kind"] == "normalised":
            lines.append(f"  {r['name']:12s} {r['value']:12.6g} {'(normalised)':>10s}")
        else:
            unit = f" {r['unit']}" if r["unit"] else ""
            lines.append(f"  {r['name']:12s} {r['value']:12.6g} {r['std']:10.3g}   "
                         f"[{r['low']:12.6g}, {r['high']:12.6g}]{unit}")
    model = _source(obj)[0]
    if model.is_lti:
        t = lti_table(obj, level)
        var = "z" if t["ts"] else "s"
        lines.append(f"  transfer function in {var}, descending powers: num {np.round(t['num'], 8).tolist()}"
                     f", den {np.round(t['den'], 8).tolist()}")
        for p in t["poles"]:
            q = p["pole"]
            pole = f"{q.real:.6g}" + (f" +- {q.imag:.6g}j" if q.imag else "")
            sd = "" if p["std_re"] is None else f" (std {p['std_re']:.2g} re, {p['std_im']:.2g} im)"
            lines.append(f"  pole {pole}{sd}: natural frequency {_num(p['wn'], p['wn_std'])} rad/s "
                         f"= {_num(p['f_hz'], p['f_std'])} Hz, damping {_num(p['zeta'], p['zeta_std'])}")
    return "\n".join(lines)


def perturbed_model(model, name: str, delta: float):
    """A copy of ``model`` with the real parameter ``name`` (e.g. 'a0.re1') moved by ``delta``."""
    from ..model.siso import Model

    side, n, part, k = _parse(name)
    a, b = model.a.copy(), model.b.copy()
    arr, K = (a, model.ka) if side == "a" else (b, model.kb)
    step = delta if part == "re" else 1j * delta
    arr[n, K + k] += step
    if k:
        arr[n, K - k] += np.conj(step)
    return Model(a, b, w0=model.w0, ts=model.ts)


def freqresp_band(obj, w, *, level: float = 0.95, branch: int = 0):
    """The model's frequency response at ``w`` with the standard deviation of its magnitude and
    phase (first order, central differences over the parameters): ``(H, std_abs, std_phase_rad)``;
    the stds are None without a covariance."""
    model, names, eta, cov = _source(obj)
    _z(level)
    H = model.freqresp(w, branch=branch)
    if cov is None or not names:
        return H, None, None
    J = np.zeros((2 * H.size, len(names)))
    for i, name in enumerate(names):
        if cov[i, i] <= 0:
            continue
        h = 1e-6 * max(abs(eta[i]), 1e-3)
        Hp = perturbed_model(model, name, h).freqresp(w, branch=branch)
        Hm = perturbed_model(model, name, -h).freqresp(w, branch=branch)
        dH = (Hp - Hm) / (2 * h)
        J[:H.size, i] = np.real(dH * np.conj(H)) / np.maximum(np.abs(H), 1e-300)
        J[H.size:, i] = np.imag(dH / np.where(H == 0, 1, H))
    V = np.einsum("ij,jk,ik->i", J, cov, J)
    s = np.sqrt(np.maximum(V, 0.0))
    return H, s[:H.size], s[H.size:]


def compare(obj, u, y):
    """Simulated against measured output over one period, and the fit in percent.

    The model's output is simulated from the mean measured input period (in steady state, on the
    frequency grid of the period); the fit is ``100 (1 - ||y - yhat|| / ||y - mean y||)`` with
    ``y`` the mean measured output period (MATLAB's ``compare``). 100 for a perfect model on
    noise-free data; the noise of the mean output lowers it.

    Parameters
    ----------
    obj : IdentificationResult or Model
    u, y : array_like, shape (P, N) or (N,)
        Periods of the measured input and output (the fit's, or fresh validation data).

    Returns
    -------
    dict with ``t`` (s), ``y`` (mean measured period), ``y_model``, ``fit`` (percent).

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model.from_tf([1.0], [1.0, 2.0], w0=2 * np.pi / 25.6)
    >>> ms = lptv.multisine(range(1, 60), 256, seed=0)
    >>> u = ms.periods(2); y = np.tile(lptv.time_signal(lptv.simulate(m, ms.spectrum), 256), (2, 1))
    >>> round(lptv.compare(m, u, y)["fit"], 9)
    100.0
    """
    from ..simulation.fds import simulate
    from ..excitation.multisine import spectrum, time_signal

    from .._validate import _array, check_finite

    model = _source(obj)[0]
    sig = {}
    for name, x in (("u", u), ("y", y)):
        a = _array(x, name)
        if np.iscomplexobj(a):
            raise ValueError(f"{name} must be a real time signal, got complex values")
        a = np.atleast_2d(a.astype(float))
        check_finite(a, name)
        sig[name] = a
    u, y = sig["u"], sig["y"]
    if u.shape != y.shape or u.ndim != 2:
        raise ValueError(f"u and y must have the same shape (P, N) or (N,), got {u.shape} and {y.shape}")
    N = u.shape[1]
    um, ym = u.mean(axis=0), y.mean(axis=0)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        Y = simulate(model, spectrum(um), warn_unstable=False)
    yhat = time_signal(np.asarray(Y)[: N // 2 + 1], N)
    den = np.linalg.norm(ym - ym.mean())
    fit = 100.0 * (1.0 - np.linalg.norm(ym - yhat) / den) if den > 0 else float("nan")
    t = np.arange(N) * (model.period / N)
    return {"t": t, "y": ym, "y_model": yhat, "fit": float(fit)}
