"""The Floquet exponents, frozen poles and HTF branches of an estimate with their uncertainty
(METHOD.md section 22), against independent routes: the exponents' derivative against central
differences of the NumPy reference (solve_ivp's monodromy matrix, the NumPy product in discrete
time), the frozen poles' against central differences of numpy.roots, the HTF band's against the
closed-form derivative of an LTI B(jw)/A(jw), the bootstrap against first order.

Tolerances: the reference's central differences with a relative step h = 1e-5 have a truncation
error O(h^2) ~ 1e-10 relative and a rounding error of the integration's tolerance over the step,
1e-12 / 1e-5 = 1e-7 relative to the exponent; 1e-5 of the largest entry leaves a factor 100
above both. The bootstrap's std with B draws has a relative sampling std 1/sqrt(2B).
"""
import warnings

import numpy as np
import pytest

import lptv
from lptv.examples import discrete_model, mathieu_model, system_measurements, third_order_model
from lptv.model.floquet_uncertainty import _siso_jacobian, first_order_notes
from lptv.reference import floquet as ref

DERIVATIVE_RTOL = 1e-5


def _names(model):
    out = []
    for n in range(model.na + 1):
        for k in range(model.ka + 1):
            out.append(f"a{n}.re{k}")
            if k:
                out.append(f"a{n}.im{k}")
    out.append("b0.re0")
    return tuple(out)


def _opt():
    return dict(tol=1e-11, min_truncation=8, max_truncation=256)


def _varying_lead():
    """a_2(t) = 1 + 0.2 cos(w0 t): F(t) needs the harmonics of 1/a_2 (the route of the paper's model)."""
    a = np.array([[0.15, 1.0, 0.15], [0.02 - 0.01j, 0.2, 0.02 + 0.01j], [0.1, 1.0, 0.1]])
    return lptv.Model(a, [[1.0]], w0=1.5)


def _third_order_fast():
    """The third-order example's coefficients with w0 = 0.5 (T0 = 12.6 s): its multipliers e^-6 ..
    e^-13 stay within the reference's products (at w0 = 0.05 they are e^-126, below rounding)."""
    m = third_order_model()
    return lptv.Model(m.a, m.b, w0=0.5)


def _discrete_short(N=16):
    """The discrete-time example's coefficients on N samples per period: at N = 256 its smaller
    multiplier (1e-37) lies below the rounding of the product (eps times the larger, 1e-25), in
    the core and the reference alike; at N = 16 both are resolved."""
    m = discrete_model()
    return lptv.Model(m.a, m.b, w0=2 * np.pi / N, ts=1.0)


@pytest.mark.parametrize("make", [lambda: mathieu_model(zeta=0.1, eps=0.3), lambda: mathieu_model(zeta=0.05, eps=0.1, w0=1.7),
                                  _third_order_fast, _discrete_short, _varying_lead],
                         ids=["mathieu-real-pair", "mathieu-complex", "third-order", "discrete", "varying-lead"])
def test_core_derivative_against_reference_differences(make):
    m = make()
    names = _names(m)
    f, J, cond = _siso_jacobian(m, names, _opt())
    lam_ref, J_ref = ref.exponent_jacobian(m.a, m.w0, names, ts=m.ts)
    lam = np.asarray(f.exponents)
    # the same exponents in the same order (the reference sorts as the core reports)
    order = [int(np.argmin(np.abs(lam_ref.real - x.real) + np.abs(np.exp(1j * m.period * (lam_ref.imag - x.imag)) - 1)))
             for x in lam]
    J_ref = J_ref[order]
    scale = np.abs(J_ref).max()
    assert scale > 0
    np.testing.assert_allclose(J, J_ref, rtol=0, atol=DERIVATIVE_RTOL * scale)
    assert np.all(np.isfinite(cond)) and np.all(cond >= 1 - 1e-9)
    assert np.all(J[:, -1] == 0)  # b does not move the exponents


def _fit(system="third_order", seed=3, periods=8, **kw):
    d = system_measurements(system, seed=seed, periods=periods)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["lines"],
                            method="sml", **kw)
    return res


def _mathieu_fit(seed=3, periods=8, noise=1e-3):
    """The damped Mathieu equation inside its first tongue (a real pair of multipliers), fitted."""
    m = mathieu_model(zeta=0.1, eps=0.3)
    ms = lptv.multisine(range(1, 16), 128, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 128)
    rng = np.random.default_rng(seed)
    u = ms.periods(periods) + noise * rng.standard_normal((periods, 128))
    y = np.tile(y1, (periods, 1)) + noise * rng.standard_normal((periods, 128))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return lptv.identify(u, y, na=2, nb=0, ka=[1, 0, 0], kb=0, w0=m.w0, lines=range(1, 20), method="sml")


def _discrete_fit(seed=3, periods=8, noise=1e-3, N=32):
    m = _discrete_short(N)
    ms = lptv.multisine(range(1, N // 2), N, seed=0)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), N)
    rng = np.random.default_rng(seed)
    u = ms.periods(periods) + noise * rng.standard_normal((periods, N))
    y = np.tile(y1, (periods, 1)) + noise * rng.standard_normal((periods, N))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return lptv.identify(u, y, na=2, nb=1, ka=[2, 1, 0], kb=[2, 0], w0=m.w0, ts=1.0,
                             lines=range(1, N // 2 - 2), method="sml")


@pytest.mark.parametrize("system", ["mathieu", "discrete"])
def test_result_intervals_against_reference_jacobian(system):
    res = _mathieu_fit() if system == "mathieu" else _discrete_fit()
    f = lptv.floquet(res)
    f0 = lptv.floquet(res.model)
    np.testing.assert_array_equal(f.exponents, f0.exponents)
    assert f.exponents_std.shape == (f.exponents.size, 2)
    lam_ref, J = ref.exponent_jacobian(res.model.a, res.model.w0, res.eta_names, ts=res.model.ts)
    order = [int(np.argmin(np.abs(lam_ref - x))) for x in f.exponents]
    J = J[order]
    std_ref = np.stack([np.sqrt(np.einsum("ij,jk,ik->i", J.real, res.covariance, J.real)),
                        np.sqrt(np.einsum("ij,jk,ik->i", J.imag, res.covariance, J.imag))], axis=1)
    np.testing.assert_allclose(f.exponents_std, std_ref, rtol=1e-4, atol=1e-12 * np.abs(f.exponents).max())
    ci = f.confidence_interval(0.95)
    assert ci.shape == (f.exponents.size, 2, 2)
    np.testing.assert_allclose(ci[:, 0].mean(axis=1), f.exponents.real)
    np.testing.assert_allclose(ci[:, 0, 1] - ci[:, 0, 0], 2 * 1.959963984540054 * f.exponents_std[:, 0])
    mi = f.multiplier_modulus_interval(0.95)
    np.testing.assert_allclose(np.log(mi) / f.period, ci[:, 0, :], rtol=1e-12)
    assert f.first_order_ok and f.uncertainty_method == "first-order"
    assert f.stable_probability > 0.9999  # many std below zero (Genz's error 1e-6)


def test_model_route_unchanged_and_without_intervals():
    m = third_order_model()
    f = lptv.floquet(m)
    assert f.exponents_std is None and f.stable_probability is None and f.uncertainty_notes == ()
    with pytest.raises(ValueError, match="no uncertainty"):
        f.confidence_interval()


def _first_order_lti(a0, noise, seed=5):
    """y' + a0 y = u fitted from 8 noisy periods: one real exponent -a0, d lambda / d a0 = -1."""
    rng = np.random.default_rng(seed)
    ms = lptv.multisine(range(1, 40), 256, seed=0)
    m = lptv.Model([[a0], [1.0]], [[1.0]], w0=0.1)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    u = ms.periods(8) + noise * rng.standard_normal((8, 256))
    y = np.tile(y1, (8, 1)) + noise * rng.standard_normal((8, 256))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return lptv.identify(u, y, na=1, nb=0, w0=0.1, method="sml")


def test_stable_probability_is_the_normal_tail_of_one_rate():
    from scipy.stats import norm

    res = _first_order_lti(0.002, 1.0)   # an exponent 1.6 std below zero
    f = lptv.floquet(res)
    i = res.eta_names.index("a0.re0")
    s = np.sqrt(res.covariance[i, i])
    assert f.exponents_std[0, 0] == pytest.approx(s, rel=1e-6)
    assert f.stable_probability == pytest.approx(norm.cdf(res.eta[i] / s), rel=1e-9)
    assert 0.9 < f.stable_probability < 0.99


def test_near_boundary_is_said():
    # a pole 0.002 from the stability boundary with a std of its own size: undecided
    res = _first_order_lti(0.001, 1.0, seed=7)
    f = lptv.floquet(res, level=0.95)
    assert 0.05 < f.stable_probability < 0.95
    assert any("not decided" in s for s in f.uncertainty_notes)
    far = lptv.floquet(_first_order_lti(0.05, 2e-2), level=0.95)
    assert far.stable_probability > 0.999 and far.uncertainty_notes == ()


def test_bootstrap_agrees_with_first_order_where_it_holds():
    res = _discrete_fit(seed=4)
    f1 = lptv.floquet(res)
    fb = lptv.floquet(res, method="bootstrap", draws=400, seed=1)
    assert fb.uncertainty_method == "bootstrap" and fb.draws.shape == (400, f1.exponents.size)
    # relative sampling std of a std from 400 draws: 1/sqrt(800) = 3.5 %; 5 of them
    np.testing.assert_allclose(fb.exponents_std, f1.exponents_std, rtol=0.18)
    assert fb.stable_probability == 1.0
    ci = fb.confidence_interval(0.9)
    assert np.all(ci[:, :, 0] <= ci[:, :, 1])


def test_failure_detection_pair_about_to_split_and_repeated():
    w0 = 2.0
    # a complex pair 0.01 from the negative real axis of mu (Im = w0/2 - 0.01), std 0.02: may split
    lam = np.array([-0.1 + (w0 / 2 - 0.01) * 1j, -0.1 - (w0 / 2 - 0.01) * 1j])
    C = np.diag([1e-4, 4e-4, 1e-4, 4e-4])
    C[1, 3] = C[3, 1] = -4e-4
    notes = first_order_notes(lam, C, np.array([2.0, 2.0]), w0)
    assert notes and "real multipliers" in notes[0]
    # the same pair far from the axis: first order holds
    lam2 = np.array([-0.1 + 0.5j, -0.1 - 0.5j])
    assert first_order_notes(lam2, C, np.array([2.0, 2.0]), w0) == ()
    # an ill-conditioned (repeated) exponent
    assert any("ill-conditioned" in s for s in first_order_notes(lam2, C, np.array([1e9, 1e9]), w0))
    # two real exponents on the same half-axis 1 std apart: may merge into a complex pair
    lam3 = np.array([-0.10 + 0j, -0.11 + 0j])
    C3 = np.diag([1e-4, 0, 1e-4, 0])
    assert any("may meet" in s for s in first_order_notes(lam3, C3, np.array([3.0, 3.0]), w0))


def test_errors_name_the_argument():
    res = _fit("discrete", seed=2, covariance="none")
    with pytest.raises(ValueError, match="covariance='none'"):
        lptv.floquet(res)
    res = _fit("discrete", seed=2)
    with pytest.raises(ValueError, match="method"):
        lptv.floquet(res, method="exact")
    with pytest.raises(ValueError, match="level"):
        lptv.floquet(res).confidence_interval(1.5)
    with pytest.raises(ValueError, match="draws"):
        lptv.floquet(res, method="bootstrap", draws=2)
    with pytest.raises(ValueError, match="model must be"):
        lptv.floquet("res")


def test_frozen_poles_std_against_differences_of_roots():
    res = _fit("third_order", seed=6)
    t = np.array([0.0, 17.0, 60.0])
    fp = lptv.frozen_poles(res, t)
    np.testing.assert_array_equal(fp.poles, lptv.frozen_poles(res.model, t))
    # central differences of numpy.roots over each parameter, poles paired by distance
    from lptv.judgement.parameters import perturbed_model

    V = np.zeros(fp.poles.shape + (2,))
    J = np.zeros(fp.poles.shape + (2, len(res.eta_names)))
    for j, name in enumerate(res.eta_names):
        if res.covariance[j, j] <= 0 or name.startswith("b"):
            continue
        h = 1e-6 * max(abs(res.eta[j]), 1e-3)
        rp = lptv.frozen_poles(perturbed_model(res.model, name, h), t)
        rm = lptv.frozen_poles(perturbed_model(res.model, name, -h), t)
        for it in range(t.size):
            ip = [int(np.argmin(np.abs(rp[it] - p))) for p in fp.poles[it]]
            im = [int(np.argmin(np.abs(rm[it] - p))) for p in fp.poles[it]]
            d = (rp[it, ip] - rm[it, im]) / (2 * h)
            J[it, :, 0, j], J[it, :, 1, j] = d.real, d.imag
    V = np.sqrt(np.einsum("...ip,pq,...iq->...i", J, res.covariance, J))
    np.testing.assert_allclose(fp.std, V, rtol=1e-4)
    assert fp.confidence_interval().shape == fp.poles.shape + (2, 2)


def test_htf_band_against_closed_form_lti():
    # LTI: G_0 = b0 / (a1 s + a0); dG/da0 = -G/A, dG/da1 = -s G/A, dG/db0 = 1/A
    rng = np.random.default_rng(8)
    ms = lptv.multisine(range(1, 40), 256, seed=0)
    m = lptv.Model([[2.0], [1.0]], [[1.5]], w0=0.1)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 256)
    u = ms.periods(8) + 1e-2 * rng.standard_normal((8, 256))
    y = np.tile(y1, (8, 1)) + 1e-2 * rng.standard_normal((8, 256))
    res = lptv.identify(u, y, na=1, nb=0, w0=0.1, method="sml")
    lines = np.arange(1, 40, 3)
    band = res.htf_band(lines=lines)
    a0, a1, b0 = res.model.a[0, 0].real, res.model.a[1, 0].real, res.model.b[0, 0].real
    s = 1j * lines * 0.1
    A = a1 * s + a0
    G = b0 / A
    np.testing.assert_allclose(band.G[0], G, rtol=1e-10)
    dG = {"a0.re0": -G / A, "a1.re0": -s * G / A, "b0.re0": 1 / A}
    Jr = np.zeros((lines.size, 2, len(res.eta_names)))
    for j, name in enumerate(res.eta_names):
        Jr[:, 0, j], Jr[:, 1, j] = dG[name].real, dG[name].imag
    C = np.einsum("lip,pq,ljq->lij", Jr, res.covariance, Jr)
    np.testing.assert_allclose(band.covariance[0], C, rtol=1e-6, atol=1e-9 * np.abs(C).max())
    assert band.contains(band.G).all()
    assert not band.contains(band.G + 10 * np.sqrt(np.abs(C[:, 0, 0]))[None]).any()
    mb = band.magnitude_band()
    assert np.all(mb[..., 0] <= np.abs(band.G)) and np.all(np.abs(band.G) <= mb[..., 1])


def test_htf_band_and_frozen_poles_need_a_covariance():
    res = _fit("discrete", seed=2, covariance="none")
    with pytest.raises(ValueError, match="covariance"):
        res.htf_band(lines=[6, 12])
    with pytest.raises(ValueError, match="covariance"):
        lptv.frozen_poles(res, [0.0])
    res = _fit("discrete", seed=2)
    with pytest.raises(ValueError, match="lines"):
        res.htf_band(lines=[0.5])


def test_several_outputs_against_the_eigenvalue_derivative_of_an_lti_matrix():
    """Two outputs, LTI (A_1 = I): the exponents are the eigenvalues of -A_0, whose derivative
    -conj(u_p) v_q / (u^H v) (numpy's eigenvectors) gives the std independently of the core's
    central differences; the bootstrap agrees within its sampling error (200 draws: 5 %; 4 of it)."""
    from lptv.examples.mimo import small_fit

    res = small_fit()
    f = lptv.floquet(res)
    A0 = res.model.a[0, :, :, 0].real
    lam, V = np.linalg.eig(-A0)
    U = np.linalg.inv(V).conj().T        # left eigenvectors, u_i^H v_j = delta_ij
    J = np.zeros((2, len(res.parameter_names)))
    for j, name in enumerate(res.parameter_names):
        if name.startswith("a0[") and name.endswith(".re0"):
            p, q = int(name[3]), int(name[5])
            J[:, j] = [-(np.conj(U[p, i]) * V[q, i]).real for i in range(2)]
    std = np.sqrt(np.einsum("ij,jk,ik->i", J, res.covariance, J))
    order = [int(np.argmin(np.abs(lam - x))) for x in f.exponents]
    np.testing.assert_allclose(f.exponents_std[:, 0], std[order], rtol=1e-4)
    np.testing.assert_array_equal(f.exponents_std[:, 1], 0.0)   # real exponents stay real
    fb = lptv.floquet(res, method="bootstrap", draws=200, seed=0)
    np.testing.assert_allclose(fb.exponents_std[:, 0], f.exponents_std[:, 0], rtol=0.2)
