"""The verdict's advice after a rejection: an order too low on an LTI record (no signal between
the excited lines) is not sent toward time variation by the harmonic score tests; a missing
harmonic on a rig whose output shows its sidebands keeps the harmonic advice. Records simulated
by SciPy (lfilter, solve_ivp), never by lptv."""
import warnings

import numpy as np
import pytest
from scipy.signal import lfilter

import lptv
import process_rig as pr

ADVICE = "try one order more first"


def _first_order_record(seed, P=8, N=200):
    """The README's quick-start filter y[k] = 0.99 y[k-1] + 0.05 u[k] in steady state, odd lines."""
    k = np.arange(P * N)
    u = sum(np.cos(2 * np.pi * l * k / N + l * l) for l in range(1, 40, 2))
    y = lfilter([0.05], [1, -0.99], np.tile(u[:N], P + 10))[-P * N:]
    rng = np.random.default_rng(seed)
    return ((u + 0.02 * rng.standard_normal(k.size)).reshape(P, N),
            (y + 0.02 * rng.standard_normal(k.size)).reshape(P, N))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_an_order_too_low_is_not_sent_toward_time_variation(seed):
    u, y = _first_order_record(seed)
    kw = dict(w0=2 * np.pi / 4, ts=1 / 50.0, lines="excited")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        low = lptv.identify(u, y, na=1, nb=0, **kw)
        right = lptv.identify(u, y, na=1, nb=1, **kw)
    assert low.model_ok is False and "one more harmonic" in low.verdict
    assert ADVICE in low.verdict and "no signal between the excited lines" in low.verdict
    assert right.model_ok and ADVICE not in right.verdict


def test_a_missing_harmonic_keeps_the_harmonic_advice():
    """The rig's stiffness varies by 25 % (and by a 10 % second harmonic): fitted without them,
    the output's sidebands show the time variation and the advice names the harmonic."""
    for second, ka in ((0.0, 0), (0.1, 1)):
        for rec in pr.records([0, 1], periods=8, loop="open", process=0.0, second=second):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = lptv.identify(rec["u"], rec["y"], na=2, nb=0, ka=[ka, 0, 0], kb=0, w0=pr.W0,
                                    lines=pr.fit_lines())
            assert res.model_ok is False and "one more harmonic on a0" in res.verdict
            assert res.residue_tests.signal_off_excited and ADVICE not in res.verdict
