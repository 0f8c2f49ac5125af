"""The same identification on many records: measurement files or arrays, one row each."""
from __future__ import annotations

import csv
import hashlib
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Optional, Sequence, Tuple

import numpy as np

from .._validate import as_float, as_int, as_path, as_positive_float, not_regular
from ..estimation.identify import COVARIANCES, METHODS, NOISES, _counts, _known_list, _rows, identify
from ..atomic import atomic_open, atomic_path
from ..records.measurements import Measurements, read_measurements, read_options
from ..model.siso import Model
from .executors import Failure, describe_executor, require, run_tasks

# The columns every row has, before the parameters (eta and eta.std by name).
COLUMNS = ("record", "ok", "error", "format", "periods", "samples", "w0", "method", "noise", "converged",
           "iterations", "cost", "fraction_above_0db", "fraction_expected", "residue_ok", "model_ok",
           "n_free_parameters", "warnings")


def _arrays(record, read):
    """u, y, w0 and the format of one record (a file is read here, i.e. on the worker); a file
    without w0 but with a sampling frequency (given or its own) has the period N / fs."""
    if isinstance(record, (str, os.PathLike)):
        m = read_measurements(record, **read)
        w0 = m.w0
        if w0 is None and read.get("period") is not None:
            w0 = 2 * np.pi / read["period"]
        elif w0 is None and m.fs is not None:
            w0 = 2 * np.pi * m.fs / m.u.shape[1]
        return m.u, m.y, w0, m.format
    if isinstance(record, Measurements):
        return record.u, record.y, record.w0, record.format
    if isinstance(record, Mapping):
        if "u" not in record or "y" not in record:
            raise ValueError("a record given as a dict needs the keys 'u' and 'y' (and optionally 'w0')")
        return record["u"], record["y"], record.get("w0"), "arrays"
    if isinstance(record, (tuple, list)) and len(record) == 2:
        return record[0], record[1], None, "arrays"
    raise TypeError(f"a record must be a file path, a (u, y) pair, a dict with 'u' and 'y' or "
                    f"lptv.Measurements, got {type(record).__name__}")


def _w0(w0, w0_record, ts, n_samples):
    if w0 is not None and w0_record is not None and not np.isclose(w0, w0_record, rtol=1e-9, atol=0):
        raise ValueError(f"w0 = {w0:.10g} rad/s was given but the record says w0 = {float(w0_record):.10g}")
    w0 = w0_record if w0_record is not None else w0
    if ts is not None:
        w0_ts = 2 * np.pi / (n_samples * ts)
        if w0 is None:
            w0 = w0_ts
        elif not np.isclose(w0, w0_ts, rtol=1e-9, atol=0):
            raise ValueError(f"w0 = {float(w0):.10g} and ts = {ts:g} give {2 * np.pi / (w0 * ts):.6g} "
                             f"samples per period, but the record has {n_samples}")
    if w0 is None:
        raise ValueError("w0 is unknown: pass w0 (rad/s) or ts, or store w0 in the record")
    return float(w0)


def file_digest(path) -> Optional[str]:
    """The SHA-256 of a file's bytes (None when it cannot be read here: on a cluster whose
    workers alone see it)."""
    h = hashlib.sha256()
    if not_regular(path):
        return None                  # a FIFO would hang the read: the task's reader refuses it
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return None
    return h.hexdigest()


def identify_record(item, settings) -> dict:
    """One record (the task :func:`identify_many` sends out): read, identify, return plain data.
    A file's item carries the digest of its bytes when the batch was planned: a file that
    changed since is refused (its result would not be the one the checkpoint stores it as)."""
    name, record, digest = item if len(item) == 3 else (*item, None)
    u, y, w0_record, fmt = _arrays(record, dict(settings.get("read") or {}, periods=settings["periods"]))
    if digest is not None and file_digest(record) != digest:
        raise ValueError("the file changed while the batch ran: run the batch again to fit its new contents")
    u, y = np.asarray(u), np.asarray(y)
    n_samples = u.shape[-1] if u.ndim else 0
    w0 = _w0(settings["w0"], w0_record, settings["ts"], n_samples)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = identify(u, y, w0=w0, ts=settings["ts"], **settings["fit"])
    extra = tuple(str(w.message) for w in caught if str(w.message) not in res.warnings)
    std = res.parameter_std
    return dict(
        record=name, ok=True, error="", format=fmt, periods=int(u.shape[0]), samples=int(n_samples),
        w0=w0, method=res.method, noise=res.noise, converged=bool(res.converged), iterations=int(res.iterations),
        cost=float(res.cost), fraction_above_0db=float(res.fraction_above_0db),
        fraction_expected=float(res.fraction_expected), residue_ok=bool(res.residue_ok),
        model_ok=bool(res.model_ok),
        n_free_parameters=int(res.n_free_parameters), warnings="; ".join(tuple(res.warnings) + extra),
        eta_names=tuple(res.eta_names), eta=res.eta, std=std, model=res.model.to_dict())


@dataclass(frozen=True, eq=False)
class BatchResult:
    """What :func:`identify_many` returns: one row per record, in the order of the records.

    A row holds the fit's figures (``COLUMNS``) and, for each parameter, its estimate (column
    named as in ``eta_names``) and reported std (``<name>.std``, WGTLS and SML). A record that
    failed has ``ok`` False and the message in ``error``; its other columns are empty.
    """

    rows: Tuple[dict, ...]
    models: Tuple[Optional[Model], ...] = field(repr=False)
    """The estimated models (None where the record failed)."""
    eta_names: Tuple[str, ...]
    executor: str = ""
    elapsed: float = 0.0

    @property
    def n_failed(self) -> int:
        return sum(not r["ok"] for r in self.rows)

    @property
    def failures(self):
        """[(record, error message)] of the records that failed."""
        return [(r["record"], r["error"]) for r in self.rows if not r["ok"]]

    @property
    def columns(self):
        return list(COLUMNS) + [c for n in self.eta_names for c in (n, n + ".std")]

    def table(self):
        """The rows as a pandas DataFrame (needs pandas: ``pip install 'lptv[batch]'``)."""
        pd = require("pandas", "BatchResult.table")
        return pd.DataFrame(list(self.rows), columns=self.columns)

    def save(self, path) -> Path:
        """Write the rows as CSV (plain Python) or Parquet (by the suffix; needs pyarrow)."""
        path = Path(as_path(path))
        if path.suffix.lower() == ".parquet":
            require("pyarrow", "writing Parquet")
            with atomic_path(path) as tmp:
                self.table().to_parquet(tmp, index=False)
        elif path.suffix.lower() == ".csv":
            with atomic_open(path, "w", newline="") as f:
                w = csv.DictWriter(f, fieldnames=self.columns, restval="")
                w.writeheader()
                for r in self.rows:
                    w.writerow({k: ("" if v is None or (isinstance(v, float) and np.isnan(v)) else v)
                                for k, v in r.items()})
        else:
            raise ValueError(f"path must end in .csv or .parquet, got {path.name!r}")
        return path


def _read(read):
    """identify_many's ``read``: checked here, before any record is read."""
    if read is None:
        return {}
    if not isinstance(read, Mapping):
        raise ValueError(f"read must be a dict of keyword arguments of lptv.read_measurements, got "
                         f"{type(read).__name__}")
    if "periods" in read:
        raise ValueError("read must not hold periods: give it as identify_many's own argument periods=")
    try:
        checked = read_options(**read)
    except ValueError as e:
        raise ValueError(f"read: {e}") from None
    return {k: v for k, v in checked.items() if k in read}


def _slim(record):
    """Only what the worker needs of a dict record (not, e.g., the truth paper_measurements adds)."""
    if isinstance(record, Mapping) and "u" in record and "y" in record:
        return {k: record[k] for k in ("u", "y", "w0") if k in record}
    return record


def _names(records, names):
    if isinstance(records, Mapping):
        if names is not None:
            raise ValueError("names must be omitted when records is a dict (its keys are the names)")
        return [str(k) for k in records], list(records.values())
    if isinstance(records, (str, bytes, os.PathLike)):
        raise ValueError(f"records must be a sequence of files or (u, y) records, got the single path "
                         f"{os.fsdecode(records)!r}: pass [path]")
    try:
        records = list(records)
    except TypeError:
        raise ValueError(f"records must be a sequence of files or (u, y) records, got "
                         f"{type(records).__name__}") from None
    if names is None:
        names = [os.fspath(r) if isinstance(r, (str, os.PathLike)) else f"record {i}"
                 for i, r in enumerate(records)]
    else:
        names = [str(n) for n in names]
        if len(names) != len(records):
            raise ValueError(f"names must give one name per record ({len(records)}), got {len(names)}")
    return names, records


def identify_many(records, *, na: int, nb: int, ka=0, kb=0, w0: Optional[float] = None,
                  ts: Optional[float] = None, lines=None, method: str = "wgtls",
                  known: Optional[Mapping] = None, tol: float = 1e-10, max_iter: int = 50,
                  periods: Optional[int] = None, read: Optional[Mapping] = None,
                  names: Optional[Sequence[str]] = None, covariance: str = "analytic",
                  executor="processes", workers: Optional[int] = None,
                  chunk_size: Optional[int] = None, progress: Optional[bool] = None,
                  checkpoint=None, on_resume=None, noise: str = "auto") -> BatchResult:
    """:func:`lptv.identify` on many records, one row of results per record.

    A record that cannot be read or fitted (a bad file, NaN in the data, a singular system)
    is reported in its row with its message; the others finish. A fit that did not converge is
    a row with ``converged`` False.

    Parameters
    ----------
    records : sequence or dict
        Each a measurement file (CSV, NPZ or MAT, as :func:`lptv.read_measurements` reads;
        read by the worker, so on a cluster the path must exist there), a ``(u, y)`` pair of
        arrays (P, N), a dict with ``u``, ``y`` and optionally ``w0``, or
        :class:`lptv.Measurements`. A dict of records names them by its keys.
    na, nb, ka, kb, ts, lines, method, known, tol, max_iter :
        As for :func:`lptv.identify`, the same for every record.
    w0 : float, optional
        Fundamental (rad/s) for records that do not carry one (a record's own w0 must agree).
        In discrete time it may come from ``ts`` and each record's samples per period.
    periods : int, optional
        Periods in a CSV record (or a vector in NPZ/MAT).
    read : dict, optional
        Other keyword arguments of :func:`lptv.read_measurements` for the files, e.g.
        ``dict(u="force", y="disp", period=10.0)`` (channels by name, fs, trim ...).
    names : sequence of str, optional
        Row labels (default: the file paths, or 'record i').
    covariance : {'analytic', 'bootstrap', 'none'}
        As for :func:`lptv.identify`, for every record. 'none' leaves the ``.std`` columns empty
        and saves about 40 % of each WGTLS fit's time (the paper's example) when only the
        estimates are wanted.
    noise : {'auto', 'sample', 'moderated'}
        As for :func:`lptv.identify` (each record chooses its own route with 'auto').
    executor, workers, chunk_size, progress :
        Where and how the fits run (:func:`lptv.batch.run_tasks`).
    checkpoint : str or Path, optional
        A folder where every finished chunk of records is written as it completes; a rerun
        with the same options and folder fits only the records it lacks: a record read from a
        file is known by its name and the SHA-256 of the file's bytes, so that a file rewritten
        since its fit is fitted again, and nothing else (:mod:`lptv.batch.parts`). A file
        that changes while the batch runs fails with that message.
    on_resume : callable, optional
        With ``checkpoint``: called once before any fit with the folder's
        :class:`lptv.batch.parts.ResumeStatus` (records read back, changed since their fits, new).

    Returns
    -------
    BatchResult
        ``.rows``, ``.models``, ``.failures``, ``.table()`` (pandas), ``.save('fits.csv')``.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import paper_measurements
    >>> recs = {f"seed {s}": paper_measurements(seed=s, periods=4) for s in (1, 2)}
    >>> recs["broken"] = (np.full((4, 2048), np.nan), np.zeros((4, 2048)))
    >>> out = lptv.identify_many(recs, na=2, nb=1, ka=3, kb=3, w0=0.04, lines=range(1, 244),
    ...                          executor="serial", progress=False)
    >>> [r["ok"] for r in out.rows], out.failures[0][0]
    ([True, True, False], 'broken')
    >>> out.models[0].na, out.rows[0]["a0.re0"] > 0
    (2, True)
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    one_record = tuple(c for c in COVARIANCES if c != "realisations")   # each record is one data set
    if not isinstance(covariance, str) or covariance not in one_record:
        raise ValueError(f"covariance must be one of {one_record} (each record is fitted alone), "
                         f"got {covariance!r}")
    if not isinstance(noise, str) or noise not in NOISES:
        raise ValueError(f"noise must be one of {NOISES}, got {noise!r}")
    if noise == "moderated" and covariance == "bootstrap":
        raise ValueError("noise='moderated' is not for covariance='bootstrap'")
    na, nb = as_int(na, "na"), as_int(nb, "nb")
    ka_l, kb_l = _counts(ka, na, "ka"), _counts(kb, nb, "kb")
    _known_list(known, ka_l, kb_l)
    if lines is not None:
        lines = _rows(lines)
    tol = as_float(tol, "tol", minimum=0.0, open_min=True)
    max_iter = as_int(max_iter, "max_iter")
    w0 = None if w0 is None else as_positive_float(w0, "w0")
    ts = None if ts is None else as_positive_float(ts, "ts")
    periods = None if periods is None else as_int(periods, "periods", minimum=1)
    read = _read(read)
    if checkpoint is not None:
        checkpoint = as_path(checkpoint, "checkpoint")
    names, recs = _names(records, names)
    settings = dict(w0=w0, ts=ts, periods=periods, read=read,
                    fit=dict(na=na, nb=nb, ka=ka_l, kb=kb_l, lines=lines, method=method, known=known,
                             tol=float(tol), max_iter=max_iter, noise=noise))
    if covariance != "analytic":   # the settings of earlier checkpoints stay as they were
        settings["fit"]["covariance"] = covariance
    t0 = time.perf_counter()
    items = [(n, _slim(r), file_digest(r) if checkpoint is not None and isinstance(r, (str, os.PathLike)) else None)
             for n, r in zip(names, recs)]
    out = run_tasks(identify_record, items, settings, executor=executor,
                    workers=workers, chunk_size=chunk_size, progress=progress, desc="identify",
                    unit="record", checkpoint=checkpoint, labels=names, on_resume=on_resume)
    elapsed = time.perf_counter() - t0

    rows, models, eta_names = [], [], []
    for name, r in zip(names, out):
        if isinstance(r, Failure):
            rows.append(dict({c: None for c in COLUMNS}, record=name, ok=False, error=r.message,
                             method=method))
            models.append(None)
            continue
        for n in r["eta_names"]:
            if n not in eta_names:
                eta_names.append(n)
        row = {c: r[c] for c in COLUMNS}
        std = r["std"]
        for i, n in enumerate(r["eta_names"]):
            row[n] = float(r["eta"][i])
            row[n + ".std"] = None if std is None else float(std[i])
        rows.append(row)
        models.append(Model.from_dict(r["model"]))
    return BatchResult(rows=tuple(rows), models=tuple(models), eta_names=tuple(eta_names),
                       executor=describe_executor(executor, workers), elapsed=elapsed)
