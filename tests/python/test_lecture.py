"""``lptv demo lecture``: the lecture's cases (lptv.apps.lecture) judged against the truth.

The demo runs once in quick mode (the same code path as the full run, fewer Monte Carlo
realisations); the tests read what it wrote. Every tolerance is justified where it is used.
"""
import argparse
import json

import numpy as np
import pytest
from scipy import stats

from lptv.apps import lecture

SEED = 2024
FIGURES = ("fig1_static_ls.png", "fig2_smd_measurement.png", "fig3_monte_carlo.png",
           "fig4_cutoff_sweep.png", "fig5_stiffness.png", "fig6_constant_k_residual.png")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("lecture")
    rc = lecture.run(argparse.Namespace(out=str(out), quick=True, seed=SEED, monte_carlo=0, periods=8))
    assert rc == 0
    return out, json.loads((out / "summary.json").read_text())


# --- case 1: static least squares ---------------------------------------------------------

def test_static_ls_matches_polyfit_and_contains_the_truth(demo):
    _, s = demo
    ls = lecture.static_ls([SEED, 0])
    # H = Y X^T (X X^T)^-1 is the straight-line fit: the same as numpy's polyfit up to rounding
    # of a 2x2 system with condition number ~20
    assert np.allclose(ls["H"], np.polyfit(ls["x"], ls["y"], 1), rtol=0, atol=1e-10)
    assert s["ls_slope"] == ls["slope"] and s["ls_intercept"] == ls["intercept"]
    lo, hi = s["ls_slope_ci"]
    assert lo < 10.0 < hi
    lo, hi = s["ls_intercept_ci"]
    assert lo < 50.0 < hi


def test_static_ls_interval_width_is_the_classical_one(demo):
    _, s = demo
    x = lecture.LS_X
    n = x.size
    t = stats.t.ppf(0.975, n - 2)
    sxx = np.sum((x - x.mean()) ** 2)
    # half-widths with the true sigma = 1: t sigma / sqrt(Sxx) and t sigma sqrt(1/n + xbar^2/Sxx)
    slope_half = t / np.sqrt(sxx)                       # 0.68
    intercept_half = t * np.sqrt(1 / n + x.mean() ** 2 / sxx)   # 0.39
    # the demo's intervals use s instead of sigma; s / sigma has a relative standard deviation
    # of 1/sqrt(2 (n-2)) = 0.071, so +-30 % is more than 4 of them
    assert np.diff(s["ls_slope_ci"])[0] / 2 == pytest.approx(slope_half, rel=0.3)
    assert np.diff(s["ls_intercept_ci"])[0] / 2 == pytest.approx(intercept_half, rel=0.3)
    assert abs(s["ls_residual_mean"]) < 1e-10     # an intercept in the model forces a zero mean


def test_static_ls_intervals_cover_the_truth_95_percent_of_the_time():
    runs = 400
    inside = np.zeros(2)
    for r in range(runs):
        ls = lecture.static_ls([99, r])
        inside += [ls["slope_ci"][0] < 10 < ls["slope_ci"][1],
                   ls["intercept_ci"][0] < 50 < ls["intercept_ci"][1]]
    # binomial standard deviation of the coverage over 400 runs: sqrt(0.95 * 0.05 / 400) = 0.011;
    # accept +-3 of them
    assert np.all(np.abs(inside / runs - 0.95) < 3 * np.sqrt(0.95 * 0.05 / runs))


# --- case 2: spring-mass-damper -----------------------------------------------------------

def test_time_domain_route_is_sound_on_noise_free_records():
    """Route (a) must not be handicapped: without noise it is off only by its finite differences.

    np.gradient's central difference has the gain sin(w h) / (w h) ~ 1 - (w h)^2 / 6 per
    derivative, so m x'' is off by at most (w h)^2 / 3 of itself at the band edge
    w = 2 pi 4 rad/s, h = 1 ms: 2.1e-4 of m w^2 = 632 N/m, i.e. 0.13 N/m against k = 100 N/m.
    """
    ms = lecture.force_multisine([SEED, 1])
    x0 = lecture.steady_state_position(lecture.smd_model(), ms)
    theta, res = lecture.time_domain_ls(np.tile(ms.signal, (4, 1)), np.tile(x0, (4, 1)))
    w, h = 2 * np.pi * lecture.EXCITED[-1] / lecture.T0, 1 / lecture.FS
    bound = (w * h) ** 2 / 3 * lecture.M * w ** 2
    assert abs(theta[0] - lecture.K) < bound
    assert abs(theta[1] - lecture.C) < bound / w     # the same error as a damping force at w


def test_frequency_domain_beats_filtered_time_domain_in_the_monte_carlo(demo):
    _, s = demo
    mc = s["monte_carlo"]
    assert mc["runs"] == 100 and mc["fd_runs_with_warnings"] == 0
    # Measured over 12 seeds of 100 runs each at these settings, the RMS ratio (a)/(b) lies in
    # 1.20..1.51 for k and 1.38..2.02 for c; the estimate of an RMS from 100 runs scatters by
    # 1/sqrt(200) = 7 %, so a ratio above 1 is not luck of the draw.
    for p in ("k", "c"):
        assert mc["fd"][p]["rms"] < mc["td"][p]["rms"], p
        assert mc["fd_lower_rms"][p]
    # (b) is consistent: its bias is well inside the scatter of the mean over the runs
    for p in ("k", "c"):
        assert abs(mc["fd"][p]["bias"]) < 4 * mc["fd"][p]["std"] / np.sqrt(mc["runs"])
    # the single measurement of the demo: both estimates close to the truth at this noise
    assert s["smd_fd"]["k"] == pytest.approx(lecture.K, rel=5 * mc["fd"]["k"]["rms"] / lecture.K)
    assert s["smd_td"]["c"] == pytest.approx(lecture.C, rel=5 * mc["td"]["c"]["rms"] / lecture.C)


def test_the_cutoff_sweep_and_conditions_are_reported(demo):
    _, s = demo
    cs = s["cutoff_sweep"]
    assert cs["cutoffs_hz"] == list(lecture.CUTOFF_SWEEP_HZ) and len(cs["k_rms"]) == len(cs["cutoffs_hz"])
    # the lecture's cut-off is one of the swept ones, and the sweep's 5 Hz point is the main
    # Monte Carlo's (a) on its first runs, so it cannot be far from it
    i = cs["cutoffs_hz"].index(lecture.CUTOFF_HZ)
    assert cs["k_rms"][i] == pytest.approx(s["monte_carlo"]["td"]["k"]["rms"], rel=0.5)
    assert [c["periods"] for c in s["conditions"]] == [8, 8, 8, 2, 4, 16]


# --- case 3: periodic stiffness -----------------------------------------------------------

def test_periodic_stiffness_is_recovered(demo):
    """Max over the period of |k_est(t) - k(t)| / k0 below 0.5 %.

    Noise level: the mean position spectrum over P = 8 periods of N = 10^4 samples has a noise
    of sigma_x / sqrt(N P) = 3.9 mm / 283 = 14 um per line, against |X_l| ~ 10 mm on the lower
    excited lines, where the equation error is dominated by |A_l| = |k - m w^2 + j c w| ~ 100 N/m
    times that noise. About 20 such lines with 2 real equations each fix each of the 5 real
    parameters of k(t) to ~ 2e-4 of k0, so k(t) (their sum with weights <= 2) to ~ 5e-4 at a
    time point; 0.5 % leaves a factor 10 for the maximum over the period and the rougher
    higher lines. A missing or mis-signed harmonic would show as 10-25 %.
    """
    _, s = demo
    assert s["kt_max_rel_error"] < 5e-3
    assert max(s["kt_max_rel_error_runs"]) < 5e-3
    assert s["kt_fd_runs_with_warnings"] == 0
    assert s["kt_fd_c"] == pytest.approx(lecture.C, rel=5e-3)


def test_constant_k_cannot_follow_k_t(demo):
    _, s = demo
    lo, hi = s["kt_true_range"]
    assert lo < s["kt_td_constant_k"] < hi
    # the constant misses k(t) by at least half its peak-to-peak swing at some time
    assert s["kt_td_constant_k_max_rel_error"] > 0.5 * (hi - lo) / lecture.K
    # and what it misses is in its residual: the mean residual over the periods follows the
    # filtered (k(t) - k_a) x(t) (noise in that mean: ~0.1 N against a few N of signal)
    assert s["kt_td_residual_correlation"] > 0.95


# --- the files ------------------------------------------------------------------------------

def test_run_writes_every_file_and_mentions_every_case(demo):
    out, s = demo
    for name in FIGURES + ("report.html", "summary.json"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    for name in FIGURES:
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    html = (out / "report.html").read_text()
    assert html.count("<img") == len(FIGURES) and html.count("<figcaption>") == len(FIGURES)
    for heading in ("1. Static least squares", "2. Spring-mass-damper", "Monte Carlo over 100",
                    "3. Periodic stiffness"):
        assert heading in html, heading
    for key in ("ls_slope", "ls_intercept", "ls_slope_ci", "ls_intercept_ci", "smd_truth", "smd_td",
                "smd_fd", "monte_carlo", "kt_max_rel_error"):
        assert key in s, key
    for m in ("td", "fd"):
        for p in ("k", "c"):
            assert set(s["monte_carlo"][m][p]) >= {"bias", "rms"}
