"""A fit cut at a multiple of the record's period is told so, with the record's period.

``--period 8`` on a record that repeats every 4 s (or a wrong ``--fs`` on a file without a time
column, which makes each period given hold two of the record's) is not refused: an LTI model is
the same at any multiple, and a system may have a period that its excitation's repeats divide.
But a time-varying model at 8 s reads the 4 s stiffness variation as its second harmonic, so the
structure of the 4 s system ends in MODEL ERRORS; the warning must name the 4 s.

The record: the mass-spring-damper of outside_records.py (stiffness k(t) varying by 30 % over the
4 s period, integrated by scipy's solve_ivp from rest), an odd multisine of period 4 s, 50 Hz, 10
periods, 1 % noise; with and without its time column.
"""
import numpy as np
import pytest

from lptv.apps import cli
from outside_records import mass_spring_damper, odd_lines, write_csv

NAMES = ["--input", "force", "--output", "displacement"]
RIGHT = ["--skip-periods", 4, "--lines", "excited", "--na", 2, "--nb", 0, "--ka", "1,0,0", "--kb", 0, "--no-report"]


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    t, f, x = mass_spring_damper(4.0, 50.0, 10, lines=odd_lines(1, 15, seed=1), noise=0.01, seed=3)
    d = tmp_path_factory.mktemp("multiple")
    np.savetxt(d / "no-time.csv", np.c_[f, x], fmt="%.10g", delimiter=",", comments="",
               header="force [N],displacement [m]")
    return write_csv(d / "rig.csv", t, f, x), d / "no-time.csv"


def cli_run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def warnings_of(out):
    return [line for line in out.splitlines() if line.startswith("warning:")]


def test_the_right_period_is_consistent_and_says_nothing_of_multiples(rig, tmp_path, capsys):
    rc, out, err = cli_run(capsys, "identify", rig[0], *NAMES, "--period", 4, *RIGHT, "--out", tmp_path / "o")
    assert rc == 0, out + err
    assert not any("record's periods" in w for w in warnings_of(out))


def test_a_period_twice_the_records_names_the_records(rig, tmp_path, capsys):
    rc, out, err = cli_run(capsys, "identify", rig[0], *NAMES, "--period", 8, "--skip-periods", 2,
                           *RIGHT[2:], "--out", tmp_path / "o")
    assert rc == 3 and "verdict: MODEL ERRORS" in out
    w = [w for w in warnings_of(out) if "record's periods" in w]
    assert len(w) == 1, out
    assert w[0].startswith("warning: the verdict's model errors may be the period's: --period 8 holds 2 of the "
                           "record's periods (input and output repeat every 4.00 s (200 samples) at the 50 Hz of "
                           "the file's column 'time [s]')")
    assert "the system's period is probably 4 s" in w[0] and "use --period 4;" in w[0]


def test_an_lti_fit_at_a_multiple_is_consistent_and_still_told(tmp_path, capsys):
    """The same rig with a constant stiffness: an LTI model does not depend on the period, so at
    8 s it is consistent; the warning stands, without the verdict's lead."""
    t, f, x = mass_spring_damper(4.0, 50.0, 10, lines=odd_lines(1, 15, seed=1), noise=0.01, seed=3, variation=0.0)
    src = write_csv(tmp_path / "lti.csv", t, f, x)
    rc, out, err = cli_run(capsys, "identify", src, *NAMES, "--period", 8, "--skip-periods", 2,
                           "--lines", "excited", "--na", 2, "--nb", 0, "--no-report", "--out", tmp_path / "lti")
    assert rc == 0, out + err
    w = [w for w in warnings_of(out) if "record's periods" in w]
    assert len(w) == 1 and w[0].startswith("warning: --period 8 holds 2 of the record's periods")


def test_a_wrong_fs_on_a_file_without_time_names_the_period_and_the_fs(rig, tmp_path, capsys):
    """The file is sampled at 50 Hz; --fs 100 with --period 4 makes periods of 400 samples, two of
    the record's 200."""
    rc, out, err = cli_run(capsys, "identify", rig[1], *NAMES, "--fs", 100, "--period", 4, "--skip-periods", 2,
                           *RIGHT[2:], "--out", tmp_path / "o")
    assert rc == 3, out + err
    w = [w for w in warnings_of(out) if "record's periods" in w]
    assert len(w) == 1, out
    assert "--period 4 at --fs 100 is 400 samples, 2 of the record's periods" in w[0]
    assert "use --period 2 at this fs, or correct --fs (200 samples in 4 s is 50 Hz)" in w[0]
