"""Running many small tasks: serially, on local processes or on a Dask cluster.

A fit takes about 10 ms, so the work is many small tasks and the per-task overhead of the
executor decides the speed: :func:`run_tasks` sends the items in chunks (one task per chunk),
puts the results back in the order of the items whatever order the chunks finish in, and shows
a progress bar with an ETA on the terminal. An item whose function raises becomes a
:class:`Failure` holding the message, and so does every item of a chunk that was lost (a worker
that died): the other items still finish.

Executors (the ``executor`` argument):

- ``"processes"`` (the default): a :class:`concurrent.futures.ProcessPoolExecutor` with
  ``workers`` processes (default: the cores this process may use). lptv's own tasks
  (``lptv.montecarlo``, ``lptv.identify_many``, ``lptv.select``) run on one pool kept between
  calls, its workers warm (lptv and scipy.signal imported once), ended at exit or by
  :func:`lptv.batch.shutdown_pool` (:mod:`lptv.batch.warm`); a function of your own gets a
  pool per call, shut down at its end;
- ``"serial"``: in this process, one item after the other;
- a scheduler address such as ``"tcp://10.0.0.5:8786"``: a :class:`distributed.Client`
  connected for the run and closed at the end (``pip install 'lptv[batch]'``); on a cluster
  (this case or the next) lptv registers a worker plugin that imports lptv and scipy.signal once per worker
  (:mod:`lptv.batch.dask_plugin`), and where Dask's ``MALLOC_TRIM_THRESHOLD_`` is set its
  chunks run with glibc's thresholds raised, trimmed after (:func:`lptv.batch.warm.malloc_kept`);
- a :class:`distributed.Client` (or a :class:`concurrent.futures.Executor`) of your own: used
  as it is and left open, so that several runs share one cluster or one pool.

Chunks: ``chunk_size`` items per task if given; otherwise, once the workers have measured the
cost of an item on an earlier call of the same function, tasks that shrink from long to short
(:func:`chunk_sizes`), so that the workers finish together; before that, :func:`default_chunk_size`.

Results do not depend on the executor: the tasks draw their random numbers from seeds handed
to them (see :func:`lptv.montecarlo`), never from the worker they run on, and they run with
one BLAS thread wherever they run. The thread count of OpenBLAS changes the rounding of its
reductions (the core's solves differ in the last bits between 1 and 2 threads), and Dask
workers start with OPENBLAS_NUM_THREADS=1 while a local process has one thread per core;
threadpoolctl (in the extra) sets it to 1 in every worker, and in this process for a serial
run. One thread per process is also what a process per core wants.
"""
from __future__ import annotations

import concurrent.futures as cf
import hashlib
import math
import os
import pickle
import sys
import time
import traceback
import weakref
from typing import Any, Callable, List, Optional, Sequence

from .common import EXTRA, Failure, _call, _one_line, one_blas_thread, require  # noqa: F401 - their names here too
from .warm import discard_pool, kept_pool, malloc_kept

# Largest chunk: 32 fits of ~12 ms are ~0.4 s, against ~1-3 ms of per-task overhead on Dask
# (bench/HISTORY.md), while leaving several chunks per worker for balance and for the ETA.
MAX_CHUNK = 32
CHUNKS_PER_WORKER = 4
# Once the cost of an item is known (measured by the workers on an earlier call of the same
# function in this process), a task lasts TASK_MIN..TASK_MAX seconds: about ten times the
# per-task overhead of a process pool (about 1 ms; TASK_MIN_DASK for Dask's 3-4 ms), at most
# what a progress bar and a checkpoint should wait for. The first round of tasks holds
# FIRST_SHARE of the items (bench/HISTORY.md, "Chunks in rounds").
TASK_MIN, TASK_MIN_DASK, TASK_MAX = 0.01, 0.04, 0.4
FIRST_SHARE = 0.75

_cost = {}   # (module, qualified name) of a task function -> seconds per item, last measured


def run_chunk(items: Sequence, fn: Callable, shared: Any) -> list:
    """The task a worker runs: ``fn(item, shared)`` for each item, failures caught per item.

    The worker keeps one BLAS thread afterwards (restoring would race with other tasks of a
    multi-threaded Dask worker; a worker of a batch has no other use for BLAS threads). Where
    ``MALLOC_TRIM_THRESHOLD_`` pins glibc's thresholds (a Dask worker) the chunk runs with them
    raised and the memory is trimmed after it (:func:`lptv.batch.warm.malloc_kept`).
    """
    one_blas_thread()
    with malloc_kept():
        return [_call(fn, item, shared) for item in items]


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def default_chunk_size(n_items: int, workers: int) -> int:
    """Items per task: about CHUNKS_PER_WORKER tasks per worker, at most MAX_CHUNK items each.

    >>> default_chunk_size(2000, 2), default_chunk_size(2000, 100), default_chunk_size(3, 2)
    (32, 5, 1)
    """
    return max(1, min(MAX_CHUNK, math.ceil(n_items / (CHUNKS_PER_WORKER * max(1, workers)))))


def chunk_sizes(n_items: int, workers: int, cost: Optional[float] = None,
                task_min: Optional[float] = None) -> List[int]:
    """The sizes of the tasks, in the order they are sent.

    Without a measured ``cost`` (seconds per item), :func:`default_chunk_size` for every task.
    With one, the tasks come in rounds of ``workers`` equal tasks (factoring): the first round
    takes FIRST_SHARE of the items, each later round half of what is left, each task at least
    ``task_min`` seconds of work (default TASK_MIN; about ten times the executor's per-task
    overhead) and at most TASK_MAX; the round that would go below that splits what is left
    evenly over the workers. The workers start and end each round together, so they finish
    together, with few tasks: for 64 items of 4.3 ms on 2 workers, 24 24 4 4 4 4.

    >>> chunk_sizes(64, 2), chunk_sizes(64, 2, cost=0.0043)
    ([8, 8, 8, 8, 8, 8, 8, 8], [24, 24, 4, 4, 4, 4])
    """
    if n_items <= 0:
        return []
    if not cost or not math.isfinite(cost) or cost <= 0:
        size = default_chunk_size(n_items, workers)
        return [size] * (n_items // size) + ([n_items % size] if n_items % size else [])
    W = max(1, workers)
    lo = max(1, math.ceil((TASK_MIN if task_min is None else task_min) / cost))
    hi = max(lo, math.floor(TASK_MAX / cost))
    sizes, left, share = [], n_items, FIRST_SHARE
    while left > 0:
        size = min(hi, math.ceil(share * left / W))
        share = 0.5
        if size < lo or left - size * W < W:   # the last round: what is left, evenly over the workers
            k = max(min(W, left), math.ceil(left / hi))
            sizes += [left // k + (1 if i < left % k else 0) for i in range(k)]
            break
        sizes += [size] * W
        left -= size * W
    return sizes


def _cost_key(fn):
    return (getattr(fn, "__module__", None), getattr(fn, "__qualname__", None))


def _plan(todo, workers, chunk_size, fn, task_min=None):
    """The chunks of ``todo`` (lists of item indices): of ``chunk_size`` items if given, else
    of :func:`chunk_sizes` with the cost measured on the last call of ``fn``."""
    if chunk_size:
        return [[todo[k] for k in c] for c in _chunks(len(todo), chunk_size)]
    chunks, start = [], 0
    for size in chunk_sizes(len(todo), workers, _cost.get(_cost_key(fn)), task_min):
        chunks.append(todo[start:start + size])
        start += size
    return chunks


class _Clock:
    """The workers' seconds per item over a call, kept for the next call of the function."""

    def __init__(self, fn):
        self.key, self.seconds, self.items = _cost_key(fn), 0.0, 0

    def add(self, n_items, seconds):
        self.seconds += seconds
        self.items += n_items

    def keep(self):
        if self.items and self.seconds > 0:
            _cost[self.key] = self.seconds / self.items


def _timed_chunk(items: Sequence, fn: Callable, shared: Any, cwd: Optional[str] = None):
    """:func:`run_chunk` and the seconds it took on the worker; in the folder ``cwd`` if given
    (a kept pool's worker was forked where the caller was then, and relative paths are the
    caller's)."""
    if cwd is not None:
        try:
            here = os.getcwd()
        except FileNotFoundError:   # the folder the worker was forked in has been deleted since
            here = None
        if here != cwd:
            os.chdir(cwd)
    t0 = time.perf_counter()
    results = run_chunk(items, fn, shared)
    return results, time.perf_counter() - t0


def _caller_folder() -> str:
    """The caller's working folder, for a kept pool's workers to run in; if it was deleted (a
    temporary folder removed while the process still stands in it), the root: a relative path
    then names nothing anywhere, and the task's own error says which."""
    try:
        return os.getcwd()
    except FileNotFoundError:
        return os.path.abspath(os.sep)


def _is_dask_client(obj) -> bool:
    return type(obj).__module__.split(".")[0] == "distributed" and hasattr(obj, "scheduler_info")


def _looks_like_address(text: str) -> bool:
    return "://" in text or (":" in text and text.rsplit(":", 1)[1].isdigit())


class _Progress:
    """A tqdm bar on a terminal (``progress=None``), always (True) or never (False)."""

    def __init__(self, total, progress, desc, unit):
        self.bar = None
        if progress is None:
            progress = sys.stderr.isatty()
        if not progress:
            return
        try:
            from tqdm.auto import tqdm
        except ImportError:
            if progress is True:
                raise ImportError(f"progress=True needs the package 'tqdm': {EXTRA}") from None
            return

        class Bar(tqdm):
            monitor_interval = 0   # no monitor thread: the process pool may fork after this

        self.bar = Bar(total=total, desc=desc, unit=unit, smoothing=0.1, dynamic_ncols=True)

    def update(self, n):
        if self.bar is not None:
            self.bar.update(n)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def describe_executor(executor, workers=None) -> str:
    """A short description, e.g. '2 processes' or 'dask tcp://127.0.0.1:8786 (4 threads)'."""
    if executor == "serial":
        return "serial"
    if executor == "processes":
        return f"{workers or available_cores()} processes"
    if isinstance(executor, str):
        return f"dask {executor}"
    if _is_dask_client(executor):
        return f"dask {executor.scheduler.address} ({_dask_threads(executor)} threads)"
    return type(executor).__name__


def _dask_threads(client) -> int:
    info = client.scheduler_info()
    return max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))


def _check_executor(executor, workers):
    if workers is not None:
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ValueError(f"workers must be a positive integer, got {workers!r}")
        if executor != "processes":
            raise ValueError(f"workers applies to executor='processes' only (executor={executor!r}); "
                             "a Dask cluster has its own workers")
    if isinstance(executor, str):
        if executor in ("serial", "processes") or _looks_like_address(executor):
            return
        raise ValueError(f"executor must be 'serial', 'processes', a Dask scheduler address like "
                         f"'tcp://host:8786', a distributed.Client or a concurrent.futures.Executor; "
                         f"got {executor!r}")
    elif not (_is_dask_client(executor) or isinstance(executor, cf.Executor)):
        raise ValueError(f"executor must be 'serial', 'processes', a scheduler address, a "
                         f"distributed.Client or a concurrent.futures.Executor, got {type(executor).__name__}")


def run_tasks(fn: Callable, items: Sequence, shared: Any = None, *, executor="processes",
              workers: Optional[int] = None, chunk_size: Optional[int] = None, progress=None,
              desc: str = "lptv", unit: str = "item", weight: int = 1, checkpoint=None,
              labels: Optional[Sequence[str]] = None, on_resume: Optional[Callable] = None) -> List[Any]:
    """``[fn(item, shared) for item in items]`` on an executor, in chunks, with progress.

    Parameters
    ----------
    fn : callable
        ``fn(item, shared)``; a module-level function (it is pickled by reference, so on a
        Dask cluster the workers need its module, i.e. lptv, installed).
    items : sequence
        Small picklable descriptions of the tasks (an index and a seed, a file name ...).
    shared : object
        What every task needs (the design of a study): sent once per chunk (once per worker
        on Dask, where it is scattered; pickling the 35 KB design of the paper's example takes
        0.06 ms, nothing next to a chunk).
    executor : {'processes', 'serial'}, str, distributed.Client or concurrent.futures.Executor
        See the module's description.
    workers : int, optional
        Processes of ``executor='processes'`` (default: the available cores).
    chunk_size : int, optional
        Items per task (default: :func:`chunk_sizes` from the cost measured on the last call of
        ``fn``, :func:`default_chunk_size` before one).
    progress : bool, optional
        Progress bar with an ETA: None shows it when stderr is a terminal.
    desc, unit, weight :
        Label and unit of the bar; each item counts ``weight`` units (e.g. the fits it makes).
    checkpoint : str or Path, optional
        A folder where each finished chunk is written as it completes (:mod:`lptv.batch.parts`);
        the items it already holds (of the same study) are read back instead of run again, so
        that a study interrupted (Ctrl-C, a kill, a lost cluster) resumes where it stopped with
        the same results, bit for bit. Each result is stored under its item's key (a hash of
        the item by content), so that an item that changed since (a rewritten file) runs again.
        A folder holding another study is refused (ValueError).
    labels : sequence of str, optional
        With ``checkpoint``: a stable name per item (e.g. its file), so that the checkpoint can
        tell an item that changed since its result was stored from a new one.
    on_resume : callable, optional
        With ``checkpoint``: called once, before anything runs, with the
        :class:`lptv.batch.parts.ResumeStatus` of the folder (items read back, changed, new).

    Returns
    -------
    list
        One entry per item, in order: ``fn``'s value or a :class:`Failure`.

    Examples
    --------
    >>> from lptv.batch import run_tasks, Failure
    >>> def inverse(x, shared):
    ...     return shared / x
    >>> out = run_tasks(inverse, [1, 2, 0, 4], 8.0, executor="serial", progress=False)
    >>> out[:2], isinstance(out[2], Failure), out[2].message, out[3]
    ([8.0, 4.0], True, 'ZeroDivisionError: float division by zero', 2.0)
    """
    _check_executor(executor, workers)
    items = list(items)
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int)
                                   or chunk_size < 1):
        raise ValueError(f"chunk_size must be a positive integer, got {chunk_size!r}")
    out = [None] * len(items)
    store, todo = None, list(range(len(items)))
    if checkpoint is not None:
        from .parts import Checkpoint

        if labels is not None and len(labels) != len(items):
            raise ValueError(f"labels must give one label per item ({len(items)}), got {len(labels)}")
        store = Checkpoint(checkpoint, fn, items, shared, desc, labels=labels)
        done = store.load()
        if on_resume is not None:
            on_resume(store.status)
        for i, r in done.items():
            out[i] = r
        todo = [i for i in todo if i not in done]

    def finished(indices, results):
        for i, r in zip(indices, results):
            out[i] = r
        if store is not None:
            store.write(indices, results)

    bar = _Progress(len(items) * weight, progress, desc, unit)
    bar.update((len(items) - len(todo)) * weight)
    try:
        if executor == "serial":
            restore = one_blas_thread()
            try:
                size = chunk_size or default_chunk_size(len(todo), 1)
                for c in _chunks(len(todo), size):
                    idx = [todo[k] for k in c]
                    results = []
                    for i in idx:
                        results.append(_call(fn, items[i], shared))
                        bar.update(weight)
                    finished(idx, results)
            finally:
                restore()
        elif executor == "processes" or isinstance(executor, cf.Executor):
            _run_futures(fn, items, todo, shared, executor, workers, chunk_size, bar, weight, finished, out)
        else:
            _run_dask(fn, items, todo, shared, executor, chunk_size, bar, weight, finished, out)
        return out
    finally:
        bar.close()


def _chunks(n, size):
    return [range(i, min(n, i + size)) for i in range(0, n, size)]


LOST = "task lost: "
"""The start of the message of an item whose chunk was lost (a dead worker, a lost cluster)."""


def _lost(chunk, e, out):
    f = Failure(f"{LOST}{_one_line(e)}", "".join(traceback.format_exception(type(e), e, e.__traceback__)))
    for i in chunk:
        out[i] = f


def _ignore_interrupts():
    """In a pool's worker: Ctrl-C (sent to the whole process group) and SIGTERM are the parent's
    to handle; the worker finishes its chunk and is shut down by the parent."""
    import signal

    from .warm import watch_parent

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    watch_parent()


def _is_lptv(fn) -> bool:
    return (getattr(fn, "__module__", None) or "").split(".")[0] == "lptv"


def _run_futures(fn, items, todo, shared, executor, workers, chunk_size, bar, weight, finished, out):
    own = executor == "processes"
    if own:
        workers = workers or available_cores()
    else:
        workers = getattr(executor, "_max_workers", None) or available_cores()
    chunks = _plan(todo, workers, chunk_size, fn)
    if not chunks:
        return
    clock = _Clock(fn)
    # lptv's own tasks run on the pool kept between calls (warm workers); a function of the
    # caller's on a pool of its own, forked now, so that it sees the caller's modules as they are
    kept = own and _is_lptv(fn)
    if kept:
        pool = kept_pool(workers)
    elif own:
        pool = cf.ProcessPoolExecutor(max_workers=min(workers, len(chunks)), initializer=_ignore_interrupts)
    else:
        pool = executor
    try:
        cwd = _caller_folder() if kept else None
        futures = {pool.submit(_timed_chunk, [items[i] for i in c], fn, shared, cwd): c for c in chunks}
        for fut in cf.as_completed(futures):
            c = futures[fut]
            try:
                results, seconds = fut.result()
            except Exception as e:  # noqa: BLE001 - a dead worker: its items fail, not the batch
                _lost(c, e, out)
            else:
                finished(c, results)
                clock.add(len(c), seconds)
            bar.update(weight * len(c))
    except BaseException:
        if kept:
            discard_pool(pool)
        elif own:
            pool.shutdown(wait=False, cancel_futures=True)
        raise
    clock.keep()
    if own and not kept:
        pool.shutdown(wait=True)


_shared_on = weakref.WeakKeyDictionary()   # Dask client -> (digest, future) of the last shared argument


def _identity(x):
    return x


def _scattered(client, shared):
    """``shared`` on the cluster as a future that every chunk depends on: one copy per worker
    that runs a chunk instead of one per task, kept for the next call with equal contents (a
    study repeated with the same design skips the round trip, 5-7 ms on a 2-core LocalCluster).
    It is a task (``_identity(shared)``), not scattered data: the scheduler holds its recipe, so
    when the workers that hold its value die, one after another, it is computed again on a live
    one, and the chunks still to run lose nothing (scattered data has no recipe: once its last
    holder died, every chunk waiting for it was cancelled)."""
    try:
        digest = hashlib.blake2b(pickle.dumps(shared, protocol=pickle.HIGHEST_PROTOCOL), digest_size=20).digest()
    except Exception:  # noqa: BLE001 - not picklable by pickle (Dask's cloudpickle may manage): no reuse
        digest = None
    kept = _shared_on.get(client)
    if digest is not None and kept is not None and kept[0] == digest and kept[1].status in ("finished", "pending"):
        return kept[1]
    fut = client.submit(_identity, shared, pure=False, priority=1 << 30)
    if digest is not None:
        _shared_on[client] = (digest, fut)
    return fut


def _run_dask(fn, items, todo, shared, executor, chunk_size, bar, weight, finished, out):
    distributed = require("distributed", "a Dask executor")
    client = distributed.Client(executor, set_as_default=False) if isinstance(executor, str) else executor
    try:
        from .dask_plugin import register

        register(client)   # every worker imports lptv and scipy.signal once, before its first chunk
        chunks = _plan(todo, _dask_threads(client), chunk_size, fn, TASK_MIN_DASK)
        if not chunks:
            return
        clock = _Clock(fn)
        shared_f = _scattered(client, shared)
        # the chunks in the order planned (the long ones first): the scheduler runs the higher
        # priority first, and would otherwise order tasks of equal priority by their random keys
        futures = [client.submit(_timed_chunk, [items[i] for i in c], fn=fn, shared=shared_f, pure=False,
                                 priority=len(chunks) - k) for k, c in enumerate(chunks)]
        where = {f.key: c for f, c in zip(futures, chunks)}
        try:
            for fut in distributed.as_completed(futures, loop=client.loop):
                c = where[fut.key]
                try:
                    results, seconds = fut.result()
                except Exception as e:  # noqa: BLE001 - a lost worker or task: its items fail
                    _lost(c, e, out)
                else:
                    finished(c, results)
                    clock.add(len(c), seconds)
                bar.update(weight * len(c))
                fut.release()
        except BaseException:
            client.cancel(futures)
            raise
        clock.keep()
    finally:
        if isinstance(executor, str):
            client.close()
