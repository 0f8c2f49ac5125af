"""Files written whole or not at all: a temporary file beside the target, renamed over it.

A study or a report killed while writing leaves the previous file (or none), never half a file:
``os.replace`` within one folder is atomic on POSIX and Windows.

>>> import os, tempfile
>>> from lptv.atomic import atomic_open
>>> d = tempfile.mkdtemp()
>>> with atomic_open(os.path.join(d, "a.txt")) as f:
...     _ = f.write("whole")
>>> open(os.path.join(d, "a.txt")).read(), sorted(os.listdir(d))
('whole', ['a.txt'])
"""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path):
    """Yields a temporary path beside ``path`` to write to; renamed to ``path`` when the block
    ends without an exception, removed otherwise."""
    path = Path(os.fspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_UMASK)   # mkstemp makes it 0600; a plain open would give this
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_open(path, mode: str = "w", **kw):
    """``open(path, mode)`` whose content appears at ``path`` only when the block ends normally."""
    with atomic_path(path) as tmp:
        with open(tmp, mode, **kw) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())


@contextlib.contextmanager
def staged_folder(out, replaces=()):
    """Yields a temporary folder inside the folder ``out`` to write a set of files into (a fit's
    model, summary and report); when the block ends normally the files are moved into ``out``
    together, under an exclusive lock on ``out`` (so that two commands writing into one folder at
    once leave one set whole, the last, never a mix), and the names of ``replaces`` that the set
    lacks are removed from ``out`` (a previous set's report, when this one has none). A block that
    raises (a full disk, an interruption) leaves ``out`` as it was; an OSError then names the file
    as it would be in ``out``."""
    out = Path(os.fspath(out))
    out.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=".staged-", dir=out))
    try:
        try:
            yield stage
        except OSError as e:
            if e.filename and str(e.filename).startswith(str(stage)):
                e.filename = str(out / Path(e.filename).relative_to(stage))
            raise
        names = sorted(p.name for p in stage.iterdir())
        with _locked(out):
            for name in set(replaces) - set(names):
                with contextlib.suppress(FileNotFoundError):
                    (out / name).unlink()
            for name in names:
                os.replace(stage / name, out / name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


@contextlib.contextmanager
def _locked(folder):
    """An exclusive advisory lock on the folder itself (flock on its descriptor; none where the
    platform has no flock)."""
    try:
        import fcntl
    except ImportError:      # Windows: the renames alone
        yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)         # closing the descriptor releases the lock


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


_UMASK = _umask()   # read once: os.umask sets it while reading it, which threads could see
