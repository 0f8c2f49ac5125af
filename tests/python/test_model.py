"""lptv.Model: coefficient evaluation against the reference, persistence, identity."""
import json

import numpy as np
import pytest

import lptv
import lptv.examples as ex
from lptv import reference as ref


def test_coefficients_match_reference(make_model, seed, domain, tol):
    model = make_model(seed, domain)
    t = np.random.default_rng(seed).uniform(-2, 2, 50) * model.period
    a_ref, b_ref = ref.coefficients_at(model, t)
    a_t, b_t = model.a_at(t), model.b_at(t)
    assert a_t.shape == (t.size, model.na + 1) and b_t.shape == (t.size, model.nb + 1)
    assert np.all(np.abs(a_t - a_ref) <= tol.COEFFICIENTS_AT * np.abs(model.a).sum(axis=1))
    assert np.all(np.abs(b_t - b_ref) <= tol.COEFFICIENTS_AT * np.abs(model.b).sum(axis=1))


def test_coefficients_are_periodic_and_real(make_model, seed, tol):
    model = make_model(seed, "ct")
    t = np.linspace(0, model.period, 9)
    a_t = model.a_at(t)
    assert a_t.dtype == float
    assert np.all(np.abs(a_t[0] - a_t[-1]) <= tol.COEFFICIENTS_AT * np.abs(model.a).sum(axis=1))


def test_frozen_polynomials(make_model, seed, tol):
    # numpy.roots order: highest power first.
    model = make_model(seed, "ct")
    t = 0.3 * model.period
    num, den = model.frozen(t)
    a_ref, b_ref = ref.coefficients_at(model, [t])
    assert num.shape == (model.nb + 1,) and den.shape == (model.na + 1,)
    assert np.all(np.abs(den - a_ref[0][::-1]) <= tol.COEFFICIENTS_AT * np.abs(model.a).sum(axis=1)[::-1])
    assert np.all(np.abs(num - b_ref[0][::-1]) <= tol.COEFFICIENTS_AT * np.abs(model.b).sum(axis=1)[::-1])


def test_lti_frozen_is_the_transfer_function():
    model = lptv.Model([2.0, 3.0, 1.0], [1.0, 1.0], w0=1.0)  # (s + 1) / (s^2 + 3 s + 2)
    num, den = model.frozen(1.234)
    assert np.array_equal(num, [1.0, 1.0]) and np.array_equal(den, [1.0, 3.0, 2.0])
    assert model.is_lti and model.a.shape == (3, 1)


def test_properties():
    m = lptv.Model(np.array([[0.1j, 1, -0.1j], [0, 1, 0]]), [[1.0], [2.0], [0.5]], w0=0.5)
    assert (m.na, m.nb, m.ka, m.kb) == (1, 2, 1, 0)
    assert m.ts is None and not m.discrete and not m.is_lti
    assert m.period == 4 * np.pi
    d = lptv.Model([[0.5], [1.0]], [[1.0]], w0=2 * np.pi / 12, ts=1.0)
    assert d.discrete and d.ts == 1.0 and d.samples_per_period == 12
    with pytest.raises(ValueError, match="continuous-time"):
        m.samples_per_period


def test_symmetrised_on_construction():
    # Rounding-level asymmetry is accepted and removed, so a_n(t) is exactly real.
    a = np.array([[0.1 + 0.2j, 1 + 1e-15j, 0.1 - 0.2j + 1e-14], [0, 1, 0]])
    m = lptv.Model(a, [[1.0]], w0=1.0)
    K = m.ka
    assert np.array_equal(m.a[:, K + 1], np.conj(m.a[:, K - 1]))
    assert np.all(m.a[:, K].imag == 0)


@pytest.mark.parametrize("domain", ["ct", "dt"])
def test_json_round_trip(make_model, seed, domain, tmp_path):
    model = make_model(seed, domain)
    path = tmp_path / "model.json"
    model.save(path)
    loaded = lptv.Model.load(path)
    assert loaded == model  # bit for bit: JSON keeps every double
    assert loaded.ts == model.ts and loaded.w0 == model.w0
    assert np.array_equal(loaded.a, model.a) and np.array_equal(loaded.b, model.b)
    d = json.loads(path.read_text())
    assert d["format"] == "lptv.Model" and d["version"] == 1


def test_json_round_trip_paper_model(tmp_path):
    model = ex.paper_model()
    model.save(tmp_path / "paper.json")
    assert lptv.Model.load(str(tmp_path / "paper.json")) == model
    assert lptv.Model.from_dict(model.to_dict()) == model


def test_load_rejects_other_files(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="not valid JSON"):
        lptv.Model.load(bad)
    bad.write_text(json.dumps({"format": "something else"}))
    with pytest.raises(ValueError, match="not an lptv.Model"):
        lptv.Model.load(bad)
    bad.write_text(json.dumps({"format": "lptv.Model", "w0": 1.0}))
    with pytest.raises(ValueError, match="lacks the field 'a_real'"):
        lptv.Model.load(bad)


def test_equality():
    a = np.array([[0.1j, 1, -0.1j], [0, 1, 0]])
    m = lptv.Model(a, [[1.0]], w0=1.0)
    assert m == lptv.Model(a.copy(), [[1.0]], w0=1.0)
    assert m != lptv.Model(a, [[1.0]], w0=2.0)
    assert m != lptv.Model(a, [[1.0]], w0=1.0, ts=2 * np.pi / 8)
    assert m != lptv.Model(a * 2, [[1.0]], w0=1.0)
    assert m != lptv.Model(a, [[1.5]], w0=1.0)
    # The same functions with a zero harmonic column are a different parametrisation.
    assert m != lptv.Model(a, [[0.0, 1.0, 0.0]], w0=1.0)
    assert m != "model" and m != a


def test_repr():
    m = lptv.Model(np.array([[0.05, 1, 0.05], [0, 1, 0], [0, 1, 0]]), [[1.0], [1.0]], w0=1.0)
    assert repr(m) == "lptv.Model(na=2, nb=1, ka=1, kb=0, w0=1, continuous)"
    d = lptv.Model([[0.5], [1.0]], [[1.0]], w0=2 * np.pi / 16, ts=0.5 * 2)
    assert repr(d) == "lptv.Model(na=1, nb=0, ka=0, kb=0, w0=0.392699, discrete, ts=1)"


def test_paper_model_is_as_documented():
    # METHOD.md section 8: 35 coefficients, a_2(t) > 0, every frozen system stable.
    m = ex.paper_model()
    assert (m.na, m.nb, m.ka, m.kb) == (2, 1, 3, 3)
    assert m.a.size + m.b.size == 35
    t = np.linspace(0, m.period, 400)
    assert m.a_at(t)[:, 2].min() > 0
    for ti in t[::20]:
        assert np.all(np.roots(m.frozen(ti)[1]).real < 0)
