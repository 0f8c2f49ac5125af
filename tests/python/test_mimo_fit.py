"""Estimation with several inputs and outputs (METHOD.md section 19): lptv.identify on (P, N, nu)
and (P, N, ny) arrays against the dense reference lptv.reference.mimo_fit (WGTLS, SML, the
covariances, the CRB), against systems integrated by solve_ivp (noise-free data give the true
coefficients), against the single-input single-output fit (a 1 x 1 fit is the SISO fit), and its
refusals of bad arguments."""
import warnings

import numpy as np
import pytest

import lptv
from lptv.examples import mimo as mx
from lptv.spectra.mimo_frequency_data import MimoFrequencyData
from lptv.reference import mimo_fit as ref

N = 32
LINES = np.arange(2, 14, 2)
STRUCTURE = {"2-in-2-out": dict(na=2, nb=0, ka=[1, 0, 0], kb=0), "1-in-2-out": dict(na=2, nb=0, ka=[1, 0, 0], kb=0),
             "2-in-1-out": dict(na=2, nb=1, ka=[1, 0, 0], kb=[1, 0])}


def experiments(system, seed, P=6, level=0.03, n=N, lines=LINES, input_level=None):
    """Orthogonal (Hadamard) experiments, E = nu, of a system's FDS steady state plus white noise
    of ``level`` times each channel's rms on every input and output sample."""
    model = mx.SYSTEMS[system]()[0]
    rng = np.random.default_rng(seed)
    d = lptv.mimo_multisines(lines, n, model.n_inputs, seed=rng)
    out = []
    for e in range(d.n_experiments):
        U = d.spectra[e]
        Y = np.asarray(lptv.simulate(model, U, lines_out=n // 2)).reshape(n // 2 + 1, -1)
        y1 = np.fft.irfft(Y * n, n, axis=0)
        u1 = d.signals[e]
        lu = level if input_level is None else input_level
        u = u1[None] + lu * u1.std(axis=0) * rng.standard_normal((P, n, u1.shape[1]))
        y = y1[None] + level * y1.std(axis=0) * rng.standard_normal((P, n, y1.shape[1]))
        out.append((u, y))
    return model, out


def reference_data(pairs, K, n=N):
    out = []
    for u, y in pairs:
        d = MimoFrequencyData.from_periods(u, y, w0=mx.W0)
        out.append((d.Y, d.U, d.C, np.arange(K + 1, n // 2 - K + 1)))
    return out


def counts(k, order, cols):
    """An int or one count per order as (order+1, cols)."""
    k = np.asarray(k)
    return np.broadcast_to(k[:, None] if k.ndim == 1 else k, (order + 1, cols)).copy()


def ref_structure(system):
    s = STRUCTURE[system]
    model = mx.SYSTEMS[system]()[0]
    ny, nu = model.n_outputs, model.n_inputs
    return ref.Structure(s["na"], s["nb"], counts(s["ka"], s["na"], ny), counts(s["kb"], s["nb"], nu), mx.W0)


@pytest.mark.parametrize("system", list(mx.SYSTEMS))
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_wgtls_matches_reference(system, seed):
    model, pairs = experiments(system, seed)
    res = lptv.identify(pairs, w0=mx.W0, method="wgtls", tol=1e-12, max_iter=100, **STRUCTURE[system])
    st = ref_structure(system)
    xi_ref, _ = ref.wgtls(st, reference_data(pairs, st.K), tol=1e-12, max_iter=100)
    assert res.converged
    # both iterate to a relative change of 1e-12; the fixed point is a smooth function of the
    # weights, so the two agree to that times the iteration's contraction (measured < 10) and the
    # rounding of the eigenproblems (eps times the generalised condition, < 1e6 here)
    err = np.abs(res.eta - xi_ref).max() / np.abs(xi_ref).max()
    assert err < 1e-9, err


@pytest.mark.parametrize("system", list(mx.SYSTEMS))
@pytest.mark.parametrize("seed", [0, 1])
def test_sml_and_covariances_match_reference(system, seed):
    model, pairs = experiments(system, seed)
    res = lptv.identify(pairs, w0=mx.W0, method="sml", tol=1e-12, **STRUCTURE[system])
    st = ref_structure(system)
    data = reference_data(pairs, st.K)
    xi_w, _ = ref.wgtls(st, data)
    xi_ref, out = ref.sml(st, data, xi_w)
    std = res.parameter_std / np.sqrt(res.covariance_factor)
    free = st.free
    # the two optimisers stop at steps below 1e-8 (the reference) and 1e-12 relative: well inside 1e-4 standard deviations
    assert np.abs(res.eta - xi_ref)[free].max() <= 1e-4 * std[free].min(), np.abs(res.eta - xi_ref)[free] / std[free]
    # the cost is at its minimum on both routes: the reference's at the production's estimate is no lower
    assert ref._cost_grad(st, res.eta, data)[0] <= ref._cost_grad(st, xi_ref, data)[0] * (1 + 1e-10)
    # the Fisher information and the sandwich at the same estimate (pure linear algebra: rounding only)
    cov_ref = np.linalg.inv(ref.fisher(st, res.eta, data))
    cov = res.covariance[np.ix_(free, free)] / res.covariance_factor
    assert np.allclose(cov, cov_ref, rtol=1e-8, atol=1e-10 * np.abs(cov_ref).max())
    from lptv.estimation.mimo_fit import core_data, core_structure, sandwich
    from lptv.spectra.mimo_frequency_data import MimoStructure
    datas = [MimoFrequencyData.from_periods(u, y, w0=mx.W0) for u, y in pairs]
    ny, nu = model.n_outputs, model.n_inputs
    s = STRUCTURE[system]
    mst = MimoStructure(s["na"], s["nb"], st.ka, st.kb, ny, nu, mx.W0)
    sw = sandwich(core_data(datas, [r for *_, r in data]), core_structure(mst), res.eta)
    sw_ref = ref.sandwich(st, res.eta, data)
    assert np.allclose(sw, sw_ref, rtol=1e-8, atol=1e-10 * np.abs(sw_ref).max())


@pytest.mark.parametrize("system", list(mx.SYSTEMS))
def test_crb_matches_reference(system):
    model, pairs = experiments(system, 0)
    d = lptv.mimo_multisines(LINES, N, model.n_inputs, seed=np.random.default_rng(0))
    noise = np.r_[np.full(model.n_outputs, 1e-4), np.full(model.n_inputs, 1e-5)]
    P = 8
    bound = lptv.mimo_crb(model, d.spectra, noise=noise, periods=P, ka=STRUCTURE[system]["ka"],
                          kb=STRUCTURE[system]["kb"])
    st = ref_structure(system)
    a, b = mx.true_parameters(model)
    assert np.allclose(st.coefficients(bound.eta)[0][(st.na, 0, 0)][0], 1.0)
    data = []
    for e in range(d.n_experiments):
        U = d.spectra[e]
        Y = np.asarray(lptv.simulate(model, U, lines_out=N // 2)).reshape(N // 2 + 1, -1)
        C = np.broadcast_to(np.diag(noise.astype(complex)) / P, (N // 2 + 1,) + (noise.size,) * 2)
        data.append((Y, U, np.array(C), np.arange(st.K + 1, N // 2 - st.K + 1)))
    crb_ref = ref.crb(st, bound.eta, data)
    cov = bound.covariance[np.ix_(st.free, st.free)]
    assert np.allclose(cov, crb_ref, rtol=1e-8, atol=1e-10 * np.abs(crb_ref).max())
    # and the normalised true parameters are the model's own coefficients times A_na,0^-1
    ra, rb = st.coefficients(bound.eta)
    Ka = a.shape[3] // 2
    for (n, p, q), v in ra.items():
        for k, c in v.items():
            assert abs(c - a[n, p, q, Ka + k]) < 1e-14


@pytest.mark.parametrize("system", list(mx.SYSTEMS))
def test_noise_free_solve_ivp_gives_true_coefficients(system):
    model = mx.SYSTEMS[system]()[0]
    n = 64
    lines = np.arange(2, 30, 3)
    d = lptv.mimo_multisines(lines, n, model.n_inputs, design="random", n_experiments=max(2, model.n_inputs),
                             seed=3)
    pairs = []
    for e in range(d.n_experiments):
        y1 = mx.steady_state(system, d.spectra[e], n)
        pairs.append((np.repeat(d.signals[e][None], 2, axis=0), np.repeat(y1[None], 2, axis=0)))
    res = lptv.identify(pairs, w0=mx.W0, **STRUCTURE[system])
    assert res.noise_free and res.covariance is None and res.model_ok is None
    a, b = mx.true_parameters(model)
    s = STRUCTURE[system]
    ny, nu = model.n_outputs, model.n_inputs
    from lptv.spectra.mimo_frequency_data import MimoStructure
    st = MimoStructure(s["na"], s["nb"], counts(s["ka"], s["na"], ny), counts(s["kb"], s["nb"], nu), ny, nu, mx.W0)
    truth = st.xi_of(a, b)
    # the integration's relative error (about 1e-13 of the largest output line, bounded by 10 rtol
    # in test_mimo_timedomain) times the condition of the TLS problem: the ratio of the largest
    # to the (ny^2 + 1)-th singular value of the scaled Jacobian, under 1e4 here
    sv = res.singular_values
    cond = sv[-1] / sv[ny * ny]
    assert cond < 1e4
    err = np.abs(res.eta - truth).max() / np.abs(truth).max()
    assert err < 10 * mx.RTOL * cond * 10, (err, cond)


@pytest.mark.parametrize("method", ["wgtls", "sml"])
@pytest.mark.parametrize("seed", [0, 1])
def test_one_by_one_equals_siso(method, seed):
    m = lptv.Model([[0.5, 2.0, 0.5], [0.0, 1.0, 0.0]], [[0.0, 1.0, 0.0]], w0=1.0)
    ms = lptv.multisine(range(2, 30), 128, seed=seed)
    y1 = lptv.time_signal(lptv.simulate(m, ms.spectrum), 128)
    rng = np.random.default_rng(seed)
    P = 6
    u = ms.periods(P) + 0.02 * rng.standard_normal((P, 128))
    y = np.tile(y1, (P, 1)) + 0.02 * rng.standard_normal((P, 128))
    kw = dict(na=1, nb=0, ka=1, kb=0, w0=1.0, method=method, tol=1e-13, max_iter=200)
    siso = lptv.identify(u, y, **kw, noise="sample")      # both on the sample variances (the moderated
    mimo = lptv.identify(u[:, :, None], y[:, :, None], **kw, noise="sample")   # route: test_mimo_moderation.py)
    assert isinstance(mimo, lptv.MimoIdentificationResult)
    assert mimo.model.n_inputs == mimo.model.n_outputs == 1
    assert np.abs(mimo.eta - siso.eta).max() <= 1e-8 * np.abs(siso.eta).max() + 1e-6 * siso.parameter_std.min()
    if method == "sml":   # the same Fisher information and factor (P-1)/(P-3); WGTLS's SISO covariance adds a
        # second-order term the MIMO sandwich leaves out
        assert np.allclose(mimo.covariance, siso.covariance, rtol=1e-6, atol=1e-12)
    assert np.allclose(mimo.model.a[:, 0, 0], siso.model.a, rtol=1e-8, atol=1e-9)


def test_result_interface():
    model, pairs = experiments("2-in-2-out", 4, P=8)
    res = lptv.identify(pairs, w0=mx.W0, method="sml", **STRUCTURE["2-in-2-out"])
    assert (res.model.n_inputs, res.model.n_outputs) == (2, 2)
    assert res.eta.shape == res.parameter_std.shape == (len(res.parameter_names),)
    assert res.covariance.shape == (res.eta.size,) * 2
    ci = res.confidence_interval(0.9)
    assert ci.shape == (res.eta.size, 2) and np.all(ci[:, 0] <= ci[:, 1])
    assert res.converged and np.isfinite(res.cost) and res.lines.size > 0
    assert isinstance(res.verdict, str) and isinstance(res.model_errors, list)
    assert res.model_ok in (True, False)
    assert res.parameter_names[0] == "a0[0,0].re0"
    fixed = [i for i, nm in enumerate(res.parameter_names) if nm.startswith("a2[") and nm.endswith(".re0")]
    assert np.allclose(res.eta[fixed], [1, 0, 0, 1]) and np.all(res.parameter_std[fixed] == 0)
    # one experiment of a (P, N, nu) pair, the wrong structure (no time variation) is rejected
    bad = lptv.identify(pairs, w0=mx.W0, method="wgtls", na=2, nb=0, ka=0, kb=0)
    assert bad.model_ok is False and bad.model_errors and bad.verdict.startswith("MODEL ERRORS: the model is rejected: ")


def _pairs():
    return experiments("2-in-2-out", 5, P=4)[1]


@pytest.mark.parametrize("call, word", [
    (lambda p: lptv.identify(p[0][0], p[0][1][:, :, 0], na=2, nb=0, w0=1.0), "y"),
    (lambda p: lptv.identify(p, na=2, nb=0, w0=1.0, ka=np.ones((4, 2))), "ka"),
    (lambda p: lptv.identify(p, na=2, nb=0, w0=1.0, ka=[[0, 1], [1, 1]]), "ka"),
    (lambda p: lptv.identify(p, na=2, nb=0, w0=1.0, kb=-1), "kb"),
    (lambda p: lptv.identify(p, na=2, nb=0, w0=1.0, method="ls"), "method"),
    (lambda p: lptv.identify(p, na=2, nb=0, w0=1.0, known={"a1": 1.0}), "known"),
    (lambda p: lptv.identify(p, na=2, nb=0, w0=1.0, ka=1, lines=[1, 2, 3]), "lines"),
    (lambda p: lptv.identify(p, na=2, nb=0), "w0"),
    (lambda p: lptv.identify(p[0][0][:1], p[0][1][:1], na=2, nb=0, w0=1.0), "u"),
    (lambda p: lptv.identify([p[0], (p[1][0][:, :, :1], p[1][1])], na=2, nb=0, w0=1.0), "experiments[1]"),
    (lambda p: lptv.identify(p, na=2, nb=0, w0=1.0, covariance="bootstrap"), "covariance"),
    (lambda p: lptv.identify(p[0][0], p[0][1] * np.nan, na=2, nb=0, w0=1.0), "y"),
    (lambda p: lptv.identify(p, na="x", nb=0, w0=1.0), "na"),
    (lambda p: lptv.mimo_crb("m", p[0][0], noise=1.0, periods=2), "model"),
    (lambda p: lptv.identify([(u[:2], y[:2]) for u, y in p], na=2, nb=0, w0=1.0), "u, y: P = 2 periods"),
])
def test_bad_inputs_name_the_argument(call, word):
    p = _pairs()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match=r"^" + word.replace("[", r"\[").replace("]", r"\]")):
            call(p)


def test_docstring_examples_run():
    import doctest
    import lptv.spectra.mimo_frequency_data
    import lptv.examples.mimo
    import lptv.estimation.mimo_identify
    import lptv.judgement.mimo_result
    for mod in (lptv.spectra.mimo_frequency_data, lptv.examples.mimo, lptv.estimation.mimo_identify, lptv.judgement.mimo_result):
        result = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
        assert result.attempted > 0 and result.failed == 0, mod.__name__
    # lptv.identify's own examples, the MIMO one included
    test = doctest.DocTestFinder().find(lptv.identify, "identify", globs={})[0]
    result = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE).run(test)
    assert result.attempted > 0 and result.failed == 0


def test_crb_of_a_mimo_model_is_mimo_crb():
    model = mx.SYSTEMS["2-in-1-out"]()[0]
    d = lptv.mimo_multisines(LINES, N, 2, seed=1)
    a = lptv.crb(model, d.spectra, var_y=1e-4, var_u=[1e-5, 2e-5], periods=8, ka=[1, 0, 0], kb=[1, 0])
    b = lptv.mimo_crb(model, d.spectra, noise=[1e-4, 1e-5, 2e-5], periods=8, ka=[1, 0, 0], kb=[1, 0])
    assert np.array_equal(a.covariance, b.covariance)
    with pytest.raises(ValueError, match="^cov_yu"):
        lptv.crb(model, d.spectra, var_y=1e-4, cov_yu=1e-6, periods=8)


def discrete_model():
    """A discrete-time 2 x 2 model (forward shift, N = 32 samples per period, ts = 1): A_2 = I,
    A_1 constant, A_0 with a periodic entry, B_0 = [[1, 0.5], [0, 1]]."""
    a = np.zeros((3, 2, 2, 3), complex)
    a[2, :, :, 1] = np.eye(2)
    a[1, :, :, 1] = [[-0.3, 0.05], [0.02, -0.2]]
    a[0, :, :, 1] = [[0.1, 0.02], [0.0, 0.08]]
    a[0, 0, 0, 0] = a[0, 0, 0, 2] = 0.03
    a[0, 1, 0, 0], a[0, 1, 0, 2] = 0.02 - 0.01j, 0.02 + 0.01j
    b = np.array([[[1.0, 0.5], [0.0, 1.0]]])
    return lptv.MimoModel(a, b, w0=2 * np.pi / N, ts=1.0)


@pytest.mark.parametrize("method", ["wgtls", "sml"])
@pytest.mark.parametrize("seed", [0, 1])
def test_discrete_time_matches_reference(method, seed):
    model = discrete_model()
    rng = np.random.default_rng(seed)
    d = lptv.mimo_multisines(np.arange(2, 14), N, 2, seed=rng)
    pairs = []
    for e in range(2):
        Y = np.asarray(lptv.simulate(model, d.spectra[e], lines_out=N // 2)).reshape(N // 2 + 1, -1)
        y1 = np.fft.irfft(Y * N, N, axis=0)
        u1 = d.signals[e]
        pairs.append((u1[None] + 0.03 * u1.std(0) * rng.standard_normal((6, N, 2)),
                      y1[None] + 0.03 * y1.std(0) * rng.standard_normal((6, N, 2))))
    kw = dict(na=2, nb=0, ka=[1, 0, 0], kb=0)
    res = lptv.identify(pairs, w0=model.w0, ts=1.0, method=method, tol=1e-12, max_iter=100, **kw)
    assert res.model.discrete
    st = ref.Structure(2, 0, counts([1, 0, 0], 2, 2), counts(0, 0, 2), model.w0, ts=1.0)
    data = reference_data(pairs, st.K)     # the spectra and covariances do not depend on w0
    xi_w, _ = ref.wgtls(st, data, tol=1e-12, max_iter=100)
    if method == "wgtls":
        assert np.abs(res.eta - xi_w).max() <= 1e-9 * np.abs(xi_w).max()
    else:
        xi_ref, _ = ref.sml(st, data, xi_w)
        std = res.parameter_std / np.sqrt(res.covariance_factor)
        assert np.abs(res.eta - xi_ref)[st.free].max() <= 1e-4 * std[st.free].min()
    # the estimate is near the truth (a few standard deviations: the data are noisy)
    a, b = model.a, model.b
    from lptv.spectra.mimo_frequency_data import MimoStructure
    truth = MimoStructure(2, 0, counts([1, 0, 0], 2, 2), counts(0, 0, 2), 2, 2, model.w0, 1.0).xi_of(a, b)
    free = st.free
    assert np.all(np.abs(res.eta - truth)[free] <= 6 * res.parameter_std[free])


def test_excited_rows_and_frequency_data():
    model, pairs = experiments("2-in-2-out", 6, P=8)
    full = lptv.identify(pairs, w0=mx.W0, method="sml", **STRUCTURE["2-in-2-out"])
    exc = lptv.identify(pairs, w0=mx.W0, method="sml", lines="excited", **STRUCTURE["2-in-2-out"])
    # the excited lines and their +-K neighbours, K = 1, in each experiment
    want = np.unique(np.concatenate([LINES + k for k in (-1, 0, 1)]))
    want = want[(want >= 2) & (want <= N // 2 - 1)]
    assert np.array_equal(np.unique(exc.lines), want) and exc.lines.size == 2 * want.size
    # rows without signal carry little information: the two estimates agree within their uncertainty
    free = full.parameter_std > 0
    assert np.all(np.abs(exc.eta - full.eta)[free] <= 3 * exc.parameter_std[free])
    # MimoFrequencyData as the data: the same fit
    datas = [lptv.MimoFrequencyData.from_periods(u, y, w0=mx.W0) for u, y in pairs]
    again = lptv.identify(datas, method="sml", **STRUCTURE["2-in-2-out"])
    assert np.array_equal(again.eta, full.eta)
    d = datas[0]
    with pytest.raises(ValueError, match="^C must"):
        lptv.MimoFrequencyData(U=d.U, Y=d.Y, C=d.C[:, :3], periods=8, w0=1.0)
    with pytest.raises(ValueError, match="^Y must"):
        lptv.MimoFrequencyData(U=d.U, Y=d.Y[:-1], C=d.C, periods=8, w0=1.0)


@pytest.mark.parametrize("method", ["wgtls", "sml"])
def test_known_leading_matrix(method):
    """known={'a2': M}: the mechanical system's own coefficients (M = diag(1, 2)), the same system
    as with A_2,0 = I: M times that estimate, its covariance K cov K^T, the joint residue tests alike."""
    model, pairs = experiments("2-in-2-out", 7, P=8)
    M = np.diag([1.0, 2.0])
    ident = lptv.identify(pairs, w0=mx.W0, method=method, **STRUCTURE["2-in-2-out"])
    phys = lptv.identify(pairs, w0=mx.W0, method=method, known={"a2": M}, **STRUCTURE["2-in-2-out"])
    Ka = phys.model.a.shape[3] // 2
    assert np.allclose(phys.model.a[2, :, :, Ka].real, M, rtol=0, atol=1e-14)
    assert np.allclose(phys.model.a, np.einsum("pj,njqk->npqk", M, ident.model.a), rtol=1e-12, atol=1e-14)
    assert np.allclose(phys.model.b, np.einsum("pj,njrk->nprk", M, ident.model.b), rtol=1e-12, atol=1e-14)
    # near the physical truth: M y'' + C y' + K(t) y = B u
    a_true = model.a
    err = np.abs(phys.model.a[0] - a_true[0])
    assert err.max() < 0.05 * np.abs(a_true[0]).max()
    fixed = [i for i, nm in enumerate(phys.parameter_names) if nm.startswith("a2[") and nm.endswith(".re0")]
    assert np.allclose(phys.eta[fixed], M.ravel()) and np.all(phys.parameter_std[fixed] == 0)
    joint = [t for t in phys.tests if t[1] < 0]
    joint_i = [t for t in ident.tests if t[1] < 0]
    assert np.allclose([t[2] for t in joint], [t[2] for t in joint_i], rtol=1e-10)
    for bad in ({"a1": M}, {"a2": np.eye(3)}, {"a2": np.zeros((2, 2))}):
        with pytest.raises(ValueError, match="^known"):
            lptv.identify(pairs, w0=mx.W0, known=bad, **STRUCTURE["2-in-2-out"])


@pytest.mark.parametrize("system", ["2-in-2-out", "2-in-1-out"])
def test_prediction_of_a_fresh_experiment(system):
    """A model fitted on noisy data predicts a fresh experiment's output, integrated by solve_ivp
    with new phases, within its uncertainty: the prediction error on every excited output line is
    within 5 standard deviations of the predictions of 200 parameter draws from N(eta, covariance)
    (a normal quantile of 5 leaves 6e-7 per line and output), and within 2 % of the output."""
    model, pairs = experiments(system, 8, P=8, n=64, lines=np.arange(2, 28, 3))
    res = lptv.identify(pairs, w0=mx.W0, method="sml", **STRUCTURE[system])
    n = 64
    d = lptv.mimo_multisines(np.arange(2, 28, 3), n, model.n_inputs, design="random", seed=99)
    y_true = np.fft.rfft(mx.steady_state(system, d.spectra[0], n), axis=0) / n
    U = d.spectra[0]
    pred = np.asarray(lptv.simulate(res.model, U, lines_out=n // 2)).reshape(n // 2 + 1, -1)
    rng = np.random.default_rng(0)
    from lptv.spectra.mimo_frequency_data import MimoStructure
    s = STRUCTURE[system]
    st = MimoStructure(s["na"], s["nb"], counts(s["ka"], s["na"], model.n_outputs),
                       counts(s["kb"], s["nb"], model.n_inputs), model.n_outputs, model.n_inputs, mx.W0)
    draws = rng.multivariate_normal(res.eta, res.covariance, size=200, method="eigh")
    sims = np.array([np.asarray(lptv.simulate(lptv.MimoModel(*st.coefficients(x), w0=mx.W0), U,
                                              lines_out=n // 2)).reshape(n // 2 + 1, -1) for x in draws])
    sd = np.sqrt(np.var(sims.real, axis=0) + np.var(sims.imag, axis=0))
    lines = np.arange(2, 28, 3)
    err = np.abs(pred[lines] - y_true[lines])
    assert np.all(err <= 5 * sd[lines]), (err / sd[lines]).max()
    assert err.max() <= 0.02 * np.abs(y_true[lines]).max()


@pytest.mark.parametrize("system", ["2-in-2-out", "2-in-1-out"])
def test_inputs_without_noise(system):
    """Inputs measured without noise: the b-columns of the Jacobian carry no noise and CJ_W is
    singular; the core eliminates those directions, the reference reverses the pencil
    (CJ v = mu H v). Both agree, for WGTLS and for SML from it."""
    model, pairs = experiments(system, 9, input_level=0.0)
    st = ref_structure(system)
    data = reference_data(pairs, st.K)
    assert np.all(data[0][2][:, -model.n_inputs:, :] == 0)        # the inputs' noise block is exactly zero
    res = lptv.identify(pairs, w0=mx.W0, method="wgtls", tol=1e-12, max_iter=100, **STRUCTURE[system])
    xi_ref, _ = ref.wgtls(st, data, tol=1e-12, max_iter=100)
    assert res.converged
    assert np.abs(res.eta - xi_ref).max() <= 1e-8 * np.abs(xi_ref).max()
    sml = lptv.identify(pairs, w0=mx.W0, method="sml", tol=1e-12, **STRUCTURE[system])
    xi_s, _ = ref.sml(st, data, xi_ref)
    std = sml.parameter_std / np.sqrt(sml.covariance_factor)
    assert np.abs(sml.eta - xi_s)[st.free].max() <= 1e-4 * std[st.free].min()
