"""The record's transient term in the fit of several channels (METHOD.md section 20, eq. 20.5,
``lptv.identify(..., transient=...)``): a noise-free record started away from the periodic
steady state, simulated here by the system's own recursion (not by lptv), is fitted exactly with
the term and not without it; the fit is the dense reference's (lptv.reference.mimo_fit) on the
spectra with the term's noise-free columns built here by hand; the default fits the term on the
record's noise only; bad values are refused naming the argument."""
import warnings

import numpy as np
import pytest

import lptv
from lptv.examples import mimo as mx
from lptv.reference import mimo_fit as ref
from lptv.spectra.mimo_frequency_data import MimoFrequencyData

N, P = 64, 4
LINES = np.arange(1, 20, 2)
W0 = 2 * np.pi / N          # ts = 1


def dt_truth():
    """A 2 x 2 discrete-time system y(t+2) + A1 y(t+1) + A0(t) y(t) = B0 u(t) with
    A0(t) = A00 + 2 Re(A01 e^{j w0 t}), A1, B0 constant: poles near |z| = 0.975 (a slow transient)."""
    A1 = np.array([[-1.9, 0.05], [0.0, -1.85]])
    A00 = np.array([[0.95, 0.02], [-0.03, 0.93]])
    A01 = np.array([[0.01 + 0.005j, 0.0], [0.0, -0.008 + 0.004j]])
    B0 = np.array([[1.0, 0.3], [-0.2, 0.8]])
    return A1, A00, A01, B0


def dt_record(seed):
    """Two Hadamard experiments of P periods, each from a random initial state (noise-free)."""
    rng = np.random.default_rng(seed)
    A1, A00, A01, B0 = dt_truth()
    ph = rng.uniform(0, 2 * np.pi, (2, LINES.size))
    t = np.arange(P * N)
    s = np.cos(np.outer(t, LINES * W0)[None] + ph[:, None, :]).sum(-1)       # (2, samples)
    out = []
    for e, sign in enumerate((1.0, -1.0)):
        u = np.stack([s[0], sign * s[1]], axis=1)                                # (samples, 2)
        y = np.zeros((P * N + 2, 2))
        y[:2] = rng.standard_normal((2, 2))
        for k in range(P * N):
            A0 = A00 + 2 * np.real(A01 * np.exp(1j * W0 * k))
            y[k + 2] = B0 @ u[k] - A1 @ y[k + 1] - A0 @ y[k]
        out.append((u.reshape(P, N, 2), y[:P * N].reshape(P, N, 2)))
    return out


def dt_xi():
    """The truth in lptv's order (row p: a0[p,0] re0 re1 im1, a0[p,1] re0 re1 im1, a1[p,0..1],
    a2[p,0..1], b0[p,0..1])."""
    A1, A00, A01, B0 = dt_truth()
    xi = []
    for p in range(2):
        for q in range(2):
            xi += [A00[p, q], A01[p, q].real, A01[p, q].imag]
        xi += list(A1[p]) + [float(p == 0), float(p == 1)] + list(B0[p])
    return np.array(xi)


def noise_free_data(pairs):
    """The periods' mean spectra (the record's bins l P) with zero (co)variances: noise-free data."""
    out = []
    for u, y in pairs:
        U = np.fft.rfft(u, axis=1).mean(axis=0) / N
        Y = np.fft.rfft(y, axis=1).mean(axis=0) / N
        out.append(MimoFrequencyData(U, Y, np.zeros((U.shape[0], 4, 4)), P, W0, 1.0))
    return out


def fit(pairs, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return lptv.identify(noise_free_data(pairs), na=2, nb=0, ka=[1, 0, 0], kb=0, w0=W0, ts=1.0,
                             lines=np.arange(2, N // 2 - 1), **kw)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_record_from_a_state_is_fitted_exactly_with_its_transient(seed):
    pairs = dt_record(seed)
    xi = dt_xi()
    with_t = fit(pairs, transient=True)
    without = fit(pairs, transient=False)
    assert with_t.noise_free and with_t.transient.shape == (2, 2, 2) and with_t.transient_powers == (1, 2)
    # the equation error of a noise-free record is -T(z) exactly (section 17 on P periods): TLS
    # then recovers the coefficients to the rounding of the spectra (1e-16 of the largest line)
    # times the problem's condition (about 1e5 for a pole at 0.975)
    assert np.abs(with_t.eta - xi).max() <= 1e-8 * np.abs(xi).max(), np.abs(with_t.eta - xi).max()
    # without it the transient biases every coefficient
    assert np.abs(without.eta - xi).max() >= 1e-4 * np.abs(xi).max()
    assert without.transient is None


def _experiments(seed, P=6, level=0.03, n=32):
    model = mx.SYSTEMS["2-in-2-out"]()[0]
    rng = np.random.default_rng(seed)
    d = lptv.mimo_multisines(np.arange(2, 14, 2), n, 2, seed=rng)
    out = []
    for e in range(d.n_experiments):
        Y = np.asarray(lptv.simulate(model, d.spectra[e], lines_out=n // 2)).reshape(n // 2 + 1, -1)
        y1 = np.fft.irfft(Y * n, n, axis=0)
        u1 = d.signals[e]
        out.append((u1[None] + level * u1.std(axis=0) * rng.standard_normal((P, n, 2)),
                    y1[None] + level * y1.std(axis=0) * rng.standard_normal((P, n, 2))))
    return out


def _reference_with_transient(pairs, n=32):
    """The reference's structure and data with the transient's columns built here: one input
    more per experiment, 1 on every line of its own experiment, noise-free, with B entries at
    s^0 and s^1 only (kb = -1 elsewhere), the model's own inputs at order 0 only."""
    E = len(pairs)
    kb = -np.ones((2, 2 + E), int)
    kb[0, :2] = 0
    kb[:, 2:] = 0
    ka = np.array([[1, 1], [0, 0], [0, 0]])
    st = ref.Structure(2, 1, ka, kb, mx.W0)
    data = []
    for e, (u, y) in enumerate(pairs):
        d = MimoFrequencyData.from_periods(u, y, w0=mx.W0)
        L1 = d.U.shape[0]
        U = np.concatenate([d.U, np.zeros((L1, E))], axis=1)
        U[:, 2 + e] = 1.0
        C = np.zeros((L1, 4 + E, 4 + E), complex)
        C[:, :4, :4] = d.C
        data.append((d.Y, U, C, np.arange(2, n // 2)))
    return st, data


@pytest.mark.parametrize("seed", [0, 1])
def test_the_transient_fit_is_the_dense_reference_s_with_the_columns_built_by_hand(seed):
    pairs = _experiments(seed)
    st, data = _reference_with_transient(pairs)
    kw = dict(na=2, nb=0, ka=[1, 0, 0], kb=0, w0=mx.W0, lines=np.arange(2, 16), transient=True)
    res = lptv.identify(pairs, method="wgtls", tol=1e-12, max_iter=100, **kw)
    xi_ref, _ = ref.wgtls(st, data, tol=1e-12, max_iter=100)
    names = [f"{n}" for n in res.parameter_names]
    ref_names = _ref_names(st)
    idx = [ref_names.index(n) for n in names]
    err = np.abs(res.eta - xi_ref[idx]).max() / np.abs(xi_ref).max()
    assert err < 1e-9, err       # as test_mimo_fit's WGTLS against the reference
    t_idx = [[[ref_names.index(f"b{m}[{p},{2 + e}].re0") for m in (0, 1)] for p in range(2)] for e in range(2)]
    assert np.allclose(res.transient, xi_ref[np.array(t_idx)], rtol=1e-7, atol=1e-9 * np.abs(xi_ref).max())
    sml = lptv.identify(pairs, method="sml", tol=1e-12, **kw)
    xs, _ = ref.sml(st, data, xi_ref)
    std = sml.parameter_std / np.sqrt(sml.covariance_factor)
    free = std > 0
    assert np.abs(sml.eta - xs[idx])[free].max() <= 1e-4 * std[free].min()
    # the model's covariance is the model's block of the inverse joint information (the
    # transient's coefficients profiled out), the reference's at the same estimate
    xfull = xs.copy()
    xfull[idx] = sml.eta
    xfull[np.array(t_idx).ravel()] = sml.transient.ravel()
    cov_ref = np.linalg.inv(ref.fisher(st, xfull, data))
    fpos = {int(i): k for k, i in enumerate(st.free)}
    sel = [fpos[idx[i]] for i in np.flatnonzero(free)]
    cov = sml.covariance[np.ix_(free, free)] / sml.covariance_factor
    assert np.allclose(cov, cov_ref[np.ix_(sel, sel)], rtol=1e-7, atol=1e-10 * np.abs(cov_ref).max())


def _ref_names(st):
    """The reference's parameter names in lptv's form ('b1[0,3].re0')."""
    out = []
    for p in range(st.ny):
        for side, n, c, K in st.coefs:
            out.append(f"{side}{n}[{p},{c}].re0")
            for k in range(1, K + 1):
                out += [f"{side}{n}[{p},{c}].re{k}", f"{side}{n}[{p},{c}].im{k}"]
    return out


def test_the_default_fits_the_transient_on_the_record_s_noise_only():
    pairs = _experiments(3)
    kw = dict(na=2, nb=0, ka=[1, 0, 0], kb=0, w0=mx.W0, lines=np.arange(2, 16))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sample = lptv.identify(pairs, noise="sample", **kw)
        full = lptv.identify(pairs, noise="full", **kw)
        off = lptv.identify(pairs, noise="full", transient=False, **kw)
    assert sample.transient is None and off.transient is None
    assert full.transient.shape == (2, 2, 2) and full.transient_powers == (0, 1)
    assert "transient term fitted" in full.summary() and "transient" not in sample.summary()


def test_bad_values_are_refused_naming_the_argument():
    pairs = _experiments(4)
    kw = dict(na=2, nb=0, ka=[1, 0, 0], kb=0, w0=mx.W0, lines=np.arange(2, 16))
    for bad in ("yes", 1.5, None, "True"):
        with pytest.raises(ValueError, match="transient must be 'auto', True or False"):
            lptv.identify(pairs, transient=bad, **kw)
    u, y = pairs[0][0][..., 0], pairs[0][1][..., 0]
    with pytest.raises(ValueError, match=r"transient=True is not built for one input and one output.*\(P, N, 1\)"):
        lptv.identify(u, y, na=2, nb=0, w0=mx.W0, transient=True)
    with pytest.raises(ValueError, match="transient: na = nb = 0"):
        lptv.identify(pairs, na=0, nb=0, w0=mx.W0, lines=np.arange(2, 16), transient=True)
