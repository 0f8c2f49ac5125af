"""lptv.MimoModel (METHOD.md section 19): the coefficient arrays, the entries' own orders and
harmonic counts, the SISO model as a 1 x 1 one, JSON save / load, repr and bad input."""
import json

import numpy as np
import pytest

import lptv
from lptv.reference import mimo as ref_mimo

from conftest import random_model


def two_mass(w0=1.0, depth=0.3, ts=None):
    """M y'' + C y' + K(t) y = u, k_c(t) = 2 (1 + depth cos(w0 t))."""
    S = np.array([[1.0, -1.0], [-1.0, 1.0]])
    K = np.zeros((2, 2, 3), complex)
    K[:, :, 1] = np.diag([5.0, 3.0]) + 2.0 * S
    K[:, :, 0] = K[:, :, 2] = S * 2.0 * depth / 2
    return lptv.MimoModel.mechanical(np.diag([1.0, 2.0]), 0.2 * np.eye(2), K, np.eye(2), w0=w0, ts=ts)


def test_arrays_and_counts():
    m = two_mass()
    assert (m.n_outputs, m.n_inputs, m.na, m.nb, m.ka, m.kb) == (2, 2, 2, 0, 1, 0)
    assert m.a.shape == (3, 2, 2, 3) and m.b.shape == (1, 2, 2, 1)
    assert m.ka_entries.tolist() == [[1, 1], [1, 1]]
    assert m.na_entries.tolist() == [[2, 0], [0, 2]]        # the off-diagonal entries are of order 0
    assert m.nb_entries.tolist() == [[0, -1], [-1, 0]]      # B = I: the off-diagonal entries vanish
    assert not m.is_lti and not m.discrete and m.ts is None


def test_entry_with_its_own_harmonic_count():
    a = np.zeros((2, 2, 2, 5), complex)
    a[1, :, :, 2] = np.eye(2)
    a[0, :, :, 2] = [[2.0, 0.5], [0.1, 3.0]]
    a[0, 0, 1, [0, 4]] = [0.1 - 0.2j, 0.1 + 0.2j]   # entry (0, 1): 2 harmonics
    a[0, 1, 0, [1, 3]] = [0.3j, -0.3j]              # entry (1, 0): 1 harmonic
    m = lptv.MimoModel(a, np.ones((1, 2, 1)), w0=0.5)
    assert m.ka == 2 and m.ka_entries.tolist() == [[0, 2], [1, 0]]
    assert m.n_inputs == 1 and m.kb_entries.tolist() == [[0], [0]]


def test_a_at_against_reference(seed):
    m = two_mass(depth=0.1 * (seed + 1))
    t = np.linspace(-3, 7, 11)
    A, B = ref_mimo.coefficients_at(m, t)
    np.testing.assert_allclose(m.a_at(t), A, rtol=0, atol=1e-13 * np.abs(m.a).sum())
    np.testing.assert_allclose(m.b_at(t), B, rtol=0, atol=1e-13)
    # k_c(t) = 2 (1 + 0.3 cos t) times the pattern of the coupling spring
    kc = 2 * (1 + 0.1 * (seed + 1) * np.cos(t))
    np.testing.assert_allclose(-m.a_at(t)[:, 0, 0, 1], kc, rtol=1e-13)


def test_siso_round_trip(domain, seed):
    s = random_model(seed, domain)
    m = lptv.MimoModel.from_siso(s)
    assert (m.n_outputs, m.n_inputs, m.na, m.nb, m.ka, m.kb) == (1, 1, s.na, s.nb, s.ka, s.kb)
    assert m.to_siso() == s
    assert m.ts == s.ts


def test_json_round_trip(tmp_path, domain):
    m = two_mass(ts=0.25 if domain == "dt" else None, w0=2 * np.pi / 32 / 0.25 if domain == "dt" else 1.0)
    p = tmp_path / "m.json"
    m.save(p)
    back = lptv.MimoModel.load(p)
    assert back == m and back.ts == m.ts
    d = json.loads(p.read_text())
    assert d["format"] == "lptv.MimoModel" and d["n_outputs"] == 2 and d["n_inputs"] == 2
    assert np.array(d["a_real"]).shape == (3, 2, 2, 3)


def test_siso_json_unchanged(tmp_path):
    """The SISO format stays what it was: no new fields, and a MIMO file is refused by Model.load."""
    s = lptv.Model([[1.0, 2.0, 1.0 + 0j][::-1], [0.0, 1.0, 0.0]], [[1.0]], w0=1.0)
    assert set(s.to_dict()) == {"format", "version", "w0", "ts", "a_real", "a_imag", "b_real", "b_imag"}
    two_mass().save(tmp_path / "m.json")
    with pytest.raises(ValueError, match="lptv.Model description"):
        lptv.Model.load(tmp_path / "m.json")
    s.save(tmp_path / "s.json")
    with pytest.raises(ValueError, match="lptv.Model.load"):
        lptv.MimoModel.load(tmp_path / "s.json")


def test_repr():
    assert repr(two_mass()) == ("lptv.MimoModel(n_outputs=2, n_inputs=2, na=2, nb=0, ka=1, kb=0, w0=1, "
                                "continuous)")


@pytest.mark.parametrize("a, b, match", [
    (np.ones((2, 2, 3, 1)), np.ones((1, 2, 1, 1)), "square"),
    (np.ones((2, 2, 2, 2)), np.ones((1, 2, 1, 1)), "odd number"),
    (np.ones((2, 2, 2, 1)), np.ones((1, 3, 1, 1)), "n_outputs = 2"),
    (np.ones((2, 2, 2)), np.ones((1, 2, 1, 1)) * np.nan, "NaN"),
    (np.concatenate([np.ones((1, 2, 2, 1)), np.zeros((1, 2, 2, 1))]), np.ones((1, 2, 1)), "identically zero"),
    (np.ones((2, 2, 2, 3)) * (1 + 1j), np.ones((1, 2, 1)), "conjugate-symmetric: entry a\\[0, 0, 0\\]"),
    (np.ones((2, 2)), np.ones((1, 2, 1)), "4-D"),
])
def test_bad_coefficients(a, b, match):
    with pytest.raises(ValueError, match=match):
        lptv.MimoModel(a, b, w0=1.0)


def test_bad_description():
    d = two_mass().to_dict()
    for key, value, match in [("n_inputs", 3, "shape"), ("version", 2, "version"), ("extra", 1, "unknown field"),
                              ("n_outputs", 0, "positive integer"), ("a_real", "x", "4-D list")]:
        bad = dict(d, **{key: value})
        with pytest.raises(ValueError, match=match):
            lptv.MimoModel.from_dict(bad)
