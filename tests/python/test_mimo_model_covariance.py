"""A model of several channels keeps its covariance in model.json: saved and read back to the
last bit, refused when tampered with, and counted by lptv.validate."""
import json

import numpy as np
import pytest

import lptv
from lptv.examples.mimo import small_fit


@pytest.fixture(scope="module")
def fit():
    return small_fit()


def test_the_covariance_survives_save_and_load(fit, tmp_path):
    m = fit.model
    assert m.covariance is not None and m.eta_names == tuple(fit.parameter_names)
    np.testing.assert_array_equal(m.covariance, fit.covariance)
    m.save(tmp_path / "m.json")
    back = lptv.MimoModel.load(tmp_path / "m.json")
    assert back == m and back.eta_names == m.eta_names
    np.testing.assert_array_equal(back.covariance, m.covariance)


@pytest.mark.parametrize("change, match", [
    (lambda d: d["covariance"][0].__setitem__(0, -1.0), "negative variance"),
    (lambda d: d["covariance"][0].__setitem__(1, d["covariance"][0][1] + 1.0), "not symmetric"),
    (lambda d: d["eta_names"].__setitem__(1, "a7[0,0].re0"), "not a coefficient entry"),
    (lambda d: d["eta_names"].pop(), "does not match its"),
    (lambda d: d["covariance"][0].__setitem__(0, True), "covariance"),
])
def test_a_tampered_covariance_is_refused_naming_it(fit, tmp_path, change, match):
    d = json.loads(json.dumps(fit.model.to_dict()))
    change(d)
    with pytest.raises(ValueError, match=match):
        lptv.MimoModel.from_dict(d)


def test_validate_counts_the_saved_covariance(fit, tmp_path):
    """A fresh record of the docs' system judged against the model read from its file: the same
    verdict and tests as against the fit's result (which carries the covariance), and a note
    when the file's covariance is taken away."""
    fit.model.save(tmp_path / "m.json")
    loaded = lptv.MimoModel.load(tmp_path / "m.json")
    from lptv.simulation.fds import simulate

    rng = np.random.default_rng(7)
    ms = lptv.multisine(range(1, 40), 128, seed=5)
    Y = simulate(loaded, ms.spectrum[:, None], lines_out=64)
    y1 = np.fft.irfft(Y * 128, 128, axis=0)
    u = ms.periods(6)[:, :, None] + 1e-3 * rng.standard_normal((6, 128, 1))
    y = y1[None] + 1e-3 * rng.standard_normal((6, 128, 2))
    from_file = lptv.validate(loaded, u, y)
    from_fit = lptv.validate(fit, u, y)
    assert [t[3] for t in from_file.tests] == pytest.approx([t[3] for t in from_fit.tests], rel=1e-9)
    bare = lptv.MimoModel(loaded.a, loaded.b, w0=loaded.w0)
    without = lptv.validate(bare, u, y)
    assert any("no covariance" in n for n in without.notes) and not any("no covariance" in n for n in from_file.notes)
