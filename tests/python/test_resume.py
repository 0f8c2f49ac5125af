"""Studies that survive an interruption: each finished chunk is on disk as it completes, SIGINT
and SIGTERM end the command in one line with status 130 / 143, and --resume completes the study
to the very table of an uninterrupted run (compared byte for byte with the library's own run)."""
import csv
import concurrent.futures as cf
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import lptv
from lptv.apps import cli
from lptv.atomic import atomic_open
from lptv.batch import run_tasks
from lptv.batch.parts import CheckpointError, stored_items
from lptv.examples import paper_measurements

pd = pytest.importorskip("pandas")

LPTV = [sys.executable, "-m", "lptv"]
RUNS = 600      # 1.2 s of fits on two workers: ~50 times the 20 ms the tests poll at before a signal
MODEL = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2): fits of ~3 ms


def study_args(out, *extra):
    return ["montecarlo", "--model", str(out.parent / "model.json"), "--excited", "1-20", "--samples", "128",
            "--runs", str(RUNS), "--periods", "4", "--method", "sml", "--seed", "5", "--chunk-size", "20",
            "--workers", "2", "--out", str(out), *extra]


def parts_in(out):
    return len(list((out / "parts").glob("part-*.json")))


def start_and_signal(argv, out, sig, more_than):
    """Start the command, wait until it has written more than ``more_than`` parts, send ``sig``."""
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while parts_in(out) <= more_than and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert p.poll() is None, "the study ended before it could be interrupted: make it longer"
    p.send_signal(sig)
    stdout, stderr = p.communicate(timeout=120)
    return p.returncode, stdout, stderr


def test_montecarlo_interrupted_twice_then_resumed_gives_the_uninterrupted_table(tmp_path):
    MODEL.save(tmp_path / "model.json")
    out = tmp_path / "mc"
    rc, stdout, stderr = start_and_signal(LPTV + study_args(out), out, signal.SIGINT, 0)
    assert rc == 130, stderr
    assert "Traceback" not in stderr and stderr.count("\n") == 1, stderr
    kept = stored_items(out / "parts")
    assert 0 < kept < RUNS and kept % 20 == 0
    assert f"interrupted by SIGINT: {kept} of {RUNS} realisations are kept in {out / 'parts'}/" in stderr
    assert not (out / "estimates.csv").exists()
    # the resumed run is stopped again, by SIGTERM this time, and keeps what it adds
    rc, stdout, stderr = start_and_signal(LPTV + study_args(out, "--resume"), out, signal.SIGTERM,
                                          parts_in(out))
    assert rc == 143 and "interrupted by SIGTERM" in stderr and stderr.count("\n") == 1, stderr
    assert f"resuming: {kept} of {RUNS} realisations are done" in stdout
    assert stored_items(out / "parts") > kept
    p = subprocess.run(LPTV + study_args(out, "--resume"), capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert stored_items(out / "parts") == RUNS
    # the library's uninterrupted run of the same study, serially, in this process
    ms = lptv.multisine(range(1, 21), 128, amplitudes=np.sqrt(2 / 20), seed=1)
    ref = lptv.montecarlo(MODEL, ms, periods=4, runs=RUNS, methods="sml", snr_in_db=50, snr_out_db=30,
                          pole_in=0.6, pole_out=0.8, correlation=0.5, seed=5, executor="serial", progress=False)
    ref.save(tmp_path / "ref")
    for name in ("estimates.csv", "fits.csv", "summary.csv"):
        assert (out / name).read_bytes() == (tmp_path / "ref" / name).read_bytes(), name


def test_a_rerun_of_another_study_replaces_the_parts_and_resume_refuses_it(tmp_path, capsys):
    MODEL.save(tmp_path / "model.json")
    out = tmp_path / "mc"
    small = ["montecarlo", "--model", str(tmp_path / "model.json"), "--excited", "1-20", "--samples", "128",
             "--runs", "6", "--periods", "4", "--workers", "1", "--out", str(out)]
    assert cli.main(small) == 0
    assert cli.main(small + ["--resume"]) == 0            # all done: nothing to fit, same tables
    stdout = capsys.readouterr().out
    assert "resuming: 6 of 6 realisations are done" in stdout
    rc = cli.main(small + ["--seed", "7", "--resume"])
    err = capsys.readouterr().err
    assert rc == 2 and "holds the parts of another study" in err and err.count("\n") == 1
    assert cli.main(small + ["--seed", "7"]) == 0          # without --resume: a new study
    assert "held the parts of another study: replaced" in capsys.readouterr().out
    rc = cli.main(small[:-1] + [str(tmp_path / "new"), "--resume"])
    assert rc == 2 and "--resume: " in capsys.readouterr().err


def test_identify_files_resume_fits_only_the_missing_files(tmp_path, capsys):
    files = []
    for s in range(1, 7):
        d = paper_measurements(seed=s, periods=4)
        files.append(str(tmp_path / f"rec{s}.npz"))
        np.savez(files[-1], u=d["u"], y=d["y"], w0=d["w0"])
    args = ["identify", *files, "--na", "2", "--nb", "1", "--ka", "3", "--kb", "3", "--lines", "1-243",
            "--workers", "1"]
    assert cli.main(args + ["--out", str(tmp_path / "ref")]) == 0
    out = tmp_path / "b"
    assert cli.main(args + ["--out", str(out)]) == 0
    parts = sorted((out / "parts").glob("part-*.json"))
    assert len(parts) > 1
    for p in parts[1:]:
        p.unlink()                                      # as if stopped after the first chunk
    (out / "results.csv").unlink()
    capsys.readouterr()
    assert cli.main(args + ["--out", str(out), "--resume"]) == 0
    stdout = capsys.readouterr().out
    first = json.loads(parts[0].read_text())["items"]
    assert f"resuming: {len(first)} of 6 files are fitted" in stdout
    assert (out / "results.csv").read_bytes() == (tmp_path / "ref" / "results.csv").read_bytes()
    rc = cli.main(["identify", files[0], "--na", "2", "--nb", "1", "--resume"])
    assert rc == 2 and "--resume applies to a batch" in capsys.readouterr().err


# ------------------------------------------------------------------------------ the library

def square(x, shared):
    return {"x": x, "v": np.array([x, x ** 0.5]), "t": (x, "ok")}


class LosesTheFirstChunk(cf.ThreadPoolExecutor):
    """An executor whose first task dies, as a chunk on a worker that was killed."""

    def __init__(self):
        super().__init__(max_workers=2)
        self.lost = False

    def submit(self, fn, *a, **kw):
        if not self.lost:
            self.lost = True
            f = cf.Future()
            f.set_exception(RuntimeError("worker killed"))
            return f
        return super().submit(fn, *a, **kw)


def test_a_lost_chunk_is_not_kept_and_runs_again(tmp_path):
    items = list(range(10))
    with LosesTheFirstChunk() as ex:
        out = run_tasks(square, items, None, executor=ex, chunk_size=3, progress=False, checkpoint=tmp_path)
    lost = [i for i, r in enumerate(out) if isinstance(r, lptv.batch.Failure)]
    assert lost == [0, 1, 2] and out[0].message.startswith("task lost: RuntimeError: worker killed")
    assert stored_items(tmp_path) == 7
    again = run_tasks(square, items, None, executor="serial", progress=False, checkpoint=tmp_path)
    ref = [square(x, None) for x in items]
    for a, b in zip(again, ref):          # read back exactly: floats, arrays, tuples
        assert a["x"] == b["x"] and a["t"] == b["t"] and a["v"].dtype == b["v"].dtype
        assert np.array_equal(a["v"], b["v"])
    with pytest.raises(CheckpointError, match="another study"):
        run_tasks(square, items[:9], None, executor="serial", progress=False, checkpoint=tmp_path)


def test_atomic_open_leaves_the_old_file_when_the_writer_fails(tmp_path):
    target = tmp_path / "table.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_open(target) as f:
            f.write("half a new ta")
            raise RuntimeError("killed")
    assert target.read_text() == "old" and os.listdir(tmp_path) == ["table.csv"]
    with atomic_open(target) as f:
        f.write("new")
    assert target.read_text() == "new" and oct(target.stat().st_mode & 0o777) != "0o600"


# ------------------------------------------------------------------------------ a cluster's faults

def _holders_of_dependencies(dask_scheduler):
    """The workers that hold the data the tasks still to run depend on (the study's design)."""
    keys = {d.key for ts in dask_scheduler.tasks.values()
            if ts.state in ("processing", "queued", "waiting", "no-worker") for d in ts.dependencies}
    return sorted({ws.address for k in keys if k in dask_scheduler.tasks for ws in dask_scheduler.tasks[k].who_has})


def test_dask_workers_killed_one_after_the_other_mid_study_lose_nothing(tmp_path):
    """Both LocalCluster workers killed by their pids, one after the other, mid-study: first one
    of them, then the other as soon as the scheduler knows it is the only holder of the study's
    design (the data every chunk still to run depends on), while the first one's successor is
    starting. The chunks they held run again on the successors, the design is not lost with its
    last holder, and the study is complete and identical to the serial one."""
    distributed = pytest.importorskip("distributed")
    import threading

    ms = lptv.multisine(range(1, 21), 128, amplitudes=np.sqrt(2 / 20), seed=1)
    kw = dict(periods=4, runs=1200, methods="sml", snr_in_db=50, snr_out_db=30, seed=3, progress=False)
    parts = tmp_path / "parts"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                                  host="127.0.0.1") as cluster, distributed.Client(cluster) as client:
        box = {}
        run = threading.Thread(target=lambda: box.update(mc=lptv.montecarlo(
            MODEL, ms, executor=client, chunk_size=10, checkpoint=parts, **kw)))
        run.start()
        deadline = time.monotonic() + 120
        while (stored_items(parts) or 0) < 40 and run.is_alive() and time.monotonic() < deadline:
            time.sleep(0.02)
        pids = client.run(os.getpid)
        first = min(pids.values())
        done_at_kills = [stored_items(parts)]
        os.kill(first, signal.SIGKILL)
        holders = []
        while run.is_alive() and time.monotonic() < deadline:
            holders = client.run_on_scheduler(_holders_of_dependencies)
            if len(holders) == 1 and holders[0] in pids and pids[holders[0]] != first:
                break
            time.sleep(0.01)
        done_at_kills.append(stored_items(parts))
        os.kill(pids[holders[0]], signal.SIGKILL)
        run.join(timeout=300)
    assert done_at_kills[-1] < kw["runs"], f"the study ended before the last kill ({done_at_kills}): make it longer"
    mc = box["mc"]
    assert all(f["ok"] for f in mc.fits), [f["error"] for f in mc.fits if not f["ok"]][:1]
    ref = lptv.montecarlo(MODEL, ms, executor="serial", **kw)
    pd.testing.assert_frame_equal(mc.table(), ref.table())
    pd.testing.assert_frame_equal(mc.fit_table(), ref.fit_table())


def test_pool_workers_end_when_the_command_is_killed(tmp_path):
    """lptv montecarlo killed by SIGKILL mid-study: its pool's workers are gone 5 s later."""
    MODEL.save(tmp_path / "model.json")
    out = tmp_path / "mc"
    p = subprocess.Popen(LPTV + study_args(out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while parts_in(out) < 2 and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert p.poll() is None, "the study ended before it could be killed: make it longer"
    children = _children(p.pid)
    assert len(children) >= 2, children              # the two workers (and the pool's helpers)
    p.kill()
    p.wait()
    time.sleep(5)
    alive = [c for c in children if _alive(c)]
    for c in alive:
        os.kill(c, signal.SIGKILL)
    assert not alive, f"{len(alive)} of {len(children)} workers outlived their parent"


def _children(pid):
    kids = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                kids.append(int(d))
    return kids


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


CLUSTER = """
import sys, time, distributed
if __name__ == "__main__":
    c = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                 host="127.0.0.1")
    print(c.scheduler_address, flush=True)
    time.sleep(600)
"""


def test_a_lost_scheduler_ends_the_study_keeping_the_finished_chunks(tmp_path):
    """The scheduler and its worker are killed mid-study: one line saying what is kept and how to
    resume, exit status 1, no tables; --resume (here on local processes) completes the study."""
    pytest.importorskip("distributed")
    MODEL.save(tmp_path / "model.json")
    (tmp_path / "cluster.py").write_text(CLUSTER)
    cluster = subprocess.Popen([sys.executable, str(tmp_path / "cluster.py")], stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True, start_new_session=True)
    try:
        address = cluster.stdout.readline().strip()
        assert address.startswith("tcp://"), address
        out = tmp_path / "mc"
        argv = study_args(out)
        argv[argv.index("--workers"):argv.index("--workers") + 2] = ["--scheduler", address]
        p = subprocess.Popen(LPTV + argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 120
        while parts_in(out) < 3 and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert p.poll() is None, "the study ended before the scheduler was killed"
        os.killpg(cluster.pid, signal.SIGKILL)       # the scheduler, its nanny and worker
        stdout, stderr = p.communicate(timeout=120)
    finally:
        if cluster.poll() is None:
            os.killpg(cluster.pid, signal.SIGKILL)
        cluster.wait()
    kept = stored_items(out / "parts")
    assert p.returncode == 1, stderr
    assert stderr.count("\n") == 1 and "Traceback" not in stderr, stderr
    assert f"{RUNS - kept} of {RUNS} realisations were lost" in stderr
    assert f"the {kept} finished are kept in {out / 'parts'}/: rerun the same command with --resume" in stderr
    assert not (out / "estimates.csv").exists()
    r = subprocess.run(LPTV + study_args(out, "--resume"), capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and f"resuming: {kept} of {RUNS}" in r.stdout, r.stderr
    with open(out / "fits.csv") as f:
        assert sum(row["ok"] == "True" for row in csv.DictReader(f)) == RUNS


# ------------------------------------------------------------------------------ records that change

def _records(folder, seeds, scale=None):
    files = []
    folder.mkdir(parents=True, exist_ok=True)
    for s in seeds:
        d = paper_measurements(seed=s, periods=4)
        y = d["y"] * (scale.get(s, 1.0) if scale else 1.0)
        files.append(str(folder / f"rec{s}.npz"))
        np.savez(files[-1], u=d["u"], y=y, w0=d["w0"])
    return files


FIT = ["--na", "2", "--nb", "1", "--ka", "3", "--kb", "3", "--lines", "1-243", "--workers", "1"]


def test_a_finished_batch_refits_the_records_that_changed_and_nothing_else(tmp_path, capsys):
    """A record rewritten after its fit (y * 3) is fitted again on the same command, alone; the
    table is the one a fresh batch of the new files gives, byte for byte."""
    files = _records(tmp_path / "recs", range(1, 5))
    out = tmp_path / "b"
    assert cli.main(["identify", *files, *FIT, "--out", str(out)]) == 0
    first = (out / "results.csv").read_text()
    _records(tmp_path / "recs", [2], scale={2: 3.0})          # rec2.npz rewritten with y * 3
    before = set((out / "parts").glob("part-*.json"))
    capsys.readouterr()
    assert cli.main(["identify", *files, *FIT, "--out", str(out)]) == 0
    stdout = capsys.readouterr().out
    assert "resuming: 3 of 4 files are fitted" in stdout
    assert "1 of 4 files changed since their fits: refitting them" in stdout
    new = set((out / "parts").glob("part-*.json")) - before
    assert [json.loads(p.read_text())["labels"] for p in new] == [[files[1]]]      # that file alone
    assert (out / "results.csv").read_text() != first
    assert cli.main(["identify", *files, *FIT, "--out", str(tmp_path / "fresh")]) == 0
    assert (out / "results.csv").read_bytes() == (tmp_path / "fresh" / "results.csv").read_bytes()
    with open(out / "results.csv") as f:
        b0 = {r["record"]: float(r["b0.re0"]) for r in csv.DictReader(f)}
    assert b0[files[1]] == pytest.approx(3 * b0[files[0]], rel=0.1)   # the new contents' fit


def test_resume_after_an_interruption_refits_a_record_changed_meanwhile(tmp_path, capsys):
    files = _records(tmp_path / "recs", range(1, 5))
    out = tmp_path / "b"
    assert cli.main(["identify", *files, *FIT, "--out", str(out)]) == 0
    (out / "results.csv").unlink()
    _records(tmp_path / "recs", [1], scale={1: 3.0})
    capsys.readouterr()
    assert cli.main(["identify", *files, *FIT, "--out", str(out), "--resume"]) == 0
    assert "1 of 4 files changed since their fits: refitting them" in capsys.readouterr().out
    assert cli.main(["identify", *files, *FIT, "--out", str(tmp_path / "fresh")]) == 0
    assert (out / "results.csv").read_bytes() == (tmp_path / "fresh" / "results.csv").read_bytes()


def test_a_file_that_changes_while_the_batch_runs_fails_its_row(tmp_path):
    """The worker compares the bytes it read with the digest the batch was planned with."""
    from lptv.batch.records import file_digest, identify_record

    files = _records(tmp_path / "recs", [1])
    item = (files[0], files[0], file_digest(files[0]))
    _records(tmp_path / "recs", [1], scale={1: 2.0})           # rewritten after planning
    settings = dict(w0=None, ts=None, periods=None, read={}, fit={})
    with pytest.raises(ValueError, match="the file changed while the batch ran"):
        identify_record(item, settings)


def test_model_names_are_unique_and_stable_for_colliding_stems(tmp_path, capsys):
    """a/rec.npz, b/rec.npz and rec-2.npz: three files, three models, whatever the order."""
    a, b, c2 = (str(tmp_path / "a" / "rec.npz"), str(tmp_path / "b" / "rec.npz"), str(tmp_path / "rec-2.npz"))
    for f, made in zip((a, b, c2), (_records(tmp_path / "a", [1]), _records(tmp_path / "b", [2]),
                                    _records(tmp_path, [3]))):
        os.replace(made[0], f)
    names = {}
    for order, out in (([a, b, c2], "o1"), ([c2, b, a], "o2")):
        assert cli.main(["identify", *order, *FIT, "--out", str(tmp_path / out)]) == 0
        summary = json.loads((tmp_path / out / "summary.json").read_text())
        assert len(set(summary["models"].values())) == 3
        assert len(list((tmp_path / out / "models").glob("*.json"))) == 3
        names[out] = summary["models"]
        for f, m in summary["models"].items():     # each model is its own file's fit
            fitted = lptv.Model.load(tmp_path / out / m)
            ref = lptv.Model.load(tmp_path / "o1" / names["o1"][f])
            np.testing.assert_array_equal(fitted.a, ref.a)
    assert names["o1"] == names["o2"]
    assert names["o1"][c2] == "models/rec-2.json"
    assert names["o1"][a] != names["o1"][b] and names["o1"][a].startswith("models/rec-")
