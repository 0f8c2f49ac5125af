"""Identification: LS, TLS, GTLS and weighted GTLS (METHOD.md sections 5-7)."""
from __future__ import annotations

import re
import warnings
from typing import Mapping, Optional, Sequence, Union

import numpy as np

from .. import _core
from ..spectra.frequency_data import FrequencyData, experiments_of, frequency_data_of
from ..model.floquet import StabilityUndecidedWarning, UnstableModelWarning, stability_check
from ..model.siso import Model
from .._validate import INT_MAX, as_counts, as_float, as_int, as_lines
from .mimo_identify import as_transient, identify_mimo, is_mimo
from ..judgement.result import IdentifiabilityWarning, IdentificationResult, _noise_alone, excited_rows  # noqa: F401 - their home was here

METHODS = ("ls", "tls", "gtls", "wgtls", "sml")
NOISES = ("auto", "sample", "moderated", "full", "full-moderated", "full-rows")
# noise='auto' moderates from this many periods: below it the lines that keep their own variance
# (lines 0 and Lmax, outliers) have 1-4 degrees of freedom, and the checks that read the moderated
# data's periods for every line (the input's presence, the rows with signal) would misjudge them.
AUTO_MIN_PERIODS = 4
# noise='auto' on the record's statistics moderates from this many periods: at P = 4 the moderated
# fits' SML intervals covered 90.8-93.7 % on bench_process_noise.py's rig, the record's sample
# variances 98.8-99.3 % (METHOD.md section 20)
AUTO_MIN_PERIODS_RECORD = 8
COVARIANCES = ("analytic", "bootstrap", "realisations", "none")


# Orders beyond this would only build huge per-coefficient lists before the core refuses them.
MAX_COEFFICIENTS = 2**20


def _counts(k, n, name):
    return as_counts(k, n, name)


def _known_list(known, ka, kb):
    if not known:
        return []
    if not isinstance(known, Mapping):
        raise ValueError("known must be a dict like {'a2': 1.5} (coefficient name -> value or Fourier row)")
    out = []
    for name, value in known.items():
        m = re.fullmatch(r"([ab])(\d+)", str(name))
        if not m:
            raise ValueError(f"known: {name!r} is not a coefficient name like 'a0' or 'b1'")
        is_a, order = m.group(1) == "a", int(m.group(2))
        counts = ka if is_a else kb
        if order >= len(counts):
            raise ValueError(f"known: {name} is not a coefficient of the model "
                             f"({'na' if is_a else 'nb'} = {len(counts) - 1})")
        K = counts[order]
        v = np.asarray(value)
        if v.dtype == object or not np.issubdtype(v.dtype, np.number):
            raise ValueError(f"known: {name} must be numeric")
        v = np.atleast_1d(v.astype(complex))
        if v.ndim != 1 or v.size % 2 != 1:
            raise ValueError(f"known: {name} must be a scalar or an odd-length Fourier row, got shape {v.shape}")
        Kv = v.size // 2
        if Kv > K:
            raise ValueError(f"known: {name} has {Kv} harmonics but its harmonic count is {K}")
        row = np.zeros(2 * K + 1, complex)
        row[K - Kv:K + Kv + 1] = v
        if not np.all(np.isfinite(row)):
            raise ValueError(f"known: {name} contains NaN or inf")
        out.append((is_a, order, row))
    return out


def _rows(lines):
    return as_lines(lines, "lines")


def _below_nyquist(lines, max_line):
    """Lines above the data's highest line (N/2, the Nyquist line) named as such, before a long
    range or array of them is converted (``lines=range(1, 10**8)`` on 2048 samples per period).
    Only a range or an integer array within the core's int is looked at here: anything else
    (floats, huge or negative values, other types) is as_lines's to name."""
    if isinstance(lines, range):
        top = (lines[-1] if lines.step > 0 else lines[0]) if len(lines) else None
    elif isinstance(lines, np.ndarray) and lines.dtype.kind in "iu" and lines.size:
        top, low = int(lines.max()), int(lines.min())
    elif isinstance(lines, (list, tuple)) and lines and all(type(v) is int for v in lines):
        top, low = max(lines), min(lines)
    else:
        return
    if isinstance(lines, range):
        low = min(lines[0], lines[-1]) if len(lines) else 0
    if top is not None and max_line < top <= INT_MAX and low >= 0:
        raise ValueError(f"lines: line {top} lies above the Nyquist line {max_line} of the data "
                         f"({2 * max_line} or {2 * max_line + 1} samples per period: line N/2 is half the "
                         "sampling frequency, the highest a period holds)")


_DEFAULT_LINES = "excited"  # what lines=None means: the usable lines K+1..Lmax-K


def identify(u, y=None, *, na: int, nb: int, ka: Union[int, Sequence[int]] = 0,
             kb: Union[int, Sequence[int]] = 0, w0: Optional[float] = None, ts: Optional[float] = None,
             lines=None, method: str = "wgtls", known: Optional[Mapping] = None, tol: float = 1e-10,
             max_iter: int = 50, covariance: str = "analytic", bootstrap: int = 200,
             seed=None, noise: str = "auto", disturbances: Optional[str] = None, transient="auto"):
    """Estimate an LPTV model from noisy input/output periods.

    Several inputs and outputs (METHOD.md section 19): ``u`` of shape (P, N, nu) and ``y`` of
    shape (P, N, ny) (3-D arrays, also for one channel), or a list of (u, y) pairs of such
    arrays (or :class:`lptv.MimoFrequencyData`) for several experiments, give a
    :class:`lptv.mimo_result.MimoIdentificationResult` whose ``model`` is a :class:`MimoModel`
    normalised to A_na,0 = I. ``ka`` is then an int for every entry of every A_n, one count
    per order (na+1,), per entry (ny, ny) or per order and entry (na+1, ny, ny), row-uniform
    (each column's entries with the same count in every row); ``kb`` likewise with (ny, nu).
    Methods 'gtls', 'wgtls' (vector residues weighted by their covariance matrices) and 'sml'
    (the exact likelihood of the rows); covariance 'analytic' (SML: the inverse Fisher
    information; WGTLS: the first-order sandwich; both times (P-1)/(P-3)) or 'none';
    ``lines`` None (every usable line K+1..N/2-K), 'excited', a sequence, or one entry per
    experiment; ``known={'a<na>': M}`` (M real, invertible, ny x ny) fixes the leading matrix's
    mean to M instead of I (the estimate and its covariance are the A_na,0 = I ones multiplied by
    M from the left). 2-D arrays stay the single-input single-output fit below.

    Parameters
    ----------
    u, y : array_like, shape (P, N)
        P >= 2 steady-state periods of input and output. Or pass a :class:`FrequencyData`
        as ``u`` (and no ``y``). Or, for several experiments on the same system fitted into one
        model, a list as ``u`` (and no ``y``) of :class:`FrequencyData` and/or ``(u, y)`` pairs
        of P_e x N_e period arrays: each may have its own P, N and excitation, all share the
        period (``w0``) and the time domain (METHOD.md section 14). The result's
        ``experiment`` says which experiment each row of ``lines`` belongs to.
    na, nb : int
        Orders of the output and input sides.
    ka, kb : int or sequence of int
        Harmonic count of every a_n (every b_m), or one count per coefficient.
    w0 : float
        Fundamental of the period in rad/s (not needed with FrequencyData).
    ts : float, optional
        Sample period of a discrete-time model.
    lines : sequence of int or 'excited', optional
        The rows (lines) of the fit. Default (None): all usable lines K+1 .. Lmax-K, K the
        largest harmonic count; kept as the library's default so that existing scripts give the
        same numbers. ``'excited'``: the lines the input excites (power 100 times above its
        noise) and, for an LPTV model, the lines within +-K of them (:func:`excited_rows`);
        this is what ``lptv identify FILE`` uses by default. With several experiments: None or
        'excited' for every experiment, or a list with one entry (None, 'excited' or a
        sequence of lines) per experiment. Whatever the rows, the verdict
        (:attr:`IdentificationResult.verdict`) judges the residues on the excited lines, so that
        lines holding only noise do not dilute a model error.
    method : {'ls', 'tls', 'gtls', 'wgtls', 'sml'}
        'wgtls' is the paper's weighted GTLS; 'sml' minimises the exact likelihood of the
        residue (METHOD.md eq. 17, rows correlated through shared lines) from the WGTLS
        estimate. Both give the covariance of ``eta`` (``res.covariance``,
        ``res.parameter_std``, ``res.confidence_interval()``).
    known : dict, optional
        Coefficients known exactly, e.g. ``{'a2': 1.5}`` (a constant) or a Fourier row of
        2K+1 values. With a known coefficient no normalisation is applied.
    tol, max_iter :
        WGTLS (SML) stops when the relative change of the parameters is below ``tol`` or after
        ``max_iter`` weighted solves (Levenberg-Marquardt steps); ``converged`` says which.
    covariance : {'analytic', 'bootstrap', 'realisations', 'none'}
        WGTLS, SML: how ``res.covariance`` is obtained. 'analytic' (default): SML's inverse
        Fisher information; WGTLS's sandwich of its estimating equation to second order in the
        noise (the noise of the Jacobian times that of the residue counts where rows carry
        little signal); both times (P-1)/(P-3) (METHOD.md section 10).
        'bootstrap': the covariance of ``bootstrap`` refits of data sets drawn from the fitted
        model and the measured noise (co)variances, P periods each (`lptv.bootstrap`), which
        follows the randomness of the noise weights at small P where the factor does not
        (bench/HISTORY.md, "Coverage on three systems"); one data set only, about ``bootstrap``
        times the cost of the fit.
        'realisations': several experiments that are independent random-phase realisations of
        one excitation (:meth:`lptv.DistortionResult.experiments`, E >= 4 of them): the
        leave-one-out jackknife over the experiments times (E-1)/(E-3) (:func:`realisation_covariance`,
        METHOD.md section 16), which needs no model of how the nonlinear distortion is correlated
        across lines; about E + 1 times the cost of the fit.
        'none': no covariance (``res.covariance`` None, ``confidence_interval`` refuses): the
        estimate, its residues and the verdict alone, for many fits whose intervals are not read
        (a structure search, a Monte Carlo of the estimates); the analytic covariance takes about
        40 % of a WGTLS fit's time on the paper's example (bench/HISTORY.md).
    bootstrap : int
        The number of refits for ``covariance='bootstrap'`` (at least 20).
    seed : int, optional
        Seeds the bootstrap's draws.
    noise : {'auto', 'sample', 'moderated', 'full', 'full-moderated'}
        The noise (co)variances the fit weighs by. 'sample': each line's own, from its P
        periods. 'full' and 'full-moderated': the same two from the whole record's bins
        between the lines instead of the periods (METHOD.md section 20:
        :meth:`FrequencyData.record_statistics`), right also for a disturbance that passes
        through the system or does not repeat in the periods (its response leaks into every
        period, and the periods' statistics count that leakage, which the mean does not hold);
        they need the periods (not FrequencyData made otherwise). 'full-rows': 'full' with each
        row read on the record's realisations of the noise (the terms between a row's lines
        and between input and output; one input and output; measured, not the default:
        METHOD.md section 20). 'moderated': each line's combined with its neighbours' by
        :func:`lptv.moderated_noise` (empirical Bayes, METHOD.md section 7), worth about
        1 + nu / 2 periods (nu the lines' median degrees of freedom, often 40-120 at P = 4 when
        the noise spectrum is smooth); the covariance's small-sample factor is taken at those
        periods. At P = 4-8 it lowers the variance of the estimate by 10-45 % and calibrates
        the analytic intervals, which the sample variances make 1.5-2.6 times too wide at
        P = 4 (bench/HISTORY.md, "The default noise route"); it assumes a noise spectrum that
        is smooth over a few lines (lines far above their neighbours keep their own variance).
        'auto' (default): 'moderated' when every experiment has P >= 4 periods and its noise
        spectrum passes the smoothness check of :func:`lptv.moderation.smooth_noise` (prior
        degrees of freedom d0 at least the lines' own 2 (P - 1), at most 10 % of the lines
        outlying), 'sample' otherwise, each from the whole record ('full-moderated', 'full')
        when :func:`lptv.correlated_lines` finds the periods' noise correlated between
        neighbouring lines (size 1 %), and 'sample' for ``covariance='bootstrap'`` or ``'realisations'`` and the
        realisations of :meth:`lptv.DistortionResult.experiments`. ``res.noise`` says which
        was used and ``res.noise_choice`` why. ``res.data`` holds the data the fit used.
    transient : {'auto', True, False}
        Several channels (3-D arrays): fit the record's transient term with the model (METHOD.md
        section 20, eq. 20.5): per experiment and output, a polynomial in s (continuous time, powers
        0 .. n - 1) or z (discrete time, powers 1 .. n), n = max(na, nb), with real coefficients,
        which a disturbance that passes through the system leaves in every row of a record. 'auto'
        (default): on the whole record's noise ('full', 'full-moderated', or 'auto' where it takes
        them), off on the periods'. ``res.transient`` holds the coefficients. One input and one
        output (2-D arrays): only 'auto' and False (the term is not fitted); True asks for arrays of
        shape (P, N, 1).
    disturbances : {None, 'remove'}
        'remove': before the fit, find the sinusoids that are not periodic in the record (off
        the period's grid, such as mains hum beside a multisine whose period is not a multiple
        of the mains period) in the input and output periods and subtract them
        (:func:`lptv.disturbances`, METHOD.md section 7); ``res.disturbances`` lists them.
        Such a sinusoid inflates the noise variances of the lines around it and makes the
        verdict find residues "too small". Needs the periods (``(u, y)`` arrays or pairs), not
        :class:`FrequencyData`. Default None: the records as given.

    Raises
    ------
    ValueError
        Besides bad arguments, degenerate data, diagnosed before estimating (METHOD.md section
        14), with the argument and the cause: no input power on the fitted lines ("u: ... zero",
        "u: ... at the level of its noise", or "u: the input is not excited on the fitted lines
        ... it is excited on lines ..."), an output without variation there ("y: ..."), fewer
        rows carrying signal than the parameters need ("lines: ..."), known coefficients that
        cannot fix the scale or that zero a_na ("known: ...").
    lptv.NumericalError
        A decomposition failed on data that passed the diagnostics (the message says which).

    Warns
    -----
    IdentifiabilityWarning
        The data do not determine the model (also :attr:`IdentificationResult.undetermined`; the
        verdict then never says "consistent").
    lptv.UnstableModelWarning
        The identified model is unstable (also :attr:`IdentificationResult.unstable`).
    UserWarning
        The core's other warnings (:attr:`IdentificationResult.warnings`).

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2)
    >>> ms = lptv.multisine(range(1, 60), 256, seed=0)
    >>> y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    >>> rng = np.random.default_rng(1)
    >>> u = ms.periods(4) + 1e-3 * rng.standard_normal((4, 256))
    >>> y = np.tile(y1, (4, 1)) + 1e-3 * rng.standard_normal((4, 256))
    >>> res = lptv.identify(u, y, na=1, nb=0, w0=0.1)
    >>> np.round(res.model.a[:, 0].real, 2)
    array([2., 1.])

    One input and two outputs, arrays of shape (P, N, nu) and (P, N, ny):

    >>> a = np.zeros((2, 2, 2)); a[1] = np.eye(2); a[0] = [[2.0, 0.5], [0.0, 3.0]]
    >>> mm = lptv.MimoModel(a, np.ones((1, 2, 1)), w0=0.1)
    >>> Y = lptv.simulate(mm, ms.spectrum[:, None], lines_out=128)
    >>> y2 = np.fft.irfft(Y * 256, 256, axis=0)[None] + 1e-3 * rng.standard_normal((4, 256, 2))
    >>> r2 = lptv.identify(u[:, :, None], y2, na=1, nb=0, w0=0.1)
    >>> r2.model.n_outputs, (np.round(r2.model.a[0, :, :, 0].real, 2) + 0.0).tolist(), r2.model_ok
    (2, [[2.0, 0.5], [0.0, 3.0]], True)
    """
    if is_mimo(u, y):
        if disturbances is not None:
            raise ValueError("disturbances: only disturbances=None is built for several inputs or outputs")
        return identify_mimo(u, y, na=na, nb=nb, ka=ka, kb=kb, w0=w0, ts=ts, lines=lines, method=method,
                             known=known, tol=tol, max_iter=max_iter, covariance=covariance, noise=noise,
                             transient=transient)
    if as_transient(transient) is True:
        raise ValueError("transient=True is not built for one input and one output given as 2-D arrays: give them "
                         "as arrays of shape (P, N, 1) (the route of several channels) to fit the record's transient "
                         "term (METHOD.md section 20 says why one channel's route does not take it by default)")
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if not isinstance(covariance, str) or covariance not in COVARIANCES:
        raise ValueError(f"covariance must be one of {COVARIANCES}, got {covariance!r}")
    if not isinstance(noise, str) or noise not in NOISES:
        raise ValueError(f"noise must be one of {NOISES}, got {noise!r}")
    if noise in ("moderated", "full-moderated") and covariance == "bootstrap":
        raise ValueError(f"noise='{noise}' is not for covariance='bootstrap': the bootstrap draws P periods "
                         "from each line's own sample variances; use covariance='analytic' with moderated noise")
    if disturbances is not None and (not isinstance(disturbances, str) or disturbances != "remove"):
        raise ValueError(f"disturbances must be None or 'remove', got {disturbances!r}")
    bootstrap = as_int(bootstrap, "bootstrap", minimum=20)
    na, nb = as_int(na, "na"), as_int(nb, "nb")
    tol = as_float(tol, "tol", minimum=0.0, open_min=True)
    max_iter = as_int(max_iter, "max_iter")
    several = y is None and isinstance(u, (list, tuple))
    # the core's analytic covariance only where it is the one reported: the bootstrap and the
    # jackknife replace it, 'none' skips it (about 1.6 ms of a 3.9 ms WGTLS fit on the paper's example)
    analytic = covariance == "analytic"
    found = ()
    if disturbances == "remove":
        u, y, found = _without_disturbances(u, y, several)
    if several:
        datas = experiments_of(u, w0, ts)
        data = datas[0]
    else:
        data = frequency_data_of(u, y, w0, ts)
    ts = data.ts if ts is None else ts
    moderation = ()
    choice = "asked for"
    if noise in ("full", "full-moderated", "full-rows"):
        if several:
            datas = [_record_data(d, f"experiments[{i}]") for i, d in enumerate(datas)]
            data = datas[0]
        else:
            data = _record_data(data, "u")
    if noise == "auto":
        noise, choice, pairs = _auto_noise(datas if several else [data], covariance)
        if noise == "full":   # the moderated routes' data come with the pairs
            if several:
                datas = [d.record_statistics() for d in datas]
                data = datas[0]
            else:
                data = data.record_statistics()
    elif noise in ("moderated", "full-moderated"):
        pairs = [_moderated(d) for d in (datas if several else [data])]
    if noise in ("moderated", "full-moderated"):
        moderation = tuple(m for _, m in pairs)
        if several:
            datas = [d for d, _ in pairs]
            data = datas[0]
        else:
            data = pairs[0][0]
    if na + nb + 2 > MAX_COEFFICIENTS:  # refused before the per-coefficient lists below are built
        raise ValueError(f"na = {na} and nb = {nb} give {na + nb + 2} coefficients, more than any fit "
                         f"can hold (the core estimates at most 4000 complex parameters)")
    ka_l, kb_l = _counts(ka, na, "ka"), _counts(kb, nb, "kb")
    kn = _known_list(known, ka_l, kb_l)
    structure = _core.Structure(na, nb, ka_l, kb_l, kn, data.w0, 0.0 if ts is None else float(ts))
    # noise='full-rows' reads each row on the noise's realisations (METHOD.md section 20)
    full_rows = noise == "full-rows"
    if several:
        rows = _experiment_rows(datas, lines, max(ka_l + kb_l))
        try:
            r = _core.identify_experiments([d._cpp for d in datas], structure, method=method, tol=float(tol),
                                           max_iter=int(max_iter), rows=rows, covariance=analytic,
                                           full_rows=full_rows)
        except ValueError as e:
            raise ValueError(_with_distortion_hint(str(e), datas)) from None
    else:
        if isinstance(lines, str):
            if lines != "excited":
                raise ValueError(f"lines must be a sequence of integers or 'excited', got {lines!r}")
            lines = excited_rows(data, max(ka_l + kb_l))
        _below_nyquist(lines, data.max_line)
        rows = [] if lines is None else _rows(lines)
        r = _core.identify(data._cpp, structure, method=method, tol=float(tol), max_iter=int(max_iter),
                           rows=rows, covariance=analytic, full_rows=full_rows)
    for msg in r.warnings:
        unident = r.nearly_unidentifiable and "unidentifiable" in msg
        warnings.warn(msg, IdentifiabilityWarning if unident else UserWarning, stacklevel=2)
    cov = r.covariance
    model = Model._from_core(r.model)
    unstable, undecided = stability_check(model)
    if undecided is not None:
        undecided = "the identified model's " + undecided
        warnings.warn(undecided, StabilityUndecidedWarning, stacklevel=2)
    if unstable is not None:
        # said once here; the verdict's own simulation of the estimate stays silent
        unstable = ("the identified " + unstable[len("the "):].split(": the periodic")[0]
                    + ": its predicted steady state is the periodic solution of its equation, which "
                    "a simulation from rest does not reach (fine for data from a stabilised experiment)")
        warnings.warn(unstable, UnstableModelWarning, stacklevel=2)
    cov_dof = None
    if covariance == "bootstrap":
        cov = _bootstrap(r, model, structure, data, several, method, tol, max_iter, bootstrap, seed)
    elif covariance == "realisations":
        cov, cov_dof = _jackknife(r, structure, datas if several else None, rows if several else None, method, tol,
                                  max_iter)
    if covariance != "realisations" and several and cov is not None and _noise_alone(datas):
        warnings.warn("the realisations carry their noise alone (DistortionResult.experiments(referred='none')) and "
                      "the nonlinear distortion is detected: the analytic covariance is the noise's alone and "
                      "understates the variance of the best linear approximation; covariance='realisations' "
                      "includes the distortion", UserWarning, stacklevel=2)
    if cov is not None:
        model.covariance, model.eta_names = np.asarray(cov), tuple(r.eta_names)
    return IdentificationResult(
        model=model, method=method, lines=np.asarray(r.rows), theta=np.asarray(r.theta),
        eta=np.asarray(r.eta), n_free_parameters=r.n_free, iterations=r.iterations, converged=r.converged,
        cost=r.cost, cost_history=np.asarray(r.cost_history), singular_values=np.asarray(r.singular_values),
        residue=np.asarray(r.residue), residue_variance=np.asarray(r.residue_variance),
        normalized_residue=np.asarray(r.normalized_residue), fraction_above_0db=r.fraction_above_0db,
        fraction_expected=r.fraction_expected, fraction_band=tuple(r.fraction_band), noise_free=r.noise_free,
        warnings=tuple(r.warnings), data=None if several else data, eta_names=tuple(r.eta_names),
        covariance=None if cov is None else np.asarray(cov), nearly_unidentifiable=r.nearly_unidentifiable,
        experiment=np.asarray(r.experiment, dtype=int), experiments=tuple(datas) if several else (),
        unstable=unstable, stability_undecided=undecided, structure=structure, noise=noise, noise_choice=choice,
        moderation=moderation, disturbances=found, covariance_dof=cov_dof, covariance_option=covariance)


def _without_disturbances(u, y, several):
    """disturbances='remove': the periods without the sinusoids :func:`lptv.disturbances` finds
    (each (u, y) pair of several experiments alike), and those sinusoids."""
    from ..spectra.disturbances import disturbances as find

    def clean(uu, yy, where):
        if isinstance(uu, FrequencyData):
            raise ValueError(f"disturbances='remove' needs the periods (u, y), not FrequencyData{where}: "
                             "the spectra no longer hold what differs between the periods")
        try:
            out = find(uu, yy)
        except ValueError as e:
            raise ValueError(f"disturbances='remove'{where}: {e}") from None
        return out.u, out.y, out.found

    if not several:
        return clean(u, y, "")
    items, found = [], []
    for i, item in enumerate(u):
        if isinstance(item, (list, tuple)) and len(item) == 2:
            uu, yy, f = clean(item[0], item[1], f" (experiments[{i}])")
            items.append((uu, yy))
            found.extend(f)
        else:   # FrequencyData is refused here; anything else, experiments_of reports
            if isinstance(item, FrequencyData):
                clean(item, None, f" (experiments[{i}])")
            items.append(item)
    return items, None, tuple(found)


def _record_data(d, name):
    """The data with the record's statistics (noise='full...'), or a ValueError naming ``name``."""
    try:
        return d.record_statistics()
    except ValueError as e:
        raise ValueError(f"noise='full' takes the noise from the whole record: {name}: {e}") from None


def _unrepeated_input(d) -> float:
    """The power of the periods' input deviations over the power of its mean, lines 1 .. Lmax - 1
    (P varU is a period's deviation variance)."""
    mean = float(np.sum(np.abs(d.U[1:-1]) ** 2))
    return float(d.periods * np.sum(d.varU[1:-1])) / mean if mean > 0 else np.inf


def _auto_noise(datas, covariance):
    """noise='auto': ('sample', 'moderated', 'full' or 'full-moderated', the sentence saying why,
    the moderated data and their ModeratedNoise per experiment for a moderated route, else None).

    First the statistics: the whole record's (the 'full' routes, METHOD.md section 20) when the
    periods' noise is correlated between neighbouring lines (:func:`lptv.correlated_lines`)
    in any experiment, else the periods'; then the moderation, as before, on those statistics.
    The sentence keeps the moderation's reason first and adds the test's."""
    from ..spectra.frequency_data import correlated_lines
    from ..spectra.moderation import moderated_noise, smooth_noise

    if covariance in ("bootstrap", "realisations"):
        return "sample", f"the sample variances: covariance='{covariance}' resamples them", None
    if any(getattr(d, "distortion", None) is not None for d in datas):
        return "sample", "the sample variances: the data are realisations of lptv.distortion", None
    if any(d.periods < 2 for d in datas):
        return "sample", "the sample variances: the data do not come from periods", None
    full, lines = False, ""
    if all(d.statistics == "record" for d in datas):
        full, lines = True, "the noise from the whole record (the data's statistics)"
    elif all(getattr(d, "_record", None) is not None for d in datas):
        tests = [correlated_lines(d) for d in datas]
        full = any(t.correlated for t in tests)
        # the record's bins are for noise that does not repeat, not for an input that does not: a
        # record cut at a wrong period has no line 20 dB above its periods' noise, and its refusal
        # (with the period the record repeats at) comes from the periods' statistics
        # the record's bins are for noise that does not repeat, not for an input that does not: in a
        # record cut at a wrong period the periods' input differs by more than its periodic power
        # (a closed loop's input holds a few % that does not repeat), and its refusal, with the
        # period the record repeats at, comes from the periods' statistics
        unrepeated = full and any(_unrepeated_input(d) > 1.0 for d in datas)
        said = [t.reason for t in tests if t.correlated == full]
        where = [i for i, t in enumerate(tests) if t.correlated == full]
        if len(datas) > 1:
            said = [f"experiment {i}: {r}" for i, r in zip(where, said)]
        lines = "; ".join(said[:3]) + (" (the noise from the whole record)" if full else "")
        if unrepeated:
            full = False
            lines = ("the noise of neighbouring lines is correlated, but the input does not repeat in the periods "
                     "(they differ by more than its periodic power): the periods' statistics")
        datas = [d.record_statistics() for d in datas] if full else datas
    sample, moderated = ("full", "full-moderated") if full else ("sample", "moderated")

    def say(head, why):
        return f"{head}: {why}" + (f"; {lines}" if lines else "")

    pairs, why = [], []
    for d in datas:
        if full and d.periods < AUTO_MIN_PERIODS_RECORD:
            return sample, say("the sample variances", (
                f"{d.periods} periods (on the record's noise the moderated route needs {AUTO_MIN_PERIODS_RECORD}: "
                f"with fewer its intervals are too narrow)")), None
        if d.periods < AUTO_MIN_PERIODS:
            return sample, say("the sample variances", (
                f"{d.periods} periods (the moderated route needs {AUTO_MIN_PERIODS}: the lines that keep "
                f"their own variance would have {2 * (d.periods - 1)} degrees of freedom)")), None
        mo = moderated_noise(d)
        ok, reason = smooth_noise(mo)
        why.append(reason)
        if not ok:
            return sample, say("the sample variances", reason), None
        pairs.append(_moderated(d, mo))
    return moderated, say("moderated", "; ".join(why)), pairs


def _moderated(d, mo=None):
    """(the data with moderated (co)variances, the ModeratedNoise) for noise='moderated'; the data
    unchanged and None when they cannot be moderated (statistics not from periods, too few
    lines). The periods the moderated variances are worth: 1 + nu / 2, nu the median of the
    lines' degrees of freedom (the covariance's small-sample factor takes one P per data set)."""
    from ..spectra.moderation import moderated_noise

    if d.periods < 2:
        return d, None
    if mo is None:
        mo = moderated_noise(d)
    if mo.prior_dof <= 0:
        return d, None
    Pe = max(int(d.periods), int(round(1.0 + float(np.median(mo.dof[1:-1])) / 2.0)))
    m = mo.data
    out = FrequencyData(m.U, m.Y, m.varU, m.varY, m.covYU, w0=m.w0, ts=m.ts, periods=Pe)
    if d.noise_realisations is not None:   # the record's realisations, each line's scaled to its moderated variance
        out = out.with_realisations(*_scaled_realisations(d, m), like=d)
    return out, mo


def _scaled_realisations(d, m):
    """d's noise realisations with each line's input (output) scaled by sqrt of m's variance over
    d's, so that their sums of squares are m's variances (METHOD.md section 20)."""
    nU, nY = d.noise_realisations
    with np.errstate(divide="ignore", invalid="ignore"):
        kU = np.where(d.varU > 0, np.sqrt(m.varU / d.varU), 0.0)
        kY = np.where(d.varY > 0, np.sqrt(m.varY / d.varY), 0.0)
    return nU * kU, nY * kY


def _bootstrap(r, model, structure, data, several, method, tol, max_iter, B, seed):
    """covariance='bootstrap': the covariance of B refits of parametric bootstrap data sets."""
    from .bootstrap import bootstrap_covariance

    if several:
        raise ValueError("covariance='bootstrap' takes one data set, not a list of experiments")
    if method not in ("wgtls", "sml"):
        raise ValueError(f"covariance='bootstrap' is for method 'wgtls' or 'sml', got {method!r}")
    if data.periods < 2 or r.noise_free:
        raise ValueError("covariance='bootstrap' needs noise statistics from P >= 2 periods")
    rows = [int(x) for x in r.rows]
    eta_names = tuple(r.eta_names)

    def fit(d):
        rb = _core.identify(d._cpp, structure, method=method, tol=float(tol), max_iter=int(max_iter),
                            rows=rows, covariance=False)
        return np.asarray(rb.eta)

    class _Res:   # what bootstrap_covariance reads of the estimate
        pass

    est = _Res()
    est.model = model
    cov = bootstrap_covariance(est, data, fit, B, seed)
    norm = [i for i, n in enumerate(eta_names) if np.allclose(cov[i], 0.0)]
    for i in norm:
        cov[i, :] = cov[:, i] = 0.0
    return cov


def realisation_covariance(estimates, dof=None, ratio=None) -> np.ndarray:
    """The covariance of a fit of E independent realisations from its E leave-one-out refits
    (``estimates``, shape (E, n)): the jackknife (E-1)/E sum_e (eta_(e) - mean)(eta_(e) - mean)^T,
    times (E-1)/(E-3), the variance of Student's t with E-1 degrees of freedom, so that
    eta +- 1.96 std covers like the t interval (METHOD.md section 16).

    ``dof``, ``ratio`` (optional, one per entry of eta): when the realisations carry unequal
    information (:func:`realisation_terms`), the jackknife's degrees of freedom per parameter (in
    [1, E-1]) and its bias factor; entry j is then scaled by ratio_j (t_{dof_j} / t_{E-1})^2 at
    97.5 %, so that eta +- 1.96 std stays a 95 % interval (the same matrix when every dof is
    E - 1 and every ratio 1).

    Examples
    --------
    >>> import numpy as np
    >>> est = np.array([[1.0], [2.0], [3.0], [4.0], [5.0]])       # E = 5 refits
    >>> float(realisation_covariance(est)[0, 0])                   # 4/5 * 10 * 4/2
    16.0
    >>> round(float(realisation_covariance(est, dof=[1.0], ratio=[0.5])[0, 0]))  # 16 0.5 (12.706 / 2.776)^2
    168
    """
    est = np.asarray(estimates, dtype=float)
    E = est.shape[0]
    if E < 4:
        raise ValueError(f"covariance='realisations' needs at least 4 experiments, got {E}")
    d = est - est.mean(axis=0)
    cov = (E - 1) / E * (d.T @ d) * (E - 1) / (E - 3)
    n = est.shape[1]
    s = np.ones(n)
    if dof is not None:
        from .._dist import t_ppf

        nu = np.asarray(dof, dtype=float)
        if nu.shape != (n,) or not np.all(np.isfinite(nu)) or np.any(nu < 1) or np.any(nu > E - 1):
            raise ValueError(f"dof must give one value in [1, {E - 1}] per parameter ({n}), got {dof!r}")
        s = s * t_ppf(0.975, nu) / t_ppf(0.975, E - 1)
    if ratio is not None:
        q = np.asarray(ratio, dtype=float)
        if q.shape != (n,) or not np.all(np.isfinite(q)) or np.any(q <= 0):
            raise ValueError(f"ratio must give one positive value per parameter ({n}), got {ratio!r}")
        s = s * np.sqrt(q)
    return cov * np.outer(s, s)


def realisation_terms(informations, free, n_eta: int):
    """The jackknife's degrees of freedom and its bias factor per entry of eta when E
    realisations carry unequal information (METHOD.md section 16). ``informations``: the E
    Fisher informations H_e of the realisations at the estimate (over the free parameters, at
    eta positions ``free``), H = sum_e H_e.

    Linearised at the estimate (where the scores sum to zero), the leave-one-out deviation of
    realisation e has covariance V_e = A_e (H_e - H_e H^-1 H_e) A_e, A_e = (H - H_e)^-1. The
    jackknife (E-1)/E sum_e (eta_(e) - mean)^2 then expects (E-1)/E sum_e (V_e)_jj where the
    estimate's variance is (H^-1)_jj: ``ratio`` is their quotient (1 for equal realisations;
    below 1 where one realisation's absence moves the fit far). As a sum of E independent
    squared terms with variances (V_e)_jj it has Satterthwaite's (sum_e V_e,jj)^2 / sum_e V_e,jj^2
    degrees of freedom, clipped to [1, E-1] (E - 1 for equal realisations). Entries of eta that
    are not free get E - 1 and 1. Raises numpy.linalg.LinAlgError when H - H_e is singular (a
    realisation alone carries some parameter).

    Examples
    --------
    >>> import numpy as np
    >>> H = [np.eye(1) * w for w in (1.0, 1.0, 1.0, 1.0, 1.0, 1.0)]    # six equal realisations
    >>> [round(float(v[0]), 12) for v in realisation_terms(H, [0], 1)]
    [5.0, 1.0]
    >>> H = [np.eye(1) * w for w in (100.0, 1.0, 1.0, 1.0, 1.0, 1.0)]  # one carries 95 %
    >>> dof, ratio = realisation_terms(H, [0], 1)
    >>> round(float(dof[0]), 3), round(float(ratio[0]), 4)
    (1.005, 0.0599)
    """
    Hs = [np.asarray(h, dtype=float) for h in informations]
    E = len(Hs)
    H = sum(Hs)
    Hi = np.linalg.inv(H)
    v = []
    for h in Hs:
        A = np.linalg.inv(H - h)
        v.append(np.diag(A @ (h - h @ Hi @ h) @ A))
    v = np.array(v)                                            # (E, n_free)
    tot, sq = v.sum(axis=0), (v ** 2).sum(axis=0)
    if not (np.all(np.isfinite(v)) and np.all(tot > 0)):
        raise np.linalg.LinAlgError("the leave-one-out terms are not positive")
    nu = np.full(int(n_eta), float(E - 1))
    ratio = np.ones(int(n_eta))
    free = np.asarray(free, dtype=int)
    nu[free] = np.clip(tot ** 2 / sq, 1.0, E - 1.0)
    ratio[free] = np.diag(Hi) / ((E - 1) / E * tot)
    return nu, ratio


def _jackknife(r, structure, datas, rows, method, tol, max_iter):
    """covariance='realisations': the jackknife over the experiments (:func:`realisation_covariance`)."""
    if datas is None:
        raise ValueError("covariance='realisations' takes a list of experiments (the realisations, e.g. "
                         "DistortionResult.experiments()), not one data set")
    if method not in ("wgtls", "sml"):
        raise ValueError(f"covariance='realisations' is for method 'wgtls' or 'sml', got {method!r}")
    E = len(datas)
    if E < 4:
        raise ValueError(f"covariance='realisations' needs at least 4 experiments (realisations), got {E}")
    # each refit keeps the rows the full fit used for the experiments it keeps
    used = np.asarray(r.experiment, dtype=int)
    fit_rows = np.asarray(r.rows, dtype=int)
    per = [[int(x) for x in fit_rows[used == e]] for e in range(E)]
    est = []
    for k in range(E):
        keep = [e for e in range(E) if e != k]
        rk = _core.identify_experiments([datas[e]._cpp for e in keep], structure, method=method, tol=float(tol),
                                        max_iter=int(max_iter), rows=[per[e] for e in keep],
                                        covariance=False)
        est.append(np.asarray(rk.eta))
    # Unequal realisations (a strongly time-varying system whose output power depends on the
    # phases): the jackknife has fewer degrees of freedom than E - 1 (METHOD.md section 16).
    dof = ratio = None
    try:
        par = _core.Parametrisation(structure)
        free = [i for i in par.free_indices if i < par.n_eta]
        theta = np.asarray(r.theta)
        H = [np.asarray(_core.ExactLikelihood(datas[e]._cpp, par, per[e]).fisher_information(theta)) for e in range(E)]
        if all(h.shape == (len(free), len(free)) for h in H):
            dof, ratio = realisation_terms(H, free, par.n_eta)
    except (np.linalg.LinAlgError, _core.NumericalError, ValueError):
        dof = ratio = None   # the terms cannot be formed: E - 1 and the plain jackknife
    cov = realisation_covariance(est, dof=dof, ratio=ratio)
    norm = [i for i in range(cov.shape[0]) if np.allclose(cov[i], 0.0)]
    for i in norm:
        cov[i, :] = cov[:, i] = 0.0
    return cov, (np.full(cov.shape[0], float(E - 1)) if dof is None else dof)


def _with_distortion_hint(msg: str, datas) -> str:
    """A refusal of a realisation of DistortionResult.experiments() as a dead output channel: the
    common nonlinear level on the output variances is above that realisation's output (its output
    power differs widely from the others', e.g. a strongly time-varying system whose response
    depends on the phases). Said, with what to do instead."""
    import re

    hit = re.match(r"experiment (\d+): y: the output shows no variation above its noise", msg)
    if hit is None or getattr(datas[0], "distortion", None) is None:
        return msg
    e = int(hit.group(1))
    power = [float(np.sum(np.abs(np.asarray(d.Y)[1:]) ** 2)) for d in datas]   # as output_spread
    return (msg + f". These are realisations of a DistortionResult with one common nonlinear level on their "
            f"output variances; realisation {e}'s output power is {power[e] / max(power):.2g} of the largest "
            f"({min(power) / max(power):.2g} at the least), below that level. A response that depends on the "
            f"phases this much has far HTF branches: fit the realisations with their noise alone and the "
            f"jackknife over them (lptv.identify(d.experiments(referred='none'), ..., "
            f"covariance='realisations')), which is consistent there; or refer the level to the input "
            f"(d.experiments(referred='input', model=that fit)), more efficient where the branches are few")


def _experiment_rows(datas, lines, K):
    """The rows of each experiment for the core: [] means that experiment's default rows."""
    E = len(datas)
    if lines is None:
        return [[] for _ in range(E)]
    if isinstance(lines, str):
        entries = [lines] * E
    else:
        if not isinstance(lines, (list, tuple)) or len(lines) != E or not all(
                v is None or isinstance(v, str) or np.ndim(v) == 1 for v in lines):
            raise ValueError(f"lines: with {E} experiments give None, 'excited', or a list of {E} entries "
                             "(None, 'excited' or a sequence of lines), one per experiment")
        entries = list(lines)
    rows = []
    for e, (v, d) in enumerate(zip(entries, datas)):
        try:
            if v is None:
                rows.append([])
            elif isinstance(v, str):
                if v != "excited":
                    raise ValueError(f"lines must be a sequence of integers or 'excited', got {v!r}")
                rows.append([int(x) for x in excited_rows(d, K)])
            else:
                rows.append(_rows(v))
        except ValueError as err:
            raise ValueError(f"lines[{e}] (experiment {e}): {err}") from None
    return rows
