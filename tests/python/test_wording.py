"""What the commands print says what happened, in words that agree with each other: counts in
number ("1 period", "1 input"), nothing dropped that was not, no negative count of periods left,
no "0 of 1 lines above the noise: the system varies in time".

The records are made outside lptv: the README's quick start (an odd multisine through
scipy.signal.lfilter's first-order filter), and a first-order recursion with a coefficient that
varies over the period, run sample by sample in NumPy.
"""
import re

import numpy as np
import pytest
from scipy.signal import lfilter

import lptv
from lptv.apps import cli

NAMES = ["--input", "force", "--output", "displacement"]


def cli_run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def quick_start(n_periods=6, start=37, seed=1, a=None):
    """The README's record: fs 50 Hz, N = 200 (4 s), odd lines 1..39, from rest, 2 % noise; with
    ``a`` (a function of the sample index) the pole varies over the period, y[k] = a(k) y[k-1] +
    0.05 u[k]."""
    fs, N = 50.0, 200
    k = np.arange(start, n_periods * N)
    u = sum(np.cos(2 * np.pi * l * k / N + l * l) for l in range(1, 40, 2))
    if a is None:
        y = lfilter([0.05], [1, -0.99], u)
    else:
        y = np.zeros(u.size)
        for i in range(u.size):
            y[i] = (a(k[i]) * y[i - 1] if i else 0.0) + 0.05 * u[i]
    rng = np.random.default_rng(seed)
    u, y = u + 0.02 * rng.standard_normal(k.size), y + 0.02 * rng.standard_normal(k.size)
    return k / fs, u, y


def write(path, t, u, y):
    np.savetxt(path, np.c_[t, u, y], delimiter=",", comments="", header="time [s],force [N],displacement [m]")
    return path


def test_skipping_more_periods_than_the_record_holds_says_so(tmp_path, capsys):
    src = write(tmp_path / "short.csv", *quick_start(n_periods=3, start=0))
    for skip, said in ((2, "leaves 1 of the record's 3 periods"), (3, "drops all of the record's 3 periods"),
                       (4, "drops more than all of the record's 3 periods")):
        with pytest.raises(ValueError) as e:
            lptv.read_measurements(src, u="force", y="displacement", period=4, skip_periods=skip)
        assert said in str(e.value) and "--skip-periods 1 at most" in str(e.value)
        assert "-1" not in str(e.value)
    rc, out, err = cli_run(capsys, "identify", src, *NAMES, "--period", 4, "--skip-periods", 4, "--na", 1,
                           "--nb", 1, "--discrete", "--out", tmp_path / "o")
    assert rc == 2 and "leaves -1" not in err and "drops more than all of the record's 3 periods" in err


def test_validate_names_only_what_it_dropped_with_counts_in_number(tmp_path, capsys):
    src = write(tmp_path / "rig.csv", *quick_start())
    rc, out, err = cli_run(capsys, "identify", src, *NAMES, "--period", 4, "--trim", "--skip-periods", 3,
                           "--lines", "excited", "--discrete", "--na", 1, "--nb", 1, "--no-report",
                           "--out", tmp_path / "fit")
    assert rc == 0, out + err
    fresh = write(tmp_path / "fresh.csv", *quick_start(n_periods=8, start=0, seed=7))
    rc, out, err = cli_run(capsys, "validate", tmp_path / "fit" / "model.json", fresh, "--skip-periods", 1,
                           "--out", tmp_path / "v")
    assert rc == 0, out + err
    assert "dropped at the start: 1 period (--skip-periods)" in out
    assert not re.search(r"(?<!\d)0 samples", out) and "1 periods" not in out


def test_several_outputs_are_counted_in_number(tmp_path, capsys):
    t, u, y = quick_start(start=0)
    y2 = y + 0.02 * np.random.default_rng(9).standard_normal(y.size)      # a second displacement sensor
    np.savetxt(tmp_path / "two.csv", np.c_[t, u, y, y2], delimiter=",", comments="",
               header="time [s],force [N],displacement [m],displacement2 [m]")
    rc, out, err = cli_run(capsys, "inspect", tmp_path / "two.csv", "--input", "force", "--output",
                           "displacement,displacement2", "--out", tmp_path / "i")
    assert rc == 0, err
    assert out.splitlines()[0].endswith(": 1 input, 2 outputs, inspected in 2 pairs")
    assert "1 inputs" not in (tmp_path / "i" / "report.html").read_text()


def test_sidebands_seen_only_on_the_detection_lines_are_not_said_to_be_absent():
    """Odd lines 1..39 next to each other leave no sideband inside the band: the one sideband line
    is 40, just above it. The varying pole puts the response on the even lines between the excited
    ones, which are the detection lines one line away."""
    t, u, y = quick_start(a=lambda k: 0.95 + 0.04 * np.cos(2 * np.pi * k / 200))
    insp = lptv.inspect(u=u, y=y, fs=50.0)
    assert insp.reach == 1 and insp.time_variation_reach == 1
    side = insp.line_class("sidebands")
    assert side.lines.tolist() == [40] and not side.present
    line = next(x for x in insp.summary().splitlines() if x.strip().startswith("sidebands"))
    assert line.strip().startswith("sidebands (+-1):") and "+-1..1" not in line
    assert "0 of 1 lines above the noise" in line
    assert "the system varies in time" not in line
    assert "none here, but the detection lines up to 1 line or more from the excited ones stand above the noise" \
        in line
