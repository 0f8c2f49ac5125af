"""Runs the cases of bad_input_cases.py and sorts what each one gives into OUTCOMES:

    clear error          the expected exception type, and the message names the argument
    warning              a warning with a meaningful result, as expected
    correct result       a valid edge case gave the right answer
    unclear error        an exception of another type, or a message that does not name the argument
    silent wrong result  no exception where one was due, or a wrong answer
    crash                the interpreter died (or the case hung past its time limit); on the
                         command line also a traceback

Python cases run in a child interpreter (``python bad_input_runner.py IDS...``), many per
process; when one kills the process it is reported as a crash and the others are re-run in a
fresh one. Command-line cases each run in their own process: ``python -m lptv ...`` from
scratch, or (``fork=True``, what the tests use) forked from a process that has imported lptv,
which saves the imports that are most of a command's time on a bad value.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

from bad_input_cases import Case, _lptv, cli_cases, cli_files, folder, python_cases

OUTCOMES = ("clear error", "warning", "correct result", "unclear error", "silent wrong result", "crash")


def classify(case: Case):
    """(outcome, detail) of one Python case, run in this process."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = case.call()
        except Exception as e:  # noqa: BLE001 - what the call raises is what is measured
            msg = f"{type(e).__name__}: {e}"
            if case.check is None and isinstance(e, case.exc) and re.search(case.match, str(e)):
                return "clear error", msg
            return "unclear error", msg
    if case.check is None:
        what = "; ".join(str(w.message) for w in caught)
        return "silent wrong result", f"returned {_short(result)}" + (f" (warned: {what})" if what else "")
    try:
        right = bool(case.check(result))
    except Exception as e:  # noqa: BLE001
        return "silent wrong result", f"the check failed: {type(e).__name__}: {e}"
    if not right:
        return "silent wrong result", f"returned {_short(result)}"
    if case.warning is not None:
        category = getattr(_lptv(), case.warning)
        if any(issubclass(w.category, category) for w in caught):
            return "warning", "; ".join(str(w.message) for w in caught)
        return "silent wrong result", f"no {case.warning}"
    return "correct result", ""


def _short(x):
    s = " ".join(repr(x).split())
    return s if len(s) < 120 else s[:117] + "..."


def _limit_memory():
    """A runaway allocation is a MemoryError in the case's process, not the machine's memory."""
    import resource

    if "asan" in os.environ.get("LD_PRELOAD", ""):
        # AddressSanitizer maps terabytes of shadow address space at start-up: under an address
        # space limit it aborts before the case runs. Its own allocator reports a runaway size.
        return
    gb = 4 * 2**30
    resource.setrlimit(resource.RLIMIT_AS, (gb, gb))


def _child(ids):
    """Run the named cases here, one JSON line each, flushed before the next starts."""
    import faulthandler
    import signal

    faulthandler.enable()
    _limit_memory()

    def timeout(signum, frame):
        raise TimeoutError("the case ran past its time limit")

    signal.signal(signal.SIGALRM, timeout)
    table = {c.id: c for c in python_cases()}
    table[SELFTEST_CRASH] = Case(SELFTEST_CRASH, "self-test", os.abort)
    table[SELFTEST_SILENT] = Case(SELFTEST_SILENT, "self-test", lambda: 1.0, match="x")
    for i in ids:
        signal.alarm(60)
        try:
            outcome, detail = classify(table[i])
        except TimeoutError as e:
            outcome, detail = "crash", str(e)
        signal.alarm(0)
        print(json.dumps({"id": i, "outcome": outcome, "detail": detail}), flush=True)
    if folder.cache_info().currsize:
        shutil.rmtree(folder(), ignore_errors=True)


SELFTEST_CRASH = "_selftest-crash"
"""A case that aborts its process: the runner must report it as a crash and go on."""
SELFTEST_SILENT = "_selftest-silent"
"""A case that returns where an error was due: the runner must call it a silent wrong result."""


def _env():
    import bad_input_cases

    env = dict(os.environ, PYTHONPATH=bad_input_cases.PYTHONPATH + os.pathsep + str(Path(__file__).parent),
               MPLBACKEND="Agg", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    return env


def run_python_cases(ids):
    """{id: (outcome, detail)} for the named Python cases, in child processes; a case that kills
    its process is a crash and the rest run in a fresh one."""
    todo, out = list(ids), {}
    while todo:
        p = subprocess.run([sys.executable, __file__, *todo], capture_output=True, text=True,
                           env=_env(), timeout=1200)
        for line in p.stdout.splitlines():
            try:
                r = json.loads(line)
            except json.JSONDecodeError:
                continue
            out[r["id"]] = (r["outcome"], r["detail"])
        left = [i for i in todo if i not in out]
        if left and p.returncode == 0:
            raise RuntimeError(f"the case runner stopped early: {p.stderr[-2000:]}")
        if left:
            out[left[0]] = ("crash", f"exit status {p.returncode}: {p.stderr.strip()[-300:]}")
            left = left[1:]
        todo = left
    return out


def run_cli_case(case: Case, d: Path):
    """(outcome, detail) of one command-line case run as ``python -m lptv ...``: status 2, one
    line on stderr, no traceback, and the line names the option (or the file)."""
    argv = [a.replace("{dir}", str(d)) for a in case.argv]
    try:
        p = subprocess.run([sys.executable, "-m", "lptv", *argv], capture_output=True, text=True,
                           env=_env(), cwd=d, timeout=60, preexec_fn=_limit_memory)
    except subprocess.TimeoutExpired:
        return _judge(case, "timeout", "")
    return _judge(case, p.returncode, p.stderr)


def _cli_server(d):
    """Read one JSON argv per line; run each ``lptv`` command in a forked process (imports done
    once, here), as ``python -m lptv`` would run it; answer with its status and stderr."""
    import traceback

    from lptv.apps import choose, cli, fileid, montecarlo  # noqa: F401 - imported before forking
    # and what the commands import on first use (SciPy's submodules: 0.3-0.7 s in every child)
    import scipy.fft, scipy.linalg, scipy.ndimage, scipy.signal, scipy.stats  # noqa: F401, E401

    os.chdir(d)
    for line in sys.stdin:
        argv = json.loads(line)
        err = tempfile.TemporaryFile()
        pid = os.fork()
        if pid == 0:
            _limit_memory()
            os.dup2(err.fileno(), 2)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1)
            code = 1
            try:
                code = cli.main(argv)
            except SystemExit as e:
                code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
                if isinstance(e.code, str):
                    print(e.code, file=sys.stderr)
            except BaseException:  # noqa: BLE001 - as the interpreter would: a traceback, status 1
                traceback.print_exc()
            finally:
                sys.stdout.flush()
                sys.stderr.flush()
                os._exit(code or 0)
        status = _wait(pid, 60)
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
        err.close()
        print(json.dumps({"status": status, "stderr": text}), flush=True)


def _wait(pid, limit):
    import signal
    import time

    t0 = time.monotonic()
    while True:
        done, st = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(st)
        if time.monotonic() - t0 > limit:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return "timeout"
        time.sleep(0.01)


def _judge(case, status, stderr):
    err = [ln for ln in stderr.splitlines() if ln.strip()]
    detail = f"status {status}: " + " | ".join(err)[-400:]
    if status == "timeout":
        return "crash", "ran past 60 s (the bad value was not refused up front)"
    if status < 0 or ("Traceback" in stderr and status not in (0, 2)):
        return "crash", detail
    if status == 0:
        return "silent wrong result", detail
    if status == 2 and len(err) == 1 and "Traceback" not in stderr and re.search(case.match, err[0]):
        return "clear error", detail
    return "unclear error", detail


def run_cli_cases(cases, workers=2, fork=True):
    """{id: (outcome, detail)} of the command-line cases. Each runs in its own process: with
    ``fork`` a process forked from one that has imported lptv (fast: the imports are most of a
    command's time on a bad value), else ``python -m lptv ...`` from scratch."""
    from concurrent.futures import ThreadPoolExecutor

    d = Path(tempfile.mkdtemp(prefix="lptv-bad-cli-"))
    try:
        cli_files(d)
        return _run_cli_cases(cases, workers, fork, d)
    finally:
        shutil.rmtree(d, ignore_errors=True)


def _run_cli_cases(cases, workers, fork, d):
    from concurrent.futures import ThreadPoolExecutor

    if not fork:
        with ThreadPoolExecutor(workers) as ex:
            results = list(ex.map(lambda c: run_cli_case(c, d), cases))
        return {c.id: r for c, r in zip(cases, results)}

    def serve(part):
        p = subprocess.Popen([sys.executable, __file__, "--cli-server", str(d)], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True, env=_env())
        out = {}
        for c in part:
            argv = [a.replace("{dir}", str(d)) for a in c.argv]
            p.stdin.write(json.dumps(argv) + "\n")
            p.stdin.flush()
            r = json.loads(p.stdout.readline())
            out[c.id] = _judge(c, r["status"], r["stderr"])
        p.stdin.close()
        p.wait(timeout=60)
        return out

    parts = [cases[i::workers] for i in range(workers)]
    with ThreadPoolExecutor(workers) as ex:
        results = list(ex.map(serve, parts))
    return {k: v for r in results for k, v in r.items()}


def run_all(workers=2, fork=True):
    """{id: (outcome, detail)} of every case (Python cases in two child processes, side by side)."""
    from concurrent.futures import ThreadPoolExecutor

    py = [c.id for c in python_cases()]
    half = (len(py) + 1) // 2
    with ThreadPoolExecutor(workers + 2) as ex:
        a = ex.submit(run_python_cases, py[:half])
        b = ex.submit(run_python_cases, py[half:])
        cli = run_cli_cases(cli_cases(), workers, fork=fork)
        out = {**a.result(), **b.result()}
    out.update(cli)
    return out


if __name__ == "__main__":
    if sys.argv[1:2] == ["--cli-server"]:
        _cli_server(sys.argv[2])
    else:
        _child(sys.argv[1:])
