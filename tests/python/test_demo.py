"""`lptv demo`: the paper's example end to end (the same code path as `make demo`)."""
import json

import pytest

from lptv.apps import cli

FILES = ["report.html", "summary.json", "fig2_fds_vs_cvode.png", "fig3_frozen_poles_zeros.png",
         "fig4_prediction_error.png", "fig5_frozen_poles_zoom.png", "fig6_normalized_residue.png",
         "measurements.npz", "model_wgtls.json"]


@pytest.fixture(scope="module")
def demo_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    assert cli.main(["demo", "--out", str(out), "--monte-carlo", "5"]) == 0
    return out


def test_demo_writes_every_file(demo_out):
    for name in FILES:
        assert (demo_out / name).stat().st_size > 0, name
    html = (demo_out / "report.html").read_text()
    for name in FILES:
        if name.endswith(".png"):
            assert "Paper: Fig." in html
    assert html.count("<img") == 5 and "Monte Carlo over 5 noise realisations" in html


def test_demo_summary_meets_the_paper(demo_out):
    s = json.loads((demo_out / "summary.json").read_text())
    assert s["n_free_parameters"] == 34
    assert s["n_lines"] == 243
    assert s["fds_vs_cvode_db"] <= -150
    assert s["wgtls_rel_error"] < s["tls_rel_error"]
    lo, hi = s["fraction_band"]
    assert lo <= s["fraction_above_0db"] <= hi
    assert 0.3 < s["fraction_expected"] < 0.42
    assert s["prediction_below_noise_db"] >= 15
    # the mean of P periods has sqrt(P) less noise: 10 log10(8) = 9 dB
    assert s["prediction_below_noise_db"] - s["prediction_below_mean_noise_db"] == pytest.approx(9.03, abs=0.01)
    for key in ("snr_in_db", "snr_out_db", "periods", "fds_speedup_vs_cvode", "wgtls_iterations",
                "prediction_below_mean_noise_db"):
        assert key in s
    mc = s["monte_carlo"]
    assert mc["runs"] == 5 and mc["wgtls"]["rms"] < mc["tls"]["rms"]


def test_demo_model_loads(demo_out):
    import lptv

    m = lptv.Model.load(demo_out / "model_wgtls.json")
    assert (m.na, m.nb, m.ka, m.kb) == (2, 1, 3, 3)
