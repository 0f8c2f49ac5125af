"""What the reports of ``lptv identify`` draw and say, checked against independent routes.

The rig: a mass-spring-damper m x'' + c x' + k(t) x = F with m = 1 kg, c = 0.8 N s/m,
k(t) = 40 (1 + 0.3 cos(2 pi t / 5)) N/m, integrated by scipy's solve_ivp under a multisine on the
30 adjacent lines 1..30 (0.2-6 Hz), 8 periods of 5 s at 200 Hz after 4 periods of start-up, 1 %
noise on both channels, written as ``time [s],force [N],displacement [m]``. Measured spectra are
taken by NumPy's FFT of the periods here, the model's prediction by CVODE's periodic steady state
(lptv.simulation.timedomain), the test's thresholds by scipy.stats: none of them is the code that draws.
"""
import json
import re

import numpy as np
import pytest
import scipy.optimize
import scipy.stats

import lptv
from conftest import (REPORT_CHI_LEVEL, REPORT_MEASURED, REPORT_PREDICTED, SCALE_VS_KNOWN_STD,
                      SCALE_VS_KNOWN_STD_UNITS)
from lptv.apps import cli, units
from lptv.examples import paper_measurements
from outside_records import mass_spring_damper, write_csv

pytest.importorskip("matplotlib")
from lptv import plots  # noqa: E402

T, FS, P = 5.0, 200.0, 8
W0 = 2 * np.pi / T
MASS, DAMPING, STIFFNESS, VARIATION = 1.0, 0.8, 40.0, 0.3
STRUCTURE = dict(na=2, nb=0, ka=[1, 0, 0], kb=0)
ARGS = ["--input", "force", "--output", "displacement", "--period", "5", "--na", "2", "--nb", "0",
        "--ka", "1,0,0", "--kb", "0"]


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    t, f, x = mass_spring_damper(T, FS, P, lines=np.arange(1, 31), start=4 * T, mass=MASS, damping=DAMPING,
                                 stiffness=STIFFNESS, variation=VARIATION)
    path = write_csv(tmp_path_factory.mktemp("rig") / "rig.csv", t - t[0], f, x)
    u, y = f.reshape(P, -1), x.reshape(P, -1)
    return path, u, y


@pytest.fixture(scope="module")
def rig_fit(rig):
    _, u, y = rig
    # the sample route: the figures' error bars and branch panel are checked against NumPy's
    # statistics of the periods (the default route would draw its moderated variances)
    return lptv.identify(u, y, **STRUCTURE, w0=W0, noise="sample")


def _run(capsys, *argv):
    rc = cli.main(["identify", *map(str, argv)])
    out, err = capsys.readouterr()
    return rc, out, err


def _numpy_spectra(u, y):
    """Mean spectra of the periods and the variances of those means (NumPy's FFT)."""
    n = u.shape[1]
    U, Y = np.fft.rfft(u, axis=1) / n, np.fft.rfft(y, axis=1) / n
    Um, Ym = U.mean(0), Y.mean(0)
    p = u.shape[0]
    vU, vY = U.var(0, ddof=1) / p, Y.var(0, ddof=1) / p
    cYU = ((Y - Ym) * np.conj(U - Um)).sum(0) / (p - 1) / p
    return Um, Ym, vU, vY, cYU


def _drawn_ratio(ax_m, ax_p, container):
    """The complex ratio drawn by an errorbar container of the magnitude panel (dB) and the
    matching one of the phase panel (degrees), with the x values."""
    x, db = container.lines[0].get_data()
    i = list(ax_m.containers).index(container)
    _, deg = ax_p.containers[i].lines[0].get_data()
    return np.asarray(x), 10 ** (np.asarray(db) / 20) * np.exp(1j * np.radians(deg))


def _drawn_prediction(ax_m, ax_p):
    mag = [l for l in ax_m.get_lines() if l.get_label().startswith("model's prediction")]
    assert len(mag) == 1
    ph = [l for l in ax_p.get_lines() if l.get_marker() == "." and l.get_color() == mag[0].get_color()]
    assert len(ph) == 1
    return np.asarray(mag[0].get_xdata()), 10 ** (mag[0].get_ydata() / 20) * np.exp(1j * np.radians(ph[0].get_ydata()))


def _fits():
    """(name, u, y, w0, identify's keywords) of the paper's example (lines 10, 20, ..., 240, whose
    branches a record separates where the neighbours' far branches stay below the noise)."""
    out = []
    for seed in (1, 3):
        m = paper_measurements(seed=seed, periods=8)
        out.append((f"paper-{seed}", m["u"], m["y"], m["w0"],
                    dict(na=2, nb=1, ka=3, kb=3, lines=range(1, 244))))
    return out


# ------------------------------------------------------------------------------ Bode of an LPTV fit

@pytest.mark.parametrize("case", ["rig", "paper-1", "paper-3"])
def test_lptv_bode_draws_measured_y_over_u_against_the_models_prediction_within_their_bands(case, rig, rig_fit):
    """Top panels: the measured Y/U (NumPy's ratio of the mean spectra, +-2 std from the periods'
    noise on input and output) and the model's output from the measured input over that input
    (CVODE's steady state of the identified model from the same input); the measured points
    scatter around the prediction as the noise says (their squared normalised distances sum to
    less than the REPORT_CHI_LEVEL quantile of a Gamma(n)); the branch G_0 alone, which the plot
    used to draw, misses them on the rig by far more."""
    from lptv.simulation import timedomain

    if case == "rig":
        _, u, y = rig
        res, w0 = rig_fit, W0
    else:
        _, u, y, w0, kw = next(c for c in _fits() if c[0] == case)
        res = lptv.identify(u, y, **kw, w0=w0, noise="sample")
    fig = plots.bode(res)
    ax_m, ax_p, ax_b = fig.axes
    assert ax_m.get_ylabel() == "|Y/U| (dB)" and ax_b.get_ylabel() == "|G_k| (dB)"
    assert len(ax_m.containers) == 1
    x, G_drawn = _drawn_ratio(ax_m, ax_p, ax_m.containers[0])
    lines = np.round(x / w0).astype(int)
    np.testing.assert_allclose(lines * w0, x, rtol=1e-12)
    Um, Ym, vU, vY, cYU = _numpy_spectra(u, y)
    G = Ym[lines] / Um[lines]
    np.testing.assert_allclose(G_drawn, G, rtol=REPORT_MEASURED)
    # the error bars: |G| +- 2 std, std from the periods (errors in variables, first order)
    var = (vY[lines] + np.abs(G) ** 2 * vU[lines] - 2 * np.real(np.conj(G) * cYU[lines])) / np.abs(Um[lines]) ** 2
    sd = np.sqrt(var)
    tops = np.array([seg[1, 1] for seg in ax_m.containers[0].lines[2][0].get_segments()])
    np.testing.assert_allclose(tops, 20 * np.log10(np.abs(G) + 2 * sd), rtol=0, atol=1e-9)
    # the prediction against CVODE from the same (mean measured) input
    xp, G_pred = _drawn_prediction(ax_m, ax_p)
    np.testing.assert_allclose(xp, x, rtol=1e-12)
    n = u.shape[1]
    top = min(2 * int(lines.max()) + 40, n // 2 - 1)       # lines far above carry noise only
    U_in = Um.copy()
    U_in[top + 1:] = 0
    y_td = timedomain.periodic_steady_state(res.model, U_in[:top + 1], n)
    G_td = (np.fft.rfft(y_td) / n)[lines] / Um[lines]
    np.testing.assert_allclose(G_pred, G_td, rtol=REPORT_PREDICTED)
    limit = scipy.stats.gamma.ppf(REPORT_CHI_LEVEL, lines.size)
    chi = float(np.sum(np.abs(G - G_td) ** 2 / var))
    assert chi < limit, (chi, limit)
    if case == "rig":
        G0 = res.model.freqresp(lines * w0)
        assert np.sum(np.abs(G - G0) ** 2 / var) > 100 * limit


def test_branch_panel_draws_the_data_only_where_the_record_separates_the_branches(rig_fit):
    """Third panel: the model's branches G_k(w) for k = -K..K (Model.freqresp); nonparametric points
    only where the record determines them: none for the rig's adjacent lines (said in the panel);
    on the paper's design the points are |Y_{l+k} / U_l| of the mean spectra (NumPy), on entries
    lptv.htf_estimate does not flag as overlapped, and the model's branches pass through them as
    the noise says."""
    ax_b = plots.bode(rig_fit).axes[2]
    assert not any(len(c.lines[0].get_xdata()) for c in ax_b.containers)
    assert any("no nonparametric estimate" in t.get_text() for t in ax_b.texts)
    assert sorted(l.get_label() for l in ax_b.get_lines() if l.get_label().startswith("G_")) == ["G_+1", "G_-1", "G_0"]
    total = chi = 0
    for name, u, y, w0, kw in _fits():
        res = lptv.identify(u, y, **kw, w0=w0, noise="sample")
        ax = plots.bode(res).axes[2]
        est = lptv.htf_estimate(u, y, w0=w0, branches=3)
        Um, Ym = _numpy_spectra(u, y)[:2]
        curves = {l.get_color(): l for l in ax.get_lines() if l.get_label().startswith("G_")}
        assert len(curves) == 7
        for c in ax.containers:
            x, db = c.lines[0].get_data()
            if not len(x):
                continue
            k = int(curves[c.lines[0].get_color()].get_label()[2:])
            l = np.round(np.asarray(x) / w0).astype(int)
            np.testing.assert_allclose(db, 20 * np.log10(np.abs(Ym[l + k] / Um[l])), rtol=0, atol=1e-9)
            row = est.overlapped[k + 3]
            assert not row[np.searchsorted(est.lines, l)].any()
            sd = est.std[k + 3][np.searchsorted(est.lines, l)]
            Gm = np.abs(res.model.freqresp(l * w0, branch=k))
            # |G| - |G_model| of a complex estimate with variance sd^2 has variance sd^2 / 2
            chi += float(np.sum(2 * (np.abs(Ym[l + k] / Um[l]) - Gm) ** 2 / sd ** 2))
            total += l.size
        drawn = sum(len(c.lines[0].get_xdata()) for c in ax.containers)
        assert drawn == int((~est.overlapped).sum())
    assert total > 0
    assert chi < scipy.stats.chi2.ppf(REPORT_CHI_LEVEL, total)


# ------------------------------------------------------------------------------ residue tests

def _f2_dof(F, p):
    """nu of F(2, nu) with survival p at F, by scipy's F distribution and a root finder."""
    g = lambda lognu: scipy.stats.f.sf(F, 2, np.exp(lognu)) - p
    if g(np.log(1e9)) >= 0:
        return np.inf
    return float(np.exp(scipy.optimize.brentq(g, np.log(1e-3), np.log(1e9), xtol=1e-14)))


def _residue_fits(rig, rig_fit):
    _, u, y = rig
    m = paper_measurements(seed=3, periods=4)
    return {"consistent": rig_fit,
            "time-invariant fit of the rig": lptv.identify(u, y, na=2, nb=0, w0=W0),
            "a harmonic short": lptv.identify(m["u"], m["y"], na=2, nb=1, ka=2, kb=3, w0=m["w0"],
                                              lines=range(1, 244))}


def test_each_residue_test_is_drawn_on_its_own_statistic_against_its_own_threshold(rig, rig_fit):
    """One bar per test, of the test's own statistic (z or F) and named as the report's table
    names it; its threshold is where its p-value reaches Holm's level alpha / (k - rank): for z the
    normal quantile (two-sided for all rows), for F the F(2, nu) quantile, nu recovered by
    scipy from the test's F and p; the bar crosses it exactly when (k - rank) p <= alpha, and is
    red exactly when the verdict says the test rejects."""
    seen = set()
    for name, res in _residue_fits(rig, rig_fit).items():
        tests = res.residue_tests
        fig = plots.residue_tests(res)
        k = len(tests.tests)
        ranks = np.argsort(np.argsort([t.p_value for t in tests.tests], kind="stable"), kind="stable")
        by_kind = {"residues": [t for t in tests.tests if t.kind != "score"],
                   "score": [t for t in tests.tests if t.kind == "score"]}
        axes = dict(zip([kd for kd in ("residues", "score") if by_kind[kd]], fig.axes))
        assert axes["residues"].get_xlabel().startswith("z:")
        if "score" in axes:
            assert axes["score"].get_xlabel().startswith("F ")
        for kind, ax in axes.items():
            bars = ax.patches
            assert len(bars) == len(by_kind[kind])
            label_at = {round(float(pos), 6): lab.get_text() for pos, lab in zip(ax.get_yticks(), ax.get_yticklabels())}
            marks = {}
            for coll in ax.collections:
                for seg in coll.get_segments():
                    marks.setdefault(round(float(np.mean(seg[:, 1])), 6), []).append(float(seg[0, 0]))
            for j, bar in enumerate(bars):            # drawn in the order of the verdict's tests
                t = by_kind[kind][j]
                yc = round(bar.get_y() + bar.get_height() / 2, 6)
                label = label_at[yc]
                i = tests.tests.index(t)
                assert bar.get_width() == pytest.approx(t.statistic, rel=1e-12)
                assert label == f"{plots.residue_test_label(t)} ({t.rows.size} rows)"
                q = tests.alpha / (k - ranks[i])
                if t.kind == "score":
                    nu = _f2_dof(t.statistic, t.p_value)
                    want = [scipy.stats.f.isf(q, 2, nu) if np.isfinite(nu) else scipy.stats.expon.isf(q)]
                elif t.name == "rows with signal":
                    want = [-scipy.stats.norm.isf(q / 2), scipy.stats.norm.isf(q / 2)]
                else:
                    want = [scipy.stats.norm.isf(q)]
                got = sorted(marks[yc])
                np.testing.assert_allclose(got, want, rtol=1e-8, atol=1e-10)
                crosses = (t.statistic >= max(want)) or (len(want) == 2 and t.statistic <= min(want))
                assert crosses == ((k - ranks[i]) * t.p_value <= tests.alpha)
                red = np.allclose(bar.get_facecolor()[:3], (0.839, 0.153, 0.157), atol=0.01)
                assert red == t.rejects
                seen.add((t.kind, t.rejects))
    assert {("score", True), ("score", False), ("residues", True), ("residues", False)} <= seen


def test_the_report_table_names_the_tests_as_the_figure_does(rig, tmp_path, capsys):
    path, _, _ = rig
    rc, out, err = _run(capsys, path, *ARGS, "--out", tmp_path / "o")
    assert rc == 0, err
    page = (tmp_path / "o" / "report.html").read_text()
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    names = [t["name"] for t in summary["residue_tests"]]
    assert names[0] == "rows with signal" and all(n.startswith("one more harmonic on ") for n in names[1:])
    cells = re.findall(r"<tr><td>([^<]*)</td><td>([^<]*)</td>", page)
    table = {what: short for short, what in cells}
    assert [table[n] for n in names] == ["all rows"] + [f"{n.split()[-1]}: +1 harmonic" for n in names[1:]]


# ------------------------------------------------------------------------------ coefficients

def test_coefficients_over_one_period_one_panel_each_with_its_band(rig_fit):
    """What the report draws per coefficient: a_0(t) = a0.re0 + 2 (a0.re1 cos w0 t - a0.im1 sin w0 t)
    with std(t)^2 = g^T C g, g = (1, 2 cos w0 t, -2 sin w0 t) over those parameters' covariance;
    the constant ones with their own std; one axes each, the band +- 1.96 std."""
    res = rig_fit
    t = np.linspace(0, T, 50)
    values, std, names = units.trajectories(res, t)
    assert names == ["a0", "a1", "a2", "b0"]
    idx = {n: i for i, n in enumerate(res.eta_names)}
    eta, C = res.eta, res.covariance
    g = np.column_stack([np.ones_like(t), 2 * np.cos(W0 * t), -2 * np.sin(W0 * t)])
    j = [idx["a0.re0"], idx["a0.re1"], idx["a0.im1"]]
    np.testing.assert_allclose(values[:, 0], g @ eta[j], rtol=1e-12)
    np.testing.assert_allclose(std[:, 0], np.sqrt(np.einsum("ti,ij,tj->t", g, C[np.ix_(j, j)], g)), rtol=1e-10)
    for c, name in ((1, "a1"), (3, "b0")):
        np.testing.assert_allclose(values[:, c], eta[idx[f"{name}.re0"]], rtol=1e-12)
        np.testing.assert_allclose(std[:, c], np.sqrt(C[idx[f"{name}.re0"], idx[f"{name}.re0"]]), rtol=1e-10)
    assert np.all(std[:, 2] == 0)                                # a2, the normalised one
    fig = plots.coefficient_bands(t, values, std, names=names, units=["N/m", None, None, None])
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_ylabel() for ax in axes] == ["a0 (N/m)", "a1", "a2", "b0"]
    z = scipy.stats.norm.ppf(0.975)
    for c, ax in enumerate(axes):
        np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), values[:, c], rtol=0, atol=0)
        lo, hi = ax.get_ylim()
        assert lo <= values[:, c].min() and values[:, c].max() <= hi
        if std[:, c].any():
            verts = ax.collections[0].get_paths()[0].vertices
            width = {}
            for xv, yv in verts:
                width.setdefault(round(xv, 9), []).append(yv)
            spans = np.array([max(width[round(tv, 9)]) - min(width[round(tv, 9)]) for tv in t])
            np.testing.assert_allclose(spans, 2 * z * std[:, c], rtol=1e-9, atol=1e-12)
    # each panel its own scale: the damping's axis spans far less than the stiffness's
    assert np.ptp(axes[1].get_ylim()) < 0.01 * np.ptp(axes[0].get_ylim())


# ------------------------------------------------------------------------------ physical units

def test_scale_gives_the_parameters_of_a_fit_with_that_coefficient_known(rig, tmp_path, capsys):
    """--scale b0=1 rescales the normalised fit and its covariance; --known b0=1 fits in that
    parametrisation through the core. WGTLS's cost does not change under a common factor of
    the parameters, so the two must agree to the stopping rule; the physical values then meet
    the rig's m, c and k(t) (within 4 of their std)."""
    path, _, _ = rig
    rc, out, err = _run(capsys, path, *ARGS, "--scale", "b0=1", "--out", tmp_path / "s")
    assert rc == 0, err
    assert "parameters in physical form (--scale b0=1):" in out
    rc, _, err = _run(capsys, path, *ARGS, "--known", "b0=1", "--out", tmp_path / "k")
    assert rc == 0, err
    s = json.loads((tmp_path / "s" / "summary.json").read_text())
    k = json.loads((tmp_path / "k" / "summary.json").read_text())
    assert s["scale"] == {"coefficient": "b0", "value": 1.0}
    scaled = {r["name"]: r for r in s["parameters_scaled"]}
    known = {r["name"]: r for r in k["parameters"]}
    assert scaled["b0.re0"]["value"] == 1.0 and scaled["b0.re0"]["std"] == 0.0
    assert set(known) == set(scaled) - {"b0.re0"}
    for name, r in known.items():
        assert scaled[name]["value"] == pytest.approx(r["value"], abs=SCALE_VS_KNOWN_STD_UNITS * r["std"])
        assert scaled[name]["std"] == pytest.approx(r["std"], rel=SCALE_VS_KNOWN_STD)
    # the normalised table is kept beside it, unchanged by --scale
    plain = {r["name"]: r for r in s["parameters"]}
    assert plain["a2.re0"]["value"] == 1.0 and plain["a2.re0"]["std"] == 0.0
    for name, truth in (("a2.re0", MASS), ("a1.re0", DAMPING), ("a0.re0", STIFFNESS),
                        ("a0.amp1", STIFFNESS * VARIATION), ("a0.phase1", 0.0)):
        assert abs(scaled[name]["value"] - truth) < 4 * scaled[name]["std"], name
    page = (tmp_path / "s" / "report.html").read_text()
    rows = dict(re.findall(r"<tr><td>(a\d\.re0)</td>(?:<td>[^<]*</td>){3}<td>([^<]*)</td>", page))
    assert rows == {"a0.re0": "N/m", "a1.re0": "N s/m", "a2.re0": "N s^2/m"}
    assert "set by --scale" in page


def test_the_report_says_the_parameters_are_normalised_and_how_to_scale_them(rig, tmp_path, capsys):
    path, _, _ = rig
    rc, _, err = _run(capsys, path, *ARGS, "--out", tmp_path / "o")
    assert rc == 0, err
    page = (tmp_path / "o" / "report.html").read_text()
    assert "the fit sets the mean of a2 to 1" in page and "--scale b0=1" in page
    assert '<p class="verdict ok">' in page
    # units in the normalised form too: with a2 = 1 the stiffness reads as k / m (1/s^2)
    rows = dict(re.findall(r"<tr><td>(a\d\.re0)</td>(?:<td>[^<]*</td>){3}<td>([^<]*)</td>", page))
    assert rows == {"a0.re0": "1/s^2", "a1.re0": "1/s", "a2.re0": ""}


def test_coefficient_units_follow_the_scaled_coefficient():
    m = lptv.Model([[40.0], [0.8], [1.0]], [[1.0], [0.1]], w0=1.0)
    assert units.coefficient_units(m, "N", "m", ("b0", 1.0)) == {
        "a0": "N/m", "a1": "N s/m", "a2": "N s^2/m", "b0": "", "b1": "s"}
    assert units.coefficient_units(m, "V", "rad/s", ("a1", 1.0)) == {
        "a0": "1/s", "a1": "", "a2": "s", "b0": "(rad/s)/(V s)", "b1": "(rad/s)/V"}
    assert units.coefficient_units(m, None, "m") == {}
    d = lptv.Model([[0.5], [1.0]], [[1.0]], w0=2 * np.pi / 10, ts=0.1)
    assert units.coefficient_units(d, "N", "m", ("b0", 1.0)) == {"a0": "N/m", "a1": "N/m", "b0": ""}
    assert [units.channel_unit(n) for n in ("force [N]", "x (mm)", "u", None)] == ["N", "mm", None, None]


def test_no_report_writes_the_model_and_summary_only(rig, tmp_path, capsys):
    path, _, _ = rig
    rc, out, err = _run(capsys, path, *ARGS, "--no-report", "--out", tmp_path / "n")
    assert rc == 0, err
    assert sorted(p.name for p in (tmp_path / "n").iterdir()) == ["model.json", "summary.json"]
    assert "report.html" not in out
    rc, _, err = _run(capsys, path, *ARGS, "--out", tmp_path / "r")
    assert rc == 0, err
    assert (tmp_path / "n" / "model.json").read_text() == (tmp_path / "r" / "model.json").read_text()
