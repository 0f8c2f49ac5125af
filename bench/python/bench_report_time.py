"""How long ``lptv identify`` takes on one record, report included, as whole processes: the command,
the command with ``--no-report``, and ``python -c "import lptv"`` (the floor every command pays), in
turn, each run a new process; wall and CPU (user + sys, the children's rusage) per run, medians and
the ratios to the import.

The record is made outside lptv (tests/python/outside_records.py): a mass-spring-damper
m x'' + c x' + k(t) x = F, m = 1, c = 0.8, k(t) = 40 (1 + 0.3 cos(2 pi t / 5)), integrated by
scipy's solve_ivp under a multisine on the 30 adjacent lines 1..30, 8 periods of 5 s at 200 Hz after
4 periods of start-up, 1 % noise on both channels, written as a CSV of 8000 rows
(``time [s],force [N],displacement [m]``). The two commands must give the same model.json, and
only the first a report.

    python bench/python/bench_report_time.py --runs 9
"""
from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "python"))
import outside_records as rec  # noqa: E402

ARGS = ["--input", "force", "--output", "displacement", "--period", "5", "--na", "2", "--nb", "0",
        "--ka", "1,0,0", "--kb", "0"]


def timed(argv, env):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run(argv, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} exited {r.returncode}: {r.stderr[-400:]}")
    return wall, cpu


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=9, help="runs of each command (default 9)")
    args = ap.parse_args(argv)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t, f, x = rec.mass_spring_damper(5.0, 200.0, 8, lines=np.arange(1, 31), start=20.0, mass=1.0, damping=0.8,
                                         stiffness=40.0, variation=0.3)
        src = rec.write_csv(tmp / "rig.csv", t - t[0], f, x)
        py = [sys.executable]
        cmds = {"identify": py + ["-m", "lptv", "identify", str(src), *ARGS, "--out", str(tmp / "a")],
                "identify --no-report": py + ["-m", "lptv", "identify", str(src), *ARGS, "--no-report",
                                              "--out", str(tmp / "b")],
                "import lptv": py + ["-c", "import lptv"]}
        for argv_ in cmds.values():                 # warm-up: file caches, compiled bytecode
            timed(argv_, env)
        runs = {name: [] for name in cmds}
        for _ in range(args.runs):
            for name, argv_ in cmds.items():
                runs[name].append(timed(argv_, env))
        if (tmp / "a" / "model.json").read_text() != (tmp / "b" / "model.json").read_text():
            raise SystemExit("the command with and without --no-report wrote different models")
        if not (tmp / "a" / "report.html").exists() or (tmp / "b" / "report.html").exists():
            raise SystemExit("report.html: expected from the command, not with --no-report")
    base = runs["import lptv"]
    print(f"{args.runs} runs each, in turn; medians (min-max) in s; ratios to 'import lptv' run by run")
    for name, r in runs.items():
        wall, cpu = np.array(r).T
        rw = np.array(wall) / np.array([b[0] for b in base])
        rc = np.array(cpu) / np.array([b[1] for b in base])
        print(f"  {name:22s} wall {statistics.median(wall):.3f} ({wall.min():.3f}-{wall.max():.3f})  "
              f"cpu {statistics.median(cpu):.3f} ({cpu.min():.3f}-{cpu.max():.3f})"
              + ("" if name == "import lptv" else
                 f"  x import: wall {statistics.median(rw):.2f}, cpu {statistics.median(rc):.2f}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
