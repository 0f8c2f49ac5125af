"""make bench-smoke: every benchmark, C++ and Python, run once at small sizes; each must exit 0.

    python bench/smoke.py BIN_DIR [--out DIR] [--only NAME ...] [--timeout SECONDS] [--jobs N]

BIN_DIR holds the built benchmark executables (bench/cpp/bench_*.cpp, one each); the Python
benchmarks (bench/python/*.py) run with this interpreter, from the repository root. Each one
runs with the arguments of SMOKE below: sizes and rounds small enough for seconds, not for
figures (the figures are `make bench`'s and bench/RESULTS.md's). A benchmark that exits with a
status other than 0, or runs past the time limit, is a failure, reported in one line with the
last line it wrote to stderr; every output is kept in --out. A benchmark source without an
entry in SMOKE (or an entry without its source) is a failure too, so that a new benchmark is
smoked from the day it is added. --jobs N runs N benchmarks at a time (their times are not
figures either way).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import threading
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# name -> arguments. C++: the executable of bench/cpp/<name>.cpp; Python: bench/python/<name>.
SMOKE = {
    # C++ (bench/cpp)
    "bench_fds_cvode": ["1", "1"],                      # seed 1, one timing round
    "bench_fds_scaling": ["10000"],                     # 10^3 and 10^4 lines
    "bench_fds_floor": ["1001", "10001"],
    "bench_fds_many_inputs": ["2001"],                  # grids of 201 and 2001 lines
    "bench_wgtls": ["1000"],                            # 10^3 rows
    "bench_estimate_floor": ["1"],                      # one seed
    # Python (bench/python)
    "bad_inputs.py": ["--limit", "4"],
    "bench_batch.py": ["--runs", "8", "--noop", "20", "--rounds", "1"],
    "bench_bla.py": ["--runs", "2", "--workers", "1"],
    "bench_bla_verdict.py": ["--runs", "2", "--workers", "1", "--cases", "paper/wiener/true"],
    "bench_checks.py": ["--rounds", "1", "--calls", "20"],
    "bench_coverage.py": ["--runs", "3", "--periods", "4", "--systems", "paper", "--workers", "1"],
    "bench_crest.py": ["timing", "10", "1"],
    "bench_dask_latency.py": ["--rounds", "1"],
    "bench_distortion.py": ["--runs", "2", "--systems", "paper", "--periods", "4"],
    "bench_distortion_core.py": ["1"],
    "bench_disturbances.py": ["--runs", "2", "--amplitudes", "3", "--workers", "1"],
    "bench_fit_times.py": ["--rounds", "1", "--calls", "2"],
    "bench_floquet.py": ["--rounds", "1", "--inner", "1"],
    "bench_floquet_cost.py": ["--rounds", "1", "--bootstrap", "10"],
    "bench_floquet_coverage.py": ["--runs", "2", "--periods", "4", "--workers", "1", "--systems", "ct-real", "dt"],
    "bench_floquet_mimo_coverage.py": ["--runs", "1", "--periods", "8", "--workers", "1"],
    "bench_htf_overlap.py": ["1"],
    "bench_identifiability.py": ["2"],
    "bench_inspect.py": ["--runs", "12"],
    "bench_mimo.py": ["--runs", "3", "--systems", "2-in-1-out"],
    "bench_mimo_cost.py": ["--rounds", "1", "--n", "64"],
    "bench_ml_lti.py": ["--rounds", "1", "--inner", "1", "--fditools", ""],
    "bench_moderation_core.py": ["1"],
    "bench_noise_route.py": ["--runs", "2", "--periods", "4", "--workers", "1"],
    "bench_process_noise.py": ["--runs", "2", "--periods", "4", "--loop", "feedback"],
    "bench_process_noise_mimo.py": ["--runs", "2", "--periods", "4", "--loop", "feedback"],
    "bench_noise_cost.py": ["--rounds", "1"],
    "bench_multi_experiment.py": ["3"],
    "bench_record.py": ["--runs", "3", "--periods", "4"],
    "bench_record_core.py": ["1", "4"],
    "bench_record_verdict.py": ["3", "2"],
    "bench_record_input_noise.py": ["3", "--levels", "4"],
    "bench_report_time.py": ["--runs", "1"],
    "bench_select.py": ["1", "--small"],
    "bench_select_time.py": ["1"],
    "bench_simulate.py": ["300", "30"],                # L = 30 and 300
    "bench_simulate_ratio.py": ["1", "1000"],
    "bench_sml.py": ["--rounds", "1", "--inner", "1"],
    "bench_uncertainty.py": ["3", "4"],
    "bench_verdict.py": ["--runs", "2", "--periods", "4", "--systems", "paper", "--workers", "1"],
    "bench_verdict_tests.py": ["--runs", "3", "--periods", "4", "--workers", "1"],
    "bench_verdict_cells.py": ["--seeds", "0", "3", "--periods", "4"],
    "bench_wgtls.py": ["1", "1"],                        # seed 1, one round
    "ct_record_aliasing.py": ["--os", "4", "--seeds", "1"],
    "periodic_records.py": [],                          # the records against their stated truth
}

# The slowest of SMOKE (Dask clusters started and stopped), started first.
LONGEST = ("bench_batch.py", "bench_dask_latency.py", "bench_select.py", "bench_wgtls.py", "bench_verdict.py")


def sources():
    cpp = sorted(p.stem for p in (ROOT / "bench" / "cpp").glob("bench_*.cpp"))
    py = sorted(p.name for p in (ROOT / "bench" / "python").glob("*.py"))
    return cpp, py


def last_line(stderr, stdout):
    """The last line on stderr (a benchmark's one-line cause), else the last on stdout."""
    for text, where in ((stderr, "stderr"), (stdout, "stdout")):
        lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
        if lines:
            return lines[-1][:300] if where == "stderr" else f"(stdout) {lines[-1][:300]}"
    return "(no output)"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bin_dir", type=Path, help="the built benchmark executables")
    ap.add_argument("--out", type=Path, default=None, help="where each output is kept (default BIN_DIR/../smoke)")
    ap.add_argument("--only", nargs="+", default=None, help="these benchmarks only")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per benchmark (default 300)")
    ap.add_argument("--jobs", type=int, default=1, help="benchmarks run at a time (default 1)")
    args = ap.parse_args(argv)
    out = args.out or args.bin_dir.parent / "smoke"
    out.mkdir(parents=True, exist_ok=True)

    cpp, py = sources()
    problems = [f"{n}: a benchmark without arguments in bench/smoke.py's SMOKE" for n in cpp + py if n not in SMOKE]
    problems += [f"{n}: in SMOKE, but no bench/cpp/{n}.cpp or bench/python/{n}" for n in SMOKE if n not in cpp + py]
    names = [n for n in cpp + py if n in SMOKE]
    if args.only:
        unknown = [n for n in args.only if n not in SMOKE]
        if unknown:
            ap.error(f"not benchmarks: {', '.join(unknown)}")
        names = [n for n in names if n in args.only]

    env = dict(os.environ, MPLBACKEND="Agg")
    t_all = time.perf_counter()
    failed = []
    lock = threading.Lock()

    def report(line, failure=None):
        with lock:
            if failure:
                failed.append(failure)
            print(line, flush=True)

    def smoke(name):
        if name in cpp:
            exe = args.bin_dir / name
            if not exe.is_file():
                why = f"{name}: not built ({exe} missing)"
                return report(f"FAILED  {why}", why)
            argv_ = [str(exe), *SMOKE[name]]
            shown = " ".join([name, *SMOKE[name]])
        else:
            argv_ = [sys.executable, str(ROOT / "bench" / "python" / name), *SMOKE[name]]
            shown = " ".join([f"bench/python/{name}", *SMOKE[name]])
        t0 = time.perf_counter()
        try:
            r = subprocess.run(argv_, cwd=ROOT, env=env, capture_output=True, text=True, timeout=args.timeout)
            status, stdout, stderr = r.returncode, r.stdout, r.stderr
        except subprocess.TimeoutExpired as e:
            status = None
            stdout = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
            stderr = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
        dt = time.perf_counter() - t0
        (out / f"{name}.txt").write_text(f"$ {shown}\n{stdout}\n--- stderr ---\n{stderr}")
        if status == 0:
            return report(f"ok      {dt:6.1f} s  {shown}")
        why = f"stopped after {args.timeout:g} s" if status is None else f"exit status {status}"
        failure = f"{name}: {why}: {last_line(stderr, stdout)} ({shown}; output in {out / (name + '.txt')})"
        report(f"FAILED  {dt:6.1f} s  {failure}", failure)

    # the longest first, so that N at a time end together
    names.sort(key=lambda n: n not in LONGEST)
    with ThreadPoolExecutor(max(1, args.jobs)) as pool:
        list(pool.map(smoke, names))

    elapsed = time.perf_counter() - t_all
    for p in problems:
        print(f"FAILED  {p}")
    bad = len(failed) + len(problems)
    print(f"bench-smoke: {len(names) - len(failed)} of {len(names)} benchmarks exited 0 in {elapsed:.0f} s"
          + (f"; {bad} failure(s) above" if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
