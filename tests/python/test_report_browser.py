"""The report of ``lptv identify`` renders in a real headless browser (Chromium).

Skipped where no Chromium is installed (Debian: ``apt-get install chromium``; ``make test``
installs it); pytest prints the reason of every skip (``-rs`` in pyproject.toml).
"""
import shutil
import subprocess

import numpy as np
import pytest

from test_workflow import FS, T0, msd, run_cli, write_csv

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


def _browser():
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    pytest.skip(f"no headless browser: none of {', '.join(BROWSERS)} on PATH (Debian: apt-get install chromium)")


def test_identify_report_renders_in_headless_chromium(tmp_path, capsys):
    browser = _browser()
    pytest.importorskip("matplotlib")
    import matplotlib.image

    u, y = msd()
    src = write_csv(tmp_path / "r.csv", u.ravel(), y.ravel())
    assert run_cli(capsys, src, "--na", 2, "--nb", 0, "--fs", FS, "--period", T0, "--method", "sml",
                   "--out", tmp_path / "o")[0] == 0
    page = tmp_path / "o" / "report.html"
    shot = tmp_path / "shot.png"
    # --no-sandbox: Chromium refuses to run as root (containers, CI) with its sandbox on
    cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1100,3000",
           f"--screenshot={shot}", page.as_uri()]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and shot.exists(), r.stderr[-2000:]
    assert shot.stat().st_size > 10_000
    img = matplotlib.image.imread(shot)
    assert img.shape[:2] == (3000, 1100)
    gray = img[..., :3].mean(axis=2)
    # not a blank page: text, tables and the figures (images drawn, not broken-image boxes)
    assert gray.std() > 0.05
    rows_inked = np.mean(gray.min(axis=1) < 0.5)
    assert rows_inked > 0.3
