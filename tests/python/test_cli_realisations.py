"""``lptv identify FILE`` on M random-phase realisations (arrays of shape (M, P, N)).

The command must separate the nonlinear distortion from the noise as :func:`lptv.distortion`
does on the same numbers, fit the best linear approximation as :func:`lptv.identify` does on
``DistortionResult.experiments()``, and say so in its output, summary.json and report; a
purely LPTV record must show no distortion. Readers other than ``lptv identify FILE`` refuse
such a file with a message naming the option.
"""
import json
import warnings

import numpy as np
import pytest

import lptv
from lptv.apps import cli
from lptv.examples import noisy_periods
from lptv.records.measurements import FileError

MODEL = lptv.Model([[0.3 + 0.1j, 2.0, 0.3 - 0.1j], [0, 1.0, 0]], [[0, 1.0, 0]], w0=0.05)
ARGS = ["--na", "1", "--nb", "0", "--ka", "1", "--kb", "1"]


def _record(path, cubic, M=4, P=8, N=256, seed=0):
    u, y = [], []
    for r in range(M):
        ms = lptv.multisine(range(4, min(61, N // 4), 4), N, seed=seed + r)
        y0 = lptv.time_signal(lptv.simulate(MODEL, ms.spectrum), N)
        a, b = noisy_periods(ms.signal, y0 + cubic * y0 ** 3, P, 60, 40, seed=100 + seed + r)
        u.append(a)
        y.append(b)
    u, y = np.array(u), np.array(y)
    np.savez(path, u=u, y=y, w0=MODEL.w0)
    return u, y


@pytest.mark.parametrize("seed", [0, 1])
def test_identify_file_of_realisations_matches_the_library(tmp_path, seed, capsys):
    src = tmp_path / "rig.npz"
    u, y = _record(src, cubic=0.5, seed=seed)
    out = tmp_path / "out"
    # 4 realisations cannot judge the fit (below): NOT DETERMINED, exit status 4
    assert cli.main(["identify", str(src), *ARGS, "--out", str(out)]) == 4
    printed = capsys.readouterr().out
    assert "4 realisations x 8 periods of 256 samples" in printed
    assert "nonlinear distortion DETECTED" in printed
    s = json.loads((out / "summary.json").read_text())
    d = lptv.distortion(u, y, w0=MODEL.w0)
    assert s["distortion"]["detected"] is True and s["realisations"] == 4
    assert s["distortion"]["statistic"] == pytest.approx(d.statistic, rel=1e-12)
    # the default rows: the excited band K+1 .. 60 + K of every realisation, noise + distortion weighted
    ref = lptv.identify(d.experiments(), na=1, nb=0, ka=1, kb=1, lines=[np.arange(2, 62)] * 4)
    model = lptv.Model.load(out / "model.json")
    assert np.allclose(model.a, ref.model.a, rtol=1e-9, atol=1e-12)
    assert np.allclose(model.b, ref.model.b, rtol=1e-9, atol=1e-12)
    html = (out / "report.html").read_text()
    assert "distortion.png" in html and (out / "distortion.png").stat().st_size > 1000
    # the verdict of a fit of the realisations: their lack of fit (4 realisations cannot reach 1 %)
    assert "lack_of_fit.png" in html and (out / "lack_of_fit.png").stat().st_size > 1000
    assert "4 realisations cannot show a lack of fit" in s["verdict"]


def test_identify_file_of_realisations_without_distortion(tmp_path, capsys):
    src = tmp_path / "lin.npz"
    _record(src, cubic=0.0, seed=3)
    out = tmp_path / "out"
    # no error found, but 4 realisations cannot show a lack of fit: NOT DETERMINED, exit status 4
    assert cli.main(["identify", str(src), *ARGS, "--out", str(out)]) == 4
    printed = capsys.readouterr().out
    assert "nonlinear distortion not detected" in printed
    s = json.loads((out / "summary.json").read_text())
    assert s["distortion"]["detected"] is False
    assert s["model_ok"] is True, s["verdict"]


def test_reader_takes_realisations_only_when_asked(tmp_path):
    src = tmp_path / "rig.npz"
    u, y = _record(src, cubic=0.0, M=3, P=4, N=64)
    with pytest.raises(FileError, match="M realisations x P periods x N samples.*realisations=True"):
        lptv.read_measurements(src)
    m = lptv.read_measurements(src, realisations=True, skip_periods=1)
    assert m.u.shape == (3, 3, 64) and m.realisations == 3
    assert np.array_equal(m.u, u[:, 1:]) and np.array_equal(m.y, y[:, 1:])
    assert lptv.read_measurements(tmp_path / "rig.npz", realisations=True).realisations == 3
    np.savez(tmp_path / "one.npz", u=u[:1], y=y[:1], w0=MODEL.w0)
    with pytest.raises(FileError, match="at least 2 are needed"):
        lptv.read_measurements(tmp_path / "one.npz", realisations=True)
    np.savez(tmp_path / "bad.npz", u=u, y=y[:, :, :60], w0=MODEL.w0)
    with pytest.raises(FileError, match="realisations x periods x samples"):
        lptv.read_measurements(tmp_path / "bad.npz", realisations=True)


def test_other_commands_refuse_realisations_with_one_line(tmp_path, capsys):
    src = tmp_path / "rig.npz"
    _record(src, cubic=0.0, M=3, P=4, N=64)
    rc = cli.main(["identify", str(src), str(src), *ARGS, "--joint", "--out", str(tmp_path / "j")])
    err = capsys.readouterr().err
    assert rc == 2 and "lptv identify FILE given alone" in err and len(err.strip().splitlines()) == 1


def test_identify_file_of_realisations_errors_name_the_realisation(tmp_path, capsys):
    src = tmp_path / "rig.npz"
    _record(src, cubic=0.0, M=3, P=4, N=64)
    rc = cli.main(["identify", str(src), *ARGS, "--lines", "1-500", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "realisation 0: lines:" in err and len(err.strip().splitlines()) == 1
    rc = cli.main(["identify", str(src), *ARGS, "--covariance", "bootstrap", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "--covariance bootstrap takes one record" in err


def test_identify_file_of_realisations_with_the_realisations_covariance(tmp_path, capsys):
    """--covariance realisations: the library's jackknife over the realisations, in model.json,
    summary.json and the report; refused for a record of periods of one realisation."""
    src = tmp_path / "rig.npz"
    u, y = _record(src, cubic=0.5, seed=4)
    out = tmp_path / "out"
    assert cli.main(["identify", str(src), *ARGS, "--covariance", "realisations", "--out", str(out)]) == 4
    capsys.readouterr()
    d = lptv.distortion(u, y, w0=MODEL.w0)
    ref = lptv.identify(d.experiments(), na=1, nb=0, ka=1, kb=1, lines=[np.arange(2, 62)] * 4,
                        covariance="realisations")
    s = json.loads((out / "summary.json").read_text())
    assert s["covariance"] == "realisations"
    model = lptv.Model.load(out / "model.json")
    assert np.allclose(model.covariance, ref.covariance, rtol=1e-9, atol=1e-15)
    assert "jackknife over the realisations" in (out / "report.html").read_text()
    one = tmp_path / "one.npz"
    np.savez(one, u=u[0], y=y[0], w0=MODEL.w0)
    rc = cli.main(["identify", str(one), *ARGS, "--covariance", "realisations", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "--covariance realisations is for a record of M x P x N" in err


def test_identify_file_of_realisations_with_the_distortion_referred_to_the_input(tmp_path, capsys):
    """--referred input: the fit of DistortionResult.experiments(referred="input", model=first fit)."""
    src = tmp_path / "rig.npz"
    u, y = _record(src, cubic=0.5, M=6)
    out = tmp_path / "out"
    # the cubic of this record acts after the dynamics: referred to the input, the fit departs
    # from the realisations' best linear approximation and the verdict rejects it (exit status 3)
    assert cli.main(["identify", str(src), *ARGS, "--referred", "input", "--out", str(out)]) == 3
    assert "referred to the input" in capsys.readouterr().out
    s = json.loads((out / "summary.json").read_text())
    assert s["referred"] == "input" and s["model_ok"] is False and "lack of fit" in s["verdict"]
    d = lptv.distortion(u, y, w0=MODEL.w0)
    rows = [np.arange(2, 62)] * 6
    first = lptv.identify(d.experiments(), na=1, nb=0, ka=1, kb=1, lines=rows)
    ref = lptv.identify(d.experiments(referred="input", model=first), na=1, nb=0, ka=1, kb=1, lines=rows)
    model = lptv.Model.load(out / "model.json")
    assert np.allclose(model.a, ref.model.a, rtol=1e-9, atol=1e-12)
    assert np.allclose(model.b, ref.model.b, rtol=1e-9, atol=1e-12)
    # a record of periods has no realisations to refer
    per = tmp_path / "periods.npz"
    np.savez(per, u=u[0], y=y[0], w0=MODEL.w0)
    assert cli.main(["identify", str(per), *ARGS, "--referred", "input", "--out", str(tmp_path / "o2")]) == 2
    assert "--referred input is for a record of M x P x N" in capsys.readouterr().err


def test_referred_input_falls_back_to_a_plain_first_fit_where_the_output_referred_one_is_refused(tmp_path, capsys):
    """The discrete-time example after a cubic actuator: one common output level swamps a weak
    realisation, so the output-referred first fit is refused; the level is referred through a
    fit of the realisations with their noise alone, as the refusal advises, and the command says
    so. The model is the library's on the same route."""
    from lptv.examples import DISCRETE_ID_LINES, DISCRETE_STRUCTURE, cubic_realisations

    r = cubic_realisations("discrete", 0.05, "input", 6, 8, seed=[1, 77])
    m, u, y = r["model"], r["u"], r["y"]
    src = tmp_path / "dt.npz"
    np.savez(src, u=u, y=y, w0=m.w0)
    out = tmp_path / "out"
    args = ["identify", str(src), "--ts", "1", "--na", "2", "--nb", "1", "--ka", "2,1,0", "--kb", "2,0",
            "--lines", "1-125", "--method", "sml", "--referred", "input", "--covariance", "realisations",
            "--out", str(out)]
    assert cli.main(args) == 0
    printed = capsys.readouterr().out
    assert "through a first fit of the realisations with their noise alone" in printed
    s = json.loads((out / "summary.json").read_text())
    assert s["first_fit"].startswith("a first fit of the realisations with their noise alone")
    d = lptv.distortion(u, y, w0=m.w0, ts=1.0)
    rows = [DISCRETE_ID_LINES] * 6
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = lptv.identify([(u[i], y[i]) for i in range(6)], w0=m.w0, ts=1.0, lines=rows, method="sml",
                              **DISCRETE_STRUCTURE)
        ref = lptv.identify(d.experiments(referred="input", model=plain), lines=rows, method="sml",
                            covariance="realisations", **DISCRETE_STRUCTURE)
    model = lptv.Model.load(out / "model.json")
    assert np.allclose(model.b, ref.model.b, rtol=1e-9, atol=1e-12)
    assert np.allclose(model.a, ref.model.a, rtol=1e-9, atol=1e-12)
    assert s["covariance_dof"] == pytest.approx(list(ref.covariance_dof), rel=1e-9)
    # without --referred (auto): these outputs differ more than 4 times, so the realisations
    # with their noise alone, intervals from the jackknife (taken whatever --covariance says), as
    # the library's route; --referred none gives the same; the report says which
    out2 = tmp_path / "none"
    args2 = [a for a in args[:-1] if a not in ("--covariance", "realisations", "--referred", "input")] + [str(out2)]
    assert cli.main(args2) == 0
    printed = capsys.readouterr().out
    assert "fitted together with their noise alone" in printed and "--referred auto chose it: the realisations' output powers differ" in printed
    assert "is no exact noise model" not in printed.split("model:")[1]   # no warning about a level not used
    s2 = json.loads((out2 / "summary.json").read_text())
    assert s2["referred"] == "none" and s2["covariance"] == "realisations" and s2["referred_option"] == "auto"
    assert cli.main(args2[:-2] + ["--referred", "none", "--covariance", "analytic", "--out", str(tmp_path / "none2")]) == 0
    assert "(--referred none; --covariance is taken as realisations)" in capsys.readouterr().out
    assert (tmp_path / "none2" / "model.json").read_text() == (out2 / "model.json").read_text()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref2 = lptv.identify(d.experiments(referred="none"), lines=rows, method="sml", covariance="realisations",
                             **DISCRETE_STRUCTURE)
    model2 = lptv.Model.load(out2 / "model.json")
    assert np.allclose(model2.b, ref2.model.b, rtol=1e-9, atol=1e-12)
    assert np.allclose(model2.a, ref2.model.a, rtol=1e-9, atol=1e-12)
    assert s2["covariance_dof"] == pytest.approx(list(ref2.covariance_dof), rel=1e-9)
    assert "each with its noise alone" in (out2 / "report.html").read_text()

