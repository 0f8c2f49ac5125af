"""Degenerate data are diagnosed before estimating, in the user's terms.

Each refusal is checked for its type (ValueError from the core's std::invalid_argument) and for
the argument and cause its message names; each is also shown not to fire on sound data of the
same shape (several seeds), and the verdict is checked against the truth: it must not call a
fit consistent when the estimate is far from the system that made the data."""
import warnings

import numpy as np
import pytest

import lptv
from lptv.examples import PAPER_ID_LINES, noisy_periods, paper_measurements, paper_model

SEEDS = [0, 1, 2]
N = 256
W0 = 0.1
TRUE = lptv.Model([2.0, 0.6, 1.0], [1.0, 0.5], w0=W0)      # (1 + 0.5 s) / (s^2 + 0.6 s + 2)


def _periods(lines, P, seed, noise=1e-3, model=TRUE):
    ms = lptv.multisine(lines, N, seed=seed)
    y1 = lptv.time_signal(lptv.simulate(model, ms.spectrum), N)
    rng = np.random.default_rng(100 + seed)
    u = ms.periods(P) + noise * rng.standard_normal((P, N))
    y = np.tile(y1, (P, 1)) + noise * rng.standard_normal((P, N))
    return u, y


FIT = dict(na=2, nb=1, w0=W0)


# ------------------------------------------------------------------------ the input
@pytest.mark.parametrize("method", ["ls", "tls", "wgtls"])
def test_zero_input_names_the_input(method):
    u, y = _periods(range(1, 60), 4, 0)
    with pytest.raises(ValueError, match=r"^u: the input spectrum is zero on the fitted lines") as e:
        lptv.identify(np.zeros_like(u), y, method=method, **FIT)
    assert "not excited" in str(e.value)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("P", [2, 4])
def test_input_of_noise_only_names_the_noise_level(seed, P):
    u, y = _periods(range(1, 60), P, seed)
    rng = np.random.default_rng(seed)
    with pytest.raises(ValueError, match=r"^u: the input spectrum on the fitted lines .* is at the "
                                         r"level of its noise"):
        lptv.identify(1e-3 * rng.standard_normal(u.shape), y, **FIT)


def test_fit_away_from_the_excited_lines_names_them():
    u, y = _periods(range(10, 21), 4, 0)
    with pytest.raises(ValueError, match=r"^u: the input is not excited on the fitted lines") as e:
        lptv.identify(u, y, lines=range(60, 90), **FIT)
    assert "excited on lines 10, 11, 12, 13, ..., 20 (11 lines)" in str(e.value)
    assert "lines='excited'" in str(e.value)


# ------------------------------------------------------------------------ the output
def test_constant_output_names_the_output():
    u, y = _periods(range(1, 60), 4, 0)
    with pytest.raises(ValueError, match=r"^y: the output is constant"):
        lptv.identify(u, np.full_like(y, 3.0), **FIT)


@pytest.mark.parametrize("seed", SEEDS)
def test_output_of_noise_only_names_the_output(seed):
    u, y = _periods(range(1, 60), 4, seed)
    rng = np.random.default_rng(seed)
    with pytest.raises(ValueError, match=r"^y: the output shows no variation above its noise"):
        lptv.identify(u, 3.0 + 1e-3 * rng.standard_normal(y.shape), **FIT)


# ------------------------------------------------------------ rows and known values
def test_too_few_rows_with_signal():
    # two excited lines carry 4 real equations for 4 free parameters; the 26 other rows only noise
    u, y = _periods([10, 11], 4, 0)
    with pytest.raises(ValueError, match=r"^lines: only 2 of the 26 fitted lines carry signal") as e:
        lptv.identify(u, y, lines=range(5, 31), **FIT)
    assert "4 real equations for 4 free parameters" in str(e.value)


def test_known_zero_cannot_fix_the_scale():
    u, y = _periods(range(1, 60), 4, 0)
    with pytest.raises(ValueError, match=r"^known: a1 = 0 cannot fix the scale"):
        lptv.identify(u, y, known={"a1": 0}, **FIT)
    with pytest.raises(ValueError, match=r"^known: a1 = 0, b0 = 0 cannot fix the scale"):
        lptv.identify(u, y, known={"a1": 0, "b0": 0.0}, **FIT)


def test_known_zero_leading_coefficient():
    u, y = _periods(range(1, 60), 4, 0)
    with pytest.raises(ValueError, match=r"^known: a2 = 0 makes the highest-order coefficient"):
        lptv.identify(u, y, known={"a2": 0, "b0": 1.0}, **FIT)


def test_a_zero_known_beside_a_nonzero_one_is_accepted():
    # b0 = 1 fixes the scale; a1 = 0 is then just a (wrong) structural choice, not degenerate
    u, y = _periods(range(1, 60), 4, 0)
    res = lptv.identify(u, y, known={"b0": 1.0, "a1": 0.6}, **FIT)
    np.testing.assert_allclose(res.model.a[:, 0].real, TRUE.a[:, 0].real, rtol=2e-2)


# ------------------------------------------------- no false alarms on sound data
@pytest.mark.parametrize("seed", SEEDS + [3, 4])
@pytest.mark.parametrize("P", [2, 4])
def test_sound_data_pass_the_diagnostics(seed, P):
    # a 20 dB multisine, and a single strong line among many noise-only rows (the aggregate test)
    for lines, fit in ((range(1, 60), None), ([7], range(1, 100))):
        u, y = _periods(lines, P, seed, noise=0.1 if len(lines) > 1 else 1e-3)
        kw = dict(FIT, na=1, nb=0) if fit is not None else FIT
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                lptv.identify(u, y, lines=fit, method="ls", **kw)
            except ValueError as e:
                # one line gives 2 equations for 2 parameters: the count check may fire, but
                # never the power checks
                assert str(e).startswith("lines:") and fit is not None, str(e)


# ------------------------------------------------------------------------ the verdict
@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("method", ["tls", "wgtls"])
def test_verdict_not_consistent_when_noise_dominates(seed, method):
    m = paper_measurements(seed=1, periods=2)
    u, y = noisy_periods(m["u0"], m["y0"], 2, 0.0, 0.0, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify(u, y, na=2, nb=1, ka=3, kb=3, w0=m["w0"], lines=PAPER_ID_LINES, method=method)
    true = paper_model()
    err = (np.linalg.norm(np.r_[res.model.a.ravel() - true.a.ravel(), res.model.b.ravel() - true.b.ravel()])
           / np.linalg.norm(np.r_[true.a.ravel(), true.b.ravel()]))
    assert err > 1.0                                # the premise: the estimate is meaningless
    assert "consistent with the noise" not in res.verdict
    assert res.undetermined is not None or not res.model_ok


@pytest.mark.parametrize("seed", [1, 2])
def test_verdict_consistent_on_good_data(seed):
    m = paper_measurements(seed=1, periods=8)
    u, y = noisy_periods(m["u0"], m["y0"], 8, 50.0, 40.0, seed=seed)
    res = lptv.identify(u, y, na=2, nb=1, ka=3, kb=3, w0=m["w0"], lines=PAPER_ID_LINES)
    true = paper_model()
    err = (np.linalg.norm(np.r_[res.model.a.ravel() - true.a.ravel(), res.model.b.ravel() - true.b.ravel()])
           / np.linalg.norm(np.r_[true.a.ravel(), true.b.ravel()]))
    assert err < 0.05
    assert res.undetermined is None and "consistent with the noise" in res.verdict


def test_rows_without_input_warn_with_the_excited_lines():
    # a(t) with two harmonics spreads the output of lines 10 and 20 to the rows 12..18 between
    # them, which hold no input line (Kb = 0): the fit sees output only, and b is fitted to noise
    # (1.5 here for a true 1)
    m = lptv.Model([[0.1, 0.2, 1.0, 0.2, 0.1], [0, 0, 1.0, 0, 0]], [[1.0]], w0=W0)
    u, y = _periods([10, 20], 4, 0, noise=1e-6, model=m)
    with pytest.warns(UserWarning, match=r"none of the fitted lines has an input line 20 dB above its "
                                         r"noise within \+-0 \(the input is excited on lines 10, 20"):
        res = lptv.identify(u, y, na=1, nb=0, ka=[2, 2], kb=0, w0=W0, lines=range(12, 19), method="ls")
    assert "consistent with the noise" not in res.verdict


def test_identifiability_warning_is_whole():
    # the core's message is built past a fixed-size buffer: it must end as written
    m = lptv.Model([[0.1, 0.2, 1.0, 0.2, 0.1], [0, 0, 1.0, 0, 0]], [[1.0]], w0=W0)
    u, y = _periods([10, 20], 4, 0, noise=1e-6, model=m)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify(u, y, na=1, nb=0, ka=[2, 2], kb=0, w0=W0, lines=range(12, 19), method="ls")
    msg = [w for w in res.warnings if "unidentifiable" in w]
    assert msg and msg[0].endswith("the likely causes (values of the noise-weighted GTLS problem on the same lines)")


def test_several_experiments_name_the_dead_one():
    good = _periods(range(1, 60), 4, 0)
    u, y = _periods(range(1, 60), 4, 1)
    with pytest.raises(ValueError, match=r"^experiment 1: u: the input spectrum is zero on the fitted lines"):
        lptv.identify([good, (np.zeros_like(u), y)], **FIT)
    # records that each carry too few rows with signal (4 real equations, 4 parameters) complete
    # each other; one line each is still too few together
    a, b = _periods([10, 11], 4, 2), _periods([30, 31], 4, 3)
    for e in (a, b):
        with pytest.raises(ValueError, match=r"^lines: only 2 of the 11 fitted lines carry signal"):
            lptv.identify(*e, lines=range(5, 16) if e is a else range(25, 36), method="ls", **FIT)
    res = lptv.identify([a, b], lines=[range(5, 16), range(25, 36)], method="ls", **FIT)
    np.testing.assert_allclose(res.model.a[:, 0].real, TRUE.a[:, 0].real, rtol=1e-2)
    a1, b1 = _periods([10], 4, 2), _periods([30], 4, 3)
    with pytest.raises(ValueError, match=r"^lines: only 2 of the fitted lines of all experiments carry signal"):
        lptv.identify([a1, b1], lines=[range(5, 16), range(25, 36)], method="ls", **FIT)
