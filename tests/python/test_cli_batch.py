"""``lptv montecarlo`` and ``lptv identify FILES... [--workers N | --scheduler ADDRESS]``: the
command line gives what the library gives (bit for bit, on any executor), writes its report and
tables, reports each failed file in its row and exits 1 then, 2 for bad options."""
import csv
import json
import subprocess
import sys

import numpy as np
import pytest

import lptv
from lptv.apps import cli
from lptv.examples import paper_measurements

pytest.importorskip("pandas")

PAPER_ARGS = ["--na", "2", "--nb", "1", "--ka", "3", "--kb", "3", "--lines", "1-243"]


def run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def test_montecarlo_on_the_paper_example_writes_its_report(tmp_path, capsys):
    out = tmp_path / "mc"
    rc, stdout, err = run(capsys, "montecarlo", "--runs", 4, "--periods", 4, "--method", "wgtls,sml",
                          "--workers", 1, "--out", out)
    assert rc == 0, err
    assert "the paper's example; 4 runs x wgtls,sml, P = 4" in stdout
    assert "wgtls  4/4 fits ok" in stdout and "sml    4/4 fits ok" in stdout
    for name in ("report.html", "estimates.csv", "fits.csv", "summary.csv", "overview.csv",
                 "summary.json", "errors.png", "coverage.png"):
        assert (out / name).stat().st_size > 100, name
    summary = json.loads((out / "summary.json").read_text())
    assert summary["executor"] == "serial" and summary["methods"] == ["wgtls", "sml"]
    assert summary["overview"]["sml"]["runs"] == 4 and summary["overview"]["sml"]["failures"] == 0
    with open(out / "estimates.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2 * 4 * 34 and rows[0]["parameter"] == "a0.re0"
    page = (out / "report.html").read_text()
    assert 'alt="errors.png"' in page and "Per parameter" in page and "(P-2)/(P-3)" in page


def test_montecarlo_of_a_model_file_on_the_cluster_is_the_library_study(tmp_path, capsys, dask_cluster):
    m = lptv.Model([[0.15, 2.0, 0.15], [0, 1.0, 0]], [[0, 1.0, 0]], w0=0.1)
    m.save(tmp_path / "model.json")
    out = tmp_path / "mc"
    rc, stdout, err = run(capsys, "montecarlo", "--model", tmp_path / "model.json", "--excited", "1-40",
                          "--samples", 256, "--runs", 6, "--periods", 4, "--method", "sml",
                          "--snr-in", 40, "--snr-out", 25, "--pole-in", 0, "--pole-out", 0.5,
                          "--correlation", 0.3, "--seed", 9, "--scheduler", dask_cluster.scheduler_address,
                          "--format", "parquet", "--out", out)
    assert rc == 0, err
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    ms = lptv.multisine(range(1, 41), 256, amplitudes=np.sqrt(2 / 40), seed=1)
    lib = lptv.montecarlo(m, ms, periods=4, runs=6, methods="sml", snr_in_db=40, snr_out_db=25,
                          pole_out=0.5, correlation=0.3, seed=9, executor="serial", progress=False)
    pd.testing.assert_frame_equal(pd.read_parquet(out / "estimates.parquet"), lib.table())


@pytest.mark.parametrize("argv,match", [
    (["--periods", "1"], "--periods must be >= 2"),
    (["--runs", "0"], "--runs must be >= 1"),
    (["--method", "wgtls,fast"], "methods: 'fast' is not one of"),
    (["--model", "nowhere.json", "--excited", "1-4"], "--model nowhere.json: No such file"),
    (["--excited", "1-4"], "--excited applies with --model only"),
    (["--workers", "0"], "--workers must be >= 1"),
    (["--correlation", "2"], "correlation must lie in"),
])
def test_montecarlo_bad_options_exit_2_with_one_line(argv, match, tmp_path, capsys):
    rc, _, err = run(capsys, "montecarlo", "--runs", 2, "--out", tmp_path / "x", *argv)
    assert rc == 2
    assert err.startswith("lptv montecarlo: error: ") and match in err and err.count("\n") == 1


def test_montecarlo_needs_excited_lines_with_a_model(tmp_path, capsys):
    lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1).save(tmp_path / "m.json")
    rc, _, err = run(capsys, "montecarlo", "--model", tmp_path / "m.json", "--out", tmp_path / "x")
    assert rc == 2 and "--model needs --excited" in err


@pytest.fixture()
def measurement_files(tmp_path):
    files = []
    for s in (1, 2, 3):
        d = paper_measurements(seed=s, periods=4)
        files.append(tmp_path / f"machine{s}.npz")
        np.savez(files[-1], u=d["u"], y=d["y"], w0=d["w0"])
    return files


def test_identify_many_files_reports_each_and_exits_1_on_a_failure(measurement_files, tmp_path, capsys, dask_cluster):
    files = [measurement_files[0], tmp_path / "missing.npz", *measurement_files[1:]]
    results = {}
    for how in (["--workers", 2], ["--workers", 1], ["--scheduler", dask_cluster.scheduler_address]):
        out = tmp_path / f"out-{how[1]}".replace(":", "").replace("/", "")
        rc, stdout, err = run(capsys, "identify", *files, *PAPER_ARGS, *how, "--out", out)
        assert rc == 1, err
        assert f"FAILED  {files[1]}: FileError: no such file" in stdout
        assert stdout.count("  ok      ") == 3 and "3 of 4 files fitted" in stdout
        results[how[0] + str(how[1])] = (out / "results.csv").read_text()
        assert sorted(p.name for p in (out / "models").iterdir()) == \
            ["machine1.json", "machine2.json", "machine3.json"]
        summary = json.loads((out / "summary.json").read_text())
        assert summary["fitted"] == 3 and summary["failed"] == 1
    texts = list(results.values())
    assert texts[0] == texts[1] == texts[2]        # bit-identical, whatever the executor
    rows = list(csv.DictReader(texts[0].splitlines()))
    assert [r["ok"] for r in rows] == ["True", "False", "True", "True"]
    z = np.load(files[2])
    ref = lptv.identify(z["u"], z["y"], w0=float(z["w0"]), na=2, nb=1, ka=3, kb=3, lines=range(1, 244))
    np.testing.assert_allclose([float(rows[2][n]) for n in ref.eta_names], ref.eta, rtol=0, atol=1e-12)
    model = lptv.Model.load(tmp_path / "out-1" / "models" / "machine2.json")
    np.testing.assert_allclose(model.a, ref.model.a, rtol=0, atol=1e-12)


def test_identify_one_file_with_workers_is_a_batch_and_all_ok_exits_0(measurement_files, tmp_path, capsys):
    rc, stdout, err = run(capsys, "identify", measurement_files[0], *PAPER_ARGS, "--workers", 1,
                          "--out", tmp_path / "one")
    assert rc == 0, err
    assert "1 of 1 files fitted" in stdout and (tmp_path / "one" / "results.csv").exists()


def test_console_help_lists_the_batch_commands():
    out = subprocess.run([sys.executable, "-m", "lptv", "--help"], capture_output=True, text=True)
    assert "montecarlo" in out.stdout
    out = subprocess.run([sys.executable, "-m", "lptv", "identify", "--help"], capture_output=True, text=True)
    assert "--scheduler ADDRESS" in out.stdout and "--workers N" in out.stdout


@pytest.mark.parametrize("missing, extra_args", [("pandas", ()), ("pyarrow", ("--format", "parquet"))])
def test_montecarlo_checks_its_optional_dependencies_before_any_fit(missing, extra_args, tmp_path):
    """Without pandas (pyarrow for Parquet) the command says which extra to install in one line
    and exits 2 before fitting: a study of 100 000 runs would otherwise take as long as it does
    before failing. The module is hidden in the child by a None in sys.modules."""
    code = (f"import sys; sys.modules[{missing!r}] = None\n"
            "from lptv.apps import cli\n"
            f"sys.exit(cli.main(['montecarlo', '--runs', '100000', '--periods', '4', '--workers', '1', "
            f"'--out', {str(tmp_path / 'mc')!r}, *{list(extra_args)!r}]))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2, p.stderr
    assert missing in p.stderr and "lptv[batch]" in p.stderr and p.stderr.count("\n") == 1
    assert "runs x" not in p.stdout            # nothing started
