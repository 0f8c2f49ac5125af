"""``lptv identify FILE`` prints the Floquet exponents with their intervals and the probability of
stability, and writes them to summary.json and report.html (METHOD.md section 22): the same
numbers as lptv.floquet of the same fit through the Python API."""
import json
import subprocess
import sys

import numpy as np

import lptv
from lptv.examples import system_measurements

LPTV = [sys.executable, "-m", "lptv"]


def test_identify_prints_and_writes_the_exponents_with_intervals(tmp_path):
    d = system_measurements("third_order", seed=3, periods=8)
    path = tmp_path / "rec.csv"
    np.savetxt(path, np.column_stack([d["u"].ravel(), d["y"].ravel()]), fmt="%.17g", delimiter=",",
               header="u,y", comments="")
    out = tmp_path / "out"
    r = subprocess.run(LPTV + ["identify", str(path), "--periods", "8", "--w0", repr(d["w0"]),
                               "--na", "3", "--nb", "1", "--ka", "2,1,0,0", "--kb", "2,0", "--lines", "1-170",
                               "--method", "sml", "--out", str(out)], capture_output=True, text=True)
    assert r.returncode in (0, 3), r.stderr
    assert "P(stable)" in r.stdout and "Floquet exponents" in r.stdout
    s = json.loads((out / "summary.json").read_text())["stability_uncertainty"]
    res = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], lines=d["lines"], method="sml")
    f = lptv.floquet(res)
    got = np.array([e["re"] + 1j * e["im"] for e in s["exponents"]])
    np.testing.assert_allclose(got, f.exponents, rtol=1e-6)
    np.testing.assert_allclose([e["re_interval"] for e in s["exponents"]], f.confidence_interval()[:, 0], rtol=1e-5)
    assert s["first_order_ok"] is True and s["stable_probability"] > 0.9999
    assert "Stability with its uncertainty" in (out / "report.html").read_text()


def test_identify_without_covariance_says_why(tmp_path):
    d = system_measurements("discrete", seed=2, periods=4)
    path = tmp_path / "rec.csv"
    np.savetxt(path, np.column_stack([d["u"].ravel(), d["y"].ravel()]), fmt="%.17g", delimiter=",",
               header="u,y", comments="")
    out = tmp_path / "out"
    r = subprocess.run(LPTV + ["identify", str(path), "--periods", "4", "--ts", "1",
                               "--na", "2", "--nb", "1", "--ka", "2,1,0", "--kb", "2,0", "--lines", "1-125",
                               "--method", "gtls", "--no-report", "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode in (0, 3), r.stderr
    assert "stability: no intervals" in r.stdout and "gives no covariance" in r.stdout
    s = json.loads((out / "summary.json").read_text())["stability_uncertainty"]
    assert "gives no covariance" in s["error"]
