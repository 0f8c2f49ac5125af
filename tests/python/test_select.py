"""lptv.select: the structure (na, nb, k) from the data.

Counts measured when these tests were written (the seeds below, lines 1..243, P = 8):
MDL recovered the paper example's (2, 1, 3) in 10 of 10 seeds (1..10) on the grid
na 1..3, nb 0..2, k 0..4, and the LTI system's (2, 1, 0) in 10 of 10 on na 1..3, nb 0..2,
k 0..2 (and in 10 of 10 with k from the HTF guide, i.e. k = 0); AIC in 4 of 10 and 4 of 10 (it keeps unneeded harmonics: see METHOD.md section 13).
The tests run 5 seeds each and ask for at least 4.
"""
import numpy as np
import pytest

import lptv
from lptv.examples import PAPER_NOISE, noisy_periods, paper_measurements, paper_multisine

LINES = range(1, 244)
SEEDS = range(1, 6)


def lti_measurements(seed, periods=8):
    """The paper example's mean system (s + 1) / (s^2 + s + 1), the same excitation and noise."""
    rng = np.random.default_rng(seed)
    model = lptv.Model([[1.0], [1.0], [1.0]], [[1.0], [1.0]], w0=0.04)
    ms = paper_multisine(seed=rng)
    y0 = lptv.time_signal(lptv.simulate(model, ms.spectrum), ms.signal.size)
    u, y = noisy_periods(ms.signal, y0, periods, 50.0, 30.0, seed=rng, **PAPER_NOISE)
    return u, y


def check_ranking(sel):
    """The verdict's passes first, SML before WGTLS, then the criterion ascending; never a rejected choice
    while another candidate passes."""
    keys = [(r["error"] != "", not r["model_ok"], r["method"] != "sml", r[sel.criterion]) for r in sel.rows]
    assert keys == sorted(keys)
    assert [r["rank"] for r in sel.rows] == list(range(1, len(sel.rows) + 1))
    top = sel.rows[0]
    assert (top["na"], top["nb"], top["k"]) == sel.choice
    if any(r["model_ok"] for r in sel.rows):
        assert top["model_ok"] and sel.choice_ok and sel.result.model_ok
    assert sel.result.model.na == sel.choice[0] and sel.result.model.nb == sel.choice[1]
    assert np.array_equal(sel.result.lines, sel.lines)


def test_paper_example_structure_recovered_in_most_seeds():
    hits = 0
    for seed in SEEDS:
        m = paper_measurements(seed=seed, periods=8)
        sel = lptv.select(m["u"], m["y"], w0=m["w0"], na=range(1, 4), nb=range(0, 3), k=range(2, 5),
                          lines=LINES, executor="serial", progress=False)
        check_ranking(sel)
        assert sel.criterion == "mdl" and np.isclose(sel.correction, 7 / 6)
        hits += sel.choice == (2, 1, 3)
    assert hits >= 4, f"(2, 1, 3) chosen in {hits} of {len(SEEDS)} seeds"


def test_lti_structure_recovered_in_most_seeds():
    hits = 0
    for seed in SEEDS:
        u, y = lti_measurements(seed)
        sel = lptv.select(u, y, w0=0.04, na=range(1, 4), nb=range(0, 3), k=range(0, 3), lines=LINES,
                          executor="serial", progress=False)
        check_ranking(sel)
        assert sel.htf_harmonics == 0 and sel.htf.branches == 4
        hits += sel.choice == (2, 1, 0)
    assert hits >= 4, f"(2, 1, 0) chosen in {hits} of {len(SEEDS)} seeds"
    # without k the HTF guide (only branch 0 above the noise) gives the grid k = 0
    sel = lptv.select(u, y, w0=0.04, na=[2], nb=[1, 2], lines=LINES, executor="serial", progress=False)
    assert {r["k"] for r in sel.rows} == {0} and sel.choice == (2, 1, 0)


def test_htf_guide_sets_the_harmonic_grid_and_default_rows_follow_the_largest_k():
    m = paper_measurements(seed=3, periods=8)
    sel = lptv.select(m["u"], m["y"], w0=m["w0"], na=[2], nb=[1], executor="serial", progress=False)
    # every branch the excitation (every 10th line) separates stands above the noise
    assert sel.htf_harmonics == 4 and sorted({r["k"] for r in sel.rows}) == [0, 1, 2, 3, 4]
    assert any("do not bound the harmonic count" in w for w in sel.warnings)
    L = m["u"].shape[1] // 2
    assert np.array_equal(sel.lines, np.arange(5, L - 4 + 1))
    assert sel.choice == (2, 1, 3)
    check_ranking(sel)


def test_aic_ranking_and_sml_rows_carry_the_exact_cost():
    m = paper_measurements(seed=2, periods=8)
    sel = lptv.select(m["u"], m["y"], w0=m["w0"], na=[2, 3], nb=[1], k=[2, 3], lines=LINES,
                      criterion="aic", refine=1, executor="serial", progress=False)
    check_ranking(sel)
    sml = [r for r in sel.rows if r["method"] == "sml"]
    assert len(sml) == 2 and {r["k"] for r in sml} == {2, 3}    # one per harmonic count
    n_rows = len(LINES)
    res = sel.result
    assert res.method == "sml"
    assert np.isclose(sel.rows[0]["V"], 2 * n_rows * res.cost, rtol=1e-12)
    c, n = sel.correction, res.n_free_parameters
    assert np.isclose(sel.rows[0]["aic"], sel.rows[0]["V"] + 2 * c * n)
    assert np.isclose(sel.rows[0]["mdl"], sel.rows[0]["V"] + c * n * np.log(2 * n_rows))


def test_every_candidate_rejected_is_said_clearly():
    m = paper_measurements(seed=1, periods=8)
    with pytest.warns(UserWarning, match="the verdict rejects EVERY candidate"):
        sel = lptv.select(m["u"], m["y"], w0=m["w0"], na=[1], nb=[0], k=[0, 1], lines=LINES,
                          executor="serial", progress=False)
    assert not sel.choice_ok and not any(r["model_ok"] for r in sel.rows)
    assert "EVERY candidate" in sel.summary()
    check_ranking(sel)


def test_serial_and_two_processes_identical_and_no_progress_off_a_terminal(capsys):
    m = paper_measurements(seed=4, periods=4)
    kw = dict(w0=m["w0"], na=[1, 2], nb=[0, 1], k=[2, 3], lines=LINES)
    a = lptv.select(m["u"], m["y"], executor="serial", **kw)
    b = lptv.select(m["u"], m["y"], executor="processes", workers=2, **kw)
    assert capsys.readouterr().err == ""          # progress=None: stderr is not a terminal here
    assert a.rows == b.rows
    assert np.array_equal(a.result.eta, b.result.eta) and a.choice == b.choice == (2, 1, 3)
    assert a.executor == "serial" and b.executor == "2 processes"
    df = a.table()
    assert list(df["rank"]) == list(range(1, len(a.rows) + 1)) and df.shape[0] == 8


@pytest.mark.parametrize("kw, name", [
    (dict(na=-1), "na"), (dict(nb=[0, 0]), "nb"), (dict(k=[]), "k"), (dict(k=[1.5]), "k"),
    (dict(criterion="bic"), "criterion"), (dict(refine=-1), "refine"), (dict(alpha=2.0), "alpha"),
    (dict(tol=0.0), "tol"), (dict(max_iter=-2), "max_iter"), (dict(lines=[1.5, 2.5]), "lines"),
    (dict(workers=0, executor="processes"), "workers"), (dict(executor="nowhere"), "executor"),
])
def test_bad_arguments_are_named(kw, name):
    m = paper_measurements(seed=1, periods=4)
    args = dict(w0=m["w0"], na=[2], nb=[1], k=[0], lines=LINES, executor="serial", progress=False)
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        lptv.select(m["u"], m["y"], **args)


def test_k_needed_when_the_excitation_is_dense():
    rng = np.random.default_rng(0)
    model = lptv.Model([[2.0], [1.0]], [[1.0]], w0=0.1)
    ms = lptv.multisine(range(1, 60), 256, seed=0)
    y1 = lptv.time_signal(lptv.simulate(model, ms.spectrum), 256)
    u = ms.periods(4) + 1e-3 * rng.standard_normal((4, 256))
    y = np.tile(y1, (4, 1)) + 1e-3 * rng.standard_normal((4, 256))
    with pytest.raises(ValueError, match="k: give the harmonic counts"):
        lptv.select(u, y, w0=0.1, na=[1], nb=[0], executor="serial")
    sel = lptv.select(u, y, w0=0.1, na=[1, 2], nb=[0, 1], k=[0], executor="serial")
    assert sel.choice == (1, 0, 0) and sel.htf is None and sel.htf_harmonics is None
    assert any("no HTF guide" in w for w in sel.warnings)


def test_docstring_example():
    import doctest
    import sys

    module = sys.modules["lptv.batch.selection"]
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


def test_cli_select(tmp_path, capsys):
    import json

    from lptv.apps.cli import main

    m = paper_measurements(seed=1, periods=4)
    src = tmp_path / "meas.npz"
    np.savez(src, u=m["u"], y=m["y"], w0=m["w0"])
    out = tmp_path / "sel"
    assert main(["select", str(src), "--na", "1-2", "--nb", "1", "--k", "2,3", "--lines", "1-243",
                 "--workers", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "choice (MDL): na = 2, nb = 1, k = 3" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["choice"] == {"na": 2, "nb": 1, "k": 3} and summary["choice_ok"]
    assert lptv.Model.load(out / "model.json").na == 2
    assert (out / "selection.csv").read_text().splitlines()[0].startswith("rank,na,nb,k")
    # every candidate rejected: the least bad is written, exit status 1
    assert main(["select", str(src), "--na", "1", "--nb", "0", "--k", "0", "--lines", "1-243",
                 "--workers", "1", "--out", str(out)]) == 1
    assert "EVERY candidate" in capsys.readouterr().out
    for bad, what in ((["--na", "2-1"], "--na"), (["--refine", "-1"], "--refine"), (["--k", "x"], "--k")):
        assert main(["select", str(src), "--workers", "1", "--out", str(out)] + bad) == 2
        assert what in capsys.readouterr().err
    assert main(["select", str(tmp_path / "missing.npz"), "--workers", "1"]) == 2
    assert "missing.npz: no such file" in capsys.readouterr().err


def test_readme_select_example_runs():
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]     # the README and the user guide (docs/guide)
    text = "\n".join(p.read_text() for p in [root / "README.md", *sorted((root / "docs" / "guide").glob("*.md"))])
    blocks = [b for b in re.findall(r"```python\n(.*?)```", text, flags=re.S) if "lptv.select(" in b]
    assert len(blocks) == 1
    ns = {}
    exec(compile(blocks[0], "06-structure.md", "exec"), ns)
    assert ns["sel"].choice == (2, 1, 3) and ns["sel"].result.method == "sml"


# ------------------------------------------------------------------------------ a rig's record from rest

def _rig_from_rest(path):
    """m x'' + c x' + k(t) x = F from rest by solve_ivp (outside_records.py): 10 periods of 4 s at
    50 Hz, a transient decaying as exp(-0.27 t) (c = 0.54), 20 odd lines, 1 % noise."""
    from outside_records import mass_spring_damper, odd_lines

    t, f, x = mass_spring_damper(4.0, 50.0, 10, lines=odd_lines(1, 20, seed=7), noise=0.01, seed=0, damping=0.54)
    np.savetxt(path, np.column_stack([t, f, x]), fmt="%.17g", delimiter=",",
               header="time [s],force [N],displacement [m]", comments="")
    return f.reshape(10, -1), x.reshape(10, -1)


def test_cli_select_takes_the_record_options_of_identify_and_each_candidate_s_verdict(tmp_path, capsys):
    import csv
    import json

    from lptv.apps.cli import main

    src = tmp_path / "rig.csv"
    u, y = _rig_from_rest(src)
    out = tmp_path / "sel"
    rc = main(["select", str(src), "--input", "force", "--output", "displacement", "--period", "4",
               "--skip-periods", "6", "--lines", "excited", "--na", "2", "--nb", "0-1", "--k", "0-1",
               "--workers", "1", "--out", str(out)])
    text, err = capsys.readouterr()
    assert rc == 0, err
    assert "4 periods of 200 samples" in text and "dropped at the start: 6 periods (--skip-periods)" in text
    assert "choice (MDL): na = 2, nb = 0, k = 1" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["skipped_periods"] == 6 and summary["choice"] == {"na": 2, "nb": 0, "k": 1}
    rows = list(csv.DictReader((out / "selection.csv").open()))
    # every candidate's verdict is lptv.identify's on the same periods and rows (the excited lines +-1)
    from lptv.estimation.identify import excited_rows

    data = lptv.FrequencyData.from_periods(u[6:], y[6:], w0=2 * np.pi / 4)
    assert summary["n_lines"] == excited_rows(data, 1).size
    for r in rows:
        na, nb, k = int(r["na"]), int(r["nb"]), int(r["k"])
        res = lptv.identify(data, na=na, nb=nb, ka=k, kb=k, lines=excited_rows(data, 1), method=r["method"],
                            covariance="none")
        assert (r["model_ok"] == "True") == res.model_ok, (r, res.verdict)
        assert r["verdict"] == ("consistent" if res.model_ok and res.undetermined is None else
                                "MODEL ERRORS" if not res.model_ok else "NOT DETERMINED")
    lti = [r for r in rows if r["k"] == "0"]
    assert lti and all(r["verdict"] == "MODEL ERRORS" for r in lti)       # never "ok"
    assert all(" ok" not in line for line in text.splitlines() if line.split()[3:4] == ["0"])


def test_select_takes_lines_excited():
    u, y = lti_measurements(1, periods=4)
    sel = lptv.select(u, y, w0=0.04, na=[2], nb=[1], k=[0, 1], lines="excited", executor="serial", progress=False)
    from lptv.estimation.identify import excited_rows

    rows = excited_rows(lptv.FrequencyData.from_periods(u, y, w0=0.04), 1)
    assert np.array_equal(sel.lines, rows) and np.array_equal(sel.result.lines, rows)
    with pytest.raises(ValueError, match="lines must be a sequence of integers or 'excited'"):
        lptv.select(u, y, w0=0.04, na=[2], nb=[1], k=[0], lines="all", executor="serial", progress=False)
