"""Monte Carlo throughput of lptv.montecarlo on each executor, and the executors' per-task overhead.

    python bench/python/bench_batch.py [R] [n_noop] [rounds]   (default 2000, 2000, 2)

1. The paper example (lptv.examples: model, multisine seed 1, P = 8, 50/30 dB coloured and
   correlated noise, lines 1..243), WGTLS, R realisations, as a user runs it:
   ``lptv.montecarlo(..., executor=E)`` with E = "serial", "processes" (2 workers, the pool
   started and stopped inside the call, as the default does) and a Dask LocalCluster of 2 worker
   processes with 1 thread each (started once before, as a cluster is; the client connected
   once; one warm-up study of 4 runs so that the workers have imported lptv). Default chunking.
   A second LocalCluster has Dask's MALLOC_TRIM_THRESHOLD_=65536 (set by its nannies in the
   workers' environment, so that glibc returns freed memory to the OS) unset: with it every
   array of 128 KB or more (the 8 x 2048 noisy periods, their spectra) is mapped and unmapped
   anew, about 1300 instead of 50 page faults per fit.
   The three must give bit-identical estimates (asserted). The executors take turns for
   ``rounds`` rounds and each one's fastest round counts (the least disturbed by other work).
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
from lptv.batch import default_chunk_size, run_tasks
from lptv.examples import (PAPER_ID_LINES, PAPER_NOISE, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, paper_model,
                           paper_multisine)


def noop(item, shared):
    return item


def load():
    return " ".join(open("/proc/loadavg").read().split()[:3])


def study(executor, R, **kw):
    model, ms = paper_model(), paper_multisine(seed=1)
    return lptv.montecarlo(model, ms, periods=8, runs=R, methods="wgtls", snr_in_db=PAPER_SNR_IN_DB,
                           snr_out_db=PAPER_SNR_OUT_DB, lines=PAPER_ID_LINES, seed=20261123,
                           executor=executor, progress=False, **PAPER_NOISE, **kw)


def main():
    R = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    n_noop = int(sys.argv[2]) if len(sys.argv) > 2 else 2000
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    from distributed import Client, LocalCluster

    print(f"machine: {os.cpu_count()} cores, load average {load()} at the start")
    import dask

    # First: a nanny also writes its pre-spawn environment into this process's os.environ, which
    # the workers of a later cluster would inherit.
    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
        cluster_nt = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  host="127.0.0.1")
    client_nt = Client(cluster_nt)
    study(client_nt, 4)
    t0 = time.perf_counter()
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                           host="127.0.0.1")
    client = Client(cluster)
    t_cluster = time.perf_counter() - t0
    study(client, 4)
    print(f"Dask LocalCluster (2 workers x 1 thread) started in {t_cluster:.2f} s, warmed by a 4-run study")
    trim = {c: next(iter(cl.run(lambda: os.environ.get("MALLOC_TRIM_THRESHOLD_")).values()))
            for c, cl in (("default", client), ("unset", client_nt))}
    print(f"MALLOC_TRIM_THRESHOLD_ in the workers: {trim}")

    # 1. throughput, side by side in one run
    print(f"\n1. paper example, WGTLS, R = {R}, P = 8: lptv.montecarlo as a user calls it "
          f"(best of {rounds} rounds; every round's wall time in seconds shown)")
    executors = (("serial", "serial", {}, 1), ("2 processes (pool per call)", "processes", {"workers": 2}, 2),
                 ("Dask LocalCluster 2 workers", client, {}, 2),
                 ("  the same, malloc trim unset", client_nt, {}, 2))
    runs, walls = {}, {name: [] for name, *_ in executors}
    for _ in range(rounds):
        for name, ex, kw, workers in executors:
            mc = study(ex, R, **kw)
            walls[name].append(mc.elapsed)
            if name not in runs or mc.elapsed < runs[name].elapsed:
                runs[name] = mc
            print(f"   round {len(walls[name])}: {name} {mc.elapsed:.2f} s (load {load()})", flush=True)
    print(f"{'executor':34s} {'wall s':>8s} {'fits/min':>9s} {'vs serial':>9s} {'chunk':>5s}  rounds")
    for name, ex, kw, workers in executors:
        mc = runs[name]
        chunk = default_chunk_size(R, workers) if ex != "serial" else 1
        ratio = mc.fits_per_minute / runs["serial"].fits_per_minute
        print(f"{name:34s} {mc.elapsed:8.2f} {mc.fits_per_minute:9.0f} {ratio:8.2f}x {chunk:5d}  "
              + " ".join(f"{w:.1f}" for w in walls[name]), flush=True)
    ref = runs["serial"].estimates["wgtls"]
    for name, mc in runs.items():
        assert np.array_equal(mc.estimates["wgtls"], ref, equal_nan=True), f"{name} differs from serial"
    fails = sum(not f["ok"] for f in runs["serial"].fits)
    print(f"estimates bit-identical on the three executors; {fails} failed fits; "
          f"{runs['serial'].report().splitlines()[1].strip()}")
    t_fit = runs["serial"].elapsed / R

    # 2. per-task overhead of empty tasks carrying the study's design
    model, ms = paper_model(), paper_multisine(seed=1)
    design = dict(u0=ms.signal, y0=ms.signal.copy(), w0=model.w0, ts=None, periods=8,
                  noise=dict(PAPER_NOISE), fit=dict(na=2, nb=1, ka=3, kb=3, lines=PAPER_ID_LINES),
                  methods=("wgtls",))
    print(f"\n2. per-task overhead: {n_noop} empty tasks, one item each, the design as shared argument")
    print(f"{'executor':34s} {'us/task':>8s} {'tasks/s':>8s} {'us/fit at chunk 32':>19s} {'% of a fit':>10s}")
    over = {}
    for name, ex, kw in (("serial", "serial", {}), ("2 processes (pool per call)", "processes", {"workers": 2}),
                         ("Dask LocalCluster 2 workers", client, {})):
        t0 = time.perf_counter()
        out = run_tasks(noop, range(n_noop), design, executor=ex, chunk_size=1, progress=False, **kw)
        dt = (time.perf_counter() - t0) / n_noop
        assert out == list(range(n_noop))
        over[name] = dt
        print(f"{name:34s} {1e6 * dt:8.1f} {1 / dt:8.0f} {1e6 * dt / 32:19.1f} {100 * dt / 32 / t_fit:9.2f}%",
              flush=True)

    # 3. on paper: when does the scheduler saturate?
    S_meas = 1 / over["Dask LocalCluster 2 workers"]
    print(f"\n3. on paper: t_fit = {1e3 * t_fit:.1f} ms (serial); a task of C fits lasts C t_fit; W workers "
          "ask the scheduler for W / (C t_fit) tasks per second;\n   it saturates when that reaches its "
          "rate S: W* = S C t_fit, with C = min(32, ceil(R / (4 W))) (the default chunking).")
    for label, S in (("S measured here (client, scheduler, 2 workers on 2 shared cores)", S_meas),
                     ("S = 1000 tasks/s (distributed docs: about 1 ms per task)", 1000.0)):
        for RR in (R, 100000):
            W = 1
            while W < 100000 and W / (min(32, math.ceil(RR / (4 * W))) * t_fit) < S:
                W += 1
            C = min(32, math.ceil(RR / (4 * W)))
            print(f"   {label}, R = {RR}: W* = {W} workers (chunk {C}, {C * t_fit:.2f} s per task)")
    for c in (client, cluster, client_nt, cluster_nt):
        c.close()
    print(f"\nload average at the end: {load()}")


if __name__ == "__main__":
    main()
