"""Disturbances that are not periodic in the record (lptv.disturbances, METHOD.md section 7).

A sinusoid off the period's grid (0.37 lines off line 85, 5 times the output noise's rms) in the
third-order system's output: found to 1e-3 lines and 1 % of its amplitude; with it the verdict
rejects the true structure with residues "too small" and says why; without it (removed by
identify(..., disturbances="remove")) the verdict keeps the structure and the lines around it
get their noise's variance back. Noise alone (white, coloured, several P and N) gives no
disturbance in at least 49 of 50 records; a sinusoid on the grid is signal and stays.
"""
import warnings

import numpy as np
import pytest

import lptv
from lptv.examples import noisy_periods, system_measurements

HUM_LINE = 85.37


def hummed(seed, amplitude=5.0, line=HUM_LINE, P=8):
    d = system_measurements("third_order", seed=seed, periods=P)
    u, y = np.asarray(d["u"]), np.asarray(d["y"])
    P, N = y.shape
    rms = np.std(y - y.mean(0))
    n = np.arange(P * N)
    a = amplitude * rms * np.sqrt(2.0)
    y_h = (y.reshape(-1) + a * np.cos(2 * np.pi * line * n / N + 1.0)).reshape(P, N)
    return d, u, y, y_h, a


def fit(d, u, y, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return lptv.identify(u, y, **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["lines"], **kw)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_sinusoid_off_the_grid_is_found_removed_and_the_verdict_keeps_the_structure(seed):
    d, u, y, y_h, a = hummed(seed)
    out = lptv.disturbances(u, y_h)
    assert len(out.found) == 1
    hum = out.found[0]
    assert hum.signal == "y"
    assert abs(hum.line - HUM_LINE) < 1e-3
    assert abs(hum.amplitude / a - 1) < 0.01
    assert np.allclose(out.u, u)                      # nothing in the input

    # the periods' own variances count the sinusoid's leakage (METHOD.md section 7)
    with_hum = fit(d, u, y_h, noise="sample")
    assert not with_hum.model_ok
    assert any("too small" in e and "lptv.disturbances" in e for e in with_hum.model_errors)
    # the default sees the leakage as noise correlated between lines and takes the whole record's
    # bins, where the leakage is P times narrower (METHOD.md section 20): the structure is kept
    default = fit(d, u, y_h)
    assert default.noise.startswith("full"), default.noise_choice
    assert default.model_ok, default.model_errors

    cleaned = fit(d, u, y_h, disturbances="remove")
    assert cleaned.model_ok, cleaned.model_errors
    assert len(cleaned.disturbances) == 1 and abs(cleaned.disturbances[0].line - HUM_LINE) < 1e-3
    assert "removed before the fit: y: a sinusoid at line 85.370" in cleaned.summary()

    # the lines around the disturbance get the noise's variance back (the same noise without it)
    near = slice(60, 111)
    v_clean = lptv.FrequencyData.from_periods(u, y, w0=d["w0"]).varY[near]
    v_hum = lptv.FrequencyData.from_periods(u, y_h, w0=d["w0"]).varY[near]
    v_removed = cleaned.data.varY[near]
    assert np.median(v_hum / v_clean) > 5
    assert 0.8 < np.median(v_removed / v_clean) < 1.25
    v_record = lptv.FrequencyData.from_periods(u, y_h, w0=d["w0"], statistics="record").varY[near]
    assert 0.8 < np.median(v_record / v_clean) < 1.25


def test_noise_alone_gives_no_disturbance_and_a_sinusoid_on_the_grid_stays():
    rng = np.random.default_rng(11)
    flagged = 0
    records = 0
    for P, N, pole in [(4, 256, 0.0), (8, 512, 0.0), (16, 256, 0.8), (4, 1024, -0.5), (8, 1024, 0.9)]:
        x0 = np.sin(2 * np.pi * 3 * np.arange(N) / N)
        for _ in range(10):
            u, y = noisy_periods(x0, 2 * x0, P, snr_in_db=30.0, snr_out_db=20.0, pole_in=pole, pole_out=pole,
                                 seed=rng)
            out = lptv.disturbances(u, y)
            flagged += bool(out.found)
            records += 1
    assert records == 50 and flagged <= 1

    P, N = 8, 512
    n = np.arange(P * N)
    u, y = noisy_periods(np.sin(2 * np.pi * 3 * np.arange(N) / N), np.zeros(N), P, snr_in_db=30.0,
                         snr_out_db=np.inf, seed=rng)
    y = 0.01 * rng.standard_normal((P, N)) + (0.5 * np.cos(2 * np.pi * 40 * n / N)).reshape(P, N)
    out = lptv.disturbances(u, y)
    assert out.found == () and np.array_equal(out.y, y)


def test_several_disturbances_and_the_input_too():
    rng = np.random.default_rng(3)
    P, N = 8, 1024
    n = np.arange(P * N)
    u = (np.cos(2 * np.pi * 5 * n / N) + 0.01 * rng.standard_normal(P * N)
         + 0.03 * np.cos(2 * np.pi * 200.25 * n / N + 0.3)).reshape(P, N)
    y = (0.01 * rng.standard_normal(P * N) + 0.05 * np.cos(2 * np.pi * 50.5 * n / N)
         + 0.02 * np.sin(2 * np.pi * 300.8 * n / N)).reshape(P, N)
    out = lptv.disturbances(u, y)
    got = sorted((d.signal, round(d.line, 2), round(d.amplitude, 3)) for d in out.found)
    assert got == [("u", 200.25, 0.03), ("y", 50.5, 0.05), ("y", 300.8, 0.02)]
    assert "u: a sinusoid at line 200.250" in out.summary()
    assert lptv.disturbances(u, y, max_count=0).found == ()


def test_several_experiments_are_cleaned_each():
    d, u, y, y_h, _ = hummed(4)
    d2 = system_measurements("third_order", seed=5, periods=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify([(u, y_h), (d2["u"], d2["y"])], **d["structure"], w0=d["w0"],
                            disturbances="remove")
    assert [round(x.line, 2) for x in res.disturbances] == [HUM_LINE]


def test_bad_arguments_are_refused_with_the_argument_named():
    d, u, y, y_h, _ = hummed(0)
    with pytest.raises(ValueError, match="u must have shape \\(P, N\\)"):
        lptv.disturbances(u.reshape(-1), y)
    with pytest.raises(ValueError, match="u and y must have the same shape"):
        lptv.disturbances(u, y[:, :-1])
    with pytest.raises(ValueError, match="u: at least 2 periods"):
        lptv.disturbances(u[:1], y[:1])
    bad = y.copy()
    bad[0, 3] = np.nan
    with pytest.raises(ValueError, match="y"):
        lptv.disturbances(u, bad)
    with pytest.raises(ValueError, match="alpha"):
        lptv.disturbances(u, y, alpha=0.0)
    with pytest.raises(ValueError, match="max_count"):
        lptv.disturbances(u, y, max_count=-1)
    with pytest.raises(ValueError, match="disturbances must be None or 'remove'"):
        fit(d, u, y, disturbances="yes")
    data = lptv.FrequencyData.from_periods(u, y, w0=d["w0"])
    with pytest.raises(ValueError, match="disturbances='remove' needs the periods"):
        lptv.identify(data, **d["structure"], disturbances="remove")
    with pytest.raises(ValueError, match="experiments\\[1\\]"):
        lptv.identify([(u, y), data], **d["structure"], w0=d["w0"], disturbances="remove")


def test_the_plot_shows_what_was_searched(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import lptv.plots

    d, u, y, y_h, _ = hummed(1)
    out = lptv.disturbances(u, y_h)
    assert set(out.spectra) == {"u", "y"}
    pos, p2, level = out.spectra["y"]
    assert pos.size == p2.size == level.size and np.all(pos % 1 != 0)     # never a line of the grid
    peak = pos[np.argmax(p2 / level)]
    assert abs(peak - HUM_LINE) < 1.0 / y.shape[0]                          # the peak is the hum's bin
    fig = lptv.plots.disturbances(out, w0=d["w0"])
    assert [ax.get_title() for ax in fig.axes] == ["input: nothing found", "output: 1 sinusoid off the grid"]
    assert fig.axes[1].get_xlabel() == "angular frequency (rad/s)"
    fig.savefig(tmp_path / "disturbances.png")
    with pytest.raises(ValueError, match="result must be an lptv.DisturbanceResult"):
        lptv.plots.disturbances(out.found)
    with pytest.raises(ValueError, match="w0"):
        lptv.plots.disturbances(out, w0=-1.0)
