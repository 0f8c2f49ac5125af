"""The README's Python example runs as printed."""
import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_example_runs(tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert blocks, "README has no Python example"
    monkeypatch.chdir(tmp_path)
    ns = {}
    exec(compile(blocks[0], "README.md", "exec"), ns)
    res, err, Y = ns["res"], ns["err"], ns["Y"]
    assert res.converged and res.residue_ok
    assert ns["poles"].shape == (100, 2)
    assert err.max() < 0.05 * abs(Y).max()
    assert (tmp_path / "model.json").exists()


def test_readme_batch_example_runs(tmp_path, monkeypatch):
    """The Monte Carlo and batch example (on local processes, as printed)."""
    blocks = [b for b in re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
              if "lptv.montecarlo(" in b]
    assert len(blocks) == 1
    monkeypatch.chdir(tmp_path)
    ns = {}
    exec(compile(blocks[0], "README.md", "exec"), ns)
    mc, summary, table = ns["mc"], ns["summary"], ns["table"]
    assert mc.runs == 100 and mc.methods == ("wgtls", "sml") and mc.executor.endswith("processes")
    assert (mc.overview().failures == 0).all()
    assert len(summary) == 2 * 34 and {"bias", "var_over_crb", "coverage"} <= set(summary.columns)
    for name in ("estimates.csv", "fits.csv", "summary.csv", "overview.csv"):
        assert (tmp_path / "study" / name).exists()
    assert list(table.record) == [f"machine {s}" for s in range(1, 5)] and table.ok.all()
