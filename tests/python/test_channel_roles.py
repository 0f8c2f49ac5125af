"""Which channel is the input and which the output: swapped channels get a hint, one channel
given in two roles (or twice in one) is refused.

The record: the mass-spring-damper of outside_records.py (m x'' + c x' + k(t) x = f(t) with a
stiffness varying over the 4 s period, integrated by scipy's solve_ivp from rest), driven by an odd
multisine of flat amplitude, 1 % noise on each channel, written as a rig writes it (``time [s],
force [N], displacement [m]``). The force is flat on the excited lines and the displacement
falls by the mode's roll-off, so read the wrong way round the "input" is the noisier channel by
some 15 dB on the median line.
"""
import json

import numpy as np
import pytest

import lptv
from lptv.apps import cli
from outside_records import mass_spring_damper, odd_lines, write_csv


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    t, f, x = mass_spring_damper(4.0, 50.0, 10, lines=odd_lines(1, 15, seed=1), noise=0.01, seed=3)
    d = tmp_path_factory.mktemp("roles")
    np.savez(d / "rig.npz", u=f, y=x, fs=50.0)
    return write_csv(d / "rig.csv", t, f, x)


def cli_run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


RIGHT = ["--period", 4, "--skip-periods", 3, "--lines", "excited", "--na", 2, "--nb", 0, "--ka", "1,0,0", "--kb", 0]


# ------------------------------------------------------------------------------ swapped channels

def test_swapped_channels_are_named_by_inspect(rig, tmp_path, capsys):
    right = lptv.inspect(rig, u="force", y="displacement")
    assert right.swapped is None
    wrong = lptv.inspect(rig, u="displacement", y="force")
    assert np.median(wrong.input_snr_db) < np.median(wrong.output_snr_db) - 10   # what the hint rests on
    assert wrong.swapped is not None and "are input and output swapped?" in wrong.swapped
    assert "--input 'force [N]' --output 'displacement [m]'" in wrong.swapped
    rc, out, err = cli_run(capsys, "inspect", rig, "--input", "displacement", "--output", "force",
                           "--out", tmp_path / "i")
    assert rc == 0, err
    assert "note:        the input 'displacement [m]' is the noisier channel" in out
    assert json.loads((tmp_path / "i" / "summary.json").read_text())["swapped"] == wrong.swapped
    rc, out, err = cli_run(capsys, "inspect", rig, "--input", "force", "--output", "displacement",
                           "--out", tmp_path / "r")
    assert rc == 0 and "are input and output swapped" not in out


def test_identify_says_the_channels_may_be_swapped_when_it_rejects(rig, tmp_path, capsys):
    rc, out, err = cli_run(capsys, "identify", rig, "--input", "displacement", "--output", "force", *RIGHT,
                           "--out", tmp_path / "w", "--no-report")
    assert rc == 3 and "verdict: MODEL ERRORS" in out
    hint = [line for line in out.splitlines() if "are input and output swapped?" in line]
    assert len(hint) == 1 and hint[0].startswith("warning: the input 'displacement [m]' is the noisier channel")
    rc, out, err = cli_run(capsys, "identify", rig, "--input", "force", "--output", "displacement", *RIGHT,
                           "--out", tmp_path / "r", "--no-report")
    assert rc == 0 and "are input and output swapped" not in out


# ------------------------------------------------------------------------------ one channel, two roles

def test_one_column_as_input_and_output_is_refused(rig, tmp_path, capsys):
    for u, y in (("force", "force"), ("force", "Force [N]")):
        with pytest.raises(ValueError, match=r"u= \(--input\) and y= \(--output\) name one column: .*'force \[N\]'"):
            lptv.inspect(rig, u=u, y=y)
        with pytest.raises(ValueError, match=r"u= \(--input\) and y= \(--output\) name one column"):
            lptv.read_measurements(rig, u=u, y=y, period=4)
    with pytest.raises(ValueError, match=r"u= \(--input\) and y= \(--output\) name one array: 'u' and 'U' name 'u'"):
        lptv.inspect(rig.with_suffix(".npz"), u="u", y="U")
    rc, out, err = cli_run(capsys, "inspect", rig, "--input", "force", "--output", "force", "--out", tmp_path / "i")
    assert rc == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("lptv inspect: error: ") and "--input" in err and "--output" in err
    assert "must be different channels" in err
    assert not (tmp_path / "i" / "report.html").exists()
    rc, out, err = cli_run(capsys, "identify", rig, "--input", "force", "--output", "force [N]", *RIGHT,
                           "--out", tmp_path / "o")
    assert rc == 2 and err.count("\n") == 1 and "name one column" in err


def test_one_channel_named_twice_is_refused(rig, tmp_path, capsys):
    for names in ("force,force", "force,Force [N]"):
        rc, out, err = cli_run(capsys, "inspect", rig, "--input", names, "--output", "displacement",
                               "--out", tmp_path / "i")
        assert rc == 2 and out == "" and err.count("\n") == 1, (names, out, err)
        assert "--input" in err and "names one input twice" in err and "'force [N]'" in err
    rc, out, err = cli_run(capsys, "inspect", rig, "--input", "force,displacement", "--output", "displacement [m]",
                           "--out", tmp_path / "i")
    assert rc == 2 and "must be different channels" in err
    with pytest.raises(ValueError, match=r"u= \(--input\) names one input twice: 'force' and 'Force \[N\]'"):
        lptv.read_measurements(rig, u=["force", "Force [N]"], y="displacement", period=4)
