"""Noise that passes through the system (METHOD.md section 20): the statistics from the whole
record against sums written out here, the test for correlated lines (its size on white noise, its
power on a rig with a disturbance), and fits of that rig simulated by solve_ivp (process_rig.py)
in open loop and under feedback."""
import functools
import warnings

import numpy as np
import pytest

import lptv
from lptv import correlated_lines

import process_rig as rig


def record_reference(u, y):
    """(varU, varY, covYU) of lines 1 .. last from the record's DFT by NumPy's full FFT."""
    P, N = u.shape
    Ur = np.fft.fft(u.reshape(-1)) / (P * N)
    Yr = np.fft.fft(y.reshape(-1)) / (P * N)
    last = N // 2 - 1 if N % 2 == 0 else N // 2
    qs = [q for q in range(-((P + 1) // 2) + 1, P // 2 + 1) if q != 0]
    out = []
    for l in range(1, last + 1):
        b = [l * P + q for q in qs]
        out.append((np.mean(abs(Ur[b]) ** 2), np.mean(abs(Yr[b]) ** 2), np.mean(Yr[b] * np.conj(Ur[b]))))
    return np.array(out).T, last


@pytest.mark.parametrize("P,N,seed", [(2, 32, 0), (3, 33, 1), (4, 64, 2), (8, 64, 3), (7, 31, 4)])
def test_record_statistics_are_the_bins_between_the_lines(P, N, seed):
    rng = np.random.default_rng(seed)
    t = np.arange(P * N)
    walk = np.cumsum(rng.standard_normal(P * N)) * 0.02          # a response that does not repeat
    u = (np.cos(2 * np.pi * 3 * t / N) + 0.1 * rng.standard_normal(P * N)).reshape(P, N)
    y = (np.sin(2 * np.pi * 3 * t / N) + 0.1 * rng.standard_normal(P * N) + walk).reshape(P, N)
    d = lptv.FrequencyData.from_periods(u, y, w0=1.0, statistics="record")
    dp = lptv.FrequencyData.from_periods(u, y, w0=1.0)
    (vu, vy, cyu), last = record_reference(u, y)
    scale = d.varY.max()
    np.testing.assert_allclose(d.varU[1:last + 1], vu, rtol=1e-10, atol=1e-14 * scale)
    np.testing.assert_allclose(d.varY[1:last + 1], vy, rtol=1e-10, atol=1e-14 * scale)
    np.testing.assert_allclose(d.covYU[1:last + 1], cyu, rtol=1e-10, atol=1e-14 * scale)
    np.testing.assert_allclose(d.U, dp.U, rtol=0, atol=1e-14)
    for l in {0, d.max_line} - set(range(1, last + 1)):     # DC and N/2 keep the periods' statistics
        assert d.varY[l] == pytest.approx(dp.varY[l], rel=1e-12, abs=1e-300)
    nu, ny = d.noise_realisations
    assert nu.shape == (P - 1, N // 2 + 1)
    np.testing.assert_allclose((abs(ny) ** 2).sum(0), d.varY, rtol=1e-12, atol=1e-300)
    assert d.statistics == "record" and dp.statistics == "periods" and dp.noise_realisations is None


def test_record_statistics_of_white_noise_have_the_periods_distribution():
    """White noise: the bins between the lines carry the variance of the mean, sigma^2 / (P N) per
    line, with 2 (P - 1) degrees of freedom: mean and spread of var / truth as the periods'."""
    rng = np.random.default_rng(7)
    P, N, sigma = 4, 256, 0.3
    ratios, ratios_p = [], []
    for _ in range(20):
        u = rng.standard_normal((P, N)) * sigma
        y = rng.standard_normal((P, N)) * sigma
        truth = sigma ** 2 / (P * N)
        ratios.append(lptv.FrequencyData.from_periods(u, y, w0=1.0, statistics="record").varY[1:-1] / truth)
        ratios_p.append(lptv.FrequencyData.from_periods(u, y, w0=1.0).varY[1:-1] / truth)
    r, rp = np.concatenate(ratios), np.concatenate(ratios_p)
    # chi2_{2(P-1)} / (2(P-1)): mean 1, variance 1/(P-1); 2540 lines: standard error 0.011
    assert abs(r.mean() - 1) < 0.04 and abs(rp.mean() - 1) < 0.04
    assert abs(r.var() - 1 / (P - 1)) < 0.05 and abs(rp.var() - 1 / (P - 1)) < 0.05


def test_correlated_lines_size_on_white_noise():
    rng = np.random.default_rng(12)
    hits = 0
    for _ in range(200):
        u = rng.standard_normal((4, 256))
        y = np.roll(u, 2, axis=1) + 0.3 * rng.standard_normal((4, 256))
        hits += correlated_lines(lptv.FrequencyData.from_periods(u, y, w0=1.0)).correlated
    # size 1 %: 2 expected of 200; 7 or more has probability 0.005
    assert hits <= 6


def test_correlated_lines_finds_a_disturbance_through_the_rig():
    recs = rig.records(range(8), periods=8, loop="open", process=5.0)
    found = [correlated_lines(lptv.FrequencyData.from_periods(r["u"], r["y"], w0=rig.W0)) for r in recs]
    assert all(f.correlated for f in found), [f.p_value for f in found]
    assert "correlated in the output" in found[0].reason
    quiet = rig.records(range(8), periods=8, loop="open", process=0.0)
    assert sum(correlated_lines(lptv.FrequencyData.from_periods(r["u"], r["y"], w0=rig.W0)).correlated
               for r in quiet) <= 1


def fit(rec, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return lptv.identify(rec["u"], rec["y"], **rig.STRUCTURE, w0=rig.W0, lines=rig.fit_lines(), **kw)


@pytest.mark.parametrize("loop", ["open", "feedback"])
def test_the_default_keeps_the_true_structure_of_a_rig_with_a_disturbance(loop):
    """A disturbance before the time-varying dynamics (and, under feedback, back through the
    input): the periods' per-line variances make the verdict reject the true structure in most
    records (bench: 60-90 %), the default takes the record's noise and keeps it; the estimates
    lie within their intervals' reach."""
    recs = rig.records(range(100, 106), periods=8, loop=loop, process=5.0)
    truth = rig.truth()
    rejected_sample = 0
    for rec in recs:
        res = fit(rec, method="sml")
        assert res.noise in ("full", "full-moderated"), res.noise_choice
        assert "the noise of neighbouring lines is correlated in" in res.noise_choice
        assert res.model_ok, res.model_errors
        free = res.parameter_std > 0
        z = (res.eta - truth)[free] / res.parameter_std[free]
        assert np.max(np.abs(z)) < 4, z
        rejected_sample += fit(rec, method="sml", noise="sample").model_ok is False
        w = fit(rec, method="wgtls")
        assert w.model_ok, w.model_errors
    assert rejected_sample >= 2


def test_the_route_for_several_channels_and_one_agree():
    """noise='full' on (P, N, 1) arrays without the record's transient term (transient=False) is
    the one-channel fit on the record's per-line statistics (several channels do not read the
    rows on the realisations yet); by default several channels fit the transient there."""
    rec = rig.records([3], periods=8, loop="feedback", process=5.0)[0]
    d = lptv.FrequencyData.from_periods(rec["u"], rec["y"], w0=rig.W0, statistics="record")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = lptv.identify(d, **rig.STRUCTURE, lines=rig.fit_lines(), method="wgtls", noise="sample")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        many = lptv.identify(rec["u"][:, :, None], rec["y"][:, :, None], **rig.STRUCTURE, w0=rig.W0,
                             lines=rig.fit_lines(), method="wgtls", noise="full", transient=False)
        auto = lptv.identify(rec["u"][:, :, None], rec["y"][:, :, None], **rig.STRUCTURE, w0=rig.W0,
                             lines=rig.fit_lines(), method="wgtls")
    assert many.noise == "full" and auto.noise.startswith("full")
    assert many.transient is None and auto.transient.shape == (1, 1, 2)
    np.testing.assert_allclose(many.eta, one.eta, rtol=1e-7, atol=1e-9 * np.abs(one.eta).max())


def test_full_route_errors_name_what_is_wrong():
    rng = np.random.default_rng(0)
    u0 = rng.standard_normal(64)                 # one period, repeated: a periodic input
    u = u0 + 0.01 * rng.standard_normal((4, 64))
    y = 0.5 * u0 + np.roll(u0, 1) + 0.01 * rng.standard_normal((4, 64))
    d = lptv.FrequencyData.from_periods(u, y, w0=1.0)
    given = lptv.FrequencyData(d.U, d.Y, d.varU, d.varY, d.covYU, w0=1.0, periods=4)
    with pytest.raises(ValueError, match="noise='full' takes the noise from the whole record: u: .*from_periods"):
        lptv.identify(given, na=1, nb=0, noise="full")
    with pytest.raises(ValueError, match="statistics must be 'periods' or 'record'"):
        lptv.FrequencyData.from_periods(u, y, w0=1.0, statistics="lines")
    with pytest.raises(ValueError, match="from_periods"):
        correlated_lines(given)
    with pytest.raises(ValueError, match="noise must be one of"):
        lptv.identify(u, y, na=1, nb=0, w0=1.0, noise="record")
    with pytest.raises(ValueError, match="full-rows.*one input and one output"):
        lptv.identify(u[:, :, None], y[:, :, None], na=1, nb=0, w0=1.0, noise="full-rows")
    with pytest.raises(ValueError, match="noise='full-moderated' is not for covariance='bootstrap'"):
        lptv.identify(u, y, na=1, nb=0, w0=1.0, noise="full-moderated", covariance="bootstrap")
    # data given without the periods: noise='auto' stays on the given statistics
    res = lptv.identify(given, na=1, nb=0)
    assert res.noise in ("sample", "moderated")


# -- the rows' noise from the realisations (METHOD.md section 20), the core against NumPy -------

from lptv import _core  # noqa: E402
from lptv.reference import likelihood as lk  # noqa: E402

from test_likelihood_core import core_data, core_par  # noqa: E402
from test_likelihood_reference import SEEDS, make_case, random_data, rows_of  # noqa: E402


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("domain", ["ct", "dt"])
def test_the_row_scaled_likelihood_against_dense_sums(seed, domain):
    """S = D S_line D (D fixed): the core's cost against r^T (D S D)^-1 r of the dense reference,
    its gradient against central differences of that cost (the core's gradient is exact for a
    fixed D), the residue covariance against D S D."""
    case = make_case(seed, domain, False)
    rng = np.random.default_rng([seed, 20])
    d, rows = random_data(rng, case.L), [int(r) for r in rows_of(case, "default")]
    lik = _core.ExactLikelihood(core_data(d), core_par(case), rows)
    scale = rng.uniform(0.6, 1.4, len(rows))
    lik.set_row_scale(scale)
    srt = np.sort(rows)
    Ds = np.repeat(scale[np.argsort(rows)], 2)

    def ref_cost(xi):
        th = case.par.Text @ xi
        M = lk.residue_map(d, case.par, srt, th)
        S = Ds[:, None] * lk.residue_covariance(d, case.par, srt, th) * Ds[None, :]
        r = M @ lk.data_vector(d)
        return float(r @ np.linalg.solve(S, r))

    xi0 = np.linalg.lstsq(case.par.Text, case.theta, rcond=None)[0].real
    for xi in (xi0, xi0 + 0.05 * rng.normal(size=xi0.size)):
        th = case.par.Text @ xi
        v = lik.cost(th)
        assert abs(v - ref_cost(xi)) <= 1e-10 * ref_cost(xi)
        g = np.asarray(lik.gradient(th))
        h = 1e-6 * max(1.0, np.abs(xi).max())
        g_fd = np.array([(ref_cost(xi + h * e) - ref_cost(xi - h * e)) / (2 * h) for e in np.eye(xi.size)])
        # central differences: truncation h^2 |V'''| and rounding eps V / h, ~1e-7 of the gradient here
        assert np.max(np.abs(g - g_fd)) <= 1e-5 * np.max(np.abs(g_fd))
        S_ref = Ds[:, None] * lk.residue_covariance(d, case.par, srt, th) * Ds[None, :]
        np.testing.assert_allclose(np.asarray(lik.residue_covariance(th)), S_ref, rtol=0,
                                   atol=1e-11 * np.abs(S_ref).max())
    lik.set_row_scale(np.ones(len(rows)))          # D = I is the likelihood without a scale
    plain = _core.ExactLikelihood(core_data(d), core_par(case), rows)
    assert lik.cost(case.theta) == pytest.approx(plain.cost(case.theta), rel=1e-14)
    with pytest.raises(ValueError, match="scale must"):
        lik.set_row_scale(-scale)


def record_rows(u, y, par, rows, theta, a, b, K, w0):
    """The rows' realisations by NumPy's FFT of the record: e_{l,q} at the bins l P + q with the
    structure's powers at each bin's own frequency; a, b the model's (n, 2K+1) harmonic rows."""
    P, N = u.shape
    Ur = np.fft.fft(u.reshape(-1)) / (P * N)
    Yr = np.fft.fft(y.reshape(-1)) / (P * N)
    qs = [q for q in range(-((P + 1) // 2) + 1, P // 2 + 1) if q != 0]
    out = []
    for l in rows:
        es = []
        for q in qs:
            bin_ = l * P + q
            e = 0
            for k in range(-K, K + 1):
                s = 1j * w0 * (bin_ - k * P) / P
                e += sum(a[n, K + k] * s ** n for n in range(a.shape[0])) * Yr[bin_ - k * P]
                e -= sum(b[m, K + k] * s ** m for m in range(b.shape[0])) * Ur[bin_ - k * P]
            es.append(e)
        out.append(np.array(es) / np.sqrt(P - 1))
    return np.array(out)


@pytest.mark.parametrize("loop", ["open", "feedback"])
def test_the_rows_noise_from_the_realisations_against_the_record_s_bins(loop):
    rec = rig.records([21], periods=8, loop=loop, process=5.0)[0]
    u, y = rec["u"], rec["y"]
    d = lptv.FrequencyData.from_periods(u, y, w0=rig.W0, statistics="record")
    res = fit(rec, method="wgtls", noise="full-rows")
    assert res.noise == "full-rows"
    K = 1
    rows = [int(l) for l in rig.fit_lines()]
    par = _core.Parametrisation(_core.Structure(2, 0, [1, 0, 0], [0], [], rig.W0, 0.0))
    e = record_rows(u, y, par, rows, res.theta, *coefficient_rows(par, res.theta, K), K, rig.W0)
    v_ref = np.sum(np.abs(e) ** 2, axis=1)
    v = np.asarray(_core.full_residue_variance(d._cpp, par, rows, res.theta))
    # sums of 7 squares of sums of 9 products: rounding ~1e-15 relative
    np.testing.assert_allclose(v, v_ref, rtol=1e-12)
    # the fit weighs by eq. 15 times the ratio of the realisations' variances to eq. 15's pooled
    # over the rows within +-3 lines (METHOD.md section 20)
    line = np.asarray(_core.residue_variance(d._cpp, par, rows, res.theta))
    r_ = np.asarray(rows)
    pooled = np.array([v_ref[np.abs(r_ - l) <= 3].sum() / line[np.abs(r_ - l) <= 3].sum() for l in r_])
    np.testing.assert_allclose(np.asarray(_core.row_noise_scale(d._cpp, par, rows, res.theta)) ** 2, pooled,
                               rtol=1e-12)
    np.testing.assert_allclose(res.residue_variance, line * pooled, rtol=1e-12)
    # CJ_W from the realisations: Re(T^H sum_l w_l Phi_l^H Phi_l T), whose quadratic form at any
    # xi is the weighted noise of the rows at theta = T xi: sum_l w_l var e_l(theta); random xi
    # (as many as CJ has entries) pin the whole symmetric matrix
    w = 1.0 / v_ref
    CJ = np.asarray(_core.full_real_column_covariance(d._cpp, par, rows, w))
    assert CJ.shape == (par.n_xi, par.n_xi) and np.allclose(CJ, CJ.T, rtol=0, atol=1e-14 * np.abs(CJ).max())
    g = np.random.default_rng(3)
    for _ in range(par.n_xi * (par.n_xi + 1) // 2):
        xi = g.normal(size=par.n_xi)
        th = np.asarray(par.Text) @ xi          # theta = Text xi (no normalisation)
        e = record_rows(u, y, par, rows, th, *coefficient_rows(par, th, K), K, rig.W0)
        assert xi @ CJ @ xi == pytest.approx(np.sum(w * np.sum(np.abs(e) ** 2, axis=1)), rel=1e-10)


def coefficient_rows(par, theta, K):
    """(a, b): the (n, 2K + 1) harmonic rows of a model's coefficients from theta."""
    m = lptv.Model._from_core(par.to_model(theta))
    a = np.zeros((m.a.shape[0], 2 * K + 1), complex)
    ka = m.a.shape[1] // 2
    a[:, K - ka:K + ka + 1] = m.a
    b = np.zeros((m.b.shape[0], 2 * K + 1), complex)
    kb = m.b.shape[1] // 2
    b[:, K - kb:K + kb + 1] = m.b
    return a, b


def _loop_csv(tmp_path, seed=7):
    rec = rig.records([seed], periods=16, loop="feedback", process=5.0, skip=0)[0]
    u, y = rec["u"].ravel(), rec["y"].ravel()
    t = np.arange(u.size) / rig.FS
    lines, amp, ph = rig.reference(0)
    r = np.cos(np.outer(t, lines * rig.W0) + ph) @ amp
    path = tmp_path / "loop.csv"
    np.savetxt(path, np.c_[t, r, u, y], delimiter=",", comments="",
               header="time [s],reference [N],force [N],displacement [m]")
    return path, (r, u, y)


def test_identify_reads_the_period_of_a_closed_loop_file(tmp_path, capsys):
    """Under feedback the input holds the loop's response to the disturbance, which repeats better
    at twice the period than white noise's deviations allow (section 18's rule (a) took 8 s for
    the rig's 4 s here before the multiple had to show lines off the period's grid): the period
    check accepts --period 4 from the input alone, and from a recorded reference column."""
    from lptv.apps import cli

    path, _ = _loop_csv(tmp_path)
    args = [str(path), "--input", "force", "--output", "displacement", "--period", "4", "--skip-periods", "6",
            "--lines", "excited", "--na", "2", "--nb", "0", "--ka", "1,0,0", "--kb", "0", "--no-report"]
    for extra, name in (((), "a"), (("--reference", "reference"), "b")):
        rc = cli.main(["identify", *args, *extra, "--out", str(tmp_path / name)])
        out = capsys.readouterr().out
        assert rc == 0, out
        assert "the model is consistent with the noise" in out and "from the whole record" in out



def test_inspect_reads_the_period_from_a_reference_column(tmp_path, capsys):
    """lptv inspect on the closed-loop record: --reference reads the period where the reference
    repeats, judges the rest on the input, and suggests a command that carries --reference,
    which fits the true structure as consistent; the input alone reads the same 4 s."""
    import shlex

    from lptv.apps import cli

    path, (r, u, y) = _loop_csv(tmp_path)
    base = ["inspect", str(path), "--input", "force", "--output", "displacement"]
    assert cli.main([*base, "--out", str(tmp_path / "i0")]) == 0
    out = capsys.readouterr().out
    assert "--period 4 " in out, out
    assert cli.main([*base, "--reference", "reference", "--out", str(tmp_path / "i1")]) == 0
    out = capsys.readouterr().out
    assert "reference 'reference [N]'" in out and "repeats every 4.00 s" in out, out
    assert "under feedback" in out
    cmd = next(ln for ln in out.splitlines() if ln.startswith("suggested:")).split(":", 1)[1].split()
    assert "--period" in cmd and cmd[cmd.index("--period") + 1] == "4"
    assert " ".join(cmd[cmd.index("--reference") + 1:][:2]) == "'reference [N]'"
    # the same in Python, from the samples: the period of the reference, the excitation of the input
    fs = rig.FS
    a = lptv.inspect(u=u, y=y, fs=fs)
    b = lptv.inspect(u=u, y=y, fs=fs, reference=r)
    assert a.period == pytest.approx(4.0) and b.period == pytest.approx(4.0)
    assert b.reference == "reference" and b.input_repeat_ratio > b.repeat_ratio
    assert b.transient_periods >= 1 and set(rig.reference(0)[0]) <= set(b.lines.tolist())
    # the suggested command, with the orders filled in, fits the true structure as consistent
    line = " ".join(cmd).replace("NA", "2").replace("NB", "0")
    args = shlex.split(line)[2:]
    ka = args.index("--ka")
    args[ka + 1:ka + 2] = ["1,0,0"]
    kb = args.index("--kb")
    args[kb + 1] = "0"
    rc = cli.main(["identify", *args, "--no-report", "--out", str(tmp_path / "fit")])
    out = capsys.readouterr().out
    assert rc == 0 and "the model is consistent with the noise" in out, out


def test_inspect_reference_refusals(tmp_path):
    path, (r, u, y) = _loop_csv(tmp_path)
    with pytest.raises(ValueError, match="reference"):
        lptv.inspect(path, u="force", y="displacement", reference="nope")
    with pytest.raises(ValueError, match="reference must have as many samples"):
        lptv.inspect(u=u, y=y, fs=rig.FS, reference=r[:-3])
    with pytest.raises(ValueError, match="reference.*constant"):
        lptv.inspect(u=u, y=y, fs=rig.FS, reference=np.ones_like(r))
    with pytest.raises(ValueError, match="reference must be the name"):
        lptv.inspect(path, u="force", y="displacement", reference=r)


@functools.lru_cache(maxsize=None)
def _closed_loop_records(skip):
    """The closed-loop rig's records of seeds 0..4, 16 periods after ``skip``, integrated in one
    solve_ivp call (each seed's record is the one rig.records([seed], ...) gives, to the
    integrator's tolerance)."""
    return rig.records(range(5), periods=16, loop="feedback", process=5.0, skip=skip)


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("skip", [0, 8])
def test_the_period_of_a_closed_loop_record_from_its_input(seed, skip):
    """The input of the closed-loop rig repeats every 4 s; its non-repeating part, the loop's
    coloured response to the disturbance, repeated better at 8 s than white noise allows in 3 of
    these 5 records (and the output at 8, 12 or 20 s): a multiple is the period only where it
    shows lines off the shorter period's grid above their own noise. (The output's multiple, judged
    on 2 of its periods too, still reads 20 s in 2 of 80 such records, seed 1 from steady state
    among them: not asserted here; METHOD.md section 18.)"""
    rec = _closed_loop_records(skip)[seed]
    r = lptv.inspect(u=rec["u"].ravel(), y=rec["y"].ravel(), fs=rig.FS)
    assert r.input_period_samples == 4 * rig.FS
