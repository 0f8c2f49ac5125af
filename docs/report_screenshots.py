"""The screenshots of the reports in docs/: report-identify.png, report-bla.png and
report-one-record.png, the top of each report.html as headless Chromium renders it.

    .venv/bin/python docs/report_screenshots.py            # needs chromium on PATH

The records are made outside lptv where a rig would make them (tests/python/outside_records.py):
a mass-spring-damper m x'' + c x' + k(t) x = F (m = 1 kg, c = 0.8 N s/m, k(t) = 40 (1 + 0.3 cos(2 pi t
/ 5)) N/m) integrated by scipy's solve_ivp under a multisine on the 30 adjacent lines 1..30, 1 %
noise on both channels: 8 periods of 5 s at 200 Hz after 4 periods of start-up for ``lptv identify``,
the first 20 s from rest (with the start-up) for ``--one-record``. The realisations of the BLA's
report are the paper's model with a cubic output nonlinearity (blaid.py's example).
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))
import outside_records as rec  # noqa: E402

RIG = dict(mass=1.0, damping=0.8, stiffness=40.0, variation=0.3)
NAMES = ["--input", "force", "--output", "displacement"]
STRUCTURE = ["--na", "2", "--nb", "0", "--ka", "1,0,0", "--kb", "0"]


def lptv(cwd, *argv):
    """lptv in the folder of the records (the reports name them without a temporary path)."""
    r = subprocess.run([sys.executable, "-m", "lptv", *map(str, argv)], capture_output=True, text=True, cwd=cwd)
    if r.returncode not in (0, 3):
        raise SystemExit(f"lptv {' '.join(map(str, argv))}: exit {r.returncode}\n{r.stderr}")
    print(r.stdout.splitlines()[0])


def shoot(page: Path, png: Path, height: int, width: int = 1000):
    from PIL import Image

    browser = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)),
                   None)
    if browser is None:
        raise SystemExit("no headless browser on PATH (Debian: apt-get install chromium)")
    with tempfile.TemporaryDirectory() as profile:
        shot = Path(profile) / "shot.png"
        # --no-sandbox: Chromium refuses to run as root (containers) with its sandbox on
        subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                        f"--user-data-dir={profile}", f"--window-size={width},{height}", f"--screenshot={shot}",
                        page.as_uri()], check=True, capture_output=True, timeout=120)
        # a palette of 256 colours keeps the file small; the page is flat colours and antialiased text
        Image.open(shot).convert("RGB").quantize(256).save(png, optimize=True)
    print(f"wrote {png.relative_to(ROOT)}")


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t, f, x = rec.mass_spring_damper(5.0, 200.0, 8, lines=np.arange(1, 31), start=20.0, **RIG)
        rec.write_csv(tmp / "rig.csv", t - t[0], f, x)
        lptv(tmp, "identify", "rig.csv", *NAMES, "--period", 5, *STRUCTURE, "--scale", "b0=1", "--out", "identify")
        shoot(tmp / "identify" / "report.html", ROOT / "docs" / "report-identify.png", 1700)

        t, f, x = rec.mass_spring_damper(5.0, 200.0, 4, lines=np.arange(1, 31), **RIG)
        rec.write_csv(tmp / "start.csv", t, f, x)
        lptv(tmp, "identify", "start.csv", "--one-record", *NAMES, "--period", 5, *STRUCTURE, "--out", "one")
        shoot(tmp / "one" / "report.html", ROOT / "docs" / "report-one-record.png", 1100)

        import lptv as lp
        from lptv.examples import noisy_periods, paper_model

        m = paper_model()
        u, y = [], []
        for r in range(6):
            ms = lp.multisine(range(10, 241, 10), 2048, amplitudes=np.sqrt(2 / 24), seed=r)
            y0 = lp.time_signal(lp.simulate(m, ms.spectrum), 2048)
            a, b = noisy_periods(ms.signal, y0 + 0.02 * y0 ** 3, 16, 50, 30, seed=100 + r)
            u.append(a)
            y.append(b)
        np.savez(tmp / "bla.npz", u=np.array(u), y=np.array(y), w0=m.w0)
        lptv(tmp, "identify", "bla.npz", "--na", 2, "--nb", 1, "--ka", 3, "--kb", 3, "--out", "bla")
        shoot(tmp / "bla" / "report.html", ROOT / "docs" / "report-bla.png", 2300)
    return 0


if __name__ == "__main__":
    sys.exit(main())
