"""Records as their users name them: channels by name, fs from a time column or a stored variable.

A rig's record as numpy and scipy write it (a CSV with the header ``time,force,displacement``, a
.mat with ``force``, ``disp`` and ``fs``, long 1-D records) is read through the command line and
``lptv.read_measurements``; the periods read back must be the very samples written (reshaped
here by hand), and the model the one ``lptv.identify`` gives on them.
"""
import json

import h5py
import numpy as np
import pytest
import scipy.io

import lptv
from lptv.apps import cli
from lptv.records.measurements import FileError

FS, T0, P = 8.0, 8.0, 4          # 64 samples per period
N = int(FS * T0)
W0 = 2 * np.pi / T0
FIT = ["--na", "1", "--nb", "0"]


@pytest.fixture(scope="module")
def record():
    """4 noisy periods of 1 / (s + 2) under a 20-line multisine, as (P, N) arrays."""
    m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=W0)
    ms = lptv.multisine(range(1, 21), N, seed=3)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), N)
    rng = np.random.default_rng(4)
    u = ms.periods(P) + 1e-3 * rng.standard_normal((P, N))
    y = np.tile(y1, (P, 1)) + 1e-3 * rng.standard_normal((P, N))
    return u, y


@pytest.fixture(scope="module")
def reference(record):
    return lptv.identify(*record, na=1, nb=0, w0=W0)


def rig_csv(path, u, y, t=None, header="time,force,displacement"):
    t = np.arange(u.size) / FS if t is None else t
    np.savetxt(path, np.column_stack([t, u.ravel(), y.ravel()]), fmt="%.17g", delimiter=",",
               header=header, comments="")
    return path


def identify_cli(capsys, *argv):
    rc = cli.main(["identify", *map(str, argv)])
    out, err = capsys.readouterr()
    return rc, out, err


def assert_same_model(path, reference):
    model = lptv.Model.load(path)
    assert model.w0 == pytest.approx(W0, rel=1e-12)
    np.testing.assert_allclose(model.a, reference.model.a, rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.b, reference.model.b, rtol=0, atol=1e-12)


# ------------------------------------------------------------------------------ CSV with a time column

def test_csv_with_a_time_column_and_named_channels(record, reference, tmp_path, capsys):
    u, y = record
    src = rig_csv(tmp_path / "rig.csv", u, y)
    m = lptv.read_measurements(src, u="force", y="displacement", period=T0)
    assert (m.fs, m.fs_source, m.input, m.output) == (FS, "column 'time'", "force", "displacement")
    np.testing.assert_array_equal(m.u, u)
    np.testing.assert_array_equal(m.y, y)
    # the command: no --fs, no --periods; the first line says where fs came from
    rc, out, err = identify_cli(capsys, src, "--input", "force", "--output", "displacement", "--period", T0,
                                *FIT, "--out", tmp_path / "o")
    assert rc == 0, err
    first = out.splitlines()[0]
    assert f"{P} periods of {N} samples" in first and "fs = 8 Hz from column 'time'" in first
    assert "input 'force', output 'displacement'" in first
    assert_same_model(tmp_path / "o" / "model.json", reference)
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["fs"] == FS and summary["fs_source"] == "column 'time'" and summary["output"] == "displacement"


def test_the_default_channel_names_and_a_wrong_name_list_what_the_file_has(record, tmp_path, capsys):
    src = rig_csv(tmp_path / "rig.csv", *record)
    rc, out, err = identify_cli(capsys, src, "--period", T0, *FIT)
    assert rc == 2 and out == "" and err.count("\n") == 1
    assert "column 'u' is missing (the header has 'time', 'force', 'displacement')" in err
    assert "--input NAME --output NAME" in err
    with pytest.raises(FileError, match=r"column 'disp', the output named by --output \(y=\), is missing "
                                        r"\(the header has 'time', 'force', 'displacement'\)"):
        lptv.read_measurements(src, u="force", y="disp", period=T0)
    # names match up to case
    assert lptv.read_measurements(src, u="FORCE", y="Displacement", period=T0).input == "force"


def test_names_match_a_header_with_a_unit_and_an_ambiguous_name_lists_the_candidates(record, tmp_path, capsys):
    u, y = record
    src = rig_csv(tmp_path / "units.csv", u, y, header="time [s],Force (N),displacement [m]")
    m = lptv.read_measurements(src, u="force", y="DISPLACEMENT", period=T0)
    assert (m.input, m.output, m.fs) == ("Force (N)", "displacement [m]", FS)
    assert m.w0 == 2 * np.pi / T0                       # the period given, as the fundamental
    np.testing.assert_array_equal(m.u, u)
    assert lptv.read_measurements(src, u="force (N)", y="displacement", period=T0).input == "Force (N)"
    # a unit given on both sides must agree
    with pytest.raises(FileError, match=r"column 'force \[kN\]', the input named by --input \(u=\), is missing"):
        lptv.read_measurements(src, u="force [kN]", y="displacement", period=T0)
    both = rig_csv(tmp_path / "two.csv", u, y, header="time,force [N],force (kN)")
    with pytest.raises(FileError, match=r"column 'force' is ambiguous: the file has 'force \[N\]', "
                                        r"'force \(kN\)'; name one of them exactly with --input"):
        lptv.read_measurements(both, u="force", y="force [N]", period=T0)
    rc, out, err = identify_cli(capsys, src, "--input", "force", "--output", "displacement", "--period", T0,
                                *FIT, "--out", tmp_path / "o")
    assert rc == 0, err
    assert "input 'Force (N)', output 'displacement [m]'" in out.splitlines()[0]


def test_several_outputs_are_read_as_channels_of_one_record(record, tmp_path):
    """A list of outputs is a record of several channels (test_mimo_measurements.py); the
    command line takes a comma list to the fit of several channels (test_cli_mimo.py)."""
    u, y = record
    src = tmp_path / "rig.csv"
    np.savetxt(src, np.column_stack([np.arange(u.size) / FS, u.ravel(), y.ravel(), 2 * y.ravel()]), fmt="%.17g",
               delimiter=",", header="time,force,displacement,velocity", comments="")
    m = lptv.read_measurements(src, u="force", y=["displacement", "velocity"], period=T0)
    assert m.u.shape == (P, N, 1) and m.y.shape == (P, N, 2) and m.output == ("displacement", "velocity")
    np.testing.assert_array_equal(m.y[..., 0], y)
    np.testing.assert_array_equal(m.y[..., 1], 2 * y)
    with pytest.raises(FileError, match="channel 'force' is named twice"):
        lptv.read_measurements(src, u="force", y=["displacement", "force"], period=T0)


def test_a_time_column_in_ms_and_the_given_fs_or_periods_take_precedence(record, tmp_path):
    u, y = record
    src = rig_csv(tmp_path / "ms.csv", u, y, t=1000 * np.arange(u.size) / FS, header="t_ms,u,y")
    m = lptv.read_measurements(src, period=T0)
    assert m.fs == FS and m.fs_source == "column 't_ms'" and m.u.shape == (P, N)
    m = lptv.read_measurements(src, fs=2 * FS, period=T0 / 2)       # given: used as it is
    assert m.fs == 2 * FS and m.fs_source is None and m.u.shape == (P, N)
    m = lptv.read_measurements(src, 2)                              # --periods: split by count
    assert m.u.shape == (2, 2 * N) and m.fs is None


def test_a_non_uniform_time_column_is_refused_naming_the_sample(record, tmp_path, capsys):
    u, y = record
    t = np.arange(u.size) / FS
    t[100:] += 0.5 / FS                                   # a sample lost half a step late
    src = rig_csv(tmp_path / "jitter.csv", u, y, t=t)
    with pytest.raises(FileError, match=r"column 'time' is not uniformly sampled: sample 101 \(line 102\) "
                                        r"is at 12.5625 s, 0.1875 s after the previous one"):
        lptv.read_measurements(src, u="force", y="displacement", period=T0)
    rc, out, err = identify_cli(capsys, src, "--input", "force", "--output", "displacement", "--period", T0, *FIT)
    assert rc == 2 and "sample 101 (line 102)" in err and err.count("\n") == 1
    # --fs overrides the time column (it is not read then)
    assert lptv.read_measurements(src, u="force", y="displacement", fs=FS, period=T0).u.shape == (P, N)


def test_fs_from_the_file_needs_the_period_to_split_a_long_record(record, tmp_path):
    src = rig_csv(tmp_path / "rig.csv", *record)
    with pytest.raises(FileError, match=r"period is needed to split the 256 samples \(fs 8 Hz from column 'time'\)"):
        lptv.read_measurements(src, u="force", y="displacement")


# ------------------------------------------------------------------------------ MAT and NPZ

def write_mat73(path, **variables):
    """Variables as MATLAB 7.3 stores them (HDF5, column-major) behind the MAT header."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            ds = f.create_dataset(name, data=np.atleast_2d(np.asarray(value, float)).T)
            ds.attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file".ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM")
    return path


@pytest.mark.parametrize("fmt, stored", [("mat5", "fs"), ("mat5", "Ts"), ("mat73", "dt"), ("npz", "t"),
                                         ("npz", "fs")])
def test_a_file_with_other_names_and_a_stored_sampling(fmt, stored, record, reference, tmp_path, capsys):
    u, y = record
    value = {"fs": FS, "Ts": 1 / FS, "dt": 1 / FS, "t": np.arange(u.size) / FS}[stored]
    variables = {"force": u.ravel(), "disp": y.ravel(), stored: value}     # 1-D long records
    src = tmp_path / ("rig.npz" if fmt == "npz" else "rig.mat")
    if fmt == "npz":
        np.savez(src, **variables)
    elif fmt == "mat5":
        scipy.io.savemat(src, variables)
    else:
        write_mat73(src, **variables)
    m = lptv.read_measurements(src, u="force", y="disp", period=T0)
    assert m.fs == pytest.approx(FS, rel=1e-12) and m.fs_source == f"variable '{stored}'"
    np.testing.assert_array_equal(m.u, u)
    np.testing.assert_array_equal(m.y, y)
    rc, out, err = identify_cli(capsys, src, "--input", "force", "--output", "disp", "--period", T0, *FIT,
                                "--out", tmp_path / "o")
    assert rc == 0, err
    assert f"from variable '{stored}'" in out.splitlines()[0]
    assert_same_model(tmp_path / "o" / "model.json", reference)


def test_a_stored_fs_gives_the_period_of_periods_arrays(record, reference, tmp_path, capsys):
    src = tmp_path / "p.mat"
    scipy.io.savemat(src, {"force": record[0], "disp": record[1], "fs": FS})    # (P, N), no period given
    rc, out, err = identify_cli(capsys, src, "--input", "force", "--output", "disp", *FIT, "--out", tmp_path / "o")
    assert rc == 0, err
    assert_same_model(tmp_path / "o" / "model.json", reference)


def test_stored_sampling_variables_that_disagree_or_are_not_scalars(record, tmp_path):
    u, y = record
    np.savez(tmp_path / "a.npz", u=u.ravel(), y=y.ravel(), fs=FS, dt=0.2)
    with pytest.raises(FileError, match="variables 'fs' and 'dt' disagree"):
        lptv.read_measurements(tmp_path / "a.npz", period=T0)
    np.savez(tmp_path / "b.npz", u=u.ravel(), y=y.ravel(), fs=[FS, FS])
    with pytest.raises(FileError, match=r"variable 'fs' must be a positive scalar \(Hz\)"):
        lptv.read_measurements(tmp_path / "b.npz", period=T0)
    np.savez(tmp_path / "c.npz", force=u, disp=y)
    with pytest.raises(FileError, match=r"array 'u' is missing \(the file has force \(4 x 64\), disp \(4 x 64\)\)"):
        lptv.read_measurements(tmp_path / "c.npz", period=T0)


def test_a_batch_of_files_reads_the_named_channels(record, reference, tmp_path, capsys):
    srcs = [rig_csv(tmp_path / f"rig{i}.csv", *record) for i in (1, 2)]
    rc = cli.main(["identify", *map(str, srcs), "--input", "force", "--output", "displacement", "--period",
                   str(T0), *FIT, "--workers", "1", "--out", str(tmp_path / "b")])
    out, err = capsys.readouterr()
    assert rc == 0, out + err
    assert_same_model(tmp_path / "b" / "models" / "rig2.json", reference)
    res = lptv.identify_many(srcs, na=1, nb=0, read=dict(u="force", y="displacement", period=T0),
                             executor="serial", progress=False)
    assert [r["ok"] for r in res.rows] == [True, True]
    np.testing.assert_allclose(res.models[0].a, reference.model.a, rtol=0, atol=1e-12)


def test_select_reads_the_named_channels_and_the_time_column(record, tmp_path, capsys):
    src = rig_csv(tmp_path / "rig.csv", *record)
    rc = cli.main(["select", str(src), "--input", "force", "--output", "displacement", "--period", str(T0),
                   "--na", "1", "--nb", "0", "--k", "0", "--refine", "0", "--workers", "1", "--out", str(tmp_path / "s")])
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert f"{P} periods of {N} samples" in out
    ref = lptv.identify(*record, na=1, nb=0, w0=W0)
    assert_same_model(tmp_path / "s" / "model.json", ref)


def test_the_physical_form_carries_units_in_the_terminal_and_summary(tmp_path, capsys):
    """Guide page 05: --scale b0=1 gives the parameters in the channels' units (force [N],
    displacement [m]) in the terminal and in summary.json's parameters_scaled."""
    u, y = _steady_rig()
    src = rig_csv(tmp_path / "rig.csv", u, y, header="time [s],force [N],displacement [m]")
    rc, out, err = identify_cli(capsys, src, "--input", "force", "--output", "displacement", "--period", T0,
                                "--na", "2", "--nb", "0", "--scale", "b0=1", "--no-report", "--out", tmp_path / "o")
    assert rc == 0, err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    units = {r["name"]: r["unit"] for r in summary["parameters_scaled"]}
    assert (units["a0.re0"], units["a1.re0"], units["a2.re0"]) == ("N/m", "N s/m", "N s^2/m")
    table = out[out.index("parameters in physical form"):]
    for name, unit in (("a0.re0", "N/m"), ("a1.re0", "N s/m"), ("a2.re0", "N s^2/m")):
        assert next(x for x in table.splitlines() if x.split()[:1] == [name]).endswith(unit), name


def _steady_rig():
    """m x'' + c x' + k x = F (m = 2, c = 3, k = 40) by solve_ivp from rest (outside_records.py); the
    last 4 of 12 periods (the transient, exp(-0.75 t), long gone), 1 % noise."""
    from outside_records import mass_spring_damper, odd_lines

    _, f, x = mass_spring_damper(T0, FS, 12, lines=odd_lines(1, 10, seed=3), noise=0.01, seed=5, variation=0.0,
                                 mass=2.0, damping=3.0, stiffness=40.0)
    return f[-P * N:].reshape(P, N), x[-P * N:].reshape(P, N)
