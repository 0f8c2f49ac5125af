"""Monte Carlo studies of the estimators: bias, variance against the Cramer-Rao bound, coverage.

One realisation draws P noisy periods of a design (true model, excitation, noise) and fits them
with each method; :func:`montecarlo` runs R of them on an executor (:mod:`lptv.batch.executors`)
and :class:`MonteCarloResult` summarises them (:mod:`lptv.batch.tables` turns them into tables
and figures).
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Dict, Optional, Sequence, Tuple, Union

import numpy as np

from .._validate import as_float, as_int, as_path, as_real_1d
from ..spectra.frequency_data import FrequencyData
from ..examples.siso import noise_variances, noisy_periods
from ..simulation.fds import simulate
from ..estimation.identify import METHODS, identify
from ..model.siso import Model
from ..excitation.multisine import Multisine, spectrum, time_signal
from ..estimation.crb import CramerRaoBound, crb
from ..records.budget import _bytes, memory_budget
from .executors import Failure, available_cores, describe_executor, run_tasks
from .tables import MonteCarloTables


def _methods(methods) -> Tuple[str, ...]:
    if isinstance(methods, str):
        methods = [m.strip() for m in methods.split(",")]
    try:
        out = tuple(methods)
    except TypeError:
        raise ValueError(f"methods must be a method name, a comma list or a sequence of names, "
                         f"got {methods!r}") from None
    if not out:
        raise ValueError("methods must name at least one method")
    for m in out:
        if m not in METHODS:
            raise ValueError(f"methods: {m!r} is not one of {METHODS}")
    if len(set(out)) != len(out):
        raise ValueError(f"methods: a method is given twice in {out}")
    return out


def _snr(x, name):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number of dB (inf: no noise), got {x!r}") from None
    if np.isnan(v) or v == -np.inf:
        raise ValueError(f"{name} must be a number of dB (inf: no noise), got {x!r}")
    return v


def _in_range(x, name, lo, hi, closed):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {x!r}") from None
    ok = lo <= v <= hi if closed else lo < v < hi
    if not ok:
        raise ValueError(f"{name} must lie in {'[' if closed else '('}{lo:g}, {hi:g}"
                         f"{']' if closed else ')'}, got {x!r}")
    return v


def _excitation(excitation) -> Multisine:
    """A Multisine, or one period of any input in time wrapped as one (for crb)."""
    if isinstance(excitation, Multisine):
        return excitation
    u0 = as_real_1d(excitation, "excitation", min_len=4)
    U = spectrum(u0)
    lines = np.flatnonzero(np.abs(U) > 1e-12 * np.abs(U).max())
    return Multisine(lines=lines, amplitudes=2 * np.abs(U[lines]), phases=np.angle(U[lines]),
                     n_samples=u0.size, spectrum=U, signal=u0)


def _fit(data, method, fit):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = identify(data, method=method, **fit)
        except Exception as e:  # noqa: BLE001 - reported in this fit's row
            text = " ".join(str(e).split())
            return dict(method=method, ok=False, error=f"{type(e).__name__}: {text}")
    extra = tuple(str(w.message) for w in caught if str(w.message) not in res.warnings)
    return dict(method=method, ok=True, error="", eta=res.eta, std=res.parameter_std,
                converged=bool(res.converged), iterations=int(res.iterations), cost=float(res.cost),
                fraction_above_0db=float(res.fraction_above_0db), residue_ok=bool(res.residue_ok),
                warnings=tuple(res.warnings) + extra)


def realisation(item, design) -> list:
    """One realisation (the task :func:`montecarlo` sends out): noise from the item's seed,
    then every method on the same data. Returns one dict per method (plain data: it travels
    back from the worker)."""
    run, seed = item
    rng = np.random.default_rng(seed)
    u, y = noisy_periods(design["u0"], design["y0"], design["periods"], seed=rng, **design["noise"])
    data = FrequencyData.from_periods(u, y, w0=design["w0"], ts=design["ts"])
    return [_fit(data, m, design["fit"]) for m in design["methods"]]


@dataclass(frozen=True, eq=False)
class MonteCarloResult(MonteCarloTables):
    """What :func:`montecarlo` returns: every estimate, its reported std, and the bound.

    The arrays hold one row per realisation (NaN where the fit failed); :meth:`table`,
    :meth:`fit_table`, :meth:`summary` and :meth:`overview` give them as pandas tables,
    :meth:`save` writes them, :meth:`plot_errors` and :meth:`plot_coverage` draw them.
    """

    methods: Tuple[str, ...]
    eta_names: Tuple[str, ...]
    truth: np.ndarray
    """The true ``eta`` (normalised as the estimates are)."""
    free: np.ndarray
    """Mask of the estimated entries of ``eta`` (the normalised one is fixed)."""
    crb: CramerRaoBound
    estimates: Dict[str, np.ndarray]
    """method -> (runs, n_eta) estimates of ``eta`` (NaN rows where the fit failed)."""
    std: Dict[str, np.ndarray]
    """method -> (runs, n_eta) reported standard deviations (NaN without a covariance)."""
    fits: Tuple[dict, ...]
    """One dict per (run, method), run-major: ok, error, converged, iterations, cost,
    fraction_above_0db, residue_ok, warnings."""
    runs: int
    periods: int
    level: float
    design: dict = field(repr=False)
    """The noise levels, lines and seed of the study (for the report)."""
    executor: str = ""
    elapsed: float = 0.0
    """Wall-clock seconds of the fits (not of the bound)."""

    @property
    def n_fits(self) -> int:
        return self.runs * len(self.methods)

    @property
    def fits_per_minute(self) -> float:
        return 60.0 * self.n_fits / self.elapsed if self.elapsed > 0 else float("nan")


RUN_BYTES, METHOD_BYTES, PARAMETER_BYTES = 500, 700, 150
"""A study's memory per run (its seed and task), per run and method (its row of fits and the task's
answer) and per run, method and parameter (estimates, std and their table's row), measured."""
SAMPLE_BYTES = 40
"""A realisation's memory per sample of its P x N periods (the noisy input and output, their
noises, spectra and the fit's arrays), measured at N = 2^14 .. 2^18 (about 39 bytes)."""


def _within_memory(runs, n_methods, n_parameters, periods, n_samples, executor, workers):
    """Refuses a study whose results, or whose realisations in flight, exceed the memory budget
    (lptv.memory_budget), before anything is built: 2^31 runs took minutes to list their seeds,
    a million periods failed every fit with a MemoryError."""
    budget = memory_budget()
    where = "lptv's memory budget of " + _bytes(budget) + " (half the machine's memory, or LPTV_MEMORY_BUDGET)"
    kept = runs * (RUN_BYTES + n_methods * (METHOD_BYTES + PARAMETER_BYTES * n_parameters))
    if kept > budget:
        raise ValueError(f"runs: a study of {runs} runs x {n_methods} method{'s' if n_methods > 1 else ''} needs about "
                         f"{_bytes(kept)} to hold their seeds and results, more than {where}: fewer runs (several "
                         "studies with their own seeds)")
    local = isinstance(executor, str) and executor == "processes"
    at_once = 1 if not local else available_cores() if workers is None else \
        int(workers) if isinstance(workers, (int, np.integer)) and workers > 0 else 1
    one = SAMPLE_BYTES * periods * n_samples
    if one * at_once + kept > budget:
        many = f" x {at_once} at once (workers)" if at_once > 1 else ""
        raise ValueError(f"periods: a realisation of {periods} periods of {n_samples} samples needs about "
                         f"{_bytes(one)} (its noisy record, spectra and fit){many}, more than {where}: fewer "
                         "periods or samples" + (", or fewer workers" if at_once > 1 else ""))


def montecarlo(model: Model, excitation: Union[Multisine, Sequence[float]], *, periods: int,
               runs: int, snr_in_db: float, snr_out_db: float, methods="wgtls",
               pole_in: float = 0.0, pole_out: float = 0.0, correlation: float = 0.0,
               lines=None, tol: float = 1e-10, max_iter: int = 50, level: float = 0.95, seed=0,
               executor="processes", workers: Optional[int] = None, chunk_size: Optional[int] = None,
               progress: Optional[bool] = None, checkpoint=None) -> MonteCarloResult:
    """A Monte Carlo study of the estimators on a design: R noise realisations, each fitted.

    Realisation r draws P periods of the steady-state input and output of ``model`` under
    ``excitation`` with the noise of :func:`lptv.examples.noisy_periods` (white or first-order
    coloured, input and output correlated or not) from the r-th child of
    ``numpy.random.SeedSequence(seed).spawn(runs)``, and fits them with every method in the
    model's own structure (its na, nb and harmonic counts). The results are therefore the same,
    bit for bit, whatever the executor, the number of workers and the chunking. The Cramer-Rao
    bound of the design (:func:`lptv.crb` with the noise's true per-line (co)variances,
    :func:`lptv.examples.noise_variances`) comes with them.

    Parameters
    ----------
    model : lptv.Model
        The true system; also the structure estimated.
    excitation : lptv.Multisine or array_like (N,)
        One period of the input.
    periods, runs : int
        P >= 2 measured periods per realisation; R >= 1 realisations.
    snr_in_db, snr_out_db : float
        Mean SNR of input and output (20 log10 of signal rms over noise rms); ``inf``: none.
    methods : str or sequence of str
        One or several of :data:`lptv.METHODS`, e.g. ``"wgtls,sml"``; all fit the same data.
    pole_in, pole_out, correlation : float
        Colour (first-order low-pass pole in (-1, 1); 0 is white) of input and output noise and
        the share of the input noise's driving sequence in the output noise, in [-1, 1].
    lines, tol, max_iter :
        As for :func:`lptv.identify`.
    level : float
        Confidence level of the intervals whose coverage is counted.
    seed : int, sequence of int or numpy.random.SeedSequence
        Root of the realisations' seeds.
    executor, workers, chunk_size, progress :
        Where and how the fits run (:func:`lptv.batch.run_tasks`): ``"processes"`` (default,
        all cores), ``"serial"``, a Dask scheduler address or ``distributed.Client``.
    checkpoint : str or Path, optional
        A folder where every finished chunk of realisations is written as it completes; a
        rerun with the same arguments and folder runs only the realisations it lacks (after
        Ctrl-C, a kill or a lost cluster), and gives the same result, bit for bit, as an
        uninterrupted run (:mod:`lptv.batch.parts`). A folder of another study is refused.

    Returns
    -------
    MonteCarloResult
        ``.summary()`` (per method and parameter: bias, RMS, std, variance / CRB, coverage),
        ``.overview()`` (per method: failures, residue-test rejections, pooled coverage),
        ``.table()`` (tidy: one row per run, method and parameter), ``.save(folder)``.

    Examples
    --------
    >>> import lptv
    >>> m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2)
    >>> ms = lptv.multisine(range(1, 60), 256, seed=0)
    >>> mc = lptv.montecarlo(m, ms, periods=8, runs=50, snr_in_db=40, snr_out_db=30,
    ...                      methods="wgtls,sml", executor="serial", progress=False)
    >>> mc.eta_names, mc.estimates["sml"].shape
    (('a0.re0', 'a1.re0', 'b0.re0'), (50, 3))
    >>> ov = mc.overview()                                        # needs pandas
    >>> int(ov.loc["sml", "failures"]), bool(0.8 < ov.loc["sml", "var_over_crb_median"] < 1.6)
    (0, True)
    """
    if not isinstance(model, Model):
        raise ValueError(f"model must be an lptv.Model, got {type(model).__name__}")
    ms = _excitation(excitation)
    periods = as_int(periods, "periods", minimum=2)
    runs = as_int(runs, "runs", minimum=1)
    methods = _methods(methods)
    noise = dict(snr_in_db=_snr(snr_in_db, "snr_in_db"), snr_out_db=_snr(snr_out_db, "snr_out_db"),
                 pole_in=_in_range(pole_in, "pole_in", -1, 1, False),
                 pole_out=_in_range(pole_out, "pole_out", -1, 1, False),
                 correlation=_in_range(correlation, "correlation", -1, 1, True))
    level = _in_range(level, "level", 0, 1, False)
    tol = as_float(tol, "tol", minimum=0.0, open_min=True)
    max_iter = as_int(max_iter, "max_iter", minimum=0)
    if checkpoint is not None:
        checkpoint = as_path(checkpoint, "checkpoint")
    if isinstance(seed, (bool, float, complex, str, bytes)):
        raise ValueError(f"seed must be an int, a sequence of ints or a SeedSequence, got {seed!r}")
    if not isinstance(seed, np.random.SeedSequence):
        try:
            seed = np.random.SeedSequence(seed)
        except (TypeError, ValueError) as e:
            raise ValueError(f"seed must be an int, a sequence of ints or a SeedSequence: {e}") from None

    N = ms.n_samples
    _within_memory(runs, len(methods), 2 * (model.a.size + model.b.size), periods, N, executor, workers)
    y0 = time_signal(simulate(model, ms.spectrum), N)
    var_u, var_y, cov_yu = noise_variances(ms.signal, y0, **noise)
    bound = crb(model, ms, var_u=var_u, var_y=var_y, cov_yu=cov_yu, periods=periods, lines=lines)
    # noise named (identify's default): a study checkpointed before that default took the
    # moderated route keeps its fingerprint apart
    fit = dict(na=model.na, nb=model.nb, ka=model.ka, kb=model.kb, lines=bound.lines,
               tol=float(tol), max_iter=max_iter, noise="auto")
    design = dict(u0=ms.signal, y0=y0, w0=model.w0, ts=model.ts, periods=periods, noise=noise,
                  fit=fit, methods=methods)

    t0 = time.perf_counter()
    out = run_tasks(realisation, list(enumerate(seed.spawn(runs))), design, executor=executor,
                    workers=workers, chunk_size=chunk_size, progress=progress, desc="montecarlo",
                    unit="fit", weight=len(methods), checkpoint=checkpoint)
    elapsed = time.perf_counter() - t0

    n = bound.eta.size
    est = {m: np.full((runs, n), np.nan) for m in methods}
    std = {m: np.full((runs, n), np.nan) for m in methods}
    fits = []
    for r, rows in enumerate(out):
        if isinstance(rows, Failure):   # the realisation itself failed: every method's row says so
            rows = [dict(method=m, ok=False, error=rows.message) for m in methods]
        for row in rows:
            m = row["method"]
            if row["ok"]:
                est[m][r] = row["eta"]
                if row["std"] is not None:
                    std[m][r] = row["std"]
            fits.append(dict(run=r, method=m, ok=row["ok"], error=row["error"],
                             converged=row.get("converged", False), iterations=row.get("iterations", 0),
                             cost=row.get("cost", np.nan),
                             fraction_above_0db=row.get("fraction_above_0db", np.nan),
                             residue_ok=row.get("residue_ok", False), warnings=row.get("warnings", ())))
    return MonteCarloResult(
        methods=methods, eta_names=tuple(bound.eta_names), truth=bound.eta, free=bound.std > 0,
        crb=bound, estimates=est, std=std, fits=tuple(fits), runs=runs, periods=periods, level=level,
        design=dict(noise, samples=N, excited_lines=np.asarray(ms.lines), fit_lines=bound.lines,
                    entropy=seed.entropy, spawn_key=seed.spawn_key, model=model.to_dict()),
        executor=describe_executor(executor, workers), elapsed=elapsed)
