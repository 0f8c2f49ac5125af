"""Monte Carlo throughput of lptv.montecarlo on each executor, and the executors' per-task overhead.

    python bench/python/bench_batch.py [R] [n_noop] [rounds]   (default 2000, 2000, 2)
    python bench/python/bench_batch.py --runs 64 256 --noop 0 --rounds 5

1. The paper example (lptv.examples: model, multisine seed 1, P = 8, 50/30 dB coloured and
   correlated noise, lines 1..243), WGTLS, R realisations, as a user runs it:
   ``lptv.montecarlo(..., executor=E)`` with E = "serial", "processes" (2 workers) twice: with
   the pool started and stopped inside the call (``lptv.batch.shutdown_pool()`` before and after
   it, inside the time: what every call did before the pool was kept) and with the pool kept
   from the previous call (what a second call does now), and a Dask LocalCluster of 2 worker
   processes with 1 thread each (started once before, as a cluster is; the client connected
   once; one warm-up study of 4 runs). Default chunking: from the cost of a realisation
   measured on the previous call (``lptv.batch.chunk_sizes``).
   A second LocalCluster has Dask's MALLOC_TRIM_THRESHOLD_=65536 (set by its nannies in the
   workers' environment, so that glibc returns freed memory to the OS) unset: with it every
   array of 128 KB or more (the 8 x 2048 noisy periods, their spectra) is mapped and unmapped
   anew, about 1300 instead of 50 page faults per fit.
   A third LocalCluster has Dask's housekeeping slowed (the worker's profiler off, the event
   loops' tick every 1 s instead of 20 ms, the system and memory monitors every 10 s): what a
   cluster that runs lptv's fits alone can be configured with (README, "Monte Carlo studies").
   All must give bit-identical estimates (asserted). The executors take turns for
   ``rounds`` rounds and each one's fastest round counts (the least disturbed by other work);
   the "paired" column is the median over the rounds of each round's serial time over the
   executor's (one quiet serial round sets every executor's best-rounds ratio; the paired
   median is what a drift of the machine's speed moves least, as farm-bench pairs its runs).
2. Per-task overhead: ``lptv.batch.run_tasks`` on n_noop empty tasks, one item per task
   (chunk_size=1), with the study's design as the shared argument (two periods of 2048 samples
   and the fit's settings, as every study task carries): wall time per task. With the default
   chunk of C fits a fit carries 1/C of it.
3. On paper: the number of workers at which the scheduler saturates for this task size with
   the default chunking (see the printed derivation).
"""
from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

import lptv
import lptv.batch.executors
from lptv.batch import chunk_sizes, run_tasks, shutdown_pool
from lptv.batch.study import realisation
from lptv.batch.warm import kept_pool
from lptv.examples import (PAPER_ID_LINES, PAPER_NOISE, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, paper_model,
                           paper_multisine)


COST_KEY = (realisation.__module__, realisation.__qualname__)


def noop(item, shared):
    return item


def load():
    return " ".join(open("/proc/loadavg").read().split()[:3])


def study(executor, R, **kw):
    model, ms = paper_model(), paper_multisine(seed=1)
    return lptv.montecarlo(model, ms, periods=8, runs=R, methods="wgtls", snr_in_db=PAPER_SNR_IN_DB,
                           snr_out_db=PAPER_SNR_OUT_DB, lines=PAPER_ID_LINES, seed=20261123,
                           executor=executor, progress=False, **PAPER_NOISE, **kw)


def parse(argv):
    import argparse

    ap = argparse.ArgumentParser(description="Monte Carlo throughput of lptv.montecarlo on each executor")
    ap.add_argument("legacy", nargs="*", type=int, help="R n_noop rounds (the old positional form)")
    ap.add_argument("--runs", nargs="+", type=int, help="study sizes R, each timed on every executor (default 2000)")
    ap.add_argument("--noop", type=int, help="empty tasks of part 2 (default 2000; 0 skips parts 2 and 3)")
    ap.add_argument("--rounds", type=int, help="rounds the executors take turns for (default 2)")
    a = ap.parse_args(argv)
    legacy = a.legacy + [None] * (3 - len(a.legacy))
    runs = a.runs or [legacy[0] or 2000]
    n_noop = a.noop if a.noop is not None else (legacy[1] if legacy[1] is not None else 2000)
    rounds = a.rounds or legacy[2] or 2
    return runs, n_noop, rounds


def timed(executor, R, per_call=False, **kw):
    """One study; with per_call the kept pool is shut down before and after it (both counted), so
    that the call starts its own pool and ends it, as every call did before the pool was kept;
    otherwise on processes a 4-run study before it (not counted) leaves the pool it finds."""
    if executor == "processes" and not per_call:
        study(executor, 4, **kw)   # the previous call (untimed): the pool is the one it left
    t0 = time.perf_counter()
    if per_call:
        shutdown_pool()
    mc = study(executor, R, **kw)
    if per_call:
        shutdown_pool()
    return mc, mc.elapsed + (time.perf_counter() - t0 - mc.elapsed if per_call else 0.0)


def main():
    sizes, n_noop, rounds = parse(sys.argv[1:])
    from distributed import Client, LocalCluster

    print(f"machine: {os.cpu_count()} cores, load average {load()} at the start")
    import dask

    # Dask's housekeeping on every worker, nanny and scheduler: the worker's profiler samples
    # every 10 ms, the event loops tick every 20 ms, the system and memory monitors (the
    # worker's and its nanny's) poll every 0.5 s and 0.1 s (distributed's defaults); all of it
    # shares the 2 cores with the fits here.
    quiet = {"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "1s",
             "distributed.admin.system-monitor.interval": "10s",
             "distributed.worker.memory.monitor-interval": "10s"}

    def start_cluster(trim=True, extra=None):
        """A LocalCluster of 2 workers x 1 thread (Dask's default worker environment, or with
        MALLOC_TRIM_THRESHOLD_ unset) and its client, warmed by a 4-run study. A nanny writes its
        pre-spawn environment into this process's os.environ, where the process pool's workers
        would find it: it is put back."""
        env = dict(os.environ)
        cfg = {} if trim else {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
        cfg.update(extra or {})
        t0 = time.perf_counter()
        with dask.config.set(cfg):
            cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                   host="127.0.0.1")
        os.environ.clear()
        os.environ.update(env)
        client = Client(cluster)
        started = time.perf_counter() - t0
        study(client, 4)
        return cluster, client, started

    trim = {}
    for label, flag in (("default", True), ("unset", False)):
        cluster, client, t_cluster = start_cluster(flag)
        trim[label] = next(iter(client.run(lambda: os.environ.get("MALLOC_TRIM_THRESHOLD_")).values()))
        client.close()
        cluster.close()
    study("processes", 4, workers=2)
    study("serial", 4)
    print(f"Dask LocalCluster (2 workers x 1 thread) started in {t_cluster:.2f} s, warmed by a 4-run study "
          "(lptv registers its warm-up plugin on the client); each Dask row starts its cluster before its "
          "turn and closes it after,\nso that no idle cluster shares the cores with the other rows")
    print(f"MALLOC_TRIM_THRESHOLD_ in the workers: {trim} (lptv raises glibc's thresholds around its "
          "chunks where it is set)")
    print("pool per call: lptv.batch.shutdown_pool() before and after the call, both inside the time "
          "(the call forks, warms and ends its own pool);\npool kept: the pool of the previous call "
          "(warm workers); chunks planned from the cost measured on the previous call")

    executors = (("serial", "serial", {}, 1), ("2 processes (pool per call)", "processes", {"workers": 2, "per_call": True}, 2),
                 ("2 processes (pool kept)", "processes", {"workers": 2}, 2),
                 ("Dask LocalCluster 2 workers", "dask", {}, 2),
                 ("  the same, malloc trim unset", "dask, trim unset", {}, 2),
                 ("  the same, housekeeping slowed", "dask, quiet", {}, 2))
    summary = []
    for R in sizes:
        # 1. throughput, side by side in one run
        print(f"\n1. paper example, WGTLS, R = {R}, P = 8: lptv.montecarlo as a user calls it "
              f"(best of {rounds} rounds; every round's wall time in seconds shown)")
        runs, walls, best = {}, {name: [] for name, *_ in executors}, {}
        for _ in range(rounds):
            for name, ex, kw, workers in executors:
                if ex.startswith("dask"):
                    cluster, client, _ = start_cluster(ex != "dask, trim unset", quiet if ex == "dask, quiet" else None)
                    mc, wall = timed(client, R, **kw)
                    client.close()
                    cluster.close()
                else:
                    if ex == "serial":
                        # the serial row without the kept pool forked from this process in the
                        # round before (its workers share this process's pages until written)
                        shutdown_pool()
                    mc, wall = timed(ex, R, **kw)
                walls[name].append(wall)
                if name not in best or wall < best[name]:
                    runs[name], best[name] = mc, wall
                print(f"   round {len(walls[name])}: {name} {wall:.3f} s (load {load()})", flush=True)
        print(f"{'executor':34s} {'wall s':>8s} {'fits/min':>9s} {'vs serial':>9s} {'paired':>7s}  "
              f"{'chunks (last call)':18s} rounds")
        for name, ex, kw, workers in executors:
            task_min = lptv.batch.executors.TASK_MIN_DASK if ex.startswith("dask") else None
            plan = ("1 item at a time" if ex == "serial" else
                    " ".join(map(str, chunk_sizes(R, workers, lptv.batch.executors._cost.get(COST_KEY), task_min))))
            ratio = best["serial"] / best[name]
            # each round's serial time over the executor's in the same round, the median over
            # the rounds: what a drift of the machine's speed between rounds moves least (one
            # quiet serial round sets the best-rounds ratio of every executor)
            paired = float(np.median(np.array(walls["serial"]) / np.array(walls[name])))
            print(f"{name:34s} {best[name]:8.3f} {60 * R / best[name]:9.0f} {ratio:8.2f}x {paired:6.2f}x  "
                  f"{plan[:18]:18s} " + " ".join(f"{w:.2f}" for w in walls[name]), flush=True)
            summary.append((R, name, ratio, paired))
        ref = runs["serial"].estimates["wgtls"]
        for name, mc in runs.items():
            assert np.array_equal(mc.estimates["wgtls"], ref, equal_nan=True), f"{name} differs from serial"
        fails = sum(not f["ok"] for f in runs["serial"].fits)
        print(f"estimates bit-identical on every executor; {fails} failed fits; "
              f"{runs['serial'].report().splitlines()[1].strip()}")
        t_fit = best["serial"] / R
    print("\nspeed-up over serial (best rounds; in brackets the median of the rounds' paired ratios):")
    for R in sizes:
        print(f"   R = {R:5d}: " + ", ".join(f"{name.strip()} {r:.2f}x ({rp:.2f}x)" for RR, name, r, rp in summary
                                           if RR == R and name != "serial"))
    if not n_noop:
        print(f"\nload average at the end: {load()}")
        return
    cluster, client, _ = start_cluster()

    # 2. per-task overhead of empty tasks carrying the study's design
    model, ms = paper_model(), paper_multisine(seed=1)
    design = dict(u0=ms.signal, y0=ms.signal.copy(), w0=model.w0, ts=None, periods=8,
                  noise=dict(PAPER_NOISE), fit=dict(na=2, nb=1, ka=3, kb=3, lines=PAPER_ID_LINES),
                  methods=("wgtls",))
    print(f"\n2. per-task overhead: {n_noop} empty tasks, one item each, the design as shared argument")
    print(f"{'executor':34s} {'us/task':>8s} {'tasks/s':>8s} {'us/fit at chunk 32':>19s} {'% of a fit':>10s}")
    over = {}
    for name, ex, kw in (("serial", "serial", {}), ("2 processes (pool per call)", "processes", {"workers": 2}),
                         ("2 processes (pool kept)", kept_pool(2), {}), ("Dask LocalCluster 2 workers", client, {})):
        t0 = time.perf_counter()
        out = run_tasks(noop, range(n_noop), design, executor=ex, chunk_size=1, progress=False, **kw)
        dt = (time.perf_counter() - t0) / n_noop
        assert out == list(range(n_noop)), f"{name}: the empty tasks returned {out[:5]}... instead of 0..{n_noop - 1}"
        over[name] = dt
        print(f"{name:34s} {1e6 * dt:8.1f} {1 / dt:8.0f} {1e6 * dt / 32:19.1f} {100 * dt / 32 / t_fit:9.2f}%",
              flush=True)

    # 3. on paper: when does the scheduler saturate?
    S_meas = 1 / over["Dask LocalCluster 2 workers"]
    print(f"\n3. on paper: t_fit = {1e3 * t_fit:.1f} ms (serial); a task of C fits lasts C t_fit; W workers "
          "ask the scheduler for W / (C t_fit) tasks per second;\n   it saturates when that reaches its "
          "rate S: W* = S C t_fit, with C = min(32, ceil(R / (4 W))) (the chunking before a cost is measured).")
    for label, S in (("S measured here (client, scheduler, 2 workers on 2 shared cores)", S_meas),
                     ("S = 1000 tasks/s (distributed docs: about 1 ms per task)", 1000.0)):
        for RR in (R, 100000):
            W = 1
            while W < 100000 and W / (min(32, math.ceil(RR / (4 * W))) * t_fit) < S:
                W += 1
            C = min(32, math.ceil(RR / (4 * W)))
            print(f"   {label}, R = {RR}: W* = {W} workers (chunk {C}, {C * t_fit:.2f} s per task)")
    client.close()
    cluster.close()
    print(f"\nload average at the end: {load()}")


if __name__ == "__main__":
    main()
