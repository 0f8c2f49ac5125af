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
