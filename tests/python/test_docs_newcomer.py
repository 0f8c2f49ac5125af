"""What a newcomer reads first says what is true: the record page on several outputs, the
screenshots' alt text, the site's index, and what ``make demo`` says while it installs and builds.
"""
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

import lptv

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def test_the_record_page_says_several_outputs_are_read_and_they_are(tmp_path):
    page = (DOCS / "guide" / "02-record.md").read_text()
    assert "not supported" not in page
    assert "`--output disp,acc`" in page and "12-several-channels.md" in page
    # what it says: a list of outputs reads (P, N, ny); a comma in one name says to give a list
    rng = np.random.default_rng(0)
    N, P = 64, 4
    u = np.tile(np.cos(2 * np.pi * 3 * np.arange(N) / N), P) + 1e-3 * rng.standard_normal(N * P)
    x1, x2 = 0.5 * u + 1e-3 * rng.standard_normal(u.size), np.roll(u, 1) + 1e-3 * rng.standard_normal(u.size)
    np.savetxt(tmp_path / "r.csv", np.c_[u, x1, x2], delimiter=",", comments="", header="f [N],x1 [m],x2 [m]")
    m = lptv.read_measurements(tmp_path / "r.csv", u="f", y=["x1", "x2"], periods=P)
    assert m.y.shape == (P, N, 2) and m.output == ("x1 [m]", "x2 [m]")
    with pytest.raises(ValueError, match=r"several outputs are a list, y=\['x1', 'x2'\]") as e:
        lptv.read_measurements(tmp_path / "r.csv", u="f", y="x1,x2", periods=P)
    assert "not supported" not in str(e.value)


def _images(text):
    """(alt, target) of every Markdown image, the alt text over several lines joined."""
    return [(" ".join(a.split()), t) for a, t in re.findall(r"!\[([^\]]*)\]\(([^)]+)\)", text)]


def test_the_screenshots_alt_text_keeps_its_command():
    """MyST puts an image's alt text into the page as plain text: inline code in it is dropped
    ("The report of : the ..."). Every image's alt text is plain, and a screenshot of a report
    names its command."""
    pages = sorted(DOCS.rglob("*.md")) + [ROOT / "README.md"]
    shots = 0
    for page in pages:
        for alt, target in _images(page.read_text()):
            assert "`" not in alt, (page.name, alt)
            if "report-" in target:
                shots += 1
                assert "lptv identify" in alt, (page.name, alt)
    assert shots >= 4


def test_the_site_index_gives_the_two_commands_a_picture_and_where_to_start():
    index = (DOCS / "index.md").read_text()
    head = index.split("```{toctree}")[0]
    block = re.search(r"```sh\n(.*?)```", head, re.S)
    assert block and "make demo" in block.group(1) and "make test" in block.group(1)
    pictures = [t for _, t in _images(head)]
    assert pictures and all((DOCS / t).is_file() for t in pictures)
    assert "## Where to start" in head
    links = re.findall(r"\]\((guide/[^)#]+\.md)\)", head)
    assert {"guide/03-inspect.md", "guide/01-excitation.md"} <= set(links)
    assert all((DOCS / t).is_file() for t in links)


def test_make_demo_says_what_it_installs_and_builds_as_it_goes(tmp_path):
    """``make -n -B demo`` lists every command of a first run on a fresh machine: each slow step
    (apt-get, pip, the build, the demo) is preceded by an echo saying what it does."""
    out = subprocess.run(["make", "-n", "-B", "-C", str(ROOT), "demo", f"VENV={tmp_path}/venv",
                          f"BUILDROOT={tmp_path}/build"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    commands = [c for c in re.split(r"(?<!\\)\n", out.stdout) if c.strip()]
    slow = {"apt-get install": "Debian packages", "pip install -qq": "Python packages",
            "--no-build-isolation": "building", "bin/lptv demo": "lptv demo"}
    for key, said in slow.items():
        where = [i for i, c in enumerate(commands) if key in c]
        assert where, key
        for i in where:
            told = commands[i] if "echo" in commands[i] and commands[i].index("echo") < commands[i].index(key) else \
                commands[i - 1]
            assert "echo" in told and said in told, (key, told)
