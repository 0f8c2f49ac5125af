"""Warm batch workers (lptv.batch.warm, lptv.batch.dask_plugin) and chunks sized by cost.

- executor="processes" runs lptv's tasks on one pool kept between calls: the same pool and the
  same worker processes for a second call, a new pool after shutdown_pool(), after a worker's
  death and for another worker count; a caller's own function gets a pool of its own.
- The Dask worker plugin is registered once per client, and results are bit-identical with it
  and without it (and with glibc's thresholds raised around a chunk or not).
- The chunk plan from a measured cost covers every item once, long tasks first.
No timings are asserted.
"""
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import lptv
import lptv.batch.dask_plugin
import lptv.batch.executors as ex
from lptv.batch import chunk_sizes, run_tasks, shutdown_pool, warm

from test_batch import STUDY, assert_same_study, small_lptv

SMALL = dict(STUDY, runs=6, methods="wgtls")


def pool_pids(pool):
    return sorted(pool._processes)


def wait_until(cond, what, limit=60.0):
    """Polls for a state the pool's manager thread reaches on its own (not a timing check)."""
    t_end = time.monotonic() + limit
    while not cond():
        if time.monotonic() > t_end:
            raise AssertionError(f"never reached: {what}")
        time.sleep(0.05)


def user_task(item, shared):
    return item * shared


@pytest.fixture
def fresh_pool():
    shutdown_pool()
    yield
    shutdown_pool()


def test_kept_pool_is_reused_and_replaced_after_shutdown_breakage_and_another_count(fresh_pool):
    model, ms = small_lptv()
    serial = lptv.montecarlo(model, ms, executor="serial", **SMALL)
    assert warm.current_pool() is None
    first = lptv.montecarlo(model, ms, executor="processes", workers=2, **SMALL)
    pool = warm.current_pool()
    assert pool is not None and first.executor == "2 processes"
    pids = pool_pids(pool)
    second = lptv.montecarlo(model, ms, executor="processes", workers=2, **SMALL)
    assert warm.current_pool() is pool and pool_pids(pool) == pids      # the same warm workers
    assert_same_study(serial, first)
    assert_same_study(serial, second)

    shutdown_pool()
    assert warm.current_pool() is None
    third = lptv.montecarlo(model, ms, executor="processes", workers=2, **SMALL)
    assert warm.current_pool() not in (None, pool)
    assert_same_study(serial, third)

    # a worker killed while the pool is idle breaks it; the next call gets a new pool
    pool = warm.current_pool()
    os.kill(pool_pids(pool)[0], signal.SIGKILL)
    wait_until(lambda: pool._broken, "the pool noticed its dead worker")
    fourth = lptv.montecarlo(model, ms, executor="processes", workers=2, **SMALL)
    assert warm.current_pool() is not pool
    assert_same_study(serial, fourth)

    # another worker count replaces the pool
    pool = warm.current_pool()
    one = lptv.montecarlo(model, ms, executor="processes", workers=1, **SMALL)
    assert warm.current_pool() is not pool and len(warm.current_pool()._processes) == 1
    assert_same_study(serial, one)


def test_a_callers_own_function_gets_a_pool_of_its_own(fresh_pool):
    assert run_tasks(user_task, [1, 2, 3], 2, workers=2, progress=False) == [2, 4, 6]
    assert warm.current_pool() is None
    # and an Executor of the caller's is used as it is and left open
    import concurrent.futures as cf

    with cf.ThreadPoolExecutor(2) as pool:
        assert run_tasks(user_task, [1, 2], 3, executor=pool, progress=False) == [3, 6]
        assert pool.submit(lambda: 5).result() == 5
    assert warm.current_pool() is None


def test_kept_pool_workers_follow_the_callers_folder(fresh_pool, tmp_path, monkeypatch):
    from lptv.examples import paper_measurements

    kw = dict(na=2, nb=1, ka=3, kb=3, lines=range(1, 244), w0=0.04, progress=False)
    d = paper_measurements(seed=1, periods=4)
    lptv.identify_many([d], executor="processes", workers=2, **kw)      # the pool forks here
    monkeypatch.chdir(tmp_path)
    np.savez("rec.npz", u=d["u"], y=d["y"], w0=d["w0"])
    out = lptv.identify_many(["rec.npz"], executor="processes", workers=2, **kw)
    assert out.rows[0]["ok"], out.rows[0]["error"]


def test_kept_pool_outlives_the_folder_it_was_started_in(fresh_pool, tmp_path, monkeypatch):
    # a notebook's run folder, deleted after the first study: the workers forked there stand in a
    # folder that no longer exists, and every later study's chunks were lost (FileNotFoundError)
    model, ms = small_lptv()
    first = tmp_path / "run"
    first.mkdir()
    monkeypatch.chdir(first)
    before = lptv.montecarlo(model, ms, executor="processes", workers=2, **SMALL)   # the pool forks here
    monkeypatch.chdir(tmp_path)
    first.rmdir()
    after = lptv.montecarlo(model, ms, executor="processes", workers=2, **SMALL)
    assert [f["error"] for f in after.fits if not f["ok"]] == []
    assert_same_study(before, after)
    # the caller itself standing in a deleted folder: the workers still run (no relative path here)
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    again = lptv.montecarlo(model, ms, executor="processes", workers=2, **SMALL)
    assert_same_study(before, again)


def test_chunk_plan_covers_every_item_once_long_tasks_first():
    for n in (1, 7, 64, 256, 2000):
        for w in (1, 2, 8):
            for cost in (None, 1e-5, 0.006, 0.05, 2.0):
                sizes = chunk_sizes(n, w, cost)
                assert sum(sizes) == n and min(sizes) >= 1
                if cost:
                    assert all(a >= b for a, b in zip(sizes, sizes[1:]))     # long tasks first
                    last = sizes[-min(w, n):]                                 # the last tasks: even
                    assert max(last) - min(last) <= 1
                    rounds = sizes[:len(sizes) - len(last)]
                    lo = max(1, int(np.ceil(ex.TASK_MIN / cost)))
                    assert all(s >= lo for s in rounds)
                    hi = max(lo, int(np.floor(ex.TASK_MAX / cost)))
                    assert max(sizes) <= max(hi, -(-n // w))
    assert chunk_sizes(0, 2, 0.01) == []
    assert chunk_sizes(64, 2, 0.0043) == [24, 24, 4, 4, 4, 4]     # rounds of equal tasks
    assert chunk_sizes(256, 2, 0.0043) == [93, 93, 18, 18, 9, 9, 4, 4, 4, 4]
    assert chunk_sizes(64, 2, 0.0043, task_min=0.04) == [24, 24, 8, 8]


def test_second_call_is_planned_from_the_measured_cost_with_the_same_results(fresh_pool, monkeypatch):
    model, ms = small_lptv()
    study = dict(SMALL, runs=20)
    monkeypatch.setattr(ex, "_cost", {})
    serial = lptv.montecarlo(model, ms, executor="serial", **study)
    key = ex._cost_key(lptv.batch.study.realisation)
    a = lptv.montecarlo(model, ms, executor="processes", workers=2, **study)
    cost = ex._cost[key]
    assert cost > 0
    planned = []
    real_plan = ex._plan
    monkeypatch.setattr(ex, "_plan", lambda *args: planned.append(real_plan(*args)) or planned[-1])
    b = lptv.montecarlo(model, ms, executor="processes", workers=2, **study)
    assert [len(c) for c in planned[0]] == chunk_sizes(20, 2, cost)
    assert sorted(i for c in planned[0] for i in c) == list(range(20))
    assert_same_study(serial, a)
    assert_same_study(serial, b)


def test_dask_plugin_registered_once_per_client_and_results_bit_identical(dask_cluster, monkeypatch):
    distributed = pytest.importorskip("distributed")
    model, ms = small_lptv()
    serial = lptv.montecarlo(model, ms, executor="serial", **SMALL)
    with distributed.Client(dask_cluster, set_as_default=False) as client:
        calls, scatters = [], []
        real = client.register_plugin
        monkeypatch.setattr(client, "register_plugin", lambda *a, **k: calls.append(a) or real(*a, **k))
        real_submit = client.submit     # the design is sent as a task of its own (_identity)
        monkeypatch.setattr(client, "submit", lambda f, *a, **k: (
            f is lptv.batch.executors._identity and scatters.append(a)) or real_submit(f, *a, **k))
        first = lptv.montecarlo(model, ms, executor=client, **SMALL)
        second = lptv.montecarlo(model, ms, executor=client, **SMALL)
        assert len(calls) <= 1 and client in lptv.batch.dask_plugin._registered
        # the design went to the workers once: the second study (equal design) reused it
        assert len(scatters) == 1
        third = lptv.montecarlo(model, ms, executor=client, **dict(SMALL, snr_out_db=SMALL["snr_out_db"] + 1))
        assert len(scatters) == 2      # another design: sent again
        assert not np.array_equal(third.estimates["wgtls"], second.estimates["wgtls"])
        names = client.run_on_scheduler(lambda dask_scheduler: list(dask_scheduler.worker_plugins))
        assert lptv.batch.dask_plugin.NAME in names
        # the workers ran the warm-up: scipy.signal is there, and the trimming variable still is
        mods = client.run(lambda: ("scipy.signal" in sys.modules, os.environ.get("MALLOC_TRIM_THRESHOLD_")))
        assert all(v == (True, "65536") for v in mods.values())
    assert_same_study(serial, first)
    assert_same_study(serial, second)

    # a cluster whose workers never get the plugin gives the same bits
    monkeypatch.setattr(lptv.batch.dask_plugin, "register", lambda client: False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                  host="127.0.0.1") as cluster, \
            distributed.Client(cluster, set_as_default=False) as client:
        bare = lptv.montecarlo(model, ms, executor=client, **SMALL)
        names = client.run_on_scheduler(lambda dask_scheduler: list(dask_scheduler.worker_plugins))
        assert lptv.batch.dask_plugin.NAME not in names
    assert_same_study(serial, bare)


def test_malloc_kept_keeps_the_bits_and_the_pages(tmp_path):
    """In a process started with Dask's MALLOC_TRIM_THRESHOLD_: the same realisations with and
    without the raised thresholds are bit-identical, and far fewer pages are faulted in."""
    code = textwrap.dedent("""
        import contextlib, resource, sys
        import numpy as np
        import lptv
        from lptv.batch import warm
        from lptv.batch.study import realisation
        from lptv.examples import paper_model, paper_multisine
        from lptv.excitation.multisine import time_signal
        m, ms = paper_model(), paper_multisine(seed=1)
        y0 = time_signal(lptv.simulate(m, ms.spectrum), ms.n_samples)
        design = dict(u0=ms.signal, y0=y0, w0=m.w0, ts=None, periods=8, methods=("wgtls",),
                      noise=dict(snr_in_db=50.0, snr_out_db=30.0, pole_in=0.0, pole_out=0.0, correlation=0.0),
                      fit=dict(na=2, nb=1, ka=3, kb=3, lines=np.arange(1, 244)))
        realisation((0, np.random.SeedSequence(0)), design)
        out = {}
        for kept in (False, True):
            f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
            with (warm.malloc_kept() if kept else contextlib.nullcontext()):
                rows = [realisation((i, np.random.SeedSequence(i)), design)[0]["eta"] for i in range(10)]
            out[kept] = (np.array(rows), resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0)
        assert np.array_equal(out[False][0], out[True][0])
        print(out[False][1], out[True][1])
    """)
    env = dict(os.environ, MALLOC_TRIM_THRESHOLD_="65536")
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    plain, kept = map(int, r.stdout.split())
    assert kept < plain / 5, (plain, kept)
