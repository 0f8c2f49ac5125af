"""``lptv identify FILES... --input f1,f2 --output x1,x2``: several inputs and outputs from files.

The records are made outside lptv: SciPy's solve_ivp (DOP853) of the two-mass system of
test_mimo_timedomain.py (M y'' + C y' + K(t) y = u, coupling spring k_c(t) = 2 (1 + 0.3 cos t)),
at its periodic steady state (shooting), under multisines made with NumPy, one experiment per
file with its own random phases, P noisy periods written as CSV columns. The command must give
the model lptv.identify gives on the same arrays, exit 0 for the right structure and 3 when a
harmonic of K(t) is missing; the options it cannot use and the channels it cannot find are
one-line errors with exit status 2.
"""
import json
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lptv
from lptv.apps import cli, mimoid

W0, N, P = 1.0, 64, 8
T0 = 2 * np.pi / W0
LINES = np.arange(1, 24, 2)            # odd lines: the +-1 sidebands of K(t) fall on even ones
NOISE = 1e-4
Mm, Cm, K0 = np.diag([1.0, 2.0]), np.diag([1.0, 2.0]), np.diag([5.0, 3.0])
S = np.array([[1.0, -1.0], [-1.0, 1.0]])
KC0, DEPTH = 2.0, 0.3


def true_model():
    Kh = np.zeros((2, 2, 3))
    Kh[:, :, 1] = K0 + KC0 * S
    Kh[:, :, 0] = Kh[:, :, 2] = KC0 * DEPTH / 2 * S
    return lptv.MimoModel.mechanical(Mm, Cm, Kh, np.eye(2), w0=W0)


def steady_period(seed):
    """One period (N samples) of u (2 channels) and y (2 channels) at periodic steady state."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(0, 2 * np.pi, (2, LINES.size))
    Minv = np.linalg.inv(Mm)

    def u(t):
        return np.sum(np.cos(np.multiply.outer(LINES * W0, np.atleast_1d(t))[None] + phi[:, :, None]), axis=1)

    def f(t, x, forced=True):
        y, v = x[:2], x[2:]
        K = K0 + KC0 * (1 + DEPTH * np.cos(W0 * t)) * S
        acc = -Minv @ (Cm @ v + K @ y) + (Minv @ u(t)[:, 0] if forced else 0)
        return np.concatenate([v, acc])

    def augmented(t, z):
        Phi = z[4:].reshape(4, 4)
        return np.concatenate([f(t, z[:4]), np.column_stack([f(t, Phi[:, j], False) for j in range(4)]).ravel()])

    sol = solve_ivp(augmented, (0, T0), np.concatenate([np.zeros(4), np.eye(4).ravel()]), method="DOP853",
                    rtol=1e-11, atol=1e-13)
    Phi = sol.y[4:, -1].reshape(4, 4)
    x0 = np.linalg.solve(np.eye(4) - Phi, sol.y[:4, -1])
    t = np.arange(N) * T0 / N
    sol = solve_ivp(f, (0, T0), x0, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=t)
    return u(t).T, sol.y[:2].T


@pytest.fixture(scope="module")
def experiments():
    """Two experiments (u, y) of shape (P, N, 2), noisy periods of the steady state."""
    out = []
    for e in range(2):
        u1, y1 = steady_period(10 + e)
        rng = np.random.default_rng(20 + e)
        u = np.tile(u1, (P, 1, 1)) + NOISE * rng.standard_normal((P, N, 2))
        y = np.tile(y1, (P, 1, 1)) + NOISE * rng.standard_normal((P, N, 2))
        out.append((u, y))
    return out


def write_csv(path, u, y, header="time,F1 [N],f2 [N],x1 [m],x2 [m]"):
    t = np.arange(P * N) * T0 / N
    np.savetxt(path, np.column_stack([t, u.reshape(-1, 2), y.reshape(-1, 2)]), fmt="%.17g", delimiter=",",
               header=header, comments="")
    return path


@pytest.fixture()
def files(experiments, tmp_path):
    return [write_csv(tmp_path / f"exp{e}.csv", *experiments[e]) for e in range(2)]


def identify_cli(capsys, *argv, report=False):
    """lptv identify; without its report unless ``report`` (asked by the tests that read
    report.html and by those whose report takes a path of its own: discrete time, no verdict)."""
    argv = [*map(str, argv)]
    if not report and "--no-report" not in argv:
        argv.append("--no-report")
    rc = cli.main(["identify", *argv])
    out, err = capsys.readouterr()
    return rc, out, err


FIT = ["--input", "f1,f2", "--output", "x1,x2", "--period", T0, "--na", "2", "--nb", "0", "--ka", "1,0,0"]

needs_fit = pytest.mark.skipif(not mimoid.mimo_fit_available(), reason="lptv.identify takes one channel only")


def true_value(name):
    """The normalised true parameter 'a0[1,0].re1' (A_na,0 = I: M^-1 times the equation)."""
    side, order, p, q, part, k = re.fullmatch(r"([ab])(\d)\[(\d),(\d)\]\.(re|im)(\d)", name).groups()
    Minv = np.linalg.inv(Mm)
    model = true_model()
    c = np.einsum("pr,nrqk->npqk", Minv, model.a if side == "a" else model.b)
    K = (c.shape[3] - 1) // 2
    v = c[int(order), int(p), int(q), K + int(k)] if int(k) <= K else 0.0
    return v.real if part == "re" else v.imag


@needs_fit
@pytest.mark.parametrize("method", ["wgtls", "sml"])
def test_the_command_gives_the_python_api_model_and_accepts_the_right_structure(method, experiments, files,
                                                                                 tmp_path, capsys):
    rc, out, err = identify_cli(capsys, *files, *FIT, "--method", method, "--out", tmp_path / "o")
    assert rc == 0, out + err
    assert "2 experiments, 2 inputs (F1 [N], f2 [N]), 2 outputs (x1 [m], x2 [m])" in out.splitlines()[0]
    assert "verdict: the model is consistent with the noise" in out
    res = lptv.identify(experiments, na=2, nb=0, ka=[1, 0, 0], kb=0, w0=W0, method=method)
    f = lptv.floquet(res.model)
    assert f"stability: stable: 4 Floquet multipliers, the largest of magnitude {f.spectral_radius:.6g}" in out
    model = lptv.MimoModel.load(tmp_path / "o" / "model.json")
    np.testing.assert_allclose(model.a, res.model.a, rtol=0, atol=1e-10 * np.abs(res.model.a).max())
    np.testing.assert_allclose(model.b, res.model.b, rtol=0, atol=1e-10 * np.abs(res.model.b).max())
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["inputs"] == ["F1 [N]", "f2 [N]"] and summary["model_ok"] is True
    assert [p["name"] for p in summary["parameters"]] == list(res.parameter_names)
    std = np.array([p["std"] for p in summary["parameters"]])
    # the estimate's multipliers: with M^-1 C = I, y = exp(-t/2) z turns the system into an
    # undamped one (z'' + (M^-1 K(t) - I/4) z = 0, away from its resonances), whose multipliers
    # lie on the unit circle: every |mu| is exp(-T0/2). The estimate's ln|mu| moves by T0 times
    # the change of the damping's eigenvalues, at most that of M^-1 C's entries: 5 std of them.
    assert summary["stability"]["is_stable"] is True
    ln_rho = np.log(summary["stability"]["spectral_radius"])
    damping_std = max(s for n, s in zip(res.parameter_names, std) if n.startswith("a1"))
    assert abs(ln_rho + 0.5 * T0) <= 5 * T0 * damping_std, (ln_rho + 0.5 * T0, damping_std)
    np.testing.assert_allclose(std, res.parameter_std, rtol=1e-8)
    # every estimate against the system integrated by solve_ivp, within 5 standard deviations
    free = std > 0
    assert free.sum() == 20
    z = [(res.eta[i] - true_value(n)) / std[i] for i, n in enumerate(res.parameter_names) if free[i]]
    assert np.max(np.abs(z)) <= 5, z


@needs_fit
def test_a_missing_harmonic_is_a_model_error(files, tmp_path, capsys):
    fit = [x if x != "1,0,0" else "0" for x in FIT]           # --ka 0: K(t) taken as constant
    rc, out, err = identify_cli(capsys, *files, *fit, "--out", tmp_path / "o")
    assert rc == 3, out + err
    assert "verdict: MODEL ERRORS: the model is rejected" in out


@needs_fit
def test_npz_periods_with_a_stored_fs_and_a_discrete_time_model(experiments, tmp_path, capsys):
    """(P, N) arrays per channel with fs stored and no period: w0 = 2 pi fs / N from one
    channel's periods; --discrete takes ts = 1 / fs and fits the model in the shift, as
    lptv.identify does on the same arrays with that ts."""
    files = []
    for e, (u, y) in enumerate(experiments):
        files.append(tmp_path / f"e{e}.npz")
        np.savez(files[-1], f1=u[..., 0], f2=u[..., 1], x1=y[..., 0], x2=y[..., 1], fs=N / T0)
    argv = ["--input", "f1,f2", "--output", "x1,x2", "--na", "2", "--nb", "2", "--ka", "1,0,0"]
    rc, out, err = identify_cli(capsys, *files, *argv, "--out", tmp_path / "c")
    assert rc in (0, 3), out + err
    assert "w0 = 1 rad/s, continuous-time model" in out.splitlines()[0]
    rc, out, err = identify_cli(capsys, *files, *argv, "--discrete", "--out", tmp_path / "d", report=True)
    assert rc in (0, 3), out + err
    summary = json.loads((tmp_path / "d" / "summary.json").read_text())
    assert summary["ts"] == pytest.approx(T0 / N, rel=1e-12) and summary["w0"] == pytest.approx(W0, rel=1e-12)
    model = lptv.MimoModel.load(tmp_path / "d" / "model.json")
    res = lptv.identify(experiments, na=2, nb=2, ka=[1, 0, 0], w0=W0, ts=T0 / N)
    assert model.discrete and np.allclose(model.a, res.model.a, rtol=0, atol=1e-10 * np.abs(res.model.a).max())


@needs_fit
def test_the_fit_s_refusals_name_the_options(files, tmp_path, capsys):
    rc, out, err = identify_cli(capsys, *files, *FIT, "--lines", "0-20", "--out", tmp_path / "o")
    assert rc == 2 and err.startswith("lptv identify: error: --lines: line 0 (") and "outside" in err
    rc, out, err = identify_cli(capsys, *files, *FIT, "--method", "ls", "--out", tmp_path / "o")
    assert rc == 2 and "--method" in err and len(err.strip().splitlines()) == 1


@needs_fit
def test_noise_free_records_give_the_system_and_no_verdict(tmp_path, capsys):
    """Identical periods (no noise): no statistics, so no verdict (exit status 4) and no std; the
    estimate is the integrated system's (DOP853 at rtol 1e-11 and a Jacobian of modest condition:
    1e-8 of the largest coefficient; measured 8e-12)."""
    files = []
    for e in range(2):
        u1, y1 = steady_period(10 + e)
        files.append(write_csv(tmp_path / f"e{e}.csv", np.tile(u1, (P, 1, 1)), np.tile(y1, (P, 1, 1))))
    rc, out, err = identify_cli(capsys, *files, *FIT, "--out", tmp_path / "o", report=True)
    assert rc == 4, out + err
    assert "verdict: NOT DETERMINED" in out
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["model_ok"] is None and all(p["std"] is None for p in summary["parameters"])
    values = np.array([p["value"] for p in summary["parameters"]])
    truth = np.array([true_value(p["name"]) for p in summary["parameters"]])
    assert np.abs(values - truth).max() <= 1e-8 * np.abs(truth).max()


def test_without_the_mimo_fit_the_command_says_so(files, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(mimoid, "mimo_fit_available", lambda: False)
    rc, out, err = identify_cli(capsys, *files, *FIT, "--out", tmp_path / "o")
    assert rc == 2 and err.strip() == f"lptv identify: error: {mimoid.NEEDS_FIT}"
    assert not (tmp_path / "o" / "model.json").exists()


def test_channels_and_options_it_cannot_use_are_one_line_errors(files, tmp_path, capsys):
    rc, out, err = identify_cli(capsys, *files, "--input", "f1,f3", *FIT[2:])
    assert rc == 2 and "column 'f3', the input named by --input (u=), is missing" in err
    assert err.startswith(f"lptv identify: error: {files[0]}: ") and len(err.strip().splitlines()) == 1
    rc, out, err = identify_cli(capsys, *files, *FIT, "--known", "a2=1")
    assert rc == 2 and "--known is for one input and one output" in err
    rc, out, err = identify_cli(capsys, *files, *FIT, "--covariance", "bootstrap")
    assert rc == 2 and "--covariance bootstrap is for one input and one output" in err
    rc, out, err = identify_cli(capsys, *files, "--input", "f1,,f2", *FIT[2:])
    assert rc == 2 and "an empty channel name" in err
    rc, out, err = identify_cli(capsys, files[0], "--input", "f1,f2", "--output", "x1,x2", "--na", "2", "--nb",
                                "0", "--period", T0, "--fs", 3.3)
    # the record's own time column names the cause (as for one channel), not the split's count
    assert rc == 2 and "--fs 3.3 contradicts the file's column 'time'" in err
    rc, out, err = identify_cli(capsys, files[0], "--input", "f1,f2", "--output", "x1,x2", "--na", "2", "--nb",
                                "0", "--period", T0, "--fs", 3.3, "--no-period-check")
    assert rc == 2 and "not a whole number" in err


@needs_fit
def test_the_report_shows_the_verdict_the_parameters_and_each_output_s_residue(experiments, files, tmp_path,
                                                                              capsys):
    """report.html: the verdict, every parameter, the residue figure of each output (its points
    the result's |e_p|^2 / C_e[p, p] in dB, computed here from the API's result) and the
    stability figure; --no-report writes none."""
    import matplotlib
    matplotlib.use("Agg")
    from lptv.apps import mimoreport

    rc, out, err = identify_cli(capsys, *files, *FIT, "--out", tmp_path / "o", report=True)
    assert rc == 0, out + err
    page = (tmp_path / "o" / "report.html").read_text()
    res = lptv.identify(experiments, na=2, nb=0, ka=[1, 0, 0], kb=0, w0=W0)
    assert "Verdict:</b> the model is consistent with the noise" in page
    assert all(n in page for n in res.parameter_names)
    assert (tmp_path / "o" / "residues.png").exists() and (tmp_path / "o" / "stability.png").exists()
    captured = {}
    real = mimoreport.Report.figure

    def keep(self, fig, filename, caption):
        captured[filename] = fig
        return real(self, fig, filename, caption)

    import unittest.mock as mock
    with mock.patch.object(mimoreport.Report, "figure", keep):
        mimoreport.build(res, files=files, inputs=["F1 [N]", "f2 [N]"], outputs=["x1 [m]", "x2 [m]"], w0=W0,
                         stability=mimoid.stability_of(res.model))
    e, C = np.asarray(res.residue), np.asarray(res.residue_covariance)
    for p, ax in enumerate(captured["residues.png"].axes):
        drawn = ax.get_lines()[0].get_ydata()
        want = 10 * np.log10(np.abs(e[:, p]) ** 2 / C[:, p, p].real)
        np.testing.assert_allclose(drawn, want, rtol=0, atol=1e-9)
        np.testing.assert_allclose(ax.get_lines()[0].get_xdata(), np.asarray(res.lines) * W0, rtol=1e-12)
    rc, out, err = identify_cli(capsys, *files, *FIT, "--out", tmp_path / "n", "--no-report")
    assert rc == 0 and not (tmp_path / "n" / "report.html").exists()
    assert "report.html" not in out


@needs_fit
@pytest.mark.parametrize("noise", ["sample", "moderated"])
def test_noise_option_gives_the_api_route(noise, experiments, files, tmp_path, capsys):
    """--noise takes lptv.identify's noise route for several channels too, and says it (the
    moderated route itself: test_mimo_moderation.py)."""
    rc, out, err = identify_cli(capsys, *files, *FIT, "--noise", noise, "--out", tmp_path / "o")
    assert rc == 0, out + err
    res = lptv.identify(experiments, na=2, nb=0, ka=[1, 0, 0], kb=0, w0=W0, noise=noise)
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["noise"] == res.noise == noise
    assert summary["noise_choice"] == res.noise_choice == "asked for"
    assert f"noise (co)variances: {noise} (asked for)" in out
    model = lptv.MimoModel.load(tmp_path / "o" / "model.json")
    np.testing.assert_allclose(model.a, res.model.a, rtol=0, atol=1e-10 * np.abs(res.model.a).max())
    # the normalised entries are written exactly (A_2,0 = I)
    names = [p["name"] for p in summary["parameters"]]
    values = {p["name"]: p["value"] for p in summary["parameters"]}
    assert [values[n] for n in names if n.startswith("a2[") and n.endswith(".re0")] == [1.0, 0.0, 0.0, 1.0]


@needs_fit
def test_inspect_several_channels_suggests_the_command_that_fits_them(files, tmp_path, capsys):
    """lptv inspect with comma lists inspects every input (with the first output) and every further
    output (with the first input), finds the period common to all (N samples: the solve_ivp
    records repeat every period) and suggests lptv identify for all channels; that command, with
    the orders filled in and the second experiment's file added, fits and accepts the model."""
    import shlex

    rc = cli.main(["inspect", str(files[0]), "--input", "f1,f2", "--output", "x1,x2", "--out", str(tmp_path / "i")])
    out, err = capsys.readouterr()
    assert rc == 0, out + err
    assert "== pair 0: input 'F1 [N]', output 'x1 [m]' ==" in out
    assert "== pair 2: input 'F1 [N]', output 'x2 [m]' ==" in out
    assert f"all channels: every channel repeats every {N} samples" in out
    summary = json.loads((tmp_path / "i" / "summary.json").read_text())
    assert summary["period_samples"] == N and len(summary["pairs"]) == 3
    assert summary["inputs"] == ["F1 [N]", "f2 [N]"] and summary["outputs"] == ["x1 [m]", "x2 [m]"]
    assert (tmp_path / "i" / "report.html").exists() and (tmp_path / "i" / "pair1" / "report.html").exists()
    argv = shlex.split(summary["command"])
    assert argv[:3] == ["lptv", "identify", str(files[0])]
    fill = {"NA": "2", "NB": "0", "KA": "1,0,0", "KB": "0"}
    argv = [argv[2], str(files[1])] + [fill.get(a, a) for a in argv[3:]] + ["--out", str(tmp_path / "o")]
    rc, out, err = identify_cli(capsys, *argv)
    assert rc == 0, out + err
    assert "verdict: the model is consistent with the noise" in out
    period = float(argv[argv.index("--period") + 1])
    assert period == pytest.approx(T0, rel=1e-9)


def test_inspect_several_channels_names_a_channel_it_cannot_find(files, capsys):
    rc = cli.main(["inspect", str(files[0]), "--input", "f1,nope", "--output", "x1,x2"])
    out, err = capsys.readouterr()
    assert rc == 2 and "nope" in err and len(err.strip().splitlines()) == 1


@needs_fit
def test_a_wrong_period_is_named_by_the_record_not_blamed_on_the_fit(files, capsys):
    """The record's own diagnosis (the first input and output) names a period the record does not
    repeat at, and a period of several of its periods that leaves too few for several outputs;
    --no-period-check fits the record as cut."""
    base = ["--input", "f1,f2", "--output", "x1,x2", "--na", "2", "--nb", "0", "--ka", "1,0,0", "--no-report"]
    rc, out, err = identify_cli(capsys, *files, *base, "--period", 0.8 * T0)
    assert rc == 2 and "the input repeats every 6.28 s (64 samples)" in err and f"use --period {T0:.12g}" in err, err
    rc, out, err = identify_cli(capsys, *files, *base, "--period", 4 * T0)
    assert rc == 2 and "holds 4 of them and leaves 2 periods, and 2 outputs need more than 2" in err, err
    assert f"use --period {T0:.12g}" in err
    rc, out, err = identify_cli(capsys, *files, *base, "--period", 4 * T0, "--no-period-check")
    assert rc == 2 and "several outputs need P > ny periods" in err


@needs_fit
def test_transient_option_gives_the_api_fit_and_says_it(experiments, files, tmp_path, capsys):
    """--transient on fits the record's transient term as lptv.identify(..., transient=True) does,
    prints and writes it; --transient off and the default on the periods' noise do not; one
    input and one output refuse --transient on with the reason."""
    rc, out, err = identify_cli(capsys, *files, *FIT, "--noise", "full", "--transient", "on", "--out", tmp_path / "o",
                                report=True)
    assert rc in (0, 3), out + err
    res = lptv.identify(experiments, na=2, nb=0, ka=[1, 0, 0], kb=0, w0=W0, noise="full", transient=True)
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["transient"]["powers"] == [0, 1] and summary["transient"]["variable"] == "s"
    np.testing.assert_allclose(summary["transient"]["coefficients"], res.transient, rtol=1e-9,
                               atol=1e-12 * np.abs(res.transient).max())
    assert "the record's transient term fitted (s^0, s^1; 8 real coefficients" in out
    assert "transient term fitted" in (tmp_path / "o" / "report.html").read_text()
    rc, out, err = identify_cli(capsys, *files, *FIT, "--noise", "full", "--transient", "off", "--out", tmp_path / "p")
    assert json.loads((tmp_path / "p" / "summary.json").read_text())["transient"] is None
    assert "transient term fitted" not in out
    rc, out, err = identify_cli(capsys, files[0], "--input", "f1", "--output", "x1", "--period", T0, "--na", "2",
                                "--nb", "0", "--transient", "on")
    assert rc == 2 and "--transient on is built for several channels" in err
