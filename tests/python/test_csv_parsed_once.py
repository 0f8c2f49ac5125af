"""`lptv identify FILE.csv` reads its file twice (the inspection, then the fit) and parses it once;
a file whose bytes change is parsed anew, even at the same size and within one timestamp tick,
and what a caller does to the arrays it got does not reach the next read."""
import numpy as np

import lptv
from lptv.apps import cli
from lptv.records import measurements
from outside_records import mass_spring_damper, odd_lines, write_csv


def _record(tmp_path):
    t, f, x = mass_spring_damper(4.0, 50.0, 4, lines=odd_lines(1, 10, seed=1), noise=0.01, seed=2, start=20.0)
    return write_csv(tmp_path / "rig.csv", t - t[0], f, x)


def test_identify_parses_its_csv_once(tmp_path, monkeypatch, capsys):
    src = _record(tmp_path)
    calls = []
    parse = measurements._parse_csv
    monkeypatch.setattr(measurements, "_parse_csv", lambda *a: calls.append(a[0]) or parse(*a))
    measurements._CSV_PARSED.clear()
    rc = cli.main(["identify", str(src), "--input", "force", "--output", "displacement", "--period", "4",
                   "--na", "2", "--nb", "0", "--ka", "1,0,0", "--no-report", "--out", str(tmp_path / "o")])
    assert rc in (0, 3), capsys.readouterr().err
    assert len(calls) == 1, calls


def test_a_changed_file_is_parsed_again_and_copies_stay_apart(tmp_path):
    src = _record(tmp_path)
    m1 = lptv.read_measurements(src, u="force", y="displacement", period=4.0)
    m1.u[...] = 0.0                                   # the caller's own arrays
    m2 = lptv.read_measurements(src, u="force", y="displacement", period=4.0)
    assert np.any(m2.u != 0.0)
    text = src.read_text()
    lines = text.splitlines()
    head, first = lines[0], lines[1].split(",")
    first[1], first[2] = first[2], first[1]           # the same bytes in another order: the same size
    src.write_text("\n".join([head, ",".join(first), *lines[2:]]) + "\n")
    assert src.stat().st_size == len(text.encode())
    m3 = lptv.read_measurements(src, u="force", y="displacement", period=4.0)
    assert m3.u.ravel()[0] == m2.y.ravel()[0] and m3.y.ravel()[0] == m2.u.ravel()[0]
    np.testing.assert_array_equal(m3.u.ravel()[1:], m2.u.ravel()[1:])
