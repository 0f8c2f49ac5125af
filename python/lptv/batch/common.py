"""What the batch's modules share: an item's :class:`Failure`, the optional dependencies'
import (:func:`require`), and the one BLAS thread every task runs with (:func:`one_blas_thread`).
:mod:`lptv.batch.executors`, :mod:`lptv.batch.parts` and :mod:`lptv.batch.warm` import them from
here, so that none of them imports another that imports it back."""
from __future__ import annotations

import sys
import traceback
from dataclasses import dataclass

EXTRA = "pip install 'lptv[batch]'"


@dataclass(frozen=True)
class Failure:
    """What :func:`run_tasks` gives for an item whose task raised: the error, on one line."""

    message: str
    detail: str = ""
    """The traceback (or the reason the chunk was lost)."""


def require(module: str, what: str, *, load: bool = True):
    """Import an optional dependency, or raise ImportError naming the extra that brings it. With
    ``load=False`` only whether it is installed is checked (without the import's cost: a command
    that refuses a bad option then does so at once); returns None."""
    import importlib
    import importlib.util

    try:
        if not load:
            if importlib.util.find_spec(module) is None:
                raise ImportError(module)
            return None
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(f"{what} needs the package '{module.split('.')[0]}': {EXTRA}") from None


def _one_line(e: BaseException) -> str:
    text = " ".join(str(e).split())
    return f"{type(e).__name__}: {text}" if text else type(e).__name__


def _call(fn, item, shared):
    try:
        return fn(item, shared)
    except Exception as e:  # noqa: BLE001 - reported in the item's row, the batch goes on
        return Failure(_one_line(e), traceback.format_exc())


_limited_at = [-1]   # len(sys.modules) when one_blas_thread last set the limits in this process


def one_blas_thread():
    """Limit the BLAS libraries loaded in this process to one thread; returns the function that
    restores the previous limits (a no-op without threadpoolctl).

    threadpoolctl scans the loaded libraries on every call (0.7 ms; once per chunk, 3-4 % of a
    short chunk's time), so a call made while the last limits hold (not restored) and no module
    was imported since, hence no BLAS library loaded, returns at once."""
    if len(sys.modules) == _limited_at[0]:
        return lambda: None
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return lambda: None
    restore = threadpool_limits(limits=1, user_api="blas").restore_original_limits
    _limited_at[0] = len(sys.modules)

    def restore_and_forget():
        _limited_at[0] = -1
        restore()
    return restore_and_forget
