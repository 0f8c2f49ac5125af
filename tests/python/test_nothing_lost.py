"""Nothing hangs, nothing is accepted silently: a file that is not a regular file, a model
description that is not a model, a study too large for the machine. Each is refused up front
with the argument (or the key) and the reason, a ValueError in Python and one line with a
non-zero exit status on the command line. Each case failed before the change that made it pass."""
import json
import re
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


# ------------------------------------------------------------------------------ model descriptions

def _description():
    m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=1.0)
    d = m.to_dict()
    d["eta_names"], d["covariance"] = ["a0.re0", "b0.re0"], [[1.0, 0.1], [0.1, 2.0]]
    return d


@pytest.mark.parametrize("key, value, message", [
    ("a_real", [[True], [1.0]], r"a_real\[0\]\[0\] holds true, not a number"),
    ("b_real", [[False]], r"b_real\[0\]\[0\] holds false"),
    ("covariance", [[-1.0, 0.1], [0.1, 2.0]], r"covariance has the negative variance -1 .*a0.re0"),
    ("covariance", [[1.0, 0.1], [0.2, 2.0]], r"covariance is not symmetric"),
    ("covariance", [[1.0, True], [0.1, 2.0]], r"covariance\[0\]\[1\] holds true"),
])
def test_a_description_that_is_not_a_model_is_refused_with_its_key(key, value, message):
    d = _description()
    lptv.Model.from_dict(d)                      # the description itself reads
    d[key] = value
    with pytest.raises(ValueError, match=message):
        lptv.Model.from_dict(d)


def test_a_leading_coefficient_that_vanishes_within_the_period_is_refused(tmp_path):
    m = lptv.Model([[0, 1.0, 0], [0.5, 0, 0.5]], [[0, 1.0, 0]], w0=1.0)      # a_1(t) = cos t
    m.save(tmp_path / "m.json")
    with pytest.raises(ValueError, match=r"a_1\(t\) vanishes near t = 1.5708 s"):
        lptv.Model.load(tmp_path / "m.json")


def test_the_stability_of_a_large_lti_model_of_several_channels_is_one_eigenproblem():
    from lptv.model.floquet import stability_check

    n, rng = 60, np.random.default_rng(0)
    a = np.zeros((4, n, n, 1))
    for k, c in enumerate([6.0, 11.0, 6.0, 1.0]):          # (s + 1)(s + 2)(s + 3) on each channel
        a[k] = c * np.eye(n)[..., None]
    b = rng.standard_normal((1, n, n, 1))
    assert stability_check(lptv.MimoModel(a, b, w0=1.0)) == (None, None)
    a[0] -= 12.0 * np.eye(n)[..., None]                     # a0 = -6: a root in the right half plane
    unstable, undecided = stability_check(lptv.MimoModel(a, b, w0=1.0))
    assert undecided is None and "root of det A(s)" in unstable


# ------------------------------------------------------------------------------ a study's sizes

@pytest.mark.parametrize("args, message", [
    (["--runs", "2147483647", "--workers", "1"],
     r"^lptv montecarlo: error: --runs: a study of 2147483647 runs x 1 method needs about \S+ TB to hold "
     r"their seeds and results, more than lptv's memory budget of "),
    (["--periods", "1000000", "--workers", "2"],
     r"^lptv montecarlo: error: --periods: a realisation of 1000000 periods of 2048 samples needs about 81.9 GB "
     r".* x 2 at once \(workers\), more than lptv's memory budget of "),
])
def test_a_study_too_large_for_the_memory_is_refused_up_front(tmp_path, args, message):
    """Before: 2^31 runs listed their seeds for minutes, a million periods failed every fit with a
    MemoryError (exit 1). Refused at once, with what it would need against the budget."""
    env = dict(os.environ, LPTV_MEMORY_BUDGET="8G")
    p = subprocess.run([*LPTV, "montecarlo", *args, "--out", "mc"], capture_output=True, text=True,
                       timeout=HANG, cwd=tmp_path, env=env)
    assert p.returncode == 2, (p.returncode, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and re.search(message, lines[0]) and "8.59 GB" in lines[0], p.stderr
    assert not (tmp_path / "mc" / "parts").exists() or not any((tmp_path / "mc" / "parts").iterdir())


def test_the_library_refuses_the_same_study_as_a_value_error():
    m, ms = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1), lptv.multisine(range(1, 11), 256, seed=0)
    with pytest.raises(ValueError, match=r"^runs: a study of 2147483647 runs x 2 methods needs about .* memory budget"):
        lptv.montecarlo(m, ms, periods=4, runs=2**31 - 1, snr_in_db=40, snr_out_db=30, methods="tls,wgtls",
                        executor="serial")
    with pytest.raises(ValueError, match=r"^periods: a realisation of 100000000 periods of 256 samples needs "
                                         r"about 1.02 TB"):
        lptv.montecarlo(m, ms, periods=10**8, runs=2, snr_in_db=40, snr_out_db=30, executor="serial")
