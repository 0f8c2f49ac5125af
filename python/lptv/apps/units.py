"""The physical form of an identified model: its parameters with one coefficient's mean set by the
user (``--scale b0=1``) and their covariance carried along, the unit of every coefficient from the
channels' units (``force [N]``), and the coefficients over one period with their bands.

The equation ``sum_n a_n(t) d^n y/dt^n = sum_m b_m(t) d^m u/dt^m`` holds for any common factor of
its coefficients; the fit fixes it by the mean of ``a_na`` = 1 (the row 'normalised' of the
parameter table). Dividing every parameter by the mean of another coefficient and multiplying by
the value the user knows for it is the same model in other units: for a mass-spring-damper driven
by a force, ``m x'' + c x' + k(t) x = F`` has ``b0 = 1``, and ``--scale b0=1`` reads ``a2`` as the
mass, ``a1`` as the damping and ``a0`` as the stiffness. The covariance follows by the Jacobian of
that division (exact to first order, as the covariance itself).
"""
from __future__ import annotations

import re
from types import SimpleNamespace
from typing import Optional, Tuple

import numpy as np

from lptv.records.measurements import FileError

_COEF = re.compile(r"([ab])(\d+)")


def parse_scale(text: Optional[str]) -> Optional[Tuple[str, float]]:
    """'b0=1' -> ('b0', 1.0); None -> None."""
    if text is None:
        return None
    name, eq, value = text.partition("=")
    name = name.strip()
    try:
        v = float(value)
    except ValueError:
        v = None
    if not eq or not _COEF.fullmatch(name) or v is None or not np.isfinite(v) or v == 0:
        raise FileError(f"--scale: '{text.strip()}' is not of the form coefficient=nonzero number "
                        "(e.g. b0=1: the mean of b_0 is 1)")
    return name, v


def scaled(res, name: str, value: float) -> SimpleNamespace:
    """The parameters of ``res`` (anything with ``model``, ``eta_names``, ``eta``, ``covariance``)
    divided by the mean of coefficient ``name`` and multiplied by ``value``: an object with the
    same four attributes (``lptv.parameter_table`` reads it) and ``scale = (name, value)``."""
    from lptv import Model

    names = list(res.eta_names)
    key = f"{name}.re0"
    if key not in names:
        have = sorted({n.split(".")[0] for n in names}, key=lambda c: (c[0], int(c[1:])))
        raise FileError(f"--scale: {name} is not a coefficient of the model ({', '.join(have)})")
    eta = np.asarray(res.eta, float)
    j = names.index(key)
    s = eta[j]
    cov = res.covariance
    if s == 0:
        raise FileError(f"--scale: the mean of {name} is estimated as 0; scale by another coefficient")
    if cov is not None and cov[j, j] > 0 and abs(s) < 2 * np.sqrt(cov[j, j]):
        raise FileError(f"--scale: the mean of {name} ({s:.3g}) is within two standard deviations of 0; "
                        "scale by a coefficient the data determine")
    f = value / s
    out_eta = f * eta
    out_cov = None
    if cov is not None:
        # d eta'_i / d eta_k = f (delta_ik - eta_i delta_kj / s)
        J = f * np.eye(eta.size)
        J[:, j] -= f * eta / s
        out_cov = J @ cov @ J.T
        out_cov[j, :] = out_cov[:, j] = 0.0        # the scaling coefficient is fixed: exactly `value`
    m = res.model
    model = Model(m.a * f, m.b * f, w0=m.w0, ts=m.ts)
    return SimpleNamespace(model=model, eta_names=tuple(names), eta=out_eta, covariance=out_cov,
                           scale=(name, value))


def channel_unit(name: Optional[str]) -> Optional[str]:
    """The unit a channel's name states at its end: 'force [N]' -> 'N', 'x (mm)' -> 'mm'."""
    if not name:
        return None
    m = re.search(r"[\[(]\s*([^\[\]()]+?)\s*[\])]\s*$", str(name))
    return m.group(1) if m else None


def coefficient_units(model, u_unit: Optional[str], y_unit: Optional[str],
                      scale: Optional[Tuple[str, float]] = None) -> dict:
    """{'a0': 'N/m', 'a1': 'N s/m', ...}: each coefficient's unit when both channels state theirs
    ({} otherwise). Every term of the equation has one unit E: a_n d^n y/dt^n is E, so a_n is
    E s^n / [y] (E / [y] in discrete time, whose shifts carry no unit); the coefficient that is set
    to a number (``scale``, else a_na) is a pure number, which fixes E."""
    if not u_unit or not y_unit:
        return {}
    ct = not model.discrete
    ref = scale[0] if scale else f"a{model.na}"
    side, n = ref[0], int(ref[1:])
    # E = [channel of ref] / s^n
    base = {y_unit if side == "a" else u_unit: 1}
    base_s = -n if ct else 0

    def unit(chan, p):
        e = dict(base)
        e[chan] = e.get(chan, 0) - 1
        e["s"] = e.get("s", 0) + base_s + (p if ct else 0)
        num = [_tok(k, v) for k, v in e.items() if v > 0]
        den = [_tok(k, -v) for k, v in e.items() if v < 0]
        text = " ".join(num) or ("1" if den else "")
        if den:
            text += "/" + (den[0] if len(den) == 1 else "(" + " ".join(den) + ")")
        return text

    out = {f"a{i}": unit(y_unit, i) for i in range(model.na + 1)}
    out.update({f"b{i}": unit(u_unit, i) for i in range(model.nb + 1)})
    return out


def _tok(name, power):
    name = f"({name})" if re.search(r"[\s/*^]", name) else name
    return name if power == 1 else f"{name}^{power}"


def trajectories(src, t):
    """The coefficients a_0..a_na, b_0..b_nb of ``src`` (a result or :func:`scaled`) at times ``t``:
    (values, std or None, names), values and std of shape (len(t), na + nb + 2); the std from the
    parameter covariance (each coefficient is linear in the parameters: its derivative is the
    change for a unit step of one parameter)."""
    from lptv.judgement.parameters import perturbed_model

    model = src.model
    names = [f"a{n}" for n in range(model.na + 1)] + [f"b{m}" for m in range(model.nb + 1)]

    def at(m):
        return np.hstack([m.a_at(t), m.b_at(t)]).real

    values = at(model)
    cov = src.covariance
    if cov is None:
        return values, None, names
    free = [i for i in range(len(src.eta_names)) if cov[i, i] > 0]
    D = np.stack([at(perturbed_model(model, src.eta_names[i], 1.0)) - values for i in free], axis=-1)
    C = cov[np.ix_(free, free)]
    var = np.einsum("tci,ij,tcj->tc", D, C, D)
    return values, np.sqrt(np.maximum(var, 0.0)), names


def table_with_units(src, u_unit: Optional[str], y_unit: Optional[str],
                     scale: Optional[Tuple[str, float]] = None) -> list:
    """:func:`lptv.parameter_table` of ``src`` with each row's ``unit`` that of its coefficient
    (:func:`coefficient_units`; a phase keeps 'deg'): what summary.json holds."""
    from lptv.judgement.parameters import parameter_table

    unit_of = coefficient_units(src.model, u_unit, y_unit, scale)
    rows = parameter_table(src)
    for r in rows:
        r["unit"] = r["unit"] or unit_of.get(r["name"].split(".")[0], "")
    return rows


def value_and_std(value: float, std: float) -> Tuple[str, str]:
    """('39.9991', '0.0018'): the value to the digits its std resolves (two significant digits of
    the std), so that a value is never shown coarser than its own uncertainty; a std of 0 (the
    normalisation, a fixed value) gives ('1', 'fixed')."""
    if not (np.isfinite(std) and std > 0):
        return f"{value:.6g}", "fixed"
    decimals = int(max(0, 1 - np.floor(np.log10(std))))
    if decimals > 12 or abs(value) >= 1e9:
        return f"{value:.{max(6, min(16, decimals))}g}", f"{std:.2g}"
    return f"{value:.{decimals}f}", f"{std:.2g}"


def format_parameters(src, u_unit: Optional[str], y_unit: Optional[str],
                      scale: Optional[Tuple[str, float]] = None) -> str:
    """The parameters of ``src`` (a result or :func:`scaled`) as aligned lines: name, value to the
    digits of its std, the std, the coefficient's unit where the channels state theirs."""
    unit_of = coefficient_units(src.model, u_unit, y_unit, scale)
    cov = src.covariance
    std = np.zeros(len(src.eta_names)) if cov is None else np.sqrt(np.maximum(np.diag(cov), 0.0))
    cells = [(n, *value_and_std(float(v), float(s)), unit_of.get(n.split(".")[0], ""))
             for n, v, s in zip(src.eta_names, src.eta, std)]
    w = [max(len(c[i]) for c in cells) for i in range(3)]
    out = []
    for n, v, s, u in cells:
        sd = f"+- {s:<{w[2]}}" if s != "fixed" else f"   {'(normalisation)' if scale is None else '(by --scale)'}"
        out.append((f"  {n:<{w[0]}}  {v:>{w[1]}} {sd}" + (f"  {u}" if u and s != "fixed" else "")).rstrip())
    return "\n".join(out)


def physical_form(physical, meas) -> Tuple[str, list]:
    """What ``lptv identify --scale`` prints and keeps of :func:`scaled` ``physical`` for the record
    ``meas`` (its channels' names state the units): (the text for the terminal, the rows of
    summary.json's ``parameters_scaled``), both with each coefficient's unit."""
    from lptv.judgement.parameters import format_parameter_table

    name, value = physical.scale
    u_unit, y_unit = channel_unit(meas.input), channel_unit(meas.output)
    unit_of = coefficient_units(physical.model, u_unit, y_unit, physical.scale)
    text = (f"parameters in physical form (--scale {name}={value:g}):\n"
            + format_parameter_table(physical, units=unit_of).replace("(normalised)", "(by --scale)"))
    return text, table_with_units(physical, u_unit, y_unit, physical.scale)


# ------------------------------------------------------------------ several inputs and outputs

_ENTRY = re.compile(r"([ab])(\d+)$")


def _unit_text(e: dict) -> str:
    num = [_tok(k, v) for k, v in e.items() if v > 0]
    den = [_tok(k, -v) for k, v in e.items() if v < 0]
    text = " ".join(num) or ("1" if den else "")
    if den:
        text += "/" + (den[0] if len(den) == 1 else "(" + " ".join(den) + ")")
    return text


def mimo_coefficient_units(model, u_units, y_units, scale: Optional[Tuple[str, float]] = None) -> dict:
    """{'a0[0,1]': 'N/m', ...}: the unit of every entry of every A_n and B_m when every channel
    states its unit ({} otherwise). Row p of the equation, sum_n A_n(t) d^n y = sum_m B_m(t) d^m u,
    has one unit E_p: A_n[p, q] is E_p s^n / [y_q], B_m[p, r] is E_p s^m / [u_r] (no s in discrete
    time); the matrix set to a number times the identity (``scale``, else A_na) has pure numbers on
    its diagonal, which fixes E_p = [y_p] s^-na (or [u_p] s^-m for B_m, [y_p] s^-n for A_n)."""
    u_units, y_units = list(u_units or ()), list(y_units or ())
    if not u_units or not y_units or not all(u_units) or not all(y_units):
        return {}
    ny, nu = model.n_outputs, model.n_inputs
    if len(y_units) != ny or len(u_units) != nu:
        return {}
    ct = not model.discrete
    ref = scale[0] if scale else f"a{model.na}"
    side, n0 = ref[0], int(ref[1:])
    if side == "b" and nu != ny:
        return {}
    out = {}
    for p in range(ny):
        base = {(y_units if side == "a" else u_units)[p]: 1}
        for c, count, chans in (("a", model.na, y_units), ("b", model.nb, u_units)):
            for n in range(count + 1):
                for q, chan in enumerate(chans):
                    e = dict(base)
                    e[chan] = e.get(chan, 0) - 1
                    e["s"] = e.get("s", 0) + ((n - n0) if ct else 0)
                    out[f"{c}{n}[{p},{q}]"] = _unit_text(e)
    return out


def scaled_mimo(res, name: str, value: float) -> SimpleNamespace:
    """The parameters of a fit of several channels (``res``: model, parameter_names, eta,
    covariance) with the equation multiplied from the left by S = value M^-1, M the mean matrix
    of coefficient ``name``, so that that mean becomes ``value`` times the identity (the same
    system; for M y'' + C y' + K(t) y = F, ``b0=1`` gives the matrices M, C, K). The covariance
    follows by the exact Jacobian of that map. An object with ``model``, ``eta_names``, ``eta``,
    ``covariance`` and ``scale = (name, value)``."""
    from lptv import MimoModel

    m = res.model
    ny, nu = m.n_outputs, m.n_inputs
    side, order = name[0], int(name[1:])
    if order > (m.na if side == "a" else m.nb):
        have = [f"a{i}" for i in range(m.na + 1)] + [f"b{i}" for i in range(m.nb + 1)]
        raise FileError(f"--scale: {name} is not a coefficient of the model ({', '.join(have)})")
    if side == "b" and nu != ny:
        raise FileError(f"--scale: {name} is a {ny} x {nu} matrix ({ny} outputs, {nu} input{'s' if nu > 1 else ''}); "
                        "several channels are scaled by setting the mean of one square matrix to a number times the "
                        f"identity, which a {ny} x {nu} matrix cannot be: name an a_n ({ny} x {ny}), or a b_m with as "
                        "many inputs as outputs")
    names = list(res.parameter_names)
    eta = np.asarray(res.eta, float)
    n_row = eta.size // ny
    idx = np.array([[names.index(f"{name}[{p},{q}].re0") for q in range(ny)] for p in range(ny)])
    M = eta[idx]
    cond = np.linalg.cond(M)
    if not np.isfinite(cond) or cond > 1e8:
        raise FileError(f"--scale: the mean of {name} is estimated as a singular matrix (condition number "
                        f"{cond:.3g}); scale by another coefficient")
    cov = res.covariance
    if cov is not None:
        # an entry of M within two standard deviations of 0 on the diagonal: the data do not fix the scale
        d = np.diag(M)
        sd = np.sqrt(np.maximum(np.diag(cov)[np.diag(idx)], 0.0))
        weak = np.flatnonzero((sd > 0) & (np.abs(d) < 2 * sd))
        if weak.size:
            p = int(weak[0])
            raise FileError(f"--scale: the mean of {name}[{p},{p}] ({d[p]:.3g}) is within two standard deviations "
                            "of 0; scale by a coefficient the data determine")
    Mi = np.linalg.inv(M)
    S = value * Mi
    Xi = eta.reshape(ny, n_row)                      # row p of the equation: Xi[p]
    out_eta = (S @ Xi).ravel()
    out_cov = None
    if cov is not None:
        # d(S Xi) = S dXi + dS Xi with dS = -S dM M^-1, dM the unit step of one entry of M
        J = np.kron(S, np.eye(n_row))
        for p in range(ny):
            for q in range(ny):
                E = np.zeros((ny, ny))
                E[p, q] = 1.0
                J[:, idx[p, q]] += (-S @ E @ Mi @ Xi).ravel()
        out_cov = J @ cov @ J.T
        fixed = idx.ravel()
        out_cov[fixed, :] = 0.0
        out_cov[:, fixed] = 0.0                       # the scaling matrix is fixed: exactly value * I
    out_eta[idx.ravel()] = (value * np.eye(ny)).ravel()
    a = np.einsum("pj,njqk->npqk", S, m.a)
    b = np.einsum("pj,njrk->nprk", S, m.b)
    return SimpleNamespace(model=MimoModel(a, b, w0=m.w0, ts=m.ts), eta_names=tuple(names),
                           parameter_names=tuple(names), eta=out_eta, covariance=out_cov, scale=(name, value))
