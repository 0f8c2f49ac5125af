"""Workers that stay warm between calls: the kept process pool, the warm-up, glibc's trimming.

A study of 64 realisations is about half a second of fits on 2 cores, and a worker process
pays more than that before its first fit: the fork, then ``scipy.signal`` and what it pulls
in (about 0.5 s, imported by the first noisy period). Three things keep that out of the
second and later calls:

- :func:`kept_pool`: one :class:`concurrent.futures.ProcessPoolExecutor` per process, made on
  the first call of ``executor="processes"`` with lptv's own task functions and reused by the
  next calls that ask for the same number of workers (another number replaces it; a pool
  broken by a dead worker or shut down is replaced by a new one); :func:`shutdown_pool` ends
  it, and it is ended at exit. A function of your own (``run_tasks(my_fn, ...)``) still gets
  a pool of its own per call: a forked worker sees the modules as they were at the fork, so
  a function defined after it (in a notebook, say) would be missing there.
- :func:`warm_up`: what every worker runs first (the pool's initializer, the Dask worker
  plugin of :mod:`lptv.batch.dask_plugin`): lptv's task modules and ``scipy.signal``
  imported, one BLAS thread.
- :func:`malloc_kept`: Dask's nannies start their workers with ``MALLOC_TRIM_THRESHOLD_=65536``
  (so that glibc hands freed memory back to the system at once); glibc then keeps its mmap
  threshold at 128 KB, and every array of a fit above that (the periods, their spectra) is
  mapped and unmapped anew: about 1300 page faults and 25 % more CPU per fit (bench/HISTORY.md).
  Around one of lptv's chunks the thresholds are raised as glibc's own dynamic rule would
  (mmap threshold 32 MB, trim threshold twice that), and afterwards they are put back and the
  free memory handed back with ``malloc_trim(0)``: the worker holds no more memory between
  tasks than Dask's setting wants, and the fits run at the speed of an untrimmed process.
  Nothing happens where the variable is not set (glibc's dynamic rule is then in force) or
  where the C library is not glibc.
"""
from __future__ import annotations

import atexit
import concurrent.futures as cf
import contextlib
import os
import threading
import time

# mallopt's parameters (malloc.h); glibc's largest dynamic mmap threshold on 64 bits
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_MMAP_MAX = 32 * 1024 * 1024
_MMAP_DEFAULT = 128 * 1024

_pool = None          # (ProcessPoolExecutor, workers) of this process
_pool_lock = threading.Lock()
_libc = None
_malloc_lock = threading.Lock()
_malloc_users = 0


def warm_up():
    """What a worker does before its first task: import lptv's task modules and ``scipy.signal``
    (the first noisy period's filter; with it scipy.stats and scipy.optimize), and limit BLAS
    to one thread (the rounding every executor shares, see :mod:`lptv.batch.executors`)."""
    import importlib

    for name in ("lptv", "lptv.batch.study", "lptv.batch.records", "lptv.batch.selection", "scipy.signal"):
        try:
            importlib.import_module(name)
        except ImportError:   # pragma: no cover - the first task reports it in its rows
            pass
    from .common import one_blas_thread

    one_blas_thread()


def watch_parent(interval: float = 0.5):
    """In a pool's worker: end this process when its parent dies, however it dies. A worker
    waits on the pool's queue, whose pipe the other workers hold open too, so a parent killed
    by SIGKILL (or the OOM killer) would leave its workers waiting forever; a daemon thread
    compares the parent's pid every ``interval`` seconds (the worker is re-parented when its
    parent dies) and ends the process without cleanup (the queue's locks may be held)."""
    parent = os.getppid()

    def watch():
        while True:
            time.sleep(interval)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="lptv-parent-watch", daemon=True).start()


def _pool_worker_start():
    import signal

    watch_parent()

    # Ctrl-C reaches the whole process group: it is the caller's to handle (the worker finishes
    # its chunk). SIGTERM keeps its default: when a worker dies, the pool terminates the others
    # (the queue's lock may have died with it, held) and would otherwise wait for them forever.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    warm_up()


def _usable(pool) -> bool:
    # the executor's own flags: set by a worker's death (BrokenProcessPool) and by shutdown()
    return not (getattr(pool, "_broken", False) or getattr(pool, "_shutdown_thread", False))


def kept_pool(workers: int) -> cf.ProcessPoolExecutor:
    """The process pool of this process with ``workers`` warm workers: the one of the previous
    call if it has that many and still works, otherwise a new one (the old one shut down)."""
    global _pool
    with _pool_lock:
        if _pool is not None:
            pool, n = _pool
            if n == workers and _usable(pool):
                return pool
            _pool = None
            pool.shutdown(wait=False, cancel_futures=True)
        pool = cf.ProcessPoolExecutor(max_workers=workers, initializer=_pool_worker_start)
        _pool = (pool, workers)
        return pool


def discard_pool(pool, wait: bool = False):
    """Shut ``pool`` down (queued tasks cancelled) and forget it if it is the kept one."""
    global _pool
    with _pool_lock:
        if _pool is not None and _pool[0] is pool:
            _pool = None
    pool.shutdown(wait=wait, cancel_futures=True)


def shutdown_pool(wait: bool = True):
    """End the process pool kept between calls (if any); the next call starts a new one."""
    with _pool_lock:
        pool = _pool[0] if _pool is not None else None
    if pool is not None:
        discard_pool(pool, wait=wait)


atexit.register(shutdown_pool)


def current_pool():
    """The kept pool, or None (for tests and the benchmark)."""
    return _pool[0] if _pool is not None else None


def _glibc():
    global _libc
    if _libc is None:
        _libc = False
        try:
            import ctypes

            lib = ctypes.CDLL(None)
            lib.mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
            lib.malloc_trim.argtypes = [ctypes.c_size_t]
            _libc = lib
        except (OSError, AttributeError):   # not glibc (musl, macOS, Windows)
            pass
    return _libc


def _env_size(name, default):
    try:
        return int(os.environ[name])
    except (KeyError, ValueError):
        return default


@contextlib.contextmanager
def malloc_kept():
    """Around one chunk: glibc's thresholds raised if ``MALLOC_TRIM_THRESHOLD_`` pinned them,
    put back and the free memory trimmed when the last chunk running in this process ends."""
    global _malloc_users
    lib = _glibc() if "MALLOC_TRIM_THRESHOLD_" in os.environ else None
    if not lib:
        yield
        return
    with _malloc_lock:
        _malloc_users += 1
        if _malloc_users == 1:
            lib.mallopt(_M_MMAP_THRESHOLD, _MMAP_MAX)
            lib.mallopt(_M_TRIM_THRESHOLD, 2 * _MMAP_MAX)
    try:
        yield
    finally:
        with _malloc_lock:
            _malloc_users -= 1
            if _malloc_users == 0:
                lib.mallopt(_M_MMAP_THRESHOLD, _env_size("MALLOC_MMAP_THRESHOLD_", _MMAP_DEFAULT))
                lib.mallopt(_M_TRIM_THRESHOLD, _env_size("MALLOC_TRIM_THRESHOLD_", _MMAP_DEFAULT))
                lib.malloc_trim(0)
