"""A single command's files and its end: a fit's model.json, summary.json and report.html are
written together or not at all (a full disk, a second command writing into the same --out), and
SIGINT (Ctrl-C) or SIGTERM ends any command in one line with the status a shell gives a process
killed by that signal (130, 143), as the batches and studies do (test_resume.py)."""
import errno
import json
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from scipy.signal import lfilter

import lptv
from lptv.apps import cli, report

LPTV = [sys.executable, "-m", "lptv"]


def _write(d, N, P, M, tag=""):
    rng = np.random.default_rng(0)

    def periodic(channels):
        spec = np.zeros((N // 2 + 1, channels), complex)
        spec[1:201] = np.exp(2j * np.pi * rng.random((200, channels)))
        return np.tile(np.fft.irfft(spec, N, axis=0), (P, 1))

    u = periodic(2)
    H = 1 / (1 + 1j * np.arange(N // 2 + 1) / 20.0)
    y = np.fft.irfft(np.fft.rfft(u.reshape(P, N, 2), axis=1) * H[None, :, None], N, axis=1).reshape(P * N, 2)
    y = y @ np.array([[1.0, 0.3], [0.2, 1.0]]) + 1e-3 * rng.standard_normal(y.shape)
    t = np.arange(P * N) * 10.24 / N
    np.savetxt(d / f"siso{tag}.csv", np.c_[t, u[:, 0], y[:, 0]], delimiter=",", header="t,u,y", comments="")
    np.savetxt(d / f"mimo{tag}.csv", np.c_[t, u, y], delimiter=",", header="t,f1,f2,x1,x2", comments="")
    uu = rng.standard_normal(M * 128)
    yy = lfilter([0.1], [1, -0.9], uu) + 0.01 * rng.standard_normal(uu.size)
    np.savetxt(d / f"rec{tag}.csv", np.c_[np.arange(uu.size) / 12.8, uu, yy], delimiter=",", header="t,u,y",
               comments="")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Periodic records (one input and output; two of each) and one record that does not repeat,
    made with NumPy and SciPy: small ones, and long ones (_long) that take the commands seconds."""
    d = tmp_path_factory.mktemp("records")
    _write(d, 1024, 8, 64)
    _write(d, 2048, 16, 256, "_long")
    return d


# ------------------------------------------------------------------------------ signals

def _catches_sigterm(pid) -> bool:
    """Whether the process has its own SIGTERM handler yet (/proc's caught-signal mask): Python
    has none by default, so the command's is installed."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("SigCgt:"):
                return bool(int(line.split()[1], 16) & (1 << (signal.SIGTERM - 1)))
    return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("name, argv, sig", [
    ("identify", ["identify", "siso_long.csv", "--period", "10.24", "--na", "1", "--nb", "0", "--ka", "1"], signal.SIGINT),
    ("identify", ["identify", "siso_long.csv", "--period", "10.24", "--na", "1", "--nb", "0", "--ka", "1"], signal.SIGTERM),
    ("inspect", ["inspect", "siso_long.csv"], signal.SIGTERM),
    ("mimo", ["identify", "mimo_long.csv", "--input", "f1,f2", "--output", "x1,x2", "--period", "10.24", "--na", "1",
              "--nb", "0"], signal.SIGINT),
    ("one-record", ["identify", "rec_long.csv", "--one-record", "--discrete", "--period", "10", "--na", "1", "--nb", "0"],
     signal.SIGTERM),
])
def test_a_single_command_interrupted_ends_in_one_line_with_the_conventional_status(files, tmp_path, name, argv,
                                                                                      sig):
    out = tmp_path / "out"
    p = subprocess.Popen(LPTV + argv + (["--out", str(out)] if argv[0] == "identify" else []), cwd=files,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while p.poll() is None and not _catches_sigterm(p.pid) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.2)
    assert p.poll() is None, ("the command ended before it could be interrupted: it never handled SIGTERM, "
                              "or its record is too short")
    p.send_signal(sig)
    _, stderr = p.communicate(timeout=120)
    assert p.returncode == 128 + sig, (p.returncode, stderr)
    assert "Traceback" not in stderr and stderr.count("\n") == 1, stderr
    assert f"lptv {argv[0]}: interrupted by {signal.Signals(sig).name}: stopped before it finished" in stderr
    assert not (out / "model.json").exists()


# ------------------------------------------------------------------------------ a fit's files together

def _folder(path):
    return {p.name: p.read_bytes() for p in sorted(path.iterdir())}


def test_a_full_disk_during_a_rerun_leaves_the_previous_fit_whole(files, tmp_path, monkeypatch, capsys):
    out = tmp_path / "fit"
    base = ["identify", str(files / "siso.csv"), "--period", "10.24", "--nb", "0", "--out", str(out)]
    assert cli.main(base + ["--na", "1"]) in (0, 3)
    before = _folder(out)
    assert {"model.json", "summary.json", "report.html"} <= set(before)

    def full(self, out_dir):      # the report's turn: the disk is full
        raise OSError(errno.ENOSPC, "No space left on device", str(out_dir) + "/report.html")

    monkeypatch.setattr(report.Report, "write", full)
    capsys.readouterr()
    assert cli.main(base + ["--na", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{out}/report.html: No space left on device" in err, err
    assert _folder(out) == before            # the previous fit, unchanged, and nothing staged left


def test_two_fits_written_into_one_folder_at_once_leave_one_whole(tmp_path):
    """The interleaving that mixed them: A has written its model and summary and builds its report
    (the slow part) while B writes all of its files; then A's report lands. Each fit's files go
    in together, so the folder ends with A's three files."""
    out = tmp_path / "fit"
    a_building, b_done = threading.Event(), threading.Event()

    def fit(name, k):
        return lptv.Model([[k], [1.0]], [[1.0]], w0=0.1), {"fit": name}

    def report_a():
        a_building.set()
        assert b_done.wait(60)
        return _report("A")

    def a():
        report.write_fit(out, *fit("A", 2.0), report_a)

    t = threading.Thread(target=a)
    t.start()
    assert a_building.wait(60)
    report.write_fit(out, *fit("B", 3.0), lambda: _report("B"))
    b_done.set()
    t.join(60)
    model = lptv.Model.load(out / "model.json")
    names = (json.loads((out / "summary.json").read_text())["fit"], (out / "report.html").read_text())
    assert model.a[0, 0].real == 2.0 and names[0] == "A" and "<title>fit A</title>" in names[1]
    assert sorted(p.name for p in out.iterdir()) == ["model.json", "report.html", "summary.json"]


def _report(name):
    r = report.Report(f"fit {name}")
    r.paragraph(name)
    return r


def test_two_commands_into_one_folder_end_with_one_fit_whole(files, tmp_path):
    out = tmp_path / "same"
    runs = [subprocess.Popen(LPTV + ["identify", "siso.csv", "--period", "10.24", "--nb", "0", "--na", na,
                                     "--out", str(out)], cwd=files, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True) for na in ("1", "2")]
    for p in runs:
        p.communicate(timeout=300)
        assert p.returncode in (0, 3)
    na = lptv.Model.load(out / "model.json").na
    summary = json.loads((out / "summary.json").read_text())
    assert summary["na"] == na and f"na = {na}," in (out / "report.html").read_text()
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
