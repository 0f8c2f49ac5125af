"""The Cramer-Rao bound of a design (METHOD.md section 10), to plan an experiment."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from .. import _core
from .._validate import _array, as_int, as_spectrum
from ..simulation.fds import simulate
from .identify import _counts, _known_list, _rows
from ..model.mimo import MimoModel
from ..model.siso import Model
from ..excitation.multisine import Multisine


@dataclass(frozen=True)
class CramerRaoBound:
    """What :func:`crb` returns."""

    covariance: np.ndarray
    """The bound on the covariance of ``eta`` (zero row and column for the normalised parameter)."""
    eta: np.ndarray
    """The true free real parameters (normalised as :func:`identify` normalises)."""
    eta_names: Tuple[str, ...]
    """The names of ``eta``'s entries (also as ``parameter_names``)."""
    lines: np.ndarray
    periods: Union[int, Tuple[int, ...]]
    """P (several experiments: one P per experiment)."""
    experiment: Optional[np.ndarray] = None
    """Per row of ``lines``: the index of its experiment (several experiments; None for one)."""

    @property
    def parameter_names(self) -> Tuple[str, ...]:
        """The names of ``eta``'s entries: the same tuple as ``eta_names`` (the name
        :class:`lptv.MimoCramerRaoBound` gives it; either works on either bound)."""
        return self.eta_names

    @property
    def std(self) -> np.ndarray:
        """The smallest standard deviation an unbiased estimator can reach, per entry of ``eta``."""
        return np.sqrt(np.diag(self.covariance))

    def relative_std(self) -> np.ndarray:
        """``std / |eta|`` (inf where the parameter is zero)."""
        with np.errstate(divide="ignore"):
            return np.where(self.eta != 0, self.std / np.abs(self.eta), np.inf)


def _per_line(v, n, name):
    arr = _array(v, name)
    if name != "cov_yu" and np.iscomplexobj(arr):
        raise ValueError(f"{name} must be real (a variance), got complex values")
    arr = arr.astype(complex if name == "cov_yu" else float)
    if arr.ndim == 0:
        arr = np.full(n, arr)
    if arr.shape != (n,):
        raise ValueError(f"{name} must be a scalar or one value per line 0..{n - 1} ({n} values), "
                         f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or inf")
    if name != "cov_yu" and np.any(arr < 0):
        raise ValueError(f"{name} must be >= 0")
    return arr


def crb(model: Model, u, *, var_y, var_u=0.0, cov_yu=0.0, periods: int = 1, lines=None,
        ka: Union[None, int, Sequence[int]] = None, kb: Union[None, int, Sequence[int]] = None,
        known: Optional[Mapping] = None) -> CramerRaoBound:
    """Cramer-Rao bound of the parameters for a design: true model, excitation, noise levels.

    The smallest covariance an unbiased estimator of ``eta`` can have when ``periods`` steady-state
    periods of the excitation are measured with noise of the given spectral (co)variances on input
    and output (METHOD.md section 10: F = J0^T S0^-1 J0 with the noiseless spectra). ``method='sml'``
    reaches it for many lines and known noise; with noise variances estimated from P periods its
    variance is about (P-2)/(P-3) times the bound.

    Parameters
    ----------
    model : lptv.Model or lptv.MimoModel
        The true system. A :class:`MimoModel` hands over to :func:`lptv.mimo_crb` with ``u``
        its input spectra (E, L+1, nu) and ``var_y`` (ny,), ``var_u`` (nu,) one period's noise
        variance per channel (a scalar for all); the result is then a
        :class:`lptv.MimoCramerRaoBound` (``known`` and ``cov_yu`` are not built for it).
    u : Multisine or array_like
        The excitation: a :class:`Multisine` or its one-sided spectrum on lines 0..L
        (``fft(u)[l] / N``).
    var_y, var_u : float or array_like over lines 0..L
        Variance of the noise on ONE period's spectrum, per line: white noise of standard
        deviation ``s`` in time with N samples per period gives ``s**2 / N``.
    cov_yu : complex or array_like
        E{dY conj(dU)} of one period's spectra (correlated input and output noise).
    periods : int
        P: the measured periods; the spectra's means then have the (co)variances above / P.
    lines : sequence of int, optional
        The rows of the fit (default as :func:`identify`).

    Several experiments (METHOD.md section 14): ``u`` a list of excitations (each its own lines
    0..L_e); ``var_y``, ``var_u``, ``cov_yu``, ``periods`` and ``lines`` then either one value for
    all or a list with one entry per experiment. The experiments are independent, so their
    Fisher informations add; ``lines`` of the result runs over all experiments and
    ``experiment`` says which experiment each row belongs to.
    ka, kb, known :
        The structure to estimate (default: the model's own orders and harmonic counts).

    Examples
    --------
    >>> import lptv
    >>> m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2)
    >>> ms = lptv.multisine(range(1, 60), 256, seed=0)
    >>> b = lptv.crb(m, ms, var_u=1e-6 / 256, var_y=1e-6 / 256, periods=8)
    >>> b.eta_names
    ('a0.re0', 'a1.re0', 'b0.re0')
    >>> bool(b.std[0] < 1e-2)
    True
    """
    if isinstance(model, MimoModel):
        return _crb_mimo(model, u, var_y, var_u, cov_yu, periods, lines, ka, kb, known)
    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model or lptv.MimoModel, got {type(model).__name__}")
    if isinstance(u, (list, tuple)) and len(u) > 0 and all(
            isinstance(x, Multisine) or np.ndim(x) == 1 for x in u):
        return _crb_experiments(model, list(u), var_y=var_y, var_u=var_u, cov_yu=cov_yu, periods=periods,
                                lines=lines, ka=ka, kb=kb, known=known)
    data, par, rows, theta, xi, periods = _design(model, u, var_y, var_u, cov_yu, periods, lines, ka, kb, known)
    cov = np.asarray(_core.cramer_rao_bound(data, par, rows, theta))
    return CramerRaoBound(covariance=cov, eta=xi[:par.n_eta], eta_names=tuple(par.eta_names),
                          lines=np.asarray(rows), periods=periods)


def _crb_mimo(model, u, var_y, var_u, cov_yu, periods, lines, ka, kb, known):
    """crb of a MimoModel: :func:`lptv.mimo_crb` with var_y (ny,) and var_u (nu,) per channel."""
    from .mimo_identify import mimo_crb

    if known:
        raise ValueError("known: not built yet for several inputs or outputs (the normalisation is A_na,0 = I)")
    if np.any(np.asarray(cov_yu) != 0):
        raise ValueError("cov_yu: correlated input and output noise is given to lptv.mimo_crb as a full "
                         "noise covariance per line (noise=(L+1, ny+nu, ny+nu)) for several channels")
    vy = np.broadcast_to(np.asarray(_array(var_y, "var_y"), dtype=float), (model.n_outputs,))
    vu = np.broadcast_to(np.asarray(_array(var_u, "var_u"), dtype=float), (model.n_inputs,))
    return mimo_crb(model, u, noise=np.r_[vy, vu], periods=periods, lines=lines, ka=ka, kb=kb)


def _design(model, u, var_y, var_u, cov_yu, periods, lines, ka, kb, known, check_count=True):
    """One experiment's noiseless data, parametrisation, rows and true (normalised) parameters."""
    if isinstance(u, Multisine):
        U = u.spectrum
    else:
        U2, was_1d = as_spectrum(u, "u")
        if not was_1d:
            raise ValueError(f"u must be one spectrum (1-D), got shape {U2.shape}")
        U = U2[:, 0]
    periods = as_int(periods, "periods", minimum=1)
    n = U.size
    vy, vu = _per_line(var_y, n, "var_y"), _per_line(var_u, n, "var_u")
    cyu = _per_line(cov_yu, n, "cov_yu")
    if np.any(np.abs(cyu) ** 2 > vy * vu * (1 + 1e-12)):
        raise ValueError("cov_yu: |cov_yu|^2 must not exceed var_y * var_u on any line")
    Y = simulate(model, U)
    data = _core.FrequencyData(U, Y, vu / periods, vy / periods, cyu / periods, 0)
    na, nb = model.na, model.nb
    ka_l = _counts(model.ka if ka is None else ka, na, "ka")
    kb_l = _counts(model.kb if kb is None else kb, nb, "kb")
    kn = _known_list(known, ka_l, kb_l)
    par = _core.Parametrisation(na, nb, ka_l, kb_l, kn, model.w0, 0.0 if model.ts is None else model.ts)
    rows = par.default_rows(data.max_line) if lines is None else _rows(lines)
    if check_count:  # several experiments: the core counts the equations over all of them
        par.check_rows(rows, data.max_line)
    xi = np.asarray(par.xi_from_theta(np.asarray(par.theta_from_model(model._cpp))))
    theta = np.asarray(par.theta_from_xi(xi))   # normalised, as the estimates are
    xi = xi / xi[par.norm_index]
    return data, par, rows, theta, xi, periods


def _crb_experiments(model, us, *, var_y, var_u, cov_yu, periods, lines, ka, kb, known) -> CramerRaoBound:
    E = len(us)

    def each(v, name):
        if isinstance(v, (list, tuple)):
            if len(v) != E:
                raise ValueError(f"{name}: with {E} experiments give one value for all or a list of {E}, "
                                 f"got {len(v)}")
            return list(v)
        return [v] * E

    vys, vus, cyus, Ps = each(var_y, "var_y"), each(var_u, "var_u"), each(cov_yu, "cov_yu"), each(periods, "periods")
    line_sets = [None] * E if lines is None else each(lines, "lines") if isinstance(lines, (list, tuple)) and len(
        lines) == E and all(v is None or np.ndim(v) == 1 for v in lines) else None
    if line_sets is None:
        raise ValueError(f"lines: with {E} experiments give None or a list of {E} entries (None or a sequence "
                         "of lines), one per experiment")
    bounds = []
    for e in range(E):
        try:
            # One experiment's data and rows, validated as for a single design.
            bounds.append(_design(model, us[e], vys[e], vus[e], cyus[e], Ps[e], line_sets[e], ka, kb, known,
                                  check_count=False))
        except ValueError as err:
            raise ValueError(f"experiment {e}: {err}") from None
    par = bounds[0][1]
    datas, rows = [b[0] for b in bounds], [b[2] for b in bounds]
    theta, xi = bounds[0][3], bounds[0][4]
    cov = np.asarray(_core.cramer_rao_bound_experiments(datas, par, rows, theta))
    return CramerRaoBound(covariance=cov, eta=xi[:par.n_eta], eta_names=tuple(par.eta_names),
                          lines=np.concatenate([np.asarray(r) for r in rows]),
                          periods=tuple(b[5] for b in bounds),
                          experiment=np.repeat(np.arange(E), [len(r) for r in rows]))
