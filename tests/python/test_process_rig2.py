"""The 2 x 2 rig with disturbances through the system (process_rig2.py, simulated by solve_ivp):
its true parameters in lptv's order and normalisation are what a noise-free record gives, and a
closed-loop record with disturbances keeps the true structure on the default noise route."""
import warnings

import numpy as np

import lptv

import process_rig2 as rig


def fit(experiments, **kw):
    return lptv.identify(experiments, **rig.STRUCTURE, w0=rig.W0, lines=rig.fit_lines(), **kw)


def test_a_noise_free_record_gives_the_true_parameters():
    """Without noise or disturbance, from rest with 12 periods of transient (exp(-24)), the last
    period repeated twice: two identical periods, the noise-free route (TLS) of both methods,
    in open loop and under feedback."""
    truth = rig.truth()
    for loop in ("open", "feedback"):
        rec = rig.record(0, periods=1, loop=loop, process=0.0, sensor=0.0, skip=12, rtol=1e-11)
        exps = [(np.tile(u, (2, 1, 1)), np.tile(y, (2, 1, 1))) for u, y in rec["experiments"]]
        for method in ("wgtls", "sml"):
            res = fit(exps, method=method)
            assert res.noise_free and res.parameter_names == rig.NAMES
            np.testing.assert_allclose(res.eta, truth, rtol=0, atol=1e-10 * np.abs(truth).max())


def test_a_closed_loop_record_with_disturbances_keeps_the_true_structure():
    """Feedback, P = 8, disturbances of 5 N rms on both masses (seed 48, fixed before the fit
    was looked at): the default route finds the lines correlated and takes the record's
    statistics, the verdict accepts the true structure and the estimates lie within 4 of their
    standard deviations."""
    rec = rig.record(48, periods=8, loop="feedback", process=5.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = fit(rec["experiments"])
    assert res.noise.startswith("full"), res.noise_choice
    assert "correlated" in res.noise_choice
    assert res.model_ok is True, res.model_errors
    free = res.parameter_std > 0
    assert free.sum() == 20
    z = (res.eta - rig.truth())[free] / res.parameter_std[free]
    assert np.max(np.abs(z)) < 4, z
