"""Several channels have the one-channel route's features: rows from line 1, intervals, the
summary with units, --scale, the verdict's words and exit status.

The records are made outside lptv: SciPy's solve_ivp (DOP853) of two masses that do not touch,
m_p y_p'' + c_p y_p' + k_p(t) y_p = u_p with k_p(t) = k_p (1 + d_p cos t), at their periodic
steady state (shooting), under multisines made with NumPy. Two experiments, the second with
input 2 reversed (an orthogonal design: per line the inputs' matrix has orthogonal columns),
so that the 2 x 2 fit of the decoupled system is compared with the one-channel fits of each
channel on the same experiments; and the 1 x 1 fit (arrays (P, N, 1)) with the one-channel fit
of the same arrays, which is the same estimator and must agree to the iterations' tolerance.
"""
import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lptv
from lptv.apps import cli, mimoreport, units
from conftest import MIMO_1X1_ETA, MIMO_1X1_STD, MIMO_DECOUPLED_SIGMAS, MIMO_DECOUPLED_STD_RATIO, MIMO_SCALED_SAME_SYSTEM

W0, N, P = 1.0, 64, 8
T0 = 2 * np.pi / W0
LINES = np.arange(1, 24, 2)            # odd lines: the +-1 sidebands of k_p(t) fall on even ones
NOISE = 1e-3
MASS, DAMP, K0, DEPTH = np.array([1.0, 2.0]), np.array([1.0, 2.0]), np.array([5.0, 3.0]), np.array([0.3, 0.2])
STRUCT = dict(na=2, nb=0, ka=[1, 0, 0], w0=W0)
ROWS = range(1, 25)                    # from line 1: row 1 reads line 0, 1 and 2 (K = 1)


def steady_period(seed):
    """One period (N samples) of u and y (2 channels each) at periodic steady state."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(0, 2 * np.pi, (2, LINES.size))

    def u(t):
        return np.sum(np.cos(np.multiply.outer(LINES * W0, np.atleast_1d(t))[None] + phi[:, :, None]), axis=1)

    def f(t, x, forced=True):
        y, v = x[:2], x[2:]
        k = K0 * (1 + DEPTH * np.cos(W0 * t))
        return np.concatenate([v, (-(DAMP * v + k * y) + (u(t)[:, 0] if forced else 0)) / MASS])

    def augmented(t, z):
        Phi = z[4:].reshape(4, 4)
        return np.concatenate([f(t, z[:4]), np.column_stack([f(t, Phi[:, j], False) for j in range(4)]).ravel()])

    sol = solve_ivp(augmented, (0, T0), np.concatenate([np.zeros(4), np.eye(4).ravel()]), method="DOP853",
                    rtol=1e-11, atol=1e-13)
    x0 = np.linalg.solve(np.eye(4) - sol.y[4:, -1].reshape(4, 4), sol.y[:4, -1])
    t = np.arange(N) * T0 / N
    sol = solve_ivp(f, (0, T0), x0, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=t)
    return u(t).T, sol.y[:2].T


@pytest.fixture(scope="module")
def periods():
    u1, y1 = steady_period(10)
    sign = np.array([1.0, -1.0])
    return [(u1, y1), (u1 * sign, y1 * sign)]        # the system is linear: input 2 reversed, output 2 too


def noisy(periods, seed):
    rng = np.random.default_rng(seed)
    return [(np.tile(u1, (P, 1, 1)) + NOISE * rng.standard_normal((P, N, 2)),
             np.tile(y1, (P, 1, 1)) + NOISE * rng.standard_normal((P, N, 2))) for u1, y1 in periods]


def true_value(name):
    """The normalised true parameter 'a0[1,1].re1' (a_2 = 1: the equation over m_p)."""
    coef, part = name.split(".")
    c, n, p, q = coef[0], int(coef[1]), int(coef[3]), int(coef[5])
    if p != q or part.startswith("im"):
        return 0.0
    k = int(part[2:])
    if c == "b":
        return 1 / MASS[p]
    if n == 0:
        return (K0[p] if k == 0 else K0[p] * DEPTH[p] / 2) / MASS[p]
    return 0.0 if k else (DAMP[p] if n == 1 else MASS[p]) / MASS[p]


def one_channel(experiments, p, lines, **kw):
    return lptv.identify([(u[..., p], y[..., p]) for u, y in experiments], **STRUCT,
                         lines=[lines] * len(experiments), noise="sample", **kw)


# ------------------------------------------------------------------------------ rows from line 1

@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_one_by_one_fit_takes_rows_from_line_1_as_the_one_channel_fit(periods, seed):
    """Arrays (P, N, 1) go the route of several channels; with rows from line 1 (row 1 reads line
    0 and line 2, row 2 lines 1..3) its WGTLS is the one-channel WGTLS on the same data: the
    conjugate lines read alike, the same estimate and the same intervals (the one-channel
    covariance adds a second-order term: conftest.MIMO_1X1_STD)."""
    experiments = noisy(periods, seed)
    u, y = experiments[0][0][..., :1], experiments[0][1][..., :1]
    one = lptv.identify(u[..., 0], y[..., 0], **STRUCT, lines=ROWS, noise="sample")
    mimo = lptv.identify(u, y, **STRUCT, lines=ROWS, noise="sample")
    assert isinstance(mimo, lptv.MimoIdentificationResult) and mimo.lines.tolist() == list(ROWS)
    assert [n.replace("[0,0]", "") for n in mimo.parameter_names] == list(one.eta_names)
    free = one.parameter_std > 0
    scale = one.parameter_std[free]
    np.testing.assert_allclose(mimo.eta[free] / scale, one.eta[free] / scale, rtol=0, atol=MIMO_1X1_ETA)
    np.testing.assert_allclose(mimo.parameter_std[free], scale, rtol=MIMO_1X1_STD)
    half = 1.6448536269514722 * scale[:, None]           # the 90 % intervals: within MIMO_1X1_STD of their width
    np.testing.assert_allclose((mimo.confidence_interval(0.9)[free] - one.confidence_interval(0.9)[free]) / half,
                               0.0, rtol=0, atol=MIMO_1X1_STD)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_decoupled_two_by_two_fit_from_line_1_is_the_one_channel_fits(periods, seed):
    """The 2 x 2 fit of the two masses, rows from line 1, against each channel's own fit of the
    same experiments: every diagonal entry within MIMO_DECOUPLED_SIGMAS of the one-channel std of
    the one-channel estimate and its interval's width within MIMO_DECOUPLED_STD_RATIO (the 2 x 2
    fit also estimates the couplings, true 0, from noisy regressors: the two estimators differ
    by noise); every entry within 5 std of the integrated system."""
    experiments = noisy(periods, seed)
    mimo = lptv.identify(experiments, **STRUCT, lines=[ROWS, ROWS], noise="sample")
    names = list(mimo.parameter_names)
    ci = mimo.confidence_interval(0.95)
    for p in range(2):
        one = one_channel(experiments, p, ROWS)
        one_ci = one.confidence_interval(0.95)
        for i, n in enumerate(one.eta_names):
            if one.parameter_std[i] == 0:
                continue
            c, part = n.split(".")
            j = names.index(f"{c}[{p},{p}].{part}")
            assert abs(mimo.eta[j] - one.eta[i]) <= MIMO_DECOUPLED_SIGMAS * one.parameter_std[i], n
            ratio = (ci[j, 1] - ci[j, 0]) / (one_ci[i, 1] - one_ci[i, 0])
            assert MIMO_DECOUPLED_STD_RATIO[0] <= ratio <= MIMO_DECOUPLED_STD_RATIO[1], (n, ratio)
    free = mimo.parameter_std > 0
    z = (mimo.eta[free] - np.array([true_value(n) for n in names])[free]) / mimo.parameter_std[free]
    assert np.max(np.abs(z)) <= 5, z
    assert mimo.model_ok and mimo.verdict.startswith("the model is consistent with the noise")


def test_rows_from_line_1_are_fitted_but_not_judged_and_sml_says_why_not(periods):
    """Rows l <= K read line 0 and conjugate lines, whose residues are not circular: the verdict's
    tests leave them out (as for one channel); SML's circular likelihood refuses them with the
    reason and the way out."""
    experiments = noisy(periods, 1)
    res = lptv.identify(experiments, **STRUCT, lines=[ROWS, ROWS], noise="sample")
    judged = res.lines[res.judged_rows]
    assert judged.min() == 2 and set(res.lines[~np.isin(np.arange(res.lines.size), res.judged_rows)]) == {1}
    with pytest.raises(ValueError, match=r"lines: line 1 is a row l <= K = 1.*method='sml'.*rows from 2"):
        lptv.identify(experiments, **STRUCT, lines=[ROWS, ROWS], method="sml", noise="sample")
    assert lptv.identify(experiments, **STRUCT, lines=[ROWS[1:], ROWS[1:]], method="sml", noise="sample").model_ok


# ------------------------------------------------------------------------------ the command line

def write_csv(path, u, y, header):
    t = np.arange(P * N) * T0 / N
    np.savetxt(path, np.column_stack([t, u.reshape(-1, 2), y.reshape(-1, 2)]), fmt="%.17g", delimiter=",",
               header=header, comments="")
    return str(path)


@pytest.fixture()
def files(periods, tmp_path):
    header = "time [s],F1 [N],F2 [N],x1 [mm],x2 [V]"
    return [write_csv(tmp_path / f"exp{e}.csv", u, y, header) for e, (u, y) in enumerate(noisy(periods, 5))]


FIT = ["--input", "f1,f2", "--output", "x1,x2", "--period", str(T0), "--na", "2", "--nb", "0", "--ka", "1,0,0",
       "--noise", "sample"]


def run(capsys, *argv, report=False):
    """lptv identify; without its report unless ``report`` (no test here reads report.html: the
    runs that keep it are those whose report takes a path of its own, a rejected or undetermined
    verdict and --scale, so that building it stays exercised)."""
    rc = cli.main(["identify", *map(str, argv), *([] if report else ["--no-report"])])
    out, err = capsys.readouterr()
    return rc, out, err


def test_the_command_takes_rows_from_line_1(files, tmp_path, capsys):
    rc, out, err = run(capsys, *files, *FIT, "--lines", "1-24", "--out", tmp_path / "o")
    assert rc == 0, out + err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["n_rows"] == 2 * 24


def test_the_summary_shows_the_intervals_and_the_units(periods, files, tmp_path, capsys):
    """The printout and summary.json: every parameter with its std and 95 % interval (the result's
    confidence_interval) and its unit from the channels' names; each diagonal entry's unit that
    of the one-channel summary for that channel; the report's residue axes name each output
    with its own unit."""
    import matplotlib
    matplotlib.use("Agg")

    rc, out, err = run(capsys, *files, *FIT, "--out", tmp_path / "o")
    assert rc == 0, out + err
    res = lptv.identify(noisy(periods, 5), **STRUCT, noise="sample")
    ci = res.confidence_interval(0.95)
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    rows = {r["name"]: r for r in summary["parameters"]}
    assert "95 % interval" in out
    want = {"a0[0,0]": "1/s^2", "a0[0,1]": "mm/(V s^2)", "a1[1,0]": "V/(mm s)", "b0[0,1]": "mm/(N s^2)",
            "b0[1,1]": "V/(N s^2)", "a2[0,1]": "mm/V"}
    for i, name in enumerate(res.parameter_names):
        r = rows[name]
        if res.parameter_std[i] == 0:
            assert r["kind"] == "normalised"
            continue
        np.testing.assert_allclose([r["low"], r["high"]], ci[i], rtol=1e-12)
        assert f"[{ci[i, 0]:12.6g}, {ci[i, 1]:12.6g}]" in out
        coef = name.split(".")[0]
        if coef in want:
            assert r["unit"] == want[coef] and f"[{ci[i, 0]:12.6g}, {ci[i, 1]:12.6g}] {want[coef]}" in out
    # the diagonal entries in the units of one channel's summary (lptv.apps.units for one pair)
    siso = lptv.Model([[5.0], [1.0], [1.0]], [[1.0]], w0=W0)
    for p, (u_unit, y_unit) in enumerate([("N", "mm"), ("N", "V")]):
        one = units.coefficient_units(siso, u_unit, y_unit)
        for c in ("a0", "a1", "b0"):
            assert rows[f"{c}[{p},{p}].re0"]["unit"] == one[c]
    captured = {}
    real = mimoreport.Report.figure

    def keep(self, fig, filename, caption):
        captured[filename] = fig
        return real(self, fig, filename, caption)

    import unittest.mock as mock
    with mock.patch.object(mimoreport.Report, "figure", keep):
        mimoreport.build(res, files=files, inputs=["F1 [N]", "F2 [N]"], outputs=["x1 [mm]", "x2 [V]"], w0=W0,
                         stability={"text": "stable", "multipliers": None})
    labels = [ax.get_ylabel() for ax in captured["residues.png"].axes]
    assert "[mm]" in labels[0] and "[V]" in labels[1] and not any("[m]" in s for s in labels)


def test_scale_gives_the_physical_matrices_as_the_one_channel_scale(periods, files, tmp_path, capsys):
    """--scale b0=1: B_0's mean is the identity, and the decoupled masses read M, C and K(t): each
    diagonal entry within MIMO_DECOUPLED_SIGMAS of the one-channel --scale b0=1 of that channel
    (lptv.apps.units.scaled, the one-channel route), its interval within MIMO_DECOUPLED_STD_RATIO
    of that one's; the fit and its verdict unchanged."""
    rc, out, err = run(capsys, *files, *FIT, "--scale", "b0=1", "--out", tmp_path / "o", report=True)
    assert rc == 0, out + err
    assert "parameters in physical form (--scale b0=1" in out
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["scale"] == {"coefficient": "b0", "value": 1.0}
    rows = {r["name"]: r for r in summary["parameters_scaled"]}
    assert [rows[f"b0[{p},{q}].re0"]["value"] for p in range(2) for q in range(2)] == [1.0, 0.0, 0.0, 1.0]
    assert rows["a2[0,0].re0"]["unit"] == "N s^2/mm" and rows["a0[1,1].re0"]["unit"] == "N/V"
    experiments = noisy(periods, 5)
    for p in range(2):
        one = one_channel(experiments, p, range(2, N // 2))     # the default rows K+1 .. N/2 - K
        phys = units.scaled(one, "b0", 1.0)
        std = np.sqrt(np.diag(phys.covariance))
        for i, n in enumerate(phys.eta_names):
            if std[i] == 0:
                continue
            c, part = n.split(".")
            r = rows[f"{c}[{p},{p}].{part}"]
            assert abs(r["value"] - phys.eta[i]) <= MIMO_DECOUPLED_SIGMAS * std[i], n
            assert MIMO_DECOUPLED_STD_RATIO[0] <= r["std"] / std[i] <= MIMO_DECOUPLED_STD_RATIO[1], n
    assert abs(rows["a2[1,1].re0"]["value"] - MASS[1]) <= 5 * rows["a2[1,1].re0"]["std"]
    plain = json.loads((tmp_path / "o" / "summary.json").read_text())["parameters"]
    rc2, out2, _ = run(capsys, *files, *FIT, "--out", tmp_path / "p")
    assert rc2 == rc and json.loads((tmp_path / "p" / "summary.json").read_text())["parameters"] == plain


def test_scale_by_a_matrix_that_is_not_square_says_why():
    from lptv.examples.mimo import small_fit
    from lptv.records.measurements import FileError

    res = small_fit()                                   # 1 input, 2 outputs: B_0 is 2 x 1
    with pytest.raises(FileError, match=r"--scale: b0 is a 2 x 1 matrix \(2 outputs, 1 input\).*square"):
        units.scaled_mimo(res, "b0", 1.0)
    phys = units.scaled_mimo(res, "a0", 2.0)            # A_0's mean set to 2 I: the same system
    a0 = phys.model.a[0, :, :, phys.model.a.shape[3] // 2].real
    np.testing.assert_allclose(a0, 2 * np.eye(2), rtol=0, atol=MIMO_SCALED_SAME_SYSTEM)
    G = lptv.simulate(res.model, np.ones((8, 1)), lines_out=7)
    np.testing.assert_allclose(lptv.simulate(phys.model, np.ones((8, 1)), lines_out=7), G, rtol=MIMO_SCALED_SAME_SYSTEM,
                               atol=0)


def test_the_verdict_s_words_and_exit_status_are_one_channel_s(periods, files, tmp_path, capsys):
    """'the model is consistent with the noise' (0), 'MODEL ERRORS:' (3), 'NOT DETERMINED' (4):
    the words of one channel, so that one grep finds both."""
    rc, out, err = run(capsys, *files, *FIT, "--out", tmp_path / "o")
    assert rc == 0 and "verdict: the model is consistent with the noise" in out, out + err
    bad = [a if a != "1,0,0" else "0" for a in FIT]     # k(t) taken as constant
    rc, out, err = run(capsys, *files, *bad, "--out", tmp_path / "b", report=True)
    assert rc == 3 and "verdict: MODEL ERRORS: the model is rejected: " in out, out + err
    assert json.loads((tmp_path / "b" / "summary.json").read_text())["verdict"].startswith("MODEL ERRORS:")
    clean = [write_csv(tmp_path / f"c{e}.csv", np.tile(u, (P, 1, 1)), np.tile(y, (P, 1, 1)),
                       "time [s],F1 [N],F2 [N],x1 [mm],x2 [V]") for e, (u, y) in enumerate(periods)]
    rc, out, err = run(capsys, *clean, *FIT, "--out", tmp_path / "c", report=True)
    assert rc == 4 and "verdict: NOT DETERMINED: " in out, out + err
    # one channel of the same files says the same words
    rc1, out1, err1 = run(capsys, files[0], *[a if a not in ("f1,f2", "x1,x2") else a[:2] for a in FIT],
                          "--out", tmp_path / "s")
    assert rc1 == 0 and "verdict: the model is consistent with the noise" in out1, out1 + err1
