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
from lptv.measurements import FileError

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
    from lptv.selection import MAX_GRID

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
