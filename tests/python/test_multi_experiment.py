"""Several experiments of one system in one fit (METHOD.md section 14): lptv.identify on a list
against the NumPy reference (stacked rows, summed column covariance, block-diagonal S), a
duplicated experiment, experiments that identify the model only together, the Cramer-Rao bound
of several experiments, errors for experiments that disagree, and ``lptv identify --joint``.
"""
import functools
import json
import subprocess
import sys
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.stats

import lptv
from lptv.reference import fds
from lptv.reference import identification as ref
from lptv.reference import likelihood as lk
from conftest import _coefficient_row

SEEDS = [0, 1, 2]
TOL, MAX_ITER = 1e-12, 200
# The SML estimates of both routes stop within 1e-13 (reference) and a relative step of 1e-13
# (core) of the same stationary point; where V is flat the point is fixed only to ~sqrt(eps)
# cond: the 1e-8 of tests/python/test_likelihood_core.py.
SML_ESTIMATE = 1e-8
# Covariances at estimates that agree to SML_ESTIMATE (WGTLS: to id_tol.ESTIMATE): the
# information is a smooth function of theta and of the denoised data, with relative
# sensitivity ~ cond(F) <= 1e3 on these problems, so 1e-8 * 1e3 = 1e-5 at most.
COVARIANCE = 1e-5


def rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b)


# ------------------------------------------------------------------------------- test systems

@functools.lru_cache(maxsize=None)
def system(seed, domain, lti):
    """na = 2, nb = 1; LPTV: harmonic counts a permutation of 0, 1, 2 on a_0..a_2 and of 1, 2 on
    b_0, b_1 (K = 2). Continuous time: w0 in [0.1, 0.2] rad/s, poles near 1 rad/s; discrete time:
    N = 63 samples per period (ts = 1), poles at radius 0.5-0.8. Each coefficient within 20 % of
    its mean."""
    rng = np.random.default_rng([seed, domain == "dt", lti, 41])
    ka = [0, 0, 0] if lti else [int(v) for v in rng.permutation([0, 1, 2])]
    kb = [0, 0] if lti else [int(v) for v in rng.permutation([1, 2])]
    if domain == "ct":
        w0, ts = float(rng.uniform(0.1, 0.2)), 0.0
        wn, zeta = rng.uniform(0.8, 1.5), rng.uniform(0.2, 0.5)
        a_dc, b_dc = [wn ** 2, 2 * zeta * wn, 1.0], [rng.uniform(0.5, 2.0), 1.0]
    else:
        w0, ts = 2 * np.pi / 63, 1.0
        r, phi = rng.uniform(0.5, 0.8), rng.uniform(0.2, 1.0)
        a_dc, b_dc = [r * r, -2 * r * np.cos(phi), 1.0], [rng.uniform(-0.5, 0.5), 1.0]
    g = rng.uniform(0.5, 2.0)
    a = [_coefficient_row(rng, c, K, 0.2) for c, K in zip(a_dc, ka)]
    b = [_coefficient_row(rng, g * c, K, 0.2) for c, K in zip(b_dc, kb)]
    pad = lambda row, K: np.pad(row, K - (row.size - 1) // 2)
    A = np.array([pad(x, max(ka)) for x in a])
    B = np.array([pad(x, max(kb)) for x in b])
    model = lptv.Model(A, B, w0=w0, ts=ts if ts else None)
    par = ref.Parametrisation(2, 1, ka, kb, (), w0, ts)
    return SimpleNamespace(model=model, par=par, ka=ka, kb=kb, w0=w0, ts=ts if ts else None,
                           theta=ref.theta_of_coefficients(par, A, B))


def periods(sys_, N, P, excited, rng, snr_u=40.0, snr_y=30.0):
    """P noisy periods of N samples under a unit multisine on the excited lines (random phases);
    white noise, correlated 0.6 between input and output. Spectra from the dense reference FDS."""
    L = N // 2
    U0 = np.zeros(L + 1, complex)
    U0[excited] = np.exp(2j * np.pi * rng.uniform(size=len(excited)))
    Y0 = fds.simulate(sys_.model, U0, guard=60, lines_out=L)
    u0, y0 = fds.time_signal(U0, N), fds.time_signal(Y0, N)
    su, sy = 10 ** (-snr_u / 20) * np.std(u0), 10 ** (-snr_y / 20) * np.std(y0)
    nu = rng.standard_normal((P, N))
    ny = 0.6 * nu + 0.8 * rng.standard_normal((P, N))
    return u0 + su * nu, y0 + sy * ny


def three_experiments(seed, domain, lti):
    """Three records of one system: different multisines (low lines, high lines, every third),
    different P and (continuous time) different N; discrete time keeps N = 63 (one ts)."""
    s = system(seed, domain, lti)
    rng = np.random.default_rng([seed, 77, domain == "dt", lti])
    Ns = (63, 95, 47) if domain == "ct" else (63, 63, 63)
    excited = (np.arange(1, 16), np.arange(12, 40) if domain == "ct" else np.arange(12, 30),
               np.arange(2, 22, 3))
    Ps = (5, 8, 6)
    recs = [periods(s, N, P, ex, rng) for N, P, ex in zip(Ns, Ps, excited)]
    return s, recs, excited


# ----------------------------------------------------------------- core against the reference

case_params = pytest.mark.parametrize(
    "seed,domain,lti", [(s, d, l) for s in SEEDS for d in ("ct", "dt") for l in (False, True)],
    ids=lambda v: str(v) if not isinstance(v, bool) else ("lti" if v else "lptv"))


def _fit(s, recs, method, lines):
    return lptv.identify(recs, na=2, nb=1, ka=s.ka, kb=s.kb, w0=s.w0, ts=s.ts, method=method,
                         lines=lines, tol=TOL, max_iter=MAX_ITER)


def _reference_rows(s, datas, excited):
    """Rows of the three experiments: the default rows, every second usable row, and the
    excited lines +-K within the usable rows (computed here from the design)."""
    K = s.par.K
    d0 = ref.default_rows(s.par, datas[0].max_line)
    d1 = ref.default_rows(s.par, datas[1].max_line)[::2]
    ex = np.unique((np.asarray(excited[2])[:, None] + np.arange(-K, K + 1)).ravel())
    d2 = ex[(ex >= K + 1) & (ex <= datas[2].max_line - K)]
    return [d0, d1, d2]


@case_params
@pytest.mark.parametrize("method", ["ls", "tls", "gtls", "wgtls"])
def test_estimators_match_reference(seed, domain, lti, method, id_tol):
    s, recs, excited = three_experiments(seed, domain, lti)
    datas = [ref.frequency_data(u, y) for u, y in recs]
    rows = _reference_rows(s, datas, excited)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # e.g. close singular values of unweighted GTLS
        res = _fit(s, recs, method, [None, rows[1], "excited"])
    assert res.n_experiments == 3
    assert np.array_equal(res.lines, np.concatenate(rows))
    assert np.array_equal(res.experiment, np.repeat([0, 1, 2], [r.size for r in rows]))
    rr = ref.estimate_experiments(datas, s.par, rows, method, tol=TOL, max_iter=MAX_ITER)
    assert rel(res.theta, rr["theta"]) <= id_tol.ESTIMATE
    assert rel(res.eta, rr["eta"]) <= id_tol.ESTIMATE
    assert abs(res.cost - rr["cost"]) <= id_tol.ESTIMATE * rr["cost"]
    sv = np.asarray(res.singular_values)
    assert sv.shape == np.shape(rr["singular_values"])
    assert np.all(np.abs(sv - rr["singular_values"]) <= id_tol.ESTIMATE * np.asarray(rr["singular_values"]))
    # Residues over all rows, each experiment's from its own data.
    e = np.concatenate([ref.residue(d, s.par, r, rr["theta"]) for d, r in zip(datas, rows)])
    v = np.concatenate([ref.residue_variance(d, s.par, r, rr["theta"]) for d, r in zip(datas, rows)])
    scale = np.concatenate([np.abs(ref.jacobian(d, s.par, r)) @ np.abs(rr["theta"]) for d, r in zip(datas, rows)])
    assert np.all(np.abs(res.residue - e) <= id_tol.ESTIMATE * scale)
    assert np.all(np.abs(res.residue_variance - v) <= id_tol.ESTIMATE * v)
    # P = 5, 8, 6: each row's expected fraction above 0 dB for its own P, averaged over the rows.
    n_rows = sum(r.size for r in rows)
    p = [ref.expected_fraction_above_0db(n_rows, s.par.n_xi - 1, d.periods) for d in datas]
    expected = sum(pe * r.size for pe, r in zip(p, rows)) / n_rows
    assert res.fraction_expected == pytest.approx(expected, rel=id_tol.FRACTION, abs=0)
    assert res.fraction_above_0db == np.mean(np.abs(e) / np.sqrt(v) > 1.0)
    if method == "wgtls":
        assert res.converged and rr["converged"] and res.iterations == rr["iterations"]
        assert rel(res.theta, s.theta) < 0.1  # consistent: near the truth at this SNR
        # The covariance: the sandwich summed over experiments, each meat with its own
        # (P-1)/(P-3) (P = 5, 8, 6 differ), at the denoised data of the reference; the
        # second-order terms with the same factors, summed before they combine (one lambda).
        w = 1.0 / np.maximum(v, ref.VARIANCE_FLOOR * v.max())
        bread, meat, at, second = 0.0, 0.0, 0, None
        for d, r in zip(datas, rows):
            c = (d.periods - 1) / (d.periods - 3)
            H, Mt = lk.sandwich_terms(d, s.par, r, rr["theta"], w[at:at + r.size])
            t = lk.second_order_terms(d, s.par, r, rr["theta"], w[at:at + r.size])
            t = dict(qq=c * t["qq"], qr=c * t["qr"], rr=c * t["rr"], cj=t["cj"])
            second = t if second is None else {k: second[k] + t[k] for k in t}
            bread, meat, at = bread + H, meat + c * Mt, at + r.size
        meat = meat + lk.second_order_meat(second, s.par, rr["theta"])
        Hinv = np.linalg.inv(bread)
        cov = lk._eta_covariance(s.par, Hinv @ meat @ Hinv)
        assert rel(res.covariance, cov) <= COVARIANCE


@pytest.mark.parametrize("seed,domain,lti", [(s, d, l) for s in SEEDS[:2] for d in ("ct", "dt")
                                             for l in (False, True)],
                         ids=lambda v: str(v) if not isinstance(v, bool) else ("lti" if v else "lptv"))
def test_sml_matches_reference(seed, domain, lti):
    s, recs, excited = three_experiments(seed, domain, lti)
    datas = [ref.frequency_data(u, y) for u, y in recs]
    rows = _reference_rows(s, datas, excited)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # e.g. close singular values of unweighted GTLS
        res = _fit(s, recs, "sml", [None, rows[1], "excited"])
    start = ref.estimate_experiments(datas, s.par, rows, "wgtls", tol=TOL, max_iter=MAX_ITER)["theta"]
    fit = lk.sml_estimate_experiments(datas, s.par, rows, start)
    assert fit["converged"] and res.converged
    assert rel(res.theta, fit["theta"]) <= SML_ESTIMATE
    V = lk.exact_cost_experiments(datas, s.par, rows, fit["theta"])
    n_rows = sum(r.size for r in rows)
    assert res.cost == pytest.approx(V / (2 * n_rows), rel=1e-9)
    # The joint minimum lies below each experiment's cost at the other experiments' optimum:
    # the cost really is the sum (a fit to experiment 0 alone has a larger total).
    alone = lk.sml_estimate_experiments(datas[:1], s.par, rows[:1], start)
    assert V < lk.exact_cost_experiments(datas, s.par, rows, alone["theta"])
    # Covariance: informations at the denoised data of each experiment, each with its own
    # (P-1)/(P-3), in the sandwich H^-1 (sum c_e F_e) H^-1, H = sum F_e.
    F = [lk.fisher_information(lk.denoised(d, s.par, r, fit["theta"]), s.par, r, fit["theta"])
         for d, r in zip(datas, rows)]
    c = [(d.periods - 1) / (d.periods - 3) for d in datas]
    Hinv = np.linalg.inv(sum(F))
    cov = lk._eta_covariance(s.par, Hinv @ sum(ce * Fe for ce, Fe in zip(c, F)) @ Hinv)
    assert rel(res.covariance, cov) <= COVARIANCE


# ------------------------------------------------------------------ a duplicated experiment

@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("method", ["wgtls", "sml"])
def test_duplicated_experiment_halves_the_covariance(seed, domain, method):
    """The same data twice: every term of the cost doubles, so the estimate is the single one and
    the information doubles (the covariance halves); the P of both is the same."""
    s, recs, _ = three_experiments(seed, domain, False)
    u, y = recs[1]
    one = _fit(s, [(u, y)], method, None)  # a one-element list
    single = lptv.identify(u, y, na=2, nb=1, ka=s.ka, kb=s.kb, w0=s.w0, ts=s.ts, method=method,
                           tol=TOL, max_iter=MAX_ITER)
    assert np.array_equal(one.theta, single.theta) and np.array_equal(one.covariance, single.covariance)
    with pytest.warns(UserWarning, match=r"experiments\[0\] and experiments\[1\] hold the same data"):
        two = _fit(s, [(u, y), (u, y)], method, None)
    assert two.n_experiments == 2 and two.lines.size == 2 * single.lines.size
    # WGTLS: the same GSVD problem (R factors of the stacked rows agree to rounding);
    # SML: both stop within the step rule of the same stationary point.
    assert rel(two.theta, single.theta) <= (1e-10 if method == "wgtls" else SML_ESTIMATE)
    assert rel(2 * two.covariance, single.covariance) <= COVARIANCE
    assert two.cost == pytest.approx(single.cost, rel=1e-8)
    assert two.fraction_above_0db == single.fraction_above_0db


# -------------------------------------------------------- identifiable together, not alone

@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("method", ["wgtls", "sml"])
def test_experiments_identify_together_what_neither_does_alone(seed, method):
    """An LPTV model with K = 1 on every coefficient: 14 free parameters. Each experiment excites
    two lines, i.e. 6 rows (the excited lines +-1) and 12 real equations: too few alone. The two
    together (12 rows, different N and P) identify it, and the truth lies within the joint
    covariance: (eta - eta0)^T C^-1 (eta - eta0) below the chi2(14) 99.9 % quantile."""
    model = lptv.Model([[0.1 - 0.05j, 1.0, 0.1 + 0.05j], [-0.05 - 0.02j, 0.8, -0.05 + 0.02j], [0, 1.0, 0]],
                       [[0.08 + 0.03j, 1.0, 0.08 - 0.03j], [0, 0.5, 0]], w0=0.1)
    s = SimpleNamespace(model=model)
    rng = np.random.default_rng([seed, 99])
    a = periods(s, 127, 8, [5, 12], rng, snr_u=50, snr_y=40)
    b = periods(s, 191, 6, [20, 27], rng, snr_u=50, snr_y=40)
    kw = dict(na=2, nb=1, ka=1, kb=1, w0=0.1, method=method, lines="excited")
    for u, y in (a, b):
        with pytest.raises(ValueError, match="free parameters"):
            lptv.identify(u, y, **kw)
    res = lptv.identify([a, b], **kw)
    assert np.array_equal(res.lines, [4, 5, 6, 11, 12, 13, 19, 20, 21, 26, 27, 28])
    par = ref.Parametrisation(2, 1, [1] * 3, [1] * 2)
    xi0 = lk.xi_of_theta(par, ref.theta_of_coefficients(par, model.a, model.b))
    eta0 = (xi0 / xi0[par.norm_index])[:par.n_eta]
    free = np.diag(res.covariance) > 0
    d = (res.eta - eta0)[free]
    stat = d @ np.linalg.solve(res.covariance[np.ix_(free, free)], d)
    assert stat < scipy.stats.chi2.ppf(0.999, free.sum())
    assert res.model_ok


def test_bode_of_several_experiments_draws_each_record_on_its_excited_lines():
    """The joint fit's Bode plot: one set of measured points per record, at that record's excited
    lines (its own Y / U), and the joint model's curve."""
    pytest.importorskip("matplotlib")
    from lptv import plots

    s = system(1, "ct", True)
    rng = np.random.default_rng(7)
    a, b = periods(s, 63, 6, np.arange(1, 12), rng), periods(s, 95, 8, np.arange(10, 40), rng)
    res = lptv.identify([a, b], na=2, nb=1, w0=s.w0, method="wgtls")
    ax_m = plots.bode(res).axes[0]
    pts = {c.get_label(): c for c in ax_m.containers}
    assert sorted(pts) == ["experiment 0 Y/U (+-2 std)", "experiment 1 Y/U (+-2 std)"]
    for e, (u, y) in enumerate((a, b)):
        d = lptv.FrequencyData.from_periods(u, y, w0=s.w0)
        rows = res.lines[res.verdict_mask & (res.experiment == e)]
        x, ydb = pts[f"experiment {e} Y/U (+-2 std)"].lines[0].get_data()
        assert np.allclose(x, rows * s.w0)
        assert np.allclose(ydb, 20 * np.log10(np.abs(d.Y[rows] / d.U[rows])))


def test_bode_of_an_lptv_fit_draws_the_excited_lines_only():
    """An LPTV fit's verdict rows hold the +-K sidebands of the excited lines, where the input is
    noise: the measured FRF Y / U is drawn on the excited lines alone (one data set and several)."""
    pytest.importorskip("matplotlib")
    from lptv import plots
    from lptv.examples import paper_measurements

    m = paper_measurements(seed=3, periods=4)
    excited = np.arange(10, 241, 10)
    one = lptv.identify(m["u"], m["y"], na=2, nb=1, ka=3, kb=3, w0=m["w0"], lines=range(1, 244))
    both = lptv.identify([(m["u"], m["y"]), (m["u"][:3], m["y"][:3])], na=2, nb=1, ka=3, kb=3, w0=m["w0"],
                         lines=[range(1, 244)] * 2)
    for res in (one, both):
        assert np.setdiff1d(res.verdict_lines, excited).size > 0     # the sidebands are verdict rows
        for c in plots.bode(res).axes[0].containers:
            x, _ = c.lines[0].get_data()
            assert np.array_equal(np.round(x / m["w0"]).astype(int), excited)


# ------------------------------------------------------------------ Cramer-Rao bound, several

@pytest.mark.parametrize("domain", ["ct", "dt"])
@pytest.mark.parametrize("lti", [False, True], ids=["lptv", "lti"])
def test_crb_of_several_experiments_matches_reference(domain, lti):
    s = system(0, domain, lti)
    rng = np.random.default_rng(5)
    Ls = (31, 47) if domain == "ct" else (31, 31)
    Us = []
    for L in Ls:
        U = np.zeros(L + 1, complex)
        U[1:L] = np.exp(2j * np.pi * rng.uniform(size=L - 1))
        Us.append(U)
    vy, vu, P = [1e-3, 4e-3], [1e-4, 2e-4], [4, 9]
    b = lptv.crb(s.model, Us, var_y=vy, var_u=vu, periods=P, ka=s.ka, kb=s.kb)
    datas = []
    for U, y_, u_, p_ in zip(Us, vy, vu, P):
        Y = fds.simulate(s.model, U, guard=60, lines_out=U.size - 1)
        n = U.size
        datas.append(ref.Data(U=U, Y=Y, varU=np.full(n, u_ / p_), varY=np.full(n, y_ / p_),
                              covYU=np.zeros(n, complex)))
    rows = [ref.default_rows(s.par, d.max_line) for d in datas]
    cov = lk.crb_experiments(datas, s.par, rows, s.theta / s.theta[s.par.theta_index(True, 2, 0)])
    assert rel(b.covariance, cov) <= 1e-8
    assert np.array_equal(b.lines, np.concatenate(rows))
    assert np.array_equal(b.experiment, np.repeat([0, 1], [r.size for r in rows]))
    # Each experiment alone has a larger bound (informations add).
    for i in range(2):
        alone = lptv.crb(s.model, Us[i], var_y=vy[i], var_u=vu[i], periods=P[i], ka=s.ka, kb=s.kb)
        assert np.all(np.diag(alone.covariance) >= np.diag(b.covariance))


# ---------------------------------------------------------------------------------- errors

def test_experiments_that_disagree_are_refused():
    s = system(0, "ct", False)
    rng = np.random.default_rng(1)
    u, y = periods(s, 63, 4, np.arange(1, 20), rng)
    kw = dict(na=2, nb=1, ka=s.ka, kb=s.kb)
    d1 = lptv.FrequencyData.from_periods(u, y, w0=s.w0)
    d2 = lptv.FrequencyData.from_periods(u, y, w0=2 * s.w0)
    with pytest.raises(ValueError, match="empty"):
        lptv.identify([], **kw, w0=s.w0)
    with pytest.raises(ValueError, match="period"):
        lptv.identify([d1, d2], **kw)
    with pytest.raises(ValueError, match=r"experiments\[1\].*FrequencyData or a \(u, y\) pair"):
        lptv.identify([d1, 3.0], **kw)
    with pytest.raises(ValueError, match=r"experiments\[1\].*w0"):
        lptv.identify([(u, y), d2], **kw, w0=s.w0)
    dt = lptv.FrequencyData.from_periods(u, y, w0=2 * np.pi / 63, ts=1.0)
    ct = lptv.FrequencyData.from_periods(u, y, w0=2 * np.pi / 63)
    with pytest.raises(ValueError, match="time domains"):
        lptv.identify([ct, dt], **kw)
    dt2 = lptv.FrequencyData(dt.U, dt.Y, dt.varU, dt.varY, w0=2 * np.pi / 63, ts=0.5, periods=4)
    with pytest.raises(ValueError, match="sample period"):
        lptv.identify([dt, dt2], **kw)
    with pytest.raises(ValueError, match="one per experiment"):
        lptv.identify([d1, d1], **kw, lines=[5, 6, 7])
    with pytest.raises(ValueError, match=r"experiment 1: lines: row 40"):
        lptv.identify([d1, d1], **kw, lines=[None, [5, 40]])
    with pytest.raises(ValueError, match="experiments must be a list"):
        lptv.spectra.frequency_data.experiments_of({"a": d1}, None, None)


# ------------------------------------------------------------------------- the command line

def test_cli_joint_fits_two_files_into_one_model(tmp_path):
    s = system(1, "ct", True)
    rng = np.random.default_rng(3)
    (ua, ya), (ub, yb) = periods(s, 63, 6, np.arange(1, 12), rng), periods(s, 95, 8, np.arange(10, 40), rng)
    np.savez(tmp_path / "low.npz", u=ua, y=ya, w0=s.w0)
    np.savez(tmp_path / "high.npz", u=ub, y=yb, w0=s.w0)
    out = tmp_path / "joint"
    cmd = [sys.executable, "-m", "lptv", "identify", str(tmp_path / "low.npz"), str(tmp_path / "high.npz"),
           "--joint", "--na", "2", "--nb", "1", "--method", "sml", "--out", str(out)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert "2 experiments fitted together" in p.stdout
    summary = json.loads((out / "summary.json").read_text())
    res = lptv.identify([(ua, ya), (ub, yb)], na=2, nb=1, w0=s.w0, method="sml")
    assert summary["n_experiments"] == 2
    assert [e["n_lines"] for e in summary["experiments"]] == [int(np.sum(res.experiment == e)) for e in (0, 1)]
    assert np.allclose(lptv.Model.load(out / "model.json").a, res.model.a, rtol=1e-12, atol=0)
    assert (out / "report.html").exists()
    # Files that disagree on the period: one line, status 2.
    np.savez(tmp_path / "other.npz", u=ub, y=yb, w0=2 * s.w0)
    p = subprocess.run(cmd[:4] + [str(tmp_path / "low.npz"), str(tmp_path / "other.npz")] + cmd[6:],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 2 and "period" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    # One file given twice: refused in one line, whichever way its path is spelled.
    p = subprocess.run(cmd[:4] + [str(tmp_path / "low.npz"), str(tmp_path / "." / "low.npz")] + cmd[6:],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 2 and "is given twice" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "joint2").exists()


def test_the_same_data_given_twice_is_said():
    """Two experiments holding identical spectra (one record given twice) are fitted, with a
    warning that names them; several channels alike."""
    s = system(0, "ct", False)
    u, y = periods(s, 63, 4, np.arange(1, 20), np.random.default_rng(2))
    kw = dict(na=2, nb=1, ka=s.ka, kb=s.kb, w0=s.w0)
    other = periods(s, 63, 4, np.arange(1, 20), np.random.default_rng(3))
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        lptv.identify([(u, y), other], **kw)     # different records: no warning
    with pytest.warns(UserWarning, match=r"experiments\[0\] and experiments\[2\] hold the same data"):
        lptv.identify([(u, y), other, (u.copy(), y.copy())], **kw)
    U, Y = u[:, :, None], y[:, :, None]
    with pytest.warns(UserWarning, match=r"experiments\[0\] and experiments\[1\] hold the same data"):
        lptv.identify([(U, Y), (U, Y)], na=2, nb=1, ka=s.ka, kb=s.kb, w0=s.w0)
