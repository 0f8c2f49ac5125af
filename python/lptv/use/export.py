"""An LTI model in the other libraries' types: scipy.signal's lti / dlti, python-control's
TransferFunction. An LPTV model is refused with the reason: those types hold LTI systems only."""
from __future__ import annotations

LPTV_REFUSED = ("the model is time-varying (harmonics ka = {ka}, kb = {kb}): an input at w gives outputs at "
                "w + k w0 for every harmonic k, which no transfer function holds (scipy.signal and python-control "
                "hold LTI systems only); use Model.freqresp(w, branch=k) or lptv.htf for its harmonic transfer "
                "function, lptv.predict to simulate it, or to_lti(t) / to_control(t) for the frozen system at a "
                "time t (not the periodic system's response)")


def refuse_lptv(model, what: str) -> None:
    if not model.is_lti:
        raise ValueError(f"{what}: " + LPTV_REFUSED.format(ka=model.ka, kb=model.kb))


def to_scipy(model):
    """scipy.signal.lti (continuous time) or dlti (dt = ts) of an LTI model."""
    refuse_lptv(model, "to_scipy")
    return model.to_lti()

