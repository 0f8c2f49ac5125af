"""Where a Dask LocalCluster's time goes in a small study, beside the work itself.

    python bench/python/bench_dask_latency.py [--rounds N]   (default 5)

A LocalCluster of 2 worker processes x 1 thread, as in bench_batch.py, on the machine's 2 cores.

1. Dask alone: four tasks that spin for 110, 110, 40 and 40 ms of wall time (the shape of
   lptv's chunks for 64 fits of 4-5 ms: two rounds, the long chunks first), submitted as
   lptv.batch submits its chunks (one ``client.submit`` each, in priority order, the shared
   argument a scattered future). Printed per round: when each task started on its worker
   and when the client received it, from the first submit; the whole over the 150 ms of
   work per worker. A spinning task measures wall time, so this part is Dask's latency alone,
   not its competition for the cores.
2. Dask's processes idle for 2 s, and during a 64-run ``lptv.montecarlo`` on the paper's
   example: the CPU time of the client's process (which holds the scheduler and both nannies
   in a LocalCluster) and of each worker, against the CPU time of the fits themselves (each
   chunk's thread time, measured on the worker).
3. The same study's chunks on the workers' clocks: start, end and thread CPU of each, from
   the call's start.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np


def spin(ms, tag, shared=None):
    t0 = time.time()
    while (time.time() - t0) * 1e3 < ms:
        pass
    return tag, t0, time.time(), os.getpid()


def install_chunk_log():
    """On a worker: wrap lptv.batch.executors._timed_chunk to log each chunk's wall-clock start
    and end and its thread CPU time (the wrapper replaces the module attribute that the
    pickled task refers to by name)."""
    import lptv.batch.executors as e

    if getattr(e._timed_chunk, "log", None) is not None:
        return
    inner = e._timed_chunk
    log = []

    def timed_chunk(items, fn, shared, cwd=None):
        t0, c0 = time.time(), time.thread_time()
        out = inner(items, fn, shared, cwd)
        log.append((len(items), t0, time.time(), time.thread_time() - c0))
        return out

    timed_chunk.log = log
    e._timed_chunk = timed_chunk


def take_chunk_log():
    import lptv.batch.executors as e

    out = list(e._timed_chunk.log)
    e._timed_chunk.log.clear()
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    import psutil
    from distributed import Client, LocalCluster, as_completed

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from bench_batch import study

    env = dict(os.environ)
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                           host="127.0.0.1")
    os.environ.clear()
    os.environ.update(env)
    client = Client(cluster)
    print(f"machine: {os.cpu_count()} cores, load average {' '.join(open('/proc/loadavg').read().split()[:3])}")

    print("\n1. Dask alone: 4 spinning tasks of 110 110 40 40 ms on 2 workers (150 ms of work each); "
          "per task: start on its worker -> received by the client, ms from the first submit")
    shared = client.scatter([b"x" * 35000], broadcast=True)[0]
    client.submit(spin, 1, -1, pure=False).result()
    over = []
    for _ in range(a.rounds):
        time.sleep(0.05)
        t0 = time.time()
        futs = [client.submit(spin, ms, k, shared=shared, pure=False, priority=4 - k)
                for k, ms in enumerate((110, 110, 40, 40))]
        got = []
        for f in as_completed(futs):
            tag, s, e, pid = f.result()
            got.append((tag, s, time.time()))
        total = 1e3 * (time.time() - t0)
        over.append(total - 150.0)
        print(f"   total {total:6.1f} ms: " + ", ".join(f"#{t} {1e3 * (s - t0):5.1f} -> {1e3 * (r - t0):5.1f}"
                                                      for t, s, r in sorted(got)))
    print(f"   beyond the 150 ms of work: median {np.median(over):.1f} ms, min {min(over):.1f} ms")

    me = psutil.Process()
    workers = {p.pid: p for p in me.children(recursive=True) if "multiprocessing-fork" in " ".join(p.cmdline())}

    def cpu():
        out = {"client": me.cpu_times()}
        out.update({pid: p.cpu_times() for pid, p in workers.items()})
        return {k: t.user + t.system for k, t in out.items()}

    c0 = cpu()
    time.sleep(2.0)
    c1 = cpu()
    idle = {k: 1e3 * (c1[k] - c0[k]) / 2.0 for k in c0}
    print(f"\n2. idle: CPU ms per s: client process (scheduler, nannies, client) {idle['client']:.0f}, "
          "workers " + " ".join(f"{v:.0f}" for k, v in idle.items() if k != "client"))

    client.run(install_chunk_log)
    study(client, 4)
    client.run(take_chunk_log)
    print("   a 64-run study, per round: wall; CPU of the client process; each worker's CPU against "
          "its chunks' thread CPU (the fits)")
    timelines = []
    for _ in range(a.rounds):
        c0 = cpu()
        t0 = time.time()
        study(client, 64)
        wall = time.time() - t0
        c1 = cpu()
        logs = {w: L for w, L in client.run(take_chunk_log).items()}
        per_pid = {}
        for w, L in logs.items():
            pid = client.run(os.getpid, workers=[w])[w]
            per_pid[pid] = L
        timelines.append((t0, per_pid))
        parts = []
        for pid in workers:
            fits = sum(c for _, _, _, c in per_pid.get(pid, []))
            parts.append(f"{1e3 * (c1[pid] - c0[pid]):4.0f} (fits {1e3 * fits:4.0f})")
        print(f"   wall {1e3 * wall:5.0f} ms; client {1e3 * (c1['client'] - c0['client']):3.0f} ms; workers "
              + ", ".join(parts))

    print("\n3. the last study's chunks on the workers' clocks (ms from the call's start): items, start, end, "
          "thread CPU")
    t0, per_pid = timelines[-1]
    for pid, L in per_pid.items():
        print(f"   worker {pid}: " + "; ".join(f"{n} items {1e3 * (s - t0):5.1f}-{1e3 * (e - t0):5.1f} "
                                             f"cpu {1e3 * c:5.1f}" for n, s, e, c in L))
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
