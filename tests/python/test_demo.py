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


def test_demo_report_shows_the_verdict_and_the_parameters_with_their_std(demo_out):
    """The report, not only the terminal, says the verdict and lists every free parameter with
    the true value (read here from lptv.examples.paper_model's arrays), both estimates and their
    standard deviations; the SML errors in std units agree with the summary's share within 2 std."""
    import re

    import numpy as np

    from lptv.examples import paper_model

    html = (demo_out / "report.html").read_text()
    assert re.search(r'<p class="verdict ok"><b>Verdict:</b> WGTLS: the model is consistent[^<]*SML: the model is '
                     r"consistent", html)
    head = "<tr><th>parameter</th><th>true</th><th>WGTLS</th><th>std</th><th>SML</th><th>std</th>"
    assert head in html
    table = html[html.index(head):]
    table = table[:table.index("</table>")]
    rows = re.findall(r"<tr>" + r"<td>([^<]*)</td>" * 7 + "</tr>", table)
    m = paper_model()
    truth = {}
    for side, arr in (("a", m.a), ("b", m.b)):
        K = (arr.shape[1] - 1) // 2
        for n in range(arr.shape[0]):
            truth[f"{side}{n}.re0"] = arr[n, K].real
            for k in range(1, K + 1):
                truth[f"{side}{n}.re{k}"], truth[f"{side}{n}.im{k}"] = arr[n, K + k].real, arr[n, K + k].imag
    assert sorted(r[0] for r in rows) == sorted(truth)
    free = [r for r in rows if r[3] != "normalised"]
    assert len(free) == 34 and [r[0] for r in rows if r[3] == "normalised"] == ["a2.re0"]
    for name, true, wg, s_wg, sm, s_sm, z in free:
        assert float(true) == pytest.approx(truth[name], rel=1e-4, abs=1e-12)
        assert float(s_wg) > 0 and float(s_sm) > 0
        assert float(z) == pytest.approx((float(sm) - float(true)) / float(s_sm), abs=0.05)
    s = json.loads((demo_out / "summary.json").read_text())
    assert np.mean([abs(float(r[6])) <= 2.0 for r in free]) == pytest.approx(s["sml_within_2_sigma"], abs=1.5 / 34)


def test_demo_states_the_fds_against_cvode_gap_once_with_its_sign(demo_out):
    """summary.json keeps the level (dB relative to the output peak, negative); the report says
    "228.5 dB below the output peak", never "-228.5 dB below"."""
    s = json.loads((demo_out / "summary.json").read_text())
    html = (demo_out / "report.html").read_text()
    assert f"{-s['fds_vs_cvode_db']:.1f} dB below the output peak" in html
    assert f"{s['fds_vs_cvode_db']:.1f} dB" not in html
