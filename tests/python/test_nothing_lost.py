"""Nothing hangs, nothing is accepted silently: a file that is not a regular file, a model
description that is not a model, a study too large for the machine. Each is refused up front
with the argument (or the key) and the reason, a ValueError in Python and one line with a
non-zero exit status on the command line. Each case failed before the change that made it pass."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import lptv

LPTV = [sys.executable, "-m", "lptv"]
# A FIFO with no writer blocks the open for ever: the refusal comes at once, so a child process
# given this long has hung, not merely run slowly.
HANG = 60


def _run(args, cwd):
    return subprocess.run(args, capture_output=True, text=True, timeout=HANG, cwd=cwd)


# ------------------------------------------------------------------------------ not a regular file

@pytest.mark.parametrize("call", [
    "lptv.inspect('rec.csv', u='u', y='y')",
    "lptv.read_measurements('rec.csv', periods=2)",
    "lptv.Model.load('model.json')",
    "lptv.MimoModel.load('model.json')",
])
def test_a_fifo_is_refused_by_the_python_api_not_waited_on(tmp_path, call):
    os.mkfifo(tmp_path / "rec.csv")
    os.mkfifo(tmp_path / "model.json")
    code = f"import lptv\ntry:\n    {call}\nexcept ValueError as e:\n    print('refused:', e)\n"
    p = _run([sys.executable, "-c", code], tmp_path)
    assert p.returncode == 0, p.stderr
    assert "refused:" in p.stdout and "FIFO" in p.stdout and "not a regular file" in p.stdout, p.stdout


@pytest.mark.parametrize("args", [
    ["inspect", "rec.csv", "--input", "u", "--output", "y"],
    ["identify", "rec.csv", "--na", "1", "--nb", "0", "--period", "1"],
    ["montecarlo", "--model", "model.json", "--excited", "1-10", "--runs", "2"],
    ["validate", "model.json", "rec.csv"],
    ["simulate", "model.json", "rec.csv"],
])
def test_a_fifo_is_one_line_and_exit_2_on_the_command_line(tmp_path, args):
    os.mkfifo(tmp_path / "rec.csv")
    os.mkfifo(tmp_path / "model.json")
    p = _run([*LPTV, *args], tmp_path)
    assert p.returncode == 2, (p.returncode, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "not a regular file" in lines[0] and "Traceback" not in p.stderr, p.stderr
