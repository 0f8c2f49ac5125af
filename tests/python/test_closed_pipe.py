"""A command whose reader stops early (``lptv inspect rig.csv | head``) finishes its work quietly.

The reader is gone before the command writes anything (the pipe's read end is closed before the
child starts), so every write meets a closed pipe, as the last ones do behind ``head``. The
command must print no traceback, write its files and exit with its own status, as it would with
nobody reading. The record: the README's quick start, a first-order response to an odd multisine
made by scipy.signal.lfilter.
"""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import lfilter


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    fs, N = 50.0, 200
    k = np.arange(37, 6 * N)
    u = sum(np.cos(2 * np.pi * l * k / N + l * l) for l in range(1, 40, 2))
    y = lfilter([0.05], [1, -0.99], u)
    rng = np.random.default_rng(1)
    u, y = u + 0.02 * rng.standard_normal(k.size), y + 0.02 * rng.standard_normal(k.size)
    path = tmp_path_factory.mktemp("pipe") / "rig.csv"
    np.savetxt(path, np.c_[k / fs, u, y], delimiter=",", comments="",
               header="time [s],force [N],displacement [m]")
    return path


def run_into_closed_pipe(*argv, cwd, stderr_too=False):
    """``python -m lptv ARGV`` with stdout (and stderr) a pipe whose reader has left."""
    r, w = os.pipe()
    os.close(r)
    try:
        proc = subprocess.run([sys.executable, "-m", "lptv", *map(str, argv)], cwd=cwd, stdout=w,
                              stderr=w if stderr_too else subprocess.PIPE, timeout=600)
    finally:
        os.close(w)
    return proc.returncode, (proc.stderr or b"").decode()


NAMES = ["--input", "force", "--output", "displacement"]


def test_inspect_into_a_closed_pipe_writes_its_report_and_exits_0(rig, tmp_path):
    rc, err = run_into_closed_pipe("inspect", rig, *NAMES, "--out", tmp_path / "i", cwd=tmp_path)
    assert "Traceback" not in err and "BrokenPipeError" not in err, err
    assert rc == 0, err
    assert (tmp_path / "i" / "report.html").stat().st_size > 0 and (tmp_path / "i" / "summary.json").exists()


def test_identify_into_a_closed_pipe_keeps_its_status_and_files(rig, tmp_path):
    """nb = 0 is the wrong order (exit 3), nb = 1 the right one (exit 0): the status is the fit's."""
    base = ["identify", rig, *NAMES, "--period", 4, "--trim", "--skip-periods", 3, "--lines", "excited",
            "--discrete", "--na", 1, "--no-report"]
    for nb, status in ((1, 0), (0, 3)):
        out = tmp_path / f"nb{nb}"
        rc, err = run_into_closed_pipe(*base, "--nb", nb, "--out", out, cwd=tmp_path)
        assert "Traceback" not in err and "BrokenPipeError" not in err, err
        assert rc == status, err
        assert (out / "model.json").exists() and (out / "summary.json").exists()


def test_help_and_errors_into_a_closed_pipe(rig, tmp_path):
    """--help (argparse prints it and exits) and an error on stderr, both into the closed pipe."""
    for cmd in (["--help"], ["inspect", "--help"], ["select", "--help"]):
        rc, err = run_into_closed_pipe(*cmd, cwd=tmp_path, stderr_too=True)
        assert rc == 0, cmd
    rc, _ = run_into_closed_pipe("inspect", tmp_path / "missing.csv", cwd=tmp_path, stderr_too=True)
    assert rc == 2
    assert not Path(tmp_path / "missing-inspect").exists()
