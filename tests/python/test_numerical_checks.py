"""Scale-aware numerical checks: the periodic steady state by shooting at a multiplier on 1,
the FDS next to a pole on an excited line, and the warning for unstable models.

Every refusal or warning is checked for its type and for the cause its message names; every
check is also shown not to fire where the answer is sound, against an independent route (the
exact transfer function, the Floquet multipliers of a hand-built monodromy)."""
import warnings

import numpy as np
import pytest

import lptv
from lptv.simulation import timedomain as td
from lptv.examples import mathieu_model, paper_model, paper_multisine

# The damped steady state against B(jw)/A(jw): CVODE's rtol = 1e-12 accumulates over the ~1/zeta
# periods the shooting's (I - Phi)^-1 stands for, i.e. rtol / (zeta T0) ~ 1e-12 / 6e-3 ~ 2e-10
# relative for zeta = 1e-3; 1e-7 leaves three decades for error growth on the other seeds.
DAMPED_REL = 1e-7


def _line1(amplitude=0.5):
    U = np.zeros(3, complex)
    U[1] = amplitude
    return U


def _exact_line(num, den, w):
    return np.polyval(num[::-1], 1j * w) / np.polyval(den[::-1], 1j * w)


# ------------------------------------------------------------- shooting (lptv.simulation.timedomain)
@pytest.mark.parametrize("w0, wn", [(1.0, 1.0), (0.5, 1.0), (1.0, 3.0)])
def test_shooting_refuses_an_undamped_resonance_on_a_harmonic(w0, wn):
    # y'' + wn^2 y = u with wn a multiple of w0: Phi = I up to CVODE's error, so ||I - Phi|| is
    # ~1e-11 while cond(I - Phi) stays ~1; without the relative test x0 came out ~1e12.
    m = lptv.Model([wn ** 2, 0.0, 1.0], [1.0], w0=w0)
    U = np.zeros(4, complex)
    U[1] = 0.5
    with pytest.raises(lptv.NumericalError, match="I - Phi is singular") as e:
        td.periodic_steady_state(m, U, 32)
    assert "Floquet multiplier at 1" in str(e.value) and "undamped resonance" in str(e.value)


@pytest.mark.parametrize("zeta", [1e-3, 1e-2])
def test_shooting_accepts_a_lightly_damped_resonance(zeta):
    # the same oscillator with damping: a genuine steady state that the check must let through,
    # equal to the exact transfer function on the line
    den, num = [1.0, 2 * zeta, 1.0], [1.0]
    m = lptv.Model(den, num, w0=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        y = td.periodic_steady_state(m, _line1(), 16)
    Y1 = np.fft.fft(y)[1] / 16
    ref = 0.5 * _exact_line(num, den, 1.0)
    assert abs(Y1 - ref) <= DAMPED_REL * abs(ref)


def test_shooting_refuses_a_discrete_time_multiplier_on_one():
    # y[k+1] - y[k] = u[k]: Phi = 1 exactly, a periodic free solution
    with pytest.raises(lptv.NumericalError, match="Floquet multiplier at 1"):
        td.periodic_steady_state(lptv.Model([[-1.0], [1.0]], [[1.0]], w0=np.pi / 8, ts=1.0),
                                 np.array([0.0, 1.0]))


# ------------------------------------------------------------------- unstable models
def _lptv_unstable():
    # y' + (-1 + 0.5 cos t) y = u: the mean of a_0 is -1, so mu = exp(2 pi) > 1
    return lptv.Model([[0.25, -1.0, 0.25], [0.0, 1.0, 0.0]], [[1.0]], w0=1.0), np.exp(2 * np.pi)


def _unstable_cases():
    m_lptv, _ = _lptv_unstable()
    return [
        ("ct-lti", lptv.Model([-1.0, 1.0], [1.0], w0=1.0)),                 # s - 1
        ("ct-lptv", m_lptv),
        ("mathieu", mathieu_model(zeta=0.02, wn=1.0, eps=0.1, w0=2.0)),    # parametric resonance
        ("dt-lti", lptv.Model([-1.5, 1.0], [1.0], w0=2 * np.pi / 8, ts=1.0)),  # z - 1.5
    ]


@pytest.mark.parametrize("name, model", _unstable_cases())
def test_simulate_warns_for_an_unstable_model(name, model):
    with pytest.warns(lptv.UnstableModelWarning, match="unstable") as rec:
        lptv.simulate(model, _line1())
    assert "never settles" in str(rec[0].message)
    # the warning points at the caller, not at the library
    assert rec[0].filename == __file__


def test_unstable_multiplier_in_the_message_matches_the_exact_one():
    m, mu = _lptv_unstable()
    with pytest.warns(lptv.UnstableModelWarning) as rec:
        lptv.simulate(m, _line1())
    got = float(str(rec[0].message).split("magnitude ")[1].split(" ")[0])
    assert got == pytest.approx(mu, rel=1e-5)   # printed with 6 significant digits


@pytest.mark.parametrize("model", [
    paper_model(), mathieu_model(zeta=0.02, wn=1.0, eps=0.06, w0=2.0),
    lptv.Model([1.0, 1.0], [1.0], w0=1.0), lptv.Model([-0.5, 1.0], [1.0], w0=2 * np.pi / 8, ts=1.0)])
def test_simulate_is_silent_for_a_stable_model(model):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lptv.simulate(model, _line1())
    assert lptv.floquet(model).is_stable   # the premise, by Hill's method


def test_simulate_warn_unstable_false_and_type_check():
    m = lptv.Model([-1.0, 1.0], [1.0], w0=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Y = lptv.simulate(m, _line1(), warn_unstable=False)
    assert Y[1] == pytest.approx(0.5 / (1j - 1.0), rel=1e-14)   # the exact periodic solution
    with pytest.raises(ValueError, match="warn_unstable"):
        lptv.simulate(m, _line1(), warn_unstable="no")


@pytest.mark.parametrize("name, model", [c for c in _unstable_cases() if c[0] != "dt-lti"])
def test_timedomain_warns_for_an_unstable_model(name, model):
    with pytest.warns(lptv.UnstableModelWarning, match="unstable") as rec:
        td.periodic_steady_state(model, _line1(), 16)
    assert rec[0].filename == __file__


def test_timedomain_warns_for_an_unstable_discrete_model():
    m = lptv.Model([-1.5, 1.0], [1.0], w0=2 * np.pi / 8, ts=1.0)
    # the multiplier over the period of N = 8 samples is 1.5^8
    with pytest.warns(lptv.UnstableModelWarning, match=f"{1.5 ** 8:.6g}".replace(".", r"\.")):
        td.periodic_steady_state(m, _line1())


def test_warning_class_is_a_user_warning():
    assert issubclass(lptv.UnstableModelWarning, UserWarning)


def test_identify_reports_an_unstable_identified_model_once():
    # noise-free steady-state data of the unstable y' - y = u (a stabilised experiment): the
    # estimate is unstable too; identify says so once (a warning and res.unstable), its
    # verdict's own simulation stays silent
    m = lptv.Model([-1.0, 1.0], [1.0], w0=0.1)
    ms = lptv.multisine(range(1, 40), 128, seed=0)
    Y = lptv.simulate(m, ms.spectrum, warn_unstable=False)
    y = lptv.time_signal(Y, 128)
    rng = np.random.default_rng(3)
    u = ms.periods(4) + 1e-4 * rng.standard_normal((4, 128))
    yy = np.tile(y, (4, 1)) + 1e-4 * rng.standard_normal((4, 128))
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        res = lptv.identify(u, yy, na=1, nb=0, w0=0.1)
        res.verdict
    unstable = [w for w in rec if issubclass(w.category, lptv.UnstableModelWarning)]
    assert len(unstable) == 1 and "identified model is unstable" in str(unstable[0].message)
    assert "identified model is unstable" in res.unstable and res.unstable in res.summary()


# ------------------------------------------------------------------ FDS conditioning
EPS = np.finfo(float).eps


def _oscillator(damping, wn=1.0):
    return [wn ** 2, damping, 1.0]          # s^2 + damping s + wn^2


@pytest.mark.parametrize("damping", [1e-9, 1e-12])
def test_fds_warns_next_to_an_undamped_resonance_on_an_excited_line(damping):
    den = _oscillator(damping)
    m = lptv.Model(den, [1.0], w0=1.0)
    with pytest.warns(lptv.ConditioningWarning, match="nearly singular on line 1") as rec:
        r = lptv.simulate(m, _line1(), full_output=True)
    assert "undamped resonance" in str(rec[0].message)
    # the condition is that of the line, (wn^2 + damping + 1) / damping, exactly for LTI
    cond = (2.0 + damping) / damping
    assert r.condition == pytest.approx(cond, rel=1e-12) and r.condition_line == 1
    # the value is still the model's exact steady state, to the digits the condition leaves
    ref = 0.5 * _exact_line([1.0], den, 1.0)
    assert abs(r.Y[1] - ref) <= 10 * cond * EPS * abs(ref)


def test_fds_still_refuses_a_pole_on_the_line_within_rounding():
    with pytest.raises(lptv.NumericalError, match="numerically singular near line -?1"):
        lptv.simulate(lptv.Model(_oscillator(1e-15), [1.0], w0=1.0), _line1())


@pytest.mark.parametrize("damping", [1e-2, 1e-6])
def test_fds_silent_for_a_resolved_resonance(damping):
    den = _oscillator(damping)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = lptv.simulate(lptv.Model(den, [1.0], w0=1.0), _line1(), full_output=True)
    assert r.condition < lptv.simulation.fds.CONDITION_WARN
    ref = 0.5 * _exact_line([1.0], den, 1.0)
    assert abs(r.Y[1] - ref) <= 10 * r.condition * EPS * abs(ref)


def test_fds_lti_resonance_on_a_line_without_input_is_silent():
    # resonance on line 2 (wn = 2), input on lines 1 and 3: LTI lines do not couple
    m = lptv.Model(_oscillator(1e-12, wn=2.0), [1.0], w0=1.0)
    U = np.zeros(4, complex)
    U[[1, 3]] = 0.5
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lptv.simulate(m, U)
    U[2] = 0.5
    with pytest.warns(lptv.ConditioningWarning, match="line 2"):
        lptv.simulate(m, U)


def test_fds_lptv_warns_when_the_resonance_line_carries_output():
    # a(s) constant, b(t) = 1 + 0.4 cos t: input on line 2 reaches lines 1..3, line 5 does not
    # reach line 1 (A is diagonal, so its output there is exactly zero)
    m = lptv.Model(_oscillator(1e-12), [[0.2, 1.0, 0.2]], w0=1.0)
    U = np.zeros(8, complex)
    U[2] = 0.5
    with pytest.warns(lptv.ConditioningWarning, match="line 1"):
        lptv.simulate(m, U)
    U[2], U[5] = 0.0, 0.5
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lptv.simulate(m, U)


def test_fds_warns_for_a_discrete_pole_next_to_the_unit_circle_on_a_line():
    # poles r exp(+-j 2 pi / 8) with r = 1 - 1e-12: on line 1 of N = 8
    N, r = 8, 1.0 - 1e-12
    th = 2 * np.pi / N
    m = lptv.Model([r * r, -2 * r * np.cos(th), 1.0], [1.0], w0=2 * np.pi / N, ts=1.0)
    with pytest.warns(lptv.ConditioningWarning, match="line 1"):
        lptv.simulate(m, _line1())
