"""``lptv identify FILE``: measurement files in, the same model as ``lptv.identify`` out.

The round trips write the demo's own measurements to every supported format and check that the
command reads back the very numbers that went in (so the model agrees with the Python API to
rounding); the error cases check the one-line message, its file name and exit status 2.
"""
import json
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy.io

import lptv
from lptv.apps import cli, fileid
from lptv.examples import paper_measurements

PAPER_ARGS = ["--na", "2", "--nb", "1", "--ka", "3", "--kb", "3", "--lines", "1-243"]
PAPER_KW = dict(na=2, nb=1, ka=3, kb=3, lines=range(1, 244))
# The command as a separate process, from this tree (PYTHONPATH is inherited): the same
# entry point as the installed ``lptv`` script, which test_console_script_entry_point checks.
LPTV = [sys.executable, "-m", "lptv"]


# ------------------------------------------------------------------------------ writers

def write_csv(path, u, y, delimiter=","):
    """Periods stacked, one sample a row, every digit kept; a time column the reader must ignore."""
    t = np.arange(u.size, dtype=float)
    np.savetxt(path, np.column_stack([t, u.ravel(), y.ravel()]), fmt="%.17g", delimiter=delimiter,
               header=delimiter.join("tuy"), comments="")
    return path


def write_mat73(path, **variables):
    """An HDF5 file laid out as MATLAB 7.3 writes one: a 512-byte userblock with the 128-byte
    MAT header, each variable a dataset with its MATLAB_class, stored column-major (transposed)."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            value = np.asarray(value)
            if value.dtype.kind in "US":
                data, cls = np.frombuffer(str(value).encode("utf-16-le"), np.uint16), "char"
            else:
                data, cls = np.atleast_2d(value).T, "double"
            ds = f.create_dataset(name, data=data)
            ds.attrs["MATLAB_class"] = np.bytes_(cls)
    text = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  6 12:00:00 2025 HDF5 schema 1.00 ."
    header = text.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM"
    with open(path, "r+b") as f:
        f.write(header)
    return path


@pytest.fixture(scope="module")
def paper():
    d = paper_measurements(seed=7, periods=8)
    ref = lptv.identify(d["u"], d["y"], w0=d["w0"], **PAPER_KW)
    return d, ref


def identify_cli(capsys, *argv):
    rc = cli.main(["identify", *map(str, argv)])
    out, err = capsys.readouterr()
    return rc, out, err


# ------------------------------------------------------------------------------ round trips

@pytest.mark.parametrize("fmt", ["csv", "npz", "mat5", "mat73"])
def test_round_trip_gives_the_python_api_model(fmt, paper, tmp_path, capsys):
    d, ref = paper
    u, y, w0 = d["u"], d["y"], d["w0"]
    P = u.shape[0]
    if fmt == "csv":
        src, extra = write_csv(tmp_path / "meas.csv", u, y), ["--periods", P, "--w0", w0]
    elif fmt == "npz":
        src, extra = tmp_path / "meas.npz", []
        np.savez(src, u=u, y=y, w0=w0)
    elif fmt == "mat5":
        src, extra = tmp_path / "meas.mat", ["--period", 2 * np.pi / w0]
        scipy.io.savemat(src, {"u": u, "y": y})
    else:
        src, extra = write_mat73(tmp_path / "meas.mat", u=u, y=y, w0=w0), []
    out = tmp_path / "out"
    rc, stdout, err = identify_cli(capsys, src, *PAPER_ARGS, *extra, "--out", out)
    assert rc == 0, err
    assert err == ""
    model = lptv.Model.load(out / "model.json")
    # The same samples go in, so only rounding (and 2 pi / (2 pi / w0) for --period) differs.
    assert model.w0 == pytest.approx(w0, rel=1e-15)
    np.testing.assert_allclose(model.a, ref.model.a, rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.b, ref.model.b, rtol=0, atol=1e-12)
    assert ref.summary().splitlines()[-1] in stdout  # the verdict line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["periods"] == P and summary["samples_per_period"] == u.shape[1]
    assert summary["n_free_parameters"] == 34 and summary["n_lines"] == 243
    assert summary["fraction_above_0db"] == pytest.approx(ref.fraction_above_0db, abs=1e-12)
    assert summary["residue_ok"] == ref.residue_ok
    page = (out / "report.html").read_text()
    for png in ("bode", "normalized_residue", "residue_tests", "frozen_poles_zeros", "coefficients"):
        assert f'alt="{png}.png"' in page and (out / f"{png}.png").stat().st_size > 1000


def test_mat73_writer_looks_like_matlab(tmp_path):
    src = write_mat73(tmp_path / "m.mat", u=np.zeros((2, 3)), y=np.zeros((2, 3)))
    assert h5py.is_hdf5(src)
    assert src.read_bytes()[:19] == b"MATLAB 7.3 MAT-file"
    with pytest.raises(NotImplementedError, match="v7.3"):  # scipy reads the version bytes
        scipy.io.loadmat(src)


def test_mat73_is_read_untransposed_and_vectors_split_by_periods(tmp_path):
    u = np.arange(15.0).reshape(3, 5)  # P = 3 periods of N = 5: any transposition shows
    y = -u
    m = lptv.read_measurements(write_mat73(tmp_path / "a.mat", u=u, y=y))
    assert m.format == "MAT v7.3" and m.w0 is None
    np.testing.assert_array_equal(m.u, u)
    np.testing.assert_array_equal(m.y, y)
    v = lptv.read_measurements(write_mat73(tmp_path / "v.mat", u=u.ravel(), y=y.ravel()), periods=3)
    np.testing.assert_array_equal(v.u, u)
    scipy.io.savemat(tmp_path / "c.mat", {"u": u.ravel()[:, None], "y": y.ravel()})  # column, row
    np.testing.assert_array_equal(lptv.read_measurements(tmp_path / "c.mat", periods=3).u, u)


def test_parse_lines():
    np.testing.assert_array_equal(fileid.parse_lines("1-3, 7,9-10"), [1, 2, 3, 7, 9, 10])
    np.testing.assert_array_equal(fileid.parse_lines("1-243"), np.arange(1, 244))


# ------------------------------------------------------------------------------ small problem

N_SMALL, TS = 64, 0.1
W0_SMALL = 2 * np.pi / (N_SMALL * TS)


@pytest.fixture(scope="module")
def small():
    """Discrete-time y[t+1] - 0.5 y[t] = u[t], 4 noisy periods."""
    m = lptv.Model([[-0.5], [1.0]], [[1.0]], w0=W0_SMALL, ts=TS)
    ms = lptv.multisine(range(1, 25), N_SMALL, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), N_SMALL)
    rng = np.random.default_rng(1)
    u = ms.periods(4) + 1e-3 * rng.standard_normal((4, N_SMALL))
    y = np.tile(y1, (4, 1)) + 1e-3 * rng.standard_normal((4, N_SMALL))
    return u, y


def test_discrete_time_takes_w0_from_ts_and_harmonic_lists(small, tmp_path, capsys):
    u, y = small
    src = tmp_path / "dt.npz"
    np.savez(src, u=u, y=y)
    rc, out, err = identify_cli(capsys, src, "--na", 1, "--nb", 0, "--ka", "1,0", "--kb", 1,
                                "--ts", TS, "--out", tmp_path / "o")
    assert rc == 0, err
    ref = lptv.identify(u, y, na=1, nb=0, ka=[1, 0], kb=1, w0=W0_SMALL, ts=TS)
    model = lptv.Model.load(tmp_path / "o" / "model.json")
    assert model.ts == TS and model.w0 == pytest.approx(W0_SMALL, rel=1e-15)
    np.testing.assert_allclose(model.a, ref.model.a, rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.b, ref.model.b, rtol=0, atol=1e-12)
    assert abs(model.a[0, 1] + 0.5) < 0.01  # the mean system is the true one


def test_known_coefficient_and_method(small, tmp_path, capsys):
    u, y = small
    src = write_csv(tmp_path / "dt.csv", u, y, delimiter=";")
    rc, out, err = identify_cli(capsys, src, "--na", 1, "--nb", 0, "--ts", TS,
                                "--periods", 4, "--known", "a1=2", "--method", "gtls",
                                "--out", tmp_path / "o")
    assert rc == 0, err
    ref = lptv.identify(u, y, na=1, nb=0, w0=W0_SMALL, ts=TS, known={"a1": 2.0}, method="gtls")
    model = lptv.Model.load(tmp_path / "o" / "model.json")
    assert model.a[1, 0] == 2.0
    np.testing.assert_allclose(model.a, ref.model.a, rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.b, ref.model.b, rtol=0, atol=1e-12)
    assert "method gtls" in out


def test_warnings_are_printed_and_kept(small, tmp_path, capsys):
    u, y = small
    src = tmp_path / "dt.npz"
    np.savez(src, u=u, y=y, w0=W0_SMALL)
    with pytest.warns(lptv.IdentifiabilityWarning):
        ref = lptv.identify(u, y, na=1, nb=0, ka=1, kb=1, w0=W0_SMALL, ts=TS)
    rc, out, err = identify_cli(capsys, src, "--na", 1, "--nb", 0, "--ka", 1, "--kb", 1,
                                "--ts", TS, "--out", tmp_path / "o")
    # the data do not determine the over-parametrised model: not called consistent, exit status 4
    assert rc == 4 and err == ""
    assert "verdict: NOT DETERMINED" in out
    assert f"warning: {ref.warnings[0]}" in out.splitlines()
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["warnings"] == list(ref.warnings)


def test_command_default_output_folder(small, tmp_path):
    u, y = small
    np.savez(tmp_path / "bench 1.npz", u=u, y=y)
    p = subprocess.run([*LPTV, "identify", "bench 1.npz", "--na", "1", "--nb", "0", "--ts", str(TS)],
                       cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert "consistent with the noise" in p.stdout
    assert lptv.Model.load(tmp_path / "bench 1-lptv" / "model.json").na == 1


# ------------------------------------------------------------------------------ errors

def _bad_csv(tmp_path, small, *, header="u,y", drop=0, cell=None):
    u, y = small
    rows = [header] + [f"{a:.17g},{b:.17g}" for a, b in zip(u.ravel(), y.ravel())]
    if drop:
        rows = rows[:-drop]
    if cell:
        row, text = cell
        rows[row] = rows[row].split(",")[0] + "," + text
    path = tmp_path / "data.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


def _npz(tmp_path, name="data.npz", **arrays):
    path = tmp_path / name
    np.savez(path, **arrays)
    return path


def _raw(tmp_path, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    return path


SMALL_ARGS = ["--na", "1", "--nb", "0", "--ts", str(TS)]

# (name, make the file, extra arguments, expected text of the error)
ERRORS = [
    ("missing column", lambda t, s: _bad_csv(t, s, header="time,u"), ["--periods", "4"],
     "column 'y' is missing (the header has 'time', 'u')"),
    ("no header", lambda t, s: _bad_csv(t, s, header="0.5,0.25"), ["--periods", "4"],
     "the first row must be a header"),
    ("not whole periods", lambda t, s: _bad_csv(t, s, drop=3), ["--periods", "4"],
     "column 'u' has 253 samples, not a whole number of periods"),
    ("NaN in CSV", lambda t, s: _bad_csv(t, s, cell=(6, "nan")), ["--periods", "4"],
     "line 7: column 'y' is NaN or inf"),
    ("text in CSV", lambda t, s: _bad_csv(t, s, cell=(9, "abc")), ["--periods", "4"],
     "line 10: column 'y' 'abc' is not a number"),
    ("empty cell", lambda t, s: _bad_csv(t, s, cell=(2, "")), ["--periods", "4"],
     "line 3: column 'y' is empty"),
    ("CSV without --periods", lambda t, s: _bad_csv(t, s), [],
     "--periods is required for a CSV record"),
    ("binary CSV", lambda t, s: _raw(t, "data.csv", b"\xff\xfe\x00\x81" * 10), ["--periods", "4"],
     "not a text file"),
    ("empty CSV", lambda t, s: _raw(t, "data.csv", b""), ["--periods", "4"], "the file is empty"),
    ("unknown extension", lambda t, s: _raw(t, "data.xlsx", b"PK"), [],
     "unknown file type '.xlsx' (expected .csv, .npz or .mat)"),
    ("no such file", lambda t, s: t / "data.npz", [], "no such file"),
    ("damaged NPZ", lambda t, s: _raw(t, "data.npz", b"not a zip archive"), [], "cannot read as NPZ"),
    ("NPZ without u", lambda t, s: _npz(t, y=s[1]), [], "array 'u' is missing (the file has y (4 x 64)); name the input and output channels with --input NAME"),
    ("NaN in NPZ", lambda t, s: _npz(t, u=np.where(np.arange(64) == 3, np.nan, s[0]), y=s[1]), [],
     "variable 'u' is NaN or inf at period 1, sample 4 (counting from 1)"),
    ("shapes differ", lambda t, s: _npz(t, u=s[0], y=s[1][:, :-1]), [],
     "u and y differ in shape: u is 4 x 64 and y is 4 x 63"),
    ("one period", lambda t, s: _npz(t, u=s[0][:1], y=s[1][:1]), ["--periods", "1"],
     "the record holds only 1 period; the noise model needs at least 2"),
    ("vector without --periods", lambda t, s: _npz(t, u=s[0].ravel(), y=s[1].ravel()), [],
     "variable 'u' is a vector of 256 samples: give --periods"),
    ("periods disagree", lambda t, s: _npz(t, u=s[0], y=s[1]), ["--periods", "3"],
     "variable 'u' holds 4 periods (4 x 64) but --periods says 3"),
    ("complex data", lambda t, s: _npz(t, u=s[0] + 1j, y=s[1]), [], "variable 'u' is complex"),
    ("bad w0 in file", lambda t, s: _npz(t, u=s[0], y=s[1], w0=[1.0, 2.0]), [],
     "variable 'w0' must be a positive scalar"),
    ("MAT without y", lambda t, s: (scipy.io.savemat(t / "data.mat", {"u": s[0], "x": s[1]}),
                                    t / "data.mat")[1], [], "variable 'y' is missing (the file has u (4 x 64), x (4 x 64)); name the input"),
    ("damaged MAT", lambda t, s: _raw(t, "data.mat", b"MATLAB 5.0 MAT-file" + b"\x00" * 50), [],
     "cannot read as a MATLAB file"),
    ("MAT v7.3 char", lambda t, s: write_mat73(t / "data.mat", u=s[0], y="text"), [],
     "variable 'y' is a MATLAB char, not a numeric array"),
    ("damaged MAT v7.3", lambda t, s: _raw(t, "data.mat", b"MATLAB 7.3 MAT-file" + b"\x00" * 600), [],
     "cannot read as a MATLAB v7.3 (HDF5) file"),
]

OPTION_ERRORS = [
    (["--lines", "9-5"], "--lines: '9-5' is an empty range"),
    (["--lines", "1-5,x"], "--lines: 'x' is not a line number or a range like 1-243"),
    (["--lines", "1-5,3"], "--lines: line 3 is given twice"),
    (["--ka", "1,x"], "--ka: '1,x' must be an integer or a comma list of integers"),
    (["--kb", "-1"], "--kb: harmonic counts must be >= 0"),
    (["--known", "a1"], "--known: 'a1' is not of the form name=number"),
    (["--periods", "0"], "--periods must be a positive integer, got 0"),
    (["--max-iter", "-1"], "--max-iter must be >= 0"),
    (["--tol", "0"], "--tol must be a positive number"),
    (["--w0", "-1"], "--w0 must be a positive number, got -1"),
    (["--w0", "1.5"], "--w0 and --ts 0.1 give 41.8879 samples per period, but the record has 64"),
    # from the library, passed on with the file name
    (["--lines", "1-40"], "lines: line 40 lies above the Nyquist line 32 of the data"),
    (["--known", "c1=1"], "known: 'c1' is not a coefficient name"),
    (["--ka", "1,1,1"], "ka must give one harmonic count per coefficient (2), got 3"),
]


def _check_one_line_error(rc, out, err, name, text):
    assert rc == 2
    assert "Traceback" not in err and out == ""
    assert err.count("\n") == 1, err
    assert err.startswith(f"lptv identify: error: {name}: "), err
    assert text in err, err


@pytest.mark.parametrize("make, extra, text", [e[1:] for e in ERRORS], ids=[e[0] for e in ERRORS])
def test_bad_file_gives_one_line_error(make, extra, text, small, tmp_path, capsys):
    src = make(tmp_path, small)
    rc, out, err = identify_cli(capsys, src, *SMALL_ARGS, *extra, "--out", tmp_path / "o")
    _check_one_line_error(rc, out, err, src, text)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("extra, text", OPTION_ERRORS, ids=[" ".join(e[0]) for e in OPTION_ERRORS])
def test_bad_option_gives_one_line_error(extra, text, small, tmp_path, capsys):
    src = _npz(tmp_path, u=small[0], y=small[1])
    rc, out, err = identify_cli(capsys, src, *SMALL_ARGS, *extra, "--out", tmp_path / "o")
    _check_one_line_error(rc, out, err, src, text)


def test_period_must_be_known_and_agree_with_the_file(small, tmp_path, capsys):
    src = _npz(tmp_path, u=small[0], y=small[1])
    rc, out, err = identify_cli(capsys, src, "--na", 1, "--nb", 0)
    _check_one_line_error(rc, out, err, src, "the period is unknown: give --w0 (rad/s) or --period (s)")
    src = _npz(tmp_path, "w.npz", u=small[0], y=small[1], w0=2.0)
    rc, out, err = identify_cli(capsys, src, "--na", 1, "--nb", 0, "--period", 1.0)
    _check_one_line_error(rc, out, err, src, "--period gives w0 = 6.283185307 rad/s but the file says w0 = 2")


def test_degenerate_record_error_from_the_library(tmp_path, capsys):
    # All-zero records: the library's data diagnostics name the dead input (this used to surface
    # as a failed normalisation), passed on in one line with the file name.
    src = _npz(tmp_path, u=np.zeros((4, 64)), y=np.zeros((4, 64)))
    rc, out, err = identify_cli(capsys, src, *SMALL_ARGS)
    _check_one_line_error(rc, out, err, src, "u: the input spectrum is zero on the fitted lines")


def test_unwritable_output_folder(small, tmp_path, capsys):
    src = _npz(tmp_path, u=small[0], y=small[1])
    taken = tmp_path / "taken"
    taken.write_text("a file where the output folder should go")
    rc, out, err = identify_cli(capsys, src, *SMALL_ARGS, "--out", taken)
    assert rc == 2 and "Traceback" not in err and err.count("\n") == 1
    assert err == f"lptv identify: error: {taken}: File exists\n"


def test_command_exit_status_and_stderr(tmp_path):
    bad = tmp_path / "data.csv"
    bad.write_text("t,u\n0,1\n1,2\n")
    p = subprocess.run([*LPTV, "identify", str(bad), "--na", "1", "--nb", "0", "--w0", "1",
                        "--periods", "2"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr == (f"lptv identify: error: {bad}: column 'y' is missing (the header has 't', 'u'); name "
                        "the input and output channels with --input NAME --output NAME (u=, y= of "
                        "lptv.read_measurements)\n")
    p = subprocess.run([*LPTV, "identify", str(bad), "--nb", "0"], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 2 and "the following arguments are required: --na" in p.stderr
    assert "Traceback" not in p.stderr


def test_console_script_entry_point():
    """The installed ``lptv`` script and ``python -m lptv`` call the same ``main``."""
    import importlib
    import re

    pyproject = (Path(__file__).resolve().parents[2] / "pyproject.toml").read_text()
    target = re.search(r'^lptv\s*=\s*"([\w.]+):(\w+)"', pyproject, flags=re.M)
    assert target, "pyproject.toml declares no lptv script"
    assert getattr(importlib.import_module(target.group(1)), target.group(2)) is cli.main
    p = subprocess.run([*LPTV, "--help"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and p.stdout.startswith("usage: lptv ")


@pytest.mark.parametrize("lines, text", [
    ("2-40,2147483647", "lines: line 2147483647 lies above the Nyquist line 128 of the data"),
    ("2-40,9223372036854775808", "--lines: '9223372036854775808' goes beyond 2147483647, the largest "
                                 "value the core takes"),
])
def test_lines_beyond_int_give_one_line_error(lines, text, tmp_path, capsys):
    # 1 / (s + 2) at w0 = 0.1, 4 noisy periods of 256 samples
    m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
    ms = lptv.multisine(range(1, 60), 256, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    rng = np.random.default_rng(1)
    src = _npz(tmp_path, "good.npz", u=ms.periods(4) + 1e-3 * rng.standard_normal((4, 256)),
               y=np.tile(y1, (4, 1)) + 1e-3 * rng.standard_normal((4, 256)), w0=0.1)
    rc, out, err = identify_cli(capsys, src, "--na", 1, "--nb", 0, "--ka", 1, "--lines", lines,
                                "--out", tmp_path / "o")
    _check_one_line_error(rc, out, err, src, text)
    assert not (tmp_path / "o").exists()


def test_bootstrap_covariance_option(small, tmp_path, capsys):
    """--covariance bootstrap gives the Python API's bootstrap covariance (same seed) in
    model.json; with several files it is refused in one line."""
    u, y = small
    src = tmp_path / "dt.npz"
    np.savez(src, u=u, y=y)
    rc, out, err = identify_cli(capsys, src, "--na", 1, "--nb", 0, "--ts", TS, "--method", "sml",
                                "--covariance", "bootstrap", "--bootstrap", 40, "--out", tmp_path / "o")
    assert rc == 0, err
    ref = lptv.identify(u, y, na=1, nb=0, w0=W0_SMALL, ts=TS, method="sml", covariance="bootstrap",
                        bootstrap=40, seed=0)
    model = lptv.Model.load(tmp_path / "o" / "model.json")
    np.testing.assert_allclose(model.covariance, ref.covariance, rtol=1e-9, atol=0)
    rc, out, err = identify_cli(capsys, src, src, "--na", 1, "--nb", 0, "--ts", TS,
                                "--covariance", "bootstrap")
    assert rc == 2 and "one record at a time" in err and err.count("\n") == 1


def test_moderated_noise_option(tmp_path, capsys):
    """--noise moderated gives the Python API's fit with noise='moderated' (model.json, and the
    summary says which noise); with several files it is refused in one line."""
    import json

    from lptv.examples import system_measurements

    d = system_measurements("discrete", seed=2, periods=4)
    src = tmp_path / "dt.npz"
    np.savez(src, u=d["u"], y=d["y"])
    st = d["structure"]
    args = ["--na", st["na"], "--nb", st["nb"], "--ka", ",".join(map(str, st["ka"])),
            "--kb", ",".join(map(str, st["kb"])), "--ts", 1.0, "--method", "sml"]
    rc, out, err = identify_cli(capsys, src, *args, "--noise", "moderated", "--out", tmp_path / "o")
    assert rc == 0, err
    ref = lptv.identify(d["u"], d["y"], **st, w0=d["w0"], ts=1.0, method="sml", noise="moderated")
    model = lptv.Model.load(tmp_path / "o" / "model.json")
    np.testing.assert_allclose(model.covariance, ref.covariance, rtol=1e-9, atol=0)
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["noise"] == "moderated"
    # a batch weighs every file's fit by its own moderated noise, and says so per row
    src2 = tmp_path / "dt2.npz"
    np.savez(src2, u=d["u"], y=d["y"])
    rc, out, err = identify_cli(capsys, src, src2, *args, "--noise", "moderated", "--out", tmp_path / "b")
    assert rc in (0, 3), err
    import csv
    with open(tmp_path / "b" / "results.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["noise"] for r in rows] == ["moderated", "moderated"]
    assert float(rows[0]["a0.re0"]) == pytest.approx(ref.eta[0], rel=1e-9)


def test_remove_disturbances_option(tmp_path, capsys):
    """--remove-disturbances gives the Python API's fit with disturbances='remove': the hum off
    the grid is named in the printed summary and in summary.json, the verdict keeps the true
    structure; with several files it is refused in one line."""
    from lptv.examples import system_measurements

    d = system_measurements("third_order", seed=0, periods=8)
    u, y = np.asarray(d["u"]), np.asarray(d["y"])
    P, N = y.shape
    n = np.arange(P * N)
    y = (y.reshape(-1) + 5 * np.std(y - y.mean(0)) * np.sqrt(2) * np.cos(2 * np.pi * 85.37 * n / N)).reshape(P, N)
    src = tmp_path / "hum.npz"
    np.savez(src, u=u, y=y)
    st = d["structure"]
    args = ["--na", st["na"], "--nb", st["nb"], "--ka", ",".join(map(str, st["ka"])),
            "--kb", ",".join(map(str, st["kb"])), "--w0", d["w0"],
            "--lines", f"{d['lines'][0]}-{d['lines'][-1]}"]
    rc, out, err = identify_cli(capsys, src, *args, "--remove-disturbances", "--out", tmp_path / "o")
    assert rc == 0, err
    assert "removed before the fit: y: a sinusoid at line 85.370" in out
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert [round(x["line"], 2) for x in summary["disturbances_removed"]] == [85.37]
    assert summary["model_ok"] is True
    ref = lptv.identify(u, y, **st, w0=d["w0"], lines=d["lines"], disturbances="remove")
    np.testing.assert_allclose(lptv.Model.load(tmp_path / "o" / "model.json").covariance, ref.covariance,
                               rtol=1e-9, atol=0)
    # the default takes the whole record's noise (the hum's leakage correlates the periods'
    # lines, METHOD.md section 20) and keeps the structure
    rc, out, err = identify_cli(capsys, src, *args, "--out", tmp_path / "o3")
    assert rc == 0 and "from the whole record" in out, out
    rc, out, err = identify_cli(capsys, src, *args, "--noise", "sample", "--out", tmp_path / "o2")
    # on the periods' own variances the verdict rejects the fit (residues below the noise): exit status 3
    assert rc == 3 and "too small" in out and "lptv.disturbances" in out and "hint: " in out
    assert "--remove-disturbances finds and removes it" in out
    rc, out, err = identify_cli(capsys, src, src, *args, "--remove-disturbances")
    assert rc == 2 and "--remove-disturbances takes one record" in err and err.count("\n") == 1
