"""lptv.montecarlo, lptv.identify_many and their executors (lptv.batch).

- The same study (and the same batch of records) gives bit-identical results serially, on 2
  local processes and on a Dask LocalCluster of 2 workers, whatever the chunking.
- A failing record or realisation is reported in its row and the others finish; a fit that
  did not converge is a row that says so.
- A small LTI study agrees with the closed-form Cramer-Rao bound within its sampling error, and
  the true noise variances the study's bound uses agree with the periodogram of the noise.
"""
import concurrent.futures as cf
import doctest
import multiprocessing
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lptv
import lptv.batch.executors
import lptv.batch.records
import lptv.batch.study
from lptv.batch import Failure, run_tasks
from lptv.examples import noise_variances, noisy_periods, paper_measurements

pd = pytest.importorskip("pandas")

PAPER_KW = dict(na=2, nb=1, ka=3, kb=3, lines=range(1, 244))


def small_lptv():
    """1st order, a0(t) = 2 + 0.3 cos(w0 t) (one harmonic): a cheap LPTV study (~1 ms a fit)."""
    m = lptv.Model([[0.15, 2.0, 0.15], [0, 1.0, 0]], [[0, 1.0, 0]], w0=0.1)
    return m, lptv.multisine(range(1, 41), 256, seed=3)


STUDY = dict(periods=4, runs=10, snr_in_db=40.0, snr_out_db=25.0, methods="wgtls,sml", pole_out=0.5,
             correlation=0.3, seed=123, progress=False)


def fork_pool():
    """Two forked processes: they see this module (and its monkeypatches) as it is now."""
    return cf.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork"))


def assert_same_study(a, b):
    assert a.methods == b.methods and a.eta_names == b.eta_names
    for m in a.methods:
        assert np.array_equal(a.estimates[m], b.estimates[m], equal_nan=True), m
        assert np.array_equal(a.std[m], b.std[m], equal_nan=True), m
    assert [{k: v for k, v in f.items() if k != "cost"} for f in a.fits] == \
           [{k: v for k, v in f.items() if k != "cost"} for f in b.fits]
    assert np.array_equal([f["cost"] for f in a.fits], [f["cost"] for f in b.fits], equal_nan=True)


# ------------------------------------------------------------------------------ bit-identical

def test_study_is_bit_identical_serially_on_processes_and_on_dask(dask_cluster):
    model, ms = small_lptv()
    serial = lptv.montecarlo(model, ms, executor="serial", **STUDY)
    procs = lptv.montecarlo(model, ms, executor="processes", workers=2, chunk_size=3, **STUDY)
    dask = lptv.montecarlo(model, ms, executor=dask_cluster.scheduler_address, **STUDY)
    assert serial.executor == "serial" and procs.executor == "2 processes"
    assert dask.executor.startswith("dask tcp://127.0.0.1")
    assert all(f["ok"] for f in serial.fits) and len(serial.fits) == 20
    assert_same_study(serial, procs)
    assert_same_study(serial, dask)
    # the seeds are those of SeedSequence(seed).spawn(runs): a study of 4 runs is the first 4 of 10
    head = lptv.montecarlo(model, ms, executor="serial", **dict(STUDY, runs=4))
    assert np.array_equal(head.estimates["sml"], serial.estimates["sml"][:4])


def test_identify_many_is_bit_identical_everywhere_and_reports_failures_in_their_rows(tmp_path, dask_cluster):
    distributed = pytest.importorskip("distributed")
    files = []
    for s in (1, 2):
        d = paper_measurements(seed=s, periods=4)
        files.append(tmp_path / f"run{s}.npz")
        np.savez(files[-1], u=d["u"], y=d["y"], w0=d["w0"])
    (tmp_path / "corrupt.npz").write_text("not an npz file")
    nan = paper_measurements(seed=3, periods=4)
    nan["u"][1, 7] = np.nan
    records = [files[0], tmp_path / "missing.npz", tmp_path / "corrupt.npz", nan, files[1]]
    kw = dict(PAPER_KW, w0=0.04, progress=False)
    serial = lptv.identify_many(records, executor="serial", **kw)
    procs = lptv.identify_many(records, executor="processes", workers=2, chunk_size=2, **kw)
    with distributed.Client(dask_cluster) as client:
        dask = lptv.identify_many(records, executor=client, **kw)
    assert [r["ok"] for r in serial.rows] == [True, False, False, False, True]
    assert serial.rows[0]["record"] == str(files[0]) and serial.rows[3]["record"] == "record 3"
    errors = dict(serial.failures)
    assert "FileError: no such file" in errors[str(tmp_path / "missing.npz")]
    assert "FileError" in errors[str(tmp_path / "corrupt.npz")]
    assert "NaN" in errors["record 3"] and errors["record 3"].startswith("ValueError")
    for other in (procs, dask):
        assert other.rows == serial.rows
        assert other.models == serial.models
    # the rows are those of lptv.identify on each record (to rounding: BLAS threads differ here)
    z = np.load(files[1])
    ref = lptv.identify(z["u"], z["y"], w0=0.04, **PAPER_KW)
    np.testing.assert_allclose([serial.rows[4][n] for n in ref.eta_names], ref.eta, rtol=0, atol=1e-12)
    assert serial.models[4].na == 2 and serial.models[1] is None
    # a fit that stops before converging is reported as such, not as a failure
    slow = lptv.identify_many(files, executor="serial", max_iter=1, **kw)
    assert [(r["ok"], r["converged"]) for r in slow.rows] == [(True, False), (True, False)]



def test_identify_many_without_covariance_gives_the_same_estimates_and_no_std():
    recs = {f"seed {s}": paper_measurements(seed=s, periods=4) for s in (1, 2)}
    kw = dict(PAPER_KW, w0=0.04, executor="serial", progress=False)
    full = lptv.identify_many(recs, **kw)
    bare = lptv.identify_many(recs, covariance="none", **kw)
    for a, b in zip(full.rows, bare.rows):
        assert a["ok"] and b["ok"]
        assert [a[n] for n in full.eta_names] == [b[n] for n in bare.eta_names]
        assert all(a[n + ".std"] > 0 for n in full.eta_names if n != "a2.re0")
        assert all(b[n + ".std"] is None for n in bare.eta_names)
    with pytest.raises(ValueError, match=r"covariance must be one of .*each record is fitted alone.*'realisations'"):
        lptv.identify_many(recs, covariance="realisations", **kw)


# ------------------------------------------------------------------------------ failures

def test_montecarlo_reports_failed_fits_and_realisations_in_their_rows(monkeypatch):
    model, ms = small_lptv()
    real_identify, real_noise = lptv.batch.study.identify, lptv.batch.study.noisy_periods

    def flaky_identify(data, method, **kw):   # sml fails where the noise at line 100 is positive
        if method == "sml" and data.Y[100].real > 0:
            raise RuntimeError("injected failure")
        return real_identify(data, method=method, **kw)

    def flaky_noise(u0, y0, P, **kw):          # the whole realisation fails for some draws
        u, y = real_noise(u0, y0, P, **kw)
        if y[0, 5] - y0[5] > 0.04:
            raise ValueError("injected noise failure")
        return u, y

    monkeypatch.setattr(lptv.batch.study, "identify", flaky_identify)
    monkeypatch.setattr(lptv.batch.study, "noisy_periods", flaky_noise)
    runs = dict(STUDY, runs=16)
    serial = lptv.montecarlo(model, ms, executor="serial", **runs)
    with fork_pool() as pool:
        procs = lptv.montecarlo(model, ms, executor=pool, chunk_size=5, **runs)
    assert_same_study(serial, procs)
    fits = serial.fit_table()
    assert len(fits) == 32 and list(fits.run.unique()) == list(range(16))
    lost = fits[fits.error == "ValueError: injected noise failure"]
    sml_only = fits[fits.error == "RuntimeError: injected failure"]
    assert 0 < lost.run.nunique() < 16 and len(lost) == 2 * lost.run.nunique()   # both methods
    assert 0 < len(sml_only) and set(sml_only.method) == {"sml"}
    ok = fits[fits.ok]
    assert len(ok) == 32 - len(lost) - len(sml_only) and (ok.error == "").all()
    # the failed rows are NaN in the arrays and left out of the statistics, the rest are used
    sml_ok = fits[fits.method == "sml"].ok.to_numpy()
    assert np.isnan(serial.estimates["sml"][~sml_ok]).all()
    assert np.isfinite(serial.estimates["sml"][sml_ok]).all()
    ov = serial.overview()
    assert ov.loc["sml", "failures"] == len(lost) // 2 + len(sml_only)
    assert ov.loc["wgtls", "failures"] == len(lost) // 2
    assert serial.statistics("sml")["n"] == int(sml_ok.sum())
    assert "injected" in serial.report()


def test_fits_that_do_not_converge_are_counted_not_dropped():
    model, ms = small_lptv()
    mc = lptv.montecarlo(model, ms, executor="serial", max_iter=1, **dict(STUDY, runs=6))
    ov = mc.overview()
    assert (ov.failures == 0).all() and (ov.not_converged == 6).all()
    assert mc.statistics("wgtls")["n"] == 6


def test_run_tasks_keeps_the_order_and_catches_failures_per_item():
    items = [4, 2, 0, 1, 8, 0, 5, 10, 16, 20, 1]
    want = [None if i == 0 else 40 / i for i in items]
    for executor in ("serial", fork_pool()):
        out = run_tasks(_forty_over, items, 40.0, executor=executor, chunk_size=3, progress=False)
        if not isinstance(executor, str):
            executor.shutdown()
        assert [None if isinstance(o, Failure) else o for o in out] == want
        assert out[2].message == "ZeroDivisionError: float division by zero"
        assert "Traceback" in out[5].detail


def _forty_over(x, shared):
    return shared / x


def _scaled(x, shared):
    return x * shared["scale"]


def test_consecutive_runs_on_one_dask_client_do_not_share_the_scattered_design(dask_cluster):
    """Each run scatters its shared argument under a key of its own: a dict scattered as it is
    would take its own keys, and the release of one run's copy would cancel the next run's tasks."""
    distributed = pytest.importorskip("distributed")
    with distributed.Client(dask_cluster) as client:
        for k in range(4):
            out = run_tasks(_scaled, range(6), {"scale": k}, executor=client, chunk_size=2, progress=False)
            assert out == [k * i for i in range(6)]


# ------------------------------------------------------------------------------ statistics

def test_lti_study_agrees_with_the_closed_form_crb(batch_tol):
    """1/(s + a) with white output noise, no input noise: the Fisher information of the
    transfer function's parameters is F = sum_l 2 Re(dG^H dG) |U|^2 / (var_y / P), formed here
    from G directly. With noise variances estimated from P periods the ML variance is about
    (P - 2) / (P - 3) times the bound."""
    a, w0, N, P, R, snr = 2.0, 0.1, 256, 16, 800, 20.0
    m = lptv.Model([[a], [1.0]], [[1.0]], w0=w0)
    ms = lptv.multisine(range(1, 60), N, seed=0)
    mc = lptv.montecarlo(m, ms, periods=P, runs=R, snr_in_db=np.inf, snr_out_db=snr,
                         methods="wgtls,sml", seed=11, workers=2, progress=False)
    y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), N)
    var_y = np.mean(y0 ** 2) * 10 ** (-snr / 10) / N          # one period's spectrum, per line
    s = 1j * w0 * mc.crb.lines
    dG = np.column_stack([-1.0 / (s + a) ** 2, 1.0 / (s + a)]) * ms.spectrum[mc.crb.lines, None]
    crb_std = np.sqrt(np.diag(np.linalg.inv(2 * np.real(dG.conj().T @ dG) / (var_y / P))))
    k = (P - 2) / (P - 3)
    summary = mc.summary()
    sig = batch_tol.MC_SIGMAS
    for method in ("wgtls", "sml"):
        s = summary.loc[method]
        assert list(s.index) == ["a0.re0", "b0.re0"] and (s.n == R).all()
        np.testing.assert_allclose(s.crb_std, crb_std, rtol=1e-10)
        np.testing.assert_array_less(np.abs(s["std"] ** 2 / (k * crb_std ** 2) - 1), sig * np.sqrt(2 / (R - 1)))
        np.testing.assert_array_less(np.abs(s.bias), sig * s.bias_se)
        np.testing.assert_array_less(np.abs(s.coverage - 0.95), sig * np.sqrt(0.95 * 0.05 / R))
        np.testing.assert_allclose(s.reported_std, np.sqrt(k) * crb_std, rtol=sig * np.sqrt(2 / (R - 1)))
    assert (mc.overview().failures == 0).all()


def test_noise_variances_match_the_periodogram_of_noisy_periods(batch_tol):
    N, D = 64, 4000
    u0 = np.sqrt(2) * np.cos(2 * np.pi * 3 * np.arange(N) / N)
    y0 = 0.5 * np.sin(2 * np.pi * 5 * np.arange(N) / N)
    noise = dict(pole_in=0.6, pole_out=-0.4, correlation=0.5)
    var_u, var_y, cov_yu = noise_variances(u0, y0, 10.0, 20.0, **noise)
    u, y = noisy_periods(u0, y0, D, 10.0, 20.0, seed=5, **noise)
    dU = np.fft.rfft(u - u0, axis=1) / N
    dY = np.fft.rfft(y - y0, axis=1) / N
    tol = batch_tol.NOISE_SIGMAS * np.sqrt(2 / D)
    np.testing.assert_allclose(np.mean(np.abs(dU) ** 2, axis=0), var_u, rtol=tol)
    np.testing.assert_allclose(np.mean(np.abs(dY) ** 2, axis=0), var_y, rtol=tol)
    # E{dY conj(dU)}: the std of the mean of the products is at most sqrt(var_u var_y / D)
    assert np.all(np.abs(np.mean(dY * dU.conj(), axis=0) - cov_yu) < tol * np.sqrt(var_u * var_y))
    assert np.all(cov_yu.real > 0.1 * np.sqrt(var_u * var_y))   # the correlation is seen at all


# ------------------------------------------------------------------------------ interface

def test_tables_files_and_figures(tmp_path):
    pytest.importorskip("pyarrow")
    model, ms = small_lptv()
    mc = lptv.montecarlo(model, ms, executor="serial", **dict(STUDY, methods="tls,sml"))
    t = mc.table()
    free = [n for n, f in zip(mc.eta_names, mc.free) if f]
    assert list(t.columns) == ["run", "method", "parameter", "true", "estimate", "std", "error", "covered"]
    assert len(t) == 2 * 10 * len(free) and t.covered[t.method == "tls"].isna().all()
    np.testing.assert_array_equal(t.error, t.estimate - t.true)
    paths = mc.save(tmp_path / "csv")
    back = pd.read_csv(paths["estimates"])
    np.testing.assert_array_equal(back.estimate, t.estimate)   # %.17g round trip
    paths = mc.save(tmp_path / "pq", format="parquet")
    pd.testing.assert_frame_equal(pd.read_parquet(paths["estimates"]), t)
    pd.testing.assert_frame_equal(pd.read_parquet(paths["fits"]), mc.fit_table())
    s = pd.read_csv(paths["summary"], index_col=[0, 1])
    assert {"bias", "rms", "var_over_crb", "coverage", "crb_std"} <= set(s.columns)
    assert mc.plot_errors().get_legend() is not None
    assert mc.plot_errors(parameter=free[0]).get_xlabel() == f"error of {free[0]}"
    assert len(mc.plot_coverage().lines) >= 2
    with pytest.raises(ValueError, match="parameter must be one of"):
        mc.plot_errors(parameter="zz")
    with pytest.raises(ValueError, match="format must be one of"):
        mc.save(tmp_path, format="xlsx")

    recs = {"a": paper_measurements(seed=1, periods=3), "b": (np.zeros((3, 8)), np.zeros((3, 8)))}
    out = lptv.identify_many(recs, executor="serial", w0=0.04, progress=False, **PAPER_KW)
    out.save(tmp_path / "fits.csv")
    out.save(tmp_path / "fits.parquet")
    c = pd.read_csv(tmp_path / "fits.csv")
    assert list(c.record) == ["a", "b"] and list(c.ok) == [True, False]
    assert list(c.columns) == out.columns and c["a0.re0.std"][0] > 0
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "fits.parquet"), out.table())


def test_progress_bar_with_eta_on_request_only(capsys):
    pytest.importorskip("tqdm")
    model, ms = small_lptv()
    lptv.montecarlo(model, ms, executor="serial", **dict(STUDY, runs=3, progress=True))
    err = capsys.readouterr().err
    assert "montecarlo" in err and "100%" in err and "6/6" in err and "<00:00" in err
    lptv.montecarlo(model, ms, executor="serial", **dict(STUDY, runs=3))   # progress=False
    assert capsys.readouterr().err == ""


BAD_STUDY = [
    (dict(periods=1), "periods must be an integer >= 2"),
    (dict(runs=0), "runs must be a positive integer"),
    (dict(methods="wgtls,fast"), "methods: 'fast' is not one of"),
    (dict(methods="sml,sml"), "methods: a method is given twice"),
    (dict(snr_in_db=float("nan")), "snr_in_db must be a number of dB"),
    (dict(pole_in=1.0), r"pole_in must lie in \(-1, 1\)"),
    (dict(correlation=1.5), r"correlation must lie in \[-1, 1\]"),
    (dict(level=95), r"level must lie in \(0, 1\)"),
    (dict(seed="x"), "seed must be an int"),
    (dict(executor="gpu"), "executor must be 'serial', 'processes', a Dask scheduler address"),
    (dict(executor="serial", workers=2), "workers applies to executor='processes' only"),
    (dict(workers=0), "workers must be a positive integer"),
    (dict(chunk_size=0), "chunk_size must be a positive integer"),
    (dict(lines=[500]), "line"),
]


@pytest.mark.parametrize("bad,match", BAD_STUDY, ids=[next(iter(b)) for b, _ in BAD_STUDY])
def test_bad_study_arguments_raise_value_errors_naming_them(bad, match):
    model, ms = small_lptv()
    with pytest.raises(ValueError, match=match):
        lptv.montecarlo(model, ms, **dict(STUDY, **bad))


def test_bad_batch_arguments_raise_value_errors_naming_them():
    rec = [(np.zeros((2, 8)), np.zeros((2, 8)))]
    for kw, match in [(dict(method="mle"), "method must be one of"), (dict(na=-1), "na must be"),
                      (dict(ka=[1]), "ka must give one harmonic count per coefficient"),
                      (dict(w0=-1.0), "w0 must be positive"), (dict(names=["a", "b"]), "names must give one name"),
                      (dict(known={"c0": 1}), "known: 'c0' is not a coefficient name")]:
        with pytest.raises(ValueError, match=match):
            lptv.identify_many(rec, **dict(dict(na=1, nb=0, w0=1.0, executor="serial"), **kw))
    with pytest.raises(ValueError, match="records must be a sequence"):
        lptv.identify_many(5, na=1, nb=0, w0=1.0)
    with pytest.raises(ValueError, match="excitation"):
        lptv.montecarlo(small_lptv()[0], "not a signal", **STUDY)


def test_docstring_examples_run():
    for mod in (lptv.batch.executors, lptv.batch.study, lptv.batch.records):
        result = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
        assert result.failed == 0 and result.attempted > 0, mod.__name__


def test_library_works_without_the_batch_extra():
    """pandas, tqdm, dask, threadpoolctl and pyarrow hidden: the fits still run and the results are
    arrays; asking for a table names the extra."""
    code = textwrap.dedent("""
        import sys
        class Hide:
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] in {"pandas", "tqdm", "dask", "distributed", "threadpoolctl", "pyarrow"}:
                    raise ImportError("hidden: " + name)
        sys.meta_path.insert(0, Hide())
        import lptv
        m = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
        ms = lptv.multisine(range(1, 30), 128, seed=0)
        mc = lptv.montecarlo(m, ms, periods=4, runs=4, snr_in_db=40, snr_out_db=30, workers=2)
        assert mc.estimates["wgtls"].shape == (4, 3) and "coverage" in mc.report()
        try:
            mc.summary()
        except ImportError as e:
            print(e)
        try:
            lptv.montecarlo(m, ms, periods=4, runs=1, snr_in_db=40, snr_out_db=30, executor="tcp://127.0.0.1:1")
        except ImportError as e:
            print(e)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == [
        "MonteCarloResult.summary needs the package 'pandas': pip install 'lptv[batch]'",
        "a Dask executor needs the package 'distributed': pip install 'lptv[batch]'"]


def test_montecarlo_command_checks_its_options_before_importing_the_tables(tmp_path):
    """`lptv montecarlo` checks that pandas is installed without importing it (a second), so that a
    bad option is refused at once; with pandas hidden it names the extra, exit 2."""
    code = textwrap.dedent("""
        import sys
        from lptv.apps import cli
        rc = cli.main(["montecarlo", "--runs", "1", "--periods", "4", "--workers", "0", "--out", sys.argv[1]])
        print(rc, "pandas" in sys.modules)
        class Hide:
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] == "pandas":
                    raise ImportError("hidden: " + name)
        sys.meta_path.insert(0, Hide())
        print(cli.main(["montecarlo", "--runs", "1", "--periods", "4", "--out", sys.argv[1]]))
    """)
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "mc")], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["2 False", "2"], out
    assert "--workers must be >= 1, got 0" in out.stderr
    assert "lptv montecarlo's tables needs the package 'pandas': pip install 'lptv[batch]'" in out.stderr
