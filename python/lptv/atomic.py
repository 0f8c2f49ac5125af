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


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


_UMASK = _umask()   # read once: os.umask sets it while reading it, which threads could see
