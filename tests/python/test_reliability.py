"""What a hostile or unlucky file, option or exit status must give: one clear error naming the
cause (never a traceback, a misread value or an allocation the machine cannot hold), and an exit
status a script can trust. Each case failed before the change that made it pass."""
import json
import subprocess
import sys

import numpy as np
import pytest

import lptv
from lptv.apps import cli
from lptv.records.measurements import FileError

LPTV = [sys.executable, "-m", "lptv"]


def _csv(tmp_path, text, name="r.csv", encoding="utf-8"):
    p = tmp_path / name
    p.write_bytes(text.encode(encoding) if isinstance(text, str) else text)
    return p


def _rows(n=16, sep=","):
    t = np.arange(n)
    return "".join(f"{np.sin(k):.6f}{sep}{np.cos(k):.6f}\n" for k in t)


# ------------------------------------------------------------------------------ CSV

def test_decimal_commas_in_a_comma_separated_file_are_refused_with_the_line(tmp_path):
    p = _csv(tmp_path, "u,y\n1,5,2,5\n3,0,4,0\n")
    with pytest.raises(FileError, match=r"line 2: 4 field\(s\), the header has 2 \(decimal commas\?"):
        lptv.read_measurements(p, periods=1)


@pytest.mark.parametrize("row, line", [("1.0,2.0,3.0", 4), ("1.0", 4)])
def test_any_row_whose_field_count_differs_from_the_header_is_refused(tmp_path, row, line):
    text = "u,y\n" + "0.5,1.5\n0.25,0.75\n" + row + "\n" + "0.5,1.5\n"
    with pytest.raises(FileError, match=rf"line {line}: \d field\(s\), the header has 2"):
        lptv.read_measurements(_csv(tmp_path, text), periods=1)


def test_a_semicolon_file_with_decimal_commas_still_reads(tmp_path):
    m = lptv.read_measurements(_csv(tmp_path, "u;y\n" + _rows(8, ";").replace(".", ",")), periods=2)
    np.testing.assert_allclose(m.u.ravel(), np.round(np.sin(np.arange(8)), 6))


def test_a_field_over_the_csv_modules_limit_is_one_line(tmp_path):
    p = _csv(tmp_path, "u,y\n1,2\n\"" + "9" * 200_000 + "\",3\n")
    with pytest.raises(FileError, match=r"line 3: field larger than field limit"):
        lptv.read_measurements(p, periods=1)
    r = subprocess.run(LPTV + ["identify", str(p), "--na", "1", "--nb", "0", "--periods", "1"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_utf16_with_its_mark_is_read_and_without_it_is_named(tmp_path):
    text = "u,y\n" + _rows(8)
    m = lptv.read_measurements(_csv(tmp_path, text, "a.csv", "utf-16"), periods=2)
    ref = lptv.read_measurements(_csv(tmp_path, text, "b.csv"), periods=2)
    np.testing.assert_array_equal(m.u, ref.u)
    with pytest.raises(FileError, match="UTF-16 text without a byte-order mark"):
        lptv.read_measurements(_csv(tmp_path, text, "c.csv", "utf-16-le"), periods=2)


# ------------------------------------------------------------------------------ JSON models

def test_a_deeply_nested_json_model_is_a_value_error(tmp_path):
    p = tmp_path / "deep.json"
    p.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ValueError, match=r"deep\.json: JSON nested deeper"):
        lptv.Model.load(p)


def test_a_400_digit_integer_in_a_model_is_named_as_such(tmp_path):
    m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
    d = m.to_dict()
    p = tmp_path / "big.json"
    p.write_text(json.dumps(d).replace('"w0": 0.1', '"w0": ' + "7" * 400))
    with pytest.raises(ValueError, match=r"big\.json: an integer of 400 digits"):
        lptv.Model.load(p)
    r = subprocess.run(LPTV + ["montecarlo", "--model", str(p), "--excited", "1-20", "--samples", "128",
                               "--runs", "2", "--out", str(tmp_path / "mc")], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and "400 digits" in r.stderr and "sizes given in the options" not in r.stderr, r.stderr


# ------------------------------------------------------------------------------ sizes

def test_lines_past_nyquist_are_named_before_any_allocation():
    from lptv.examples import paper_measurements

    d = paper_measurements(seed=1, periods=4)           # 2048 samples per period: line 1024 is Nyquist
    with pytest.raises(ValueError, match=r"line 99999999 lies above the Nyquist line 1024"):
        lptv.identify(d["u"], d["y"], na=2, nb=1, ka=3, kb=3, w0=d["w0"], lines=np.arange(1, 10 ** 8))


def test_select_refuses_a_grid_above_its_bound_before_any_fit():
    from lptv.examples import paper_measurements
    from lptv.batch.selection import MAX_GRID

    d = paper_measurements(seed=1, periods=4)
    with pytest.raises(ValueError, match=rf"68921 structures .* more than lptv.selection.MAX_GRID = {MAX_GRID}"):
        lptv.select(d["u"], d["y"], w0=d["w0"], na=range(41), nb=range(41), k=range(41), executor="serial")


# ------------------------------------------------------------------------------ exit status

@pytest.mark.parametrize("every", [1, 2])
def test_montecarlo_exits_1_when_fits_failed(tmp_path, capsys, monkeypatch, every):
    """Fits that fail (here every fit, or every other one, by a fit that raises) are rows of
    fits.csv, and the command's status says so: 1, as for lptv identify FILES... ."""
    import lptv.batch.study as study

    real, calls = study._fit, []

    def failing(data, method, fit):
        calls.append(1)
        if len(calls) % every == 0:
            raise RuntimeError("the fit failed")
        return real(data, method, fit)

    monkeypatch.setattr(study, "_fit", failing)
    lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1).save(tmp_path / "m.json")
    rc = cli.main(["montecarlo", "--model", str(tmp_path / "m.json"), "--excited", "1-20", "--samples", "128",
                   "--runs", "4", "--periods", "4", "--workers", "1", "--out", str(tmp_path / "mc")])
    err = capsys.readouterr().err
    assert rc == 1 and f"{4 // every} of 4 fits failed" in err and "Traceback" not in err, err
    assert (tmp_path / "mc" / "fits.csv").exists()


def test_montecarlo_of_a_model_whose_bound_is_singular_is_one_line(tmp_path, capsys):
    """b = 0: the output carries no signal and the Cramer-Rao bound does not exist."""
    lptv.Model([[2.0], [1.0]], [[0.0]], w0=0.1).save(tmp_path / "m.json")
    rc = cli.main(["montecarlo", "--model", str(tmp_path / "m.json"), "--excited", "1-20", "--samples", "128",
                   "--runs", "2", "--periods", "4", "--workers", "1", "--out", str(tmp_path / "mc")])
    err = capsys.readouterr().err
    assert rc == 1 and err.count("\n") == 1 and "singular" in err, err


# ------------------------------------------------------------------------------ the memory budget

def _npz_declaring(path, shape):
    """An NPZ whose members' headers declare ``shape`` (float64) but hold no data."""
    import io
    import zipfile

    with zipfile.ZipFile(path, "w") as z:
        for name in ("u", "y"):
            b = io.BytesIO()
            np.lib.format.write_array_header_2_0(b, {"descr": "<f8", "fortran_order": False, "shape": shape})
            z.writestr(name + ".npy", b.getvalue())
    return path


def test_an_npz_declaring_terabytes_is_refused_before_any_allocation(tmp_path):
    p = _npz_declaring(tmp_path / "huge.npz", (1_000_000, 1_000_000))
    with pytest.raises(FileError, match=r"the NPZ file declares 16 TB of samples \('[uy]': 1000000000000 "
                                        r"values\), more than lptv's memory budget"):
        lptv.read_measurements(p)
    r = subprocess.run(LPTV + ["identify", str(p), "--na", "1", "--nb", "0"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and "memory budget" in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_a_mat73_dataset_declaring_terabytes_is_refused(tmp_path):
    h5py = pytest.importorskip("h5py")
    p = tmp_path / "huge.mat"
    with h5py.File(p, "w", userblock_size=512) as f:
        for name in ("u", "y"):
            f.create_dataset(name, shape=(1_000_000, 1_000_000), dtype="f8", chunks=(1, 1000))
    with open(p, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file".ljust(128))
    with pytest.raises(FileError, match=r"the MATLAB v7.3 file declares 16 TB of samples"):
        lptv.read_measurements(p)


def test_the_budget_is_a_setting_and_files_within_it_read(tmp_path, monkeypatch):
    p = tmp_path / "r.npz"
    np.savez(p, u=np.ones((4, 256)), y=np.ones((4, 256)), w0=1.0)       # 16 kB as float64
    monkeypatch.setenv("LPTV_MEMORY_BUDGET", "10K")
    with pytest.raises(FileError, match=r"declares 16.4 kB of samples .* budget of 10.2 kB"):
        lptv.read_measurements(p)
    monkeypatch.setenv("LPTV_MEMORY_BUDGET", "1M")
    assert lptv.read_measurements(p).u.shape == (4, 256)
    monkeypatch.setenv("LPTV_MEMORY_BUDGET", "lots")
    with pytest.raises(FileError, match="LPTV_MEMORY_BUDGET must be a number of bytes"):
        lptv.read_measurements(p)


# ------------------------------------------------------------------------------ drift and transient

def _filtered_record(P=6, N=256, seed=0, transient=False):
    """A periodic random-phase input (NumPy) through a second-order filter (scipy.signal), in
    steady state or from rest, with 1 % noise: made outside lptv."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    X = np.zeros(N // 2 + 1, complex)
    X[1:40] = np.exp(2j * np.pi * rng.random(39))
    u1 = np.fft.irfft(X, N) * N / np.sqrt(39)
    b, a = signal.butter(2, 0.15)
    u = np.tile(u1, P + (0 if transient else 4))
    y = signal.lfilter(b, a, u)
    if not transient:
        u, y = u[4 * N:], y[4 * N:]
    u = u.reshape(P, N) + 0.01 * rng.standard_normal((P, N))
    y = y.reshape(P, N) + 0.01 * np.std(y) * rng.standard_normal((P, N))
    return u, y


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_linear_drift_is_called_a_drift_and_detrend_removes_it(tmp_path, seed):
    u, y = _filtered_record(seed=seed)
    P, N = y.shape
    drift = 0.05 * np.std(y) * (np.arange(P * N) / N).reshape(P, N)       # 5 % of y's std per period
    c = lptv.check_record(u, y + drift, warn=False)
    assert any("output drifts" in m and "--detrend" in m for m in c.messages), c.messages
    assert not any(m.startswith("the first period differs") for m in c.messages), c.messages
    assert not any("input drifts" in m for m in c.messages), c.messages
    np.savez(tmp_path / "d.npz", u=u, y=y + drift, w0=1.0)
    m = lptv.read_measurements(tmp_path / "d.npz", detrend=True)
    assert lptv.check_record(m.u, m.y, warn=False).ok
    # the trend is gone and the periods' shape kept: within the noise of the record without drift
    np.testing.assert_allclose(m.y - m.y.mean(), y - y.mean(), atol=6 * 0.01 * np.std(y))


@pytest.mark.parametrize("seed", [0, 1])
def test_a_start_up_transient_is_still_a_transient_and_no_drift(seed):
    u, y = _filtered_record(seed=seed, transient=True)
    c = lptv.check_record(u, y, warn=False)
    assert any("start-up transient" in m for m in c.messages), c.messages
    assert not any("drifts" in m for m in c.messages), c.messages


@pytest.mark.parametrize("seed", range(5))
def test_a_steady_record_is_neither(seed):
    u, y = _filtered_record(seed=seed)
    assert lptv.check_record(u, y, warn=False).ok


def test_a_batch_with_model_errors_exits_3_and_says_which(tmp_path, capsys):
    """The paper's LPTV records fitted as LTI (ka = kb = 0): every file fitted, every verdict
    rejects the structure; the same records with the right structure exit 0."""
    import csv

    from lptv.examples import paper_measurements

    files = []
    for s in (1, 2):
        d = paper_measurements(seed=s, periods=4)
        files.append(str(tmp_path / f"rec{s}.npz"))
        np.savez(files[-1], u=d["u"], y=d["y"], w0=d["w0"])
    base = ["identify", *files, "--na", "2", "--nb", "1", "--lines", "4-240", "--workers", "1"]
    assert cli.main(base + ["--ka", "0", "--kb", "0", "--out", str(tmp_path / "lti")]) == 3
    out = capsys.readouterr().out
    assert out.count("MODEL ERRORS") == 2 and "2 with model errors (column model_ok)" in out, out
    with open(tmp_path / "lti" / "results.csv") as f:
        assert [r["model_ok"] for r in csv.DictReader(f)] == ["False", "False"]
    assert cli.main(base + ["--ka", "3", "--kb", "3", "--out", str(tmp_path / "lptv")]) == 0
    with open(tmp_path / "lptv" / "results.csv") as f:
        assert [r["model_ok"] for r in csv.DictReader(f)] == ["True", "True"]


@pytest.mark.parametrize("suffix", [".mat", ".npz", ".csv"])
def test_a_transposed_record_with_a_constant_input_is_refused(tmp_path, suffix):
    """The input cannot tell a transposed record (a constant repeats either way); the output can."""
    import scipy.io

    rng = np.random.default_rng(0)
    P, N = 4, 256
    n = np.arange(N)
    y = np.tile(np.sin(2 * np.pi * 3 * n / N) + 0.3 * np.sin(2 * np.pi * 7 * n / N), (P, 1))
    y += 0.01 * rng.standard_normal((P, N))
    u = np.ones((P, N))
    p = tmp_path / ("r" + suffix)
    if suffix == ".mat":
        scipy.io.savemat(p, {"u": u.T, "y": y.T})
    elif suffix == ".npz":
        np.savez(p, u=u.T, y=y.T)
    else:   # the counts exchanged: 256 periods of 4 samples
        p.write_text("u,y\n" + "".join(f"{a},{b}\n" for a, b in zip(u.ravel(), y.ravel())))
    with pytest.raises(FileError, match=r"'y'.*(transposed|--periods)"):
        lptv.read_measurements(p, **({"periods": 256} if suffix == ".csv" else {}))
