"""The Python examples of the README and of the user guide (docs/guide/*.md) run as printed."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
DOCS = [README] + sorted((ROOT / "docs" / "guide").glob("*.md"))

# One marker per Python block of the README and the guide: the test that runs it finds it by this.
MARKERS = ("lptv.frozen_poles(res.model", "lptv.inspect(", "lptv.read_measurements(", "lptv.montecarlo(",
           "records.append(", "lptv.plots.distortion(d)", "lptv.min_crest_multisine(", "transient_record(",
           "continuous=True", 'referred="input"', 'referred="none"', 'disturbances="remove"',
           "lptv.mimo_htf_estimate(", "f = lptv.floquet(m)", "lptv.select(", "res.noise_choice",
           'u=["f1", "f2"]', "from lptv import floquet, frozen_poles", "lptv.validate(model",
           "kp * (r(t) - x)", "f.stable_probability")


def all_text():
    return "\n".join(p.read_text() for p in DOCS)


def python_blocks():
    """(file name, block) of every Python block of the README and the guide."""
    return [(p.name, b) for p in DOCS for b in re.findall(r"```python\n(.*?)```", p.read_text(), flags=re.S)]


def find_block(marker):
    blocks = [(name, b) for name, b in python_blocks() if marker in b]
    assert len(blocks) == 1, f"{marker!r} is in {len(blocks)} blocks of the README and the guide"
    return blocks[0]


def run_block(marker, tmp_path, monkeypatch, ns=None):
    """Runs the one Python block of the README or the guide that contains ``marker``, in
    tmp_path (in the names ``ns`` when given); its names."""
    name, block = find_block(marker)
    monkeypatch.chdir(tmp_path)
    ns = {} if ns is None else ns
    exec(compile(block, name, "exec"), ns)
    return ns


def test_every_block_is_run_by_its_marker():
    """Each Python block of the README and the guide holds exactly one of the markers, and each
    marker is in exactly one block: a new block needs its test."""
    for name, block in python_blocks():
        held = [m for m in MARKERS if m in block]
        assert len(held) == 1, f"a block of {name} holds the markers {held}:\n{block[:300]}"
    for m in MARKERS:
        find_block(m)


def test_readme_python_example_runs(tmp_path, monkeypatch):
    ns = run_block("lptv.frozen_poles(res.model", tmp_path, monkeypatch)
    res, err, Y = ns["res"], ns["err"], ns["Y"]
    assert res.converged and res.residue_ok
    assert ns["poles"].shape == (100, 2)
    assert err.max() < 0.05 * abs(Y).max()
    assert (tmp_path / "model.json").exists()


def test_readme_batch_example_runs(tmp_path, monkeypatch):
    """The Monte Carlo and batch example (on local processes, as printed)."""
    ns = run_block("lptv.montecarlo(", tmp_path, monkeypatch)
    mc, summary, table = ns["mc"], ns["summary"], ns["table"]
    assert mc.runs == 100 and mc.methods == ("wgtls", "sml") and mc.executor.endswith("processes")
    assert (mc.overview().failures == 0).all()
    assert len(summary) == 2 * 34 and {"bias", "var_over_crb", "coverage"} <= set(summary.columns)
    for name in ("estimates.csv", "fits.csv", "summary.csv", "overview.csv"):
        assert (tmp_path / "study" / name).exists()
    assert list(table.record) == [f"machine {s}" for s in range(1, 5)] and table.ok.all()


def test_readme_several_experiments_example_runs(tmp_path, monkeypatch):
    """Two records of the paper's model fitted together: against the truth and the CRB of both."""
    import numpy as np

    import lptv
    from lptv.examples import paper_model

    ns = run_block("records.append(", tmp_path, monkeypatch)
    res = ns["res"]
    assert res.n_experiments == 2 and np.array_equal(np.bincount(res.experiment), [243, 243])
    assert res.converged and res.model_ok
    # Every parameter within 4.5 of its reported std of the truth (34 parameters, one seed).
    truth = lptv.crb(paper_model(), lptv.multisine(range(10, 121, 10), 2048), var_y=1.0).eta
    free = res.parameter_std > 0
    assert np.all(np.abs(res.eta - truth)[free] <= 4.5 * res.parameter_std[free])


def test_readme_real_rig_example_runs(tmp_path, monkeypatch):
    """The distortion example: the cubic is detected, the BLA's branches are finite where
    estimated, and the fit weighted by noise and distortion is near its noise level."""
    import numpy as np

    ns = run_block("lptv.plots.distortion(d)", tmp_path, monkeypatch)
    d, bla = ns["d"], ns["bla"]
    assert d.detected and ns["ax"].get_ylabel() == "power (dB)"
    assert np.isfinite(ns["G"][d.branches]).all()            # branch 0 at every excited line
    assert abs(bla.residue_tests.tests[0].statistic) < 5
    # ... and the command line on the file the block saves, as the README prints it
    import json
    import shlex

    from lptv.apps import cli

    cmd = re.search(r"```sh\n(lptv identify rig\.npz[^\n]*)\n```", all_text()).group(1)
    assert cli.main(shlex.split(cmd)[1:]) == 0
    s = json.loads((tmp_path / "rig-lptv" / "summary.json").read_text())
    assert s["realisations"] == 6 and s["distortion"]["detected"] and (tmp_path / "rig-lptv" / "distortion.png").exists()


def test_readme_excitation_design_example_runs(tmp_path, monkeypatch):
    """The design example: the printed lines and crest factors are what the code gives."""
    import numpy as np

    ns = run_block("lptv.min_crest_multisine(", tmp_path, monkeypatch)
    d, design = ns["d"], ns["design"]
    assert d.excited[:4].tolist() == [5, 25, 45, 65] and d.odd_detection[:3].tolist() == [15, 35, 55]
    assert design.crest_factor < design.initial_crest_factor
    assert ns["flat"].crest_factor <= 1.5
    assert len(ns["realisations"]) == 6
    assert all(np.allclose(np.abs(r.spectrum[d.excited]), 0.5) for r in ns["realisations"])


def test_readme_single_record_example_runs(tmp_path, monkeypatch):
    """One record: the fit with the transient is near its noise level, the one without is not."""
    ns = run_block("transient_record(", tmp_path, monkeypatch)
    res, steady = ns["res"], ns["steady"]
    assert res.periods == 4 and res.converged and 0.8 < res.cost_ratio < 1.2
    assert steady.cost_ratio > 5


def test_readme_continuous_record_example_runs(tmp_path, monkeypatch):
    """One continuous-time record (CVODE): a continuous-time model near its noise level."""
    ns = run_block("continuous=True", tmp_path, monkeypatch)
    res = ns["res"]
    assert res.periods == 2 and res.converged and 0.8 < res.cost_ratio < 1.2
    assert res.model.ts is None and res.transient.size == 5


def test_readme_input_referred_example_runs(tmp_path, monkeypatch):
    """The block that refers an actuator's distortion to the input continues the rig's block."""
    ns = run_block("lptv.plots.distortion(d)", tmp_path, monkeypatch)
    run_block('referred="input"', tmp_path, monkeypatch, ns)
    lof = ns["bla_in"].lack_of_fit
    assert lof is not None and lof.realisations == 6 and ns["bla_in"].covariance is not None


def test_readme_noise_alone_example_runs(tmp_path, monkeypatch):
    """The strongly time-varying system's BLA: the realisations with their noise alone and the
    jackknife. Every parameter within its 99.9 % interval of the exact BLA (the reported std is
    scaled so that +-1.96 std is the t interval of its degrees of freedom, about 1 here: one
    realisation carries most of the information; its calibration is bench/HISTORY.md's), and the
    lack of fit keeps it."""
    import numpy as np

    from lptv.examples import exact_bla

    ns = run_block('referred="none"', tmp_path, monkeypatch)
    d, bla = ns["d"], ns["bla"]
    assert d.depends_on_phases and d.realisations == 12
    assert bla.covariance_dof is not None and not bla.lack_of_fit.rejects
    # the cost holds the distortion (the weights are the noise's): above its noise limit, yet the
    # verdict is the lack of fit's
    assert bla.cost > bla.cost_limit and bla.model_ok
    truth = exact_bla("discrete", 0.05)
    names = bla.eta_names
    free = bla.parameter_std > 0
    ref = []
    for name in names:
        arr = np.array(truth.a if name[0] == "a" else truth.b)
        n, part = name[1:].split(".")
        K = (arr.shape[1] - 1) // 2
        z = arr[int(n), K + int(part[2:])]
        ref.append(z.real if part.startswith("re") else z.imag)
    from scipy import stats

    z = np.abs(bla.eta - np.array(ref))[free] / bla.parameter_std[free]
    dof = bla.covariance_dof[free]
    assert np.all(z < 1.959964 * stats.t.ppf(0.9995, dof) / stats.t.ppf(0.975, dof))
    assert np.all(z < 10)     # (0.05-4.3 here: the t_1 intervals are wide, the estimates are not)


def test_readme_inspect_example_runs(tmp_path, monkeypatch, capsys):
    """The record the block makes: 1163 samples of a 200-sample period from sample 37 on, so 5
    whole periods and 163 samples before them; the filter starts from rest (a transient); the
    commands and the messages the README quotes are what the command prints."""
    import shlex

    from lptv.apps import cli

    ns = run_block("lptv.inspect(", tmp_path, monkeypatch)
    insp = ns["insp"]
    assert (insp.period, insp.periods, insp.leftover) == (4.0, 5, 163) and insp.transient_periods >= 1
    assert insp.lines.tolist() == list(range(1, 40, 2))
    text = README.read_text()
    printed = capsys.readouterr().out
    assert f"{insp.period} {insp.periods} {insp.leftover} {insp.transient_periods}" in printed
    assert f"# 4.0 5 163 {insp.transient_periods}" in text
    suggested = re.search(r"The suggested command \(`(lptv identify rig.csv[^`]*)`\)", text, flags=re.S).group(1)
    assert " ".join(suggested.split()) == insp.command
    cmd = re.search(r"```sh\n(lptv inspect rig\.csv[^#\n]*)", text).group(1)
    assert cli.main(shlex.split(cmd)[1:]) == 0 and (tmp_path / "rig-inspect" / "report.html").exists()
    capsys.readouterr()
    base = ["identify", "rig.csv", "--input", "force", "--output", "displacement", "--na", "1", "--nb", "0"]
    flat = " ".join(text.split())
    for extra, quoted in ((["--period", "5"], "the input repeats every 4.00 s (200 samples), not every 5 s"),
                          (["--period", "4", "--fs", "100"], "--fs 100 contradicts the file's column 'time [s]' (50 Hz)")):
        assert cli.main(base + extra) == 2
        err = capsys.readouterr().err
        start = flat.index(quoted)
        assert flat[start:flat.index("`", start)] in err


def test_readme_quick_start_identify_runs(tmp_path, monkeypatch, capsys):
    """The quick start's two commands on the record the README makes: one order too few is
    rejected (exit status 3), the right orders are consistent (0), with the verdicts it quotes;
    the Python equivalent gives the same verdict."""
    import shlex

    from lptv.apps import cli

    ns = run_block("lptv.inspect(", tmp_path, monkeypatch)
    capsys.readouterr()
    text = README.read_text()
    flat = " ".join(text.split())
    cmds = re.search(r"```sh\n(lptv identify rig\.csv[^\n]*)\n(lptv identify rig\.csv[^\n]*)\n```", text).groups()
    codes, outs = [], []
    for cmd in cmds:
        codes.append(cli.main(shlex.split(cmd)[1:]))
        outs.append(" ".join(capsys.readouterr().out.split()))
    assert codes == [3, 0]
    for out, quoted in zip(outs, ("verdict: MODEL ERRORS: the model is rejected: the normalised residues on the 20 rows with signal are too large",
                                  "verdict: the model is consistent with the noise")):
        assert quoted in flat and quoted in out
    assert (tmp_path / "rig-lptv" / "report.html").exists()
    res = run_block("lptv.read_measurements(", tmp_path, monkeypatch, ns)["res"]
    assert res.model_ok and res.verdict.startswith("the model is consistent with the noise")


def test_guide_disturbances_example_runs(tmp_path, monkeypatch, capsys):
    """The hum off the period's grid: the verdict finds the residues too small, the hum is found
    at the line the comment says, and removing it gives a consistent model."""
    run_block('disturbances="remove"', tmp_path, monkeypatch)
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("MODEL ERRORS") and "too small" in out[0]
    assert "a sinusoid at line 85.370" in "\n".join(out[1:-1])
    assert "consistent" in out[-1] and not out[-1].startswith("MODEL ERRORS")


def test_guide_mimo_example_runs(tmp_path, monkeypatch):
    """Two masses with a periodic coupling: the HTF matrices from two orthogonal experiments
    against the model's, within the noise and their reported variance."""
    import numpy as np

    ns = run_block("lptv.mimo_htf_estimate(", tmp_path, monkeypatch)
    est, G0 = ns["est"], ns["G0"]
    assert est.G.shape == (10, 3, 2, 2)
    assert np.abs(est.G[:, 1] - G0).max() < 0.05 * np.abs(G0).max()
    z = np.abs(est.G[:, 1] - G0) / np.sqrt(est.variance[:, 1])
    assert z.max() < 6


def test_guide_use_the_model_example_runs(tmp_path, monkeypatch, capsys):
    """A model saved, read back and validated on a second record of its system: consistent, fit
    above 95 %, no coefficient moved; the steady-state prediction follows that record's output
    to its noise; the LTI export's response is the transfer function's."""
    import numpy as np

    ns = run_block("lptv.validate(model", tmp_path, monkeypatch)
    check, y, second = ns["check"], ns["y_steady"], ns["second"]
    assert check.model_ok and check.fit_percent[0] >= 95.0 and not check.changed
    assert capsys.readouterr().out.startswith("the model is consistent with the fresh record")
    ym = second["y"].ravel()
    assert np.linalg.norm(y - ym) <= 0.05 * np.linalg.norm(ym - ym.mean())
    assert abs(ns["H"][0] - 1 / (100 - 100 + 40j)) <= 1e-12 * abs(ns["H"][0])


def test_guide_identify_example_runs(tmp_path, monkeypatch):
    """Four periods of the paper's example, weighed by moderated noise variances (the default
    route, which says so): consistent, every parameter with its std; the fit without a
    covariance has none."""
    ns = run_block("res.noise_choice", tmp_path, monkeypatch)
    res, quick = ns["res"], ns["quick"]
    assert res.noise == "moderated" and res.noise_choice.startswith("moderated: the noise spectrum is smooth")
    assert res.converged and res.model_ok and (res.parameter_std[res.parameter_std > 0]).size == 34
    assert quick.converged and quick.covariance is None


def test_guide_reading_several_channels_runs(tmp_path, monkeypatch):
    """The files of two experiments of the two-mass system read back as (P, N, 2) arrays: the
    samples written (savetxt's 18 digits), the names as the header has them."""
    import numpy as np

    ns = run_block('u=["f1", "f2"]', tmp_path, monkeypatch)
    m, d = ns["m"], ns["d"]
    assert m.u.shape == (4, 256, 2) and m.y.shape == (4, 256, 2)
    assert m.input == ("F1 [N]", "F2 [N]") and m.output == ("x1 [m]", "x2 [m]")
    assert m.fs_source == "column 'time [s]'" and abs(m.fs - 256 / (2 * np.pi)) <= 1e-9 * m.fs      # fs of the times, to 9 digits
    # the samples written: the multisine and the simulated steady state, plus noise of std 1e-3
    np.testing.assert_allclose(m.u, np.broadcast_to(d.signals[0], (4, 256, 2)), rtol=0, atol=6e-3)
    assert np.abs(m.y - ns["y0"][:, :, 0]).max() < 6e-3
    # the fit: consistent, and K(t)'s harmonic within 5 standard deviations of 0.3 S
    res = ns["res"]
    assert res.model_ok
    S = np.array([[1.0, -1.0], [-1.0, 1.0]])
    for i, name in enumerate(res.parameter_names):
        if name.startswith("a0[") and name.endswith(".re1"):
            p, q = int(name[3]), int(name[5])
            assert abs(res.eta[i] - 0.3 * S[p, q]) <= 5 * res.parameter_std[i], name


def test_guide_stability_of_several_outputs_runs(tmp_path, monkeypatch):
    """The pumped two masses: damped frozen poles, unstable at depth 0.4 (the last of the loop)
    with the spectral radius printed (1.0273; solve_ivp agrees in test_mimo_floquet.py)."""
    ns = run_block("from lptv import floquet, frozen_poles", tmp_path, monkeypatch)
    f, poles = ns["f"], ns["poles"]
    assert poles.shape == (50, 4) and poles.real.max() < 0
    assert not f.is_stable and round(f.spectral_radius, 4) == 1.0273


def test_guide_feedback_example_runs(tmp_path, monkeypatch, capsys):
    """The closed-loop rig integrated by solve_ivp: the default route takes the record's noise and
    keeps the true structure, its estimates near the rig's coefficients."""
    import numpy as np

    ns = run_block("kp * (r(t) - x)", tmp_path, monkeypatch)
    res = ns["res"]
    out = capsys.readouterr().out.splitlines()
    assert res.noise.startswith("full") and out[0] == res.noise
    assert res.model_ok and out[1].startswith("the model is consistent with the noise")
    truth = np.array([30.0, 3.75, 0.0, 1.0, 1.0, 1.0])
    free = res.parameter_std > 0
    assert np.all(np.abs(res.eta - truth)[free] < 4 * res.parameter_std[free])


def test_guide_floquet_with_uncertainty(tmp_path, monkeypatch):
    """The guide's exponents with their intervals (METHOD.md section 22): the true model's exponents
    within 4 std, the shapes printed. The truth by Hill's method (test_floquet.py checks it against
    exact multipliers and products): at T0 = 126 s the multipliers e^-60 .. e^-126 lie below the
    rounding of any product of the period, solve_ivp's included."""
    import numpy as np

    import lptv

    ns = run_block("f.stable_probability", tmp_path, monkeypatch)
    f, d = ns["f"], ns["d"]
    true = lptv.floquet(d["model"]).exponents
    for lam, s in zip(f.exponents, f.exponents_std):
        t = true[np.argmin(np.abs(true - lam))]
        assert abs(t.real - lam.real) < 4 * s[0] and abs(t.imag - lam.imag) < 4 * s[1] + 1e-9
    assert f.confidence_interval(0.95).shape == (3, 2, 2)
    assert ns["poles"].std.shape == (64, 3, 2)
    assert ns["band"].magnitude_band().shape == (3, 20, 2)
