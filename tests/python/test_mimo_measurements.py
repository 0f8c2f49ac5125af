"""Reading several inputs and outputs (METHOD.md section 19, "Reading several channels"):
``lptv.read_measurements(path, u=[...], y=[...])`` on CSV, NPZ, MAT v5 and MAT v7.3 files
written here with numpy, scipy.io and h5py; the arrays read back must be the very samples
written, arranged by hand as (P, N, nu) and (P, N, ny). File I/O only: exact equality (CSV
written with 17 significant digits)."""
import h5py
import numpy as np
import pytest
import scipy.io

import lptv
from lptv.records.measurements import FileError

FS, T0, P = 16.0, 4.0, 5          # 64 samples per period
N = int(FS * T0)


@pytest.fixture(scope="module", params=[0, 1, 2])
def channels(request):
    """Four channels of P periods (P, N) each: f1, f2 in, x1, x2 out (random numbers: the
    reader does not look at them)."""
    rng = np.random.default_rng(request.param)
    return {name: rng.standard_normal((P, N)) for name in ("f1", "f2", "x1", "x2")}


def by_hand(ch, names):
    """(P, N, len(names)): channel c at [..., c]."""
    out = np.empty((P, N, len(names)))
    for c, n in enumerate(names):
        out[:, :, c] = ch[n]
    return out


def write_csv(path, ch, header):
    t = np.arange(P * N) / FS
    cols = [t] + [ch[n].ravel() for n in ("f1", "f2", "x1", "x2")]
    np.savetxt(path, np.column_stack(cols), fmt="%.17g", delimiter=",", header=header, comments="")
    return path


def write_mat73(path, **variables):
    """Variables as MATLAB 7.3 stores them (HDF5, column-major) behind the MAT header."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            ds = f.create_dataset(name, data=np.atleast_2d(np.asarray(value, float)).T)
            ds.attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file".ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM")
    return path


def test_csv_columns_named_up_to_case_and_unit(channels, tmp_path):
    src = write_csv(tmp_path / "rig.csv", channels, "time [s],F1 [N],f2,x1 (m),X2")
    m = lptv.read_measurements(src, u=["f1", "F2"], y=["x1", "x2"], period=T0)
    assert m.u.shape == (P, N, 2) and m.y.shape == (P, N, 2)
    np.testing.assert_array_equal(m.u, by_hand(channels, ["f1", "f2"]))
    np.testing.assert_array_equal(m.y, by_hand(channels, ["x1", "x2"]))
    assert m.input == ("F1 [N]", "f2") and m.output == ("x1 (m)", "X2")
    assert m.fs == FS and m.fs_source == "column 'time [s]'" and m.w0 == pytest.approx(2 * np.pi / T0)
    # the order given is the order of the channels
    m = lptv.read_measurements(src, u=["f2", "f1"], y=("X2",), period=T0)
    np.testing.assert_array_equal(m.u, by_hand(channels, ["f2", "f1"]))
    assert m.y.shape == (P, N, 1) and m.output == ("X2",)
    # one input, two outputs; two inputs, one output
    m = lptv.read_measurements(src, u="f1", y=["x1", "x2"], period=T0)
    assert m.u.shape == (P, N, 1) and m.y.shape == (P, N, 2)
    np.testing.assert_array_equal(m.u[..., 0], channels["f1"])
    m = lptv.read_measurements(src, u=["f1", "f2"], y="x2", period=T0)
    assert m.u.shape == (P, N, 2) and m.y.shape == (P, N, 1)


def test_one_name_or_a_list_of_one_stays_two_dimensional(channels, tmp_path):
    src = write_csv(tmp_path / "rig.csv", channels, "time,f1,f2,x1,x2")
    for u, y in (("f2", "x1"), (["f2"], ["x1"]), (["f2"], "x1")):
        m = lptv.read_measurements(src, u=u, y=y, period=T0)
        assert m.u.shape == (P, N) and (m.input, m.output) == ("f2", "x1")
        np.testing.assert_array_equal(m.y, channels["x1"])


@pytest.mark.parametrize("fmt", ["npz", "npz-long", "mat5", "mat73"])
def test_npz_and_mat_variables(fmt, channels, tmp_path):
    """(P, N) arrays, or long vectors split by the stored fs and the period; skip_periods and
    trim act on every channel alike."""
    if fmt == "npz":
        src = tmp_path / "r.npz"
        np.savez(src, **channels, w0=2 * np.pi / T0)
        m = lptv.read_measurements(src, u=["f1", "f2"], y=["x1", "x2"], skip_periods=1)
        np.testing.assert_array_equal(m.u, by_hand(channels, ["f1", "f2"])[1:])
        np.testing.assert_array_equal(m.y, by_hand(channels, ["x1", "x2"])[1:])
        assert m.w0 == 2 * np.pi / T0 and m.skipped == 1
        return
    if fmt == "npz-long":
        src = tmp_path / "r.npz"
        extra = {n: np.concatenate([[9.0, 9.0, 9.0], v.ravel()]) for n, v in channels.items()}
        np.savez(src, **extra, fs=FS)
        m = lptv.read_measurements(src, u=["f1", "f2"], y=["x1", "x2"], period=T0, trim=True)
        assert m.trimmed == 3
    elif fmt == "mat5":
        src = tmp_path / "r.mat"
        scipy.io.savemat(src, {**{n: v.ravel()[:, None] for n, v in channels.items()}, "Ts": 1 / FS})
        m = lptv.read_measurements(src, u=["f1", "f2"], y=["x1", "x2"], period=T0)
    else:
        src = write_mat73(tmp_path / "r.mat", **{n: v.ravel() for n, v in channels.items()}, dt=1 / FS)
        m = lptv.read_measurements(src, u=["f1", "f2"], y=["x1", "x2"], period=T0)
    np.testing.assert_array_equal(m.u, by_hand(channels, ["f1", "f2"]))
    np.testing.assert_array_equal(m.y, by_hand(channels, ["x1", "x2"]))
    assert m.fs == FS


def test_errors_name_the_channel(channels, tmp_path):
    src = write_csv(tmp_path / "rig.csv", channels, "time,f1,f2,x1,x2")
    with pytest.raises(FileError, match=r"column 'f3', the input named by --input \(u=\), is missing "
                                        r"\(the header has 'time', 'f1', 'f2', 'x1', 'x2'\)"):
        lptv.read_measurements(src, u=["f1", "f3"], y=["x1", "x2"], period=T0)
    with pytest.raises(FileError, match=r"column 'x3', the output named by --output \(y=\), is missing"):
        lptv.read_measurements(src, u=["f1", "f2"], y=["x3", "x1"], period=T0)
    with pytest.raises(FileError, match="channel 'F1' is named twice"):
        lptv.read_measurements(src, u=["f1", "f2"], y=["F1", "x1"], period=T0)
    with pytest.raises(FileError, match="at least one output channel, got an empty list"):
        lptv.read_measurements(src, u=["f1", "f2"], y=[], period=T0)
    with pytest.raises(FileError, match=r"must name channels of the file \(non-empty str\), got 3"):
        lptv.read_measurements(src, u=["f1", 3], y=["x1", "x2"], period=T0)
    npz = tmp_path / "r.npz"
    np.savez(npz, **{n: np.stack([v, v]) for n, v in channels.items()}, w0=2 * np.pi / T0)
    with pytest.raises(FileError, match="realisations=True reads one input and one output"):
        lptv.read_measurements(npz, u=["f1", "f2"], y=["x1", "x2"], realisations=True)
    # channels of different lengths in one NPZ
    bad = tmp_path / "bad.npz"
    np.savez(bad, f1=channels["f1"], f2=channels["f2"][:, :-1], x1=channels["x1"], x2=channels["x2"],
             w0=2 * np.pi / T0)
    with pytest.raises(FileError, match="differ in shape"):
        lptv.read_measurements(bad, u=["f1", "f2"], y=["x1", "x2"])
