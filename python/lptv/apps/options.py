"""What the commands share about their options.

Every bad option value ends in one line on stderr and exit status 2, never a usage block or a
traceback: argparse's own errors go through :class:`Parser`; a message of the library that names
a Python argument (``max_iter must be ...``) is put in the option's terms (``--max-iter must be
...``) by :func:`in_option_terms`; ranges of lines or grid values are bounded before they are
expanded; an output folder given with ``--out`` is checked before any work, so that a folder
that cannot be written is reported at once.
"""
from __future__ import annotations

import argparse
import contextlib
import errno
import os
import re
import signal
import tempfile
import threading
from pathlib import Path

from lptv.measurements import FileError

INT_MAX = 2**31 - 1
"""The largest integer the core takes (a C int)."""
MAX_EXPANDED = 2**26
"""The most values a range option (``--lines 1-N``) may expand to: the largest grid of the core."""


MODEL_REJECTED = 3
"""The exit status of ``lptv identify FILE`` when the verdict finds model errors (MODEL ERRORS);
0 when it calls the model consistent with the data, :data:`NOT_DETERMINED` when the data cannot
decide, 2 for a file or options that cannot be used, 1 for a computation that failed."""
NOT_DETERMINED = 4
"""The exit status when the verdict cannot call the model consistent though it finds no error
(NOT DETERMINED: too little signal for the structure, or too few realisations to judge)."""


def verdict_status(res) -> int:
    """0 for a model the verdict calls consistent with the data, :data:`MODEL_REJECTED` when it
    finds model errors, :data:`NOT_DETERMINED` when the data do not determine the model."""
    if not res.model_ok:
        return MODEL_REJECTED
    return 0 if res.undetermined is None else NOT_DETERMINED


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``prog: error: message`` on stderr, exit status 2 (the usage
    block stays in ``--help``)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {' '.join(str(message).split())}\n")


def integer(value, opt, minimum=0, maximum=INT_MAX):
    """An integer option's value within [minimum, maximum], or a FileError naming the option."""
    if value is None:
        return None
    if value < minimum:
        raise FileError(f"{opt} must be >= {minimum}, got {value}")
    if value > maximum:
        raise FileError(f"{opt} must be at most {maximum}, got {value}")
    return value


def bounded_range(lo: int, hi: int, opt: str, token: str, limit: int = MAX_EXPANDED):
    """range(lo, hi + 1) after checking that hi fits the core's int and that the range is not
    larger than ``limit`` values (a typo like 1-99999999999 would otherwise fill the memory)."""
    if hi > INT_MAX:
        raise FileError(f"{opt}: '{token}' goes beyond {INT_MAX}, the largest value the core takes")
    if hi - lo + 1 > limit:
        raise FileError(f"{opt}: '{token}' holds {hi - lo + 1} values; at most {limit} are accepted")
    return range(lo, hi + 1)


def output_folder(path):
    """Check, before any work, that the folder given with ``--out`` can be made and written, without
    leaving anything behind: OSError (its filename the folder) when a file stands there, or the
    nearest existing folder above it refuses a new entry."""
    if path is None:
        return None
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise FileExistsError(errno.EEXIST, "File exists", str(path))
    parent = p
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, "Not a directory", str(path))
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".lptv-probe-", dir=parent))
    except OSError as e:
        raise OSError(e.errno, e.strerror, str(path)) from None
    return path


def in_option_terms(message: str, names: dict) -> str:
    """A library message that starts with a Python argument's name (``max_iter must be``,
    ``lines: row 0 ...``), restated with the option (``--max-iter must be``)."""
    for name, opt in names.items():
        new = re.sub(rf"^{re.escape(name)}(?=[\s:])", opt, message)
        if new != message:
            return new
    return message


class Interrupted(KeyboardInterrupt):
    """SIGINT (Ctrl-C) or SIGTERM during a long command; ``status`` is the exit status a shell
    gives a process killed by that signal (128 + its number: 130, 143)."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum
        self.status = 128 + signum


@contextlib.contextmanager
def interruptible():
    """Turns the first SIGINT or SIGTERM in the block into :class:`Interrupted` (the command then
    stops cleanly: what is finished stays on disk) and ignores the next ones (a second Ctrl-C, or
    the same signal sent to the process group), so that the command's last line and exit status
    are its own. The previous handlers are restored after a block that was not interrupted; an
    interrupted command is ending, and keeps ignoring them until it exits."""
    signals = (signal.SIGINT, signal.SIGTERM)
    interrupted = []

    def handler(signum, frame):
        for s in signals:
            signal.signal(s, signal.SIG_IGN)
        interrupted.append(signum)
        raise Interrupted(signum)

    if threading.current_thread() is not threading.main_thread():
        yield   # signals reach the main thread only
        return
    old = {s: signal.signal(s, handler) for s in signals}
    try:
        yield
    finally:
        if not interrupted:
            for s, h in old.items():
                signal.signal(s, h)
