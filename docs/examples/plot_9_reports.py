"""
The reports of ``lptv identify``
================================

A rig as an engineer records it: a mass-spring-damper m x'' + c x' + k(t) x = F with
m = 1 kg, c = 0.8 N s/m and a stiffness k(t) = 40 (1 + 0.3 cos(2 pi t / 5)) N/m that varies with a
5 s period, driven by a multisine on the 30 adjacent lines 0.2-6 Hz, integrated by scipy's
``solve_ivp`` (outside lptv), 1 % noise on force and displacement, 8 periods at 200 Hz after
4 periods of start-up, written as ``time [s],force [N],displacement [m]``. The command fits it,
prints the verdict and writes ``report.html``; ``--scale b0=1`` adds the parameters in the
physical form where the force enters with b0 = 1, so that a2 is the mass, a1 the damping and a0
the stiffness, in the units the columns' names state.

The top of that report, rendered by headless Chromium (``docs/report_screenshots.py`` makes these
screenshots):

.. image:: /report-identify.png
   :width: 100%
   :alt: the top of report.html of lptv identify on the rig

The report of the best linear approximation (``lptv identify bla.npz``, six random-phase
realisations of the paper's model with a cubic output, METHOD.md section 16) and that of one record
fitted whole with its start-up transient (``lptv identify start.csv --one-record``, the rig's first
20 s from rest):

.. image:: /report-bla.png
   :width: 100%
   :alt: the top of report.html of lptv identify on M x P x N realisations

.. image:: /report-one-record.png
   :width: 100%
   :alt: report.html of lptv identify --one-record
"""
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import solve_ivp

import lptv
import lptv.plots
from lptv.apps import cli

T, fs, P = 5.0, 200.0, 8
w0 = 2 * np.pi / T
lines = np.arange(1, 31)
rng = np.random.default_rng(0)
phases = rng.uniform(0, 2 * np.pi, lines.size)


def force(t):
    return np.cos(np.multiply.outer(t, lines * w0) + phases).sum(axis=-1) / np.sqrt(lines.size / 2)


def rhs(t, s):
    k = 40.0 * (1 + 0.3 * np.cos(w0 * t))
    return [s[1], force(t) - 0.8 * s[1] - k * s[0]]


n = int(T * fs)
t = np.arange((P + 4) * n) / fs
x = solve_ivp(rhs, (0, t[-1]), [0.0, 0.0], t_eval=t, method="DOP853", rtol=1e-9, atol=1e-12).y[0][4 * n:]
f = force(t)[4 * n:]
f = f + 0.01 * f.std() * rng.standard_normal(f.size)
x = x + 0.01 * x.std() * rng.standard_normal(x.size)
folder = Path(tempfile.mkdtemp())
np.savetxt(folder / "rig.csv", np.column_stack([t[:P * n], f, x]), delimiter=",", comments="",
           header="time [s],force [N],displacement [m]")

# %%
# The command
# -----------
status = cli.main(["identify", str(folder / "rig.csv"), "--input", "force", "--output", "displacement",
                   "--period", "5", "--na", "2", "--nb", "0", "--ka", "1,0,0", "--kb", "0", "--scale", "b0=1",
                   "--out", str(folder / "rig-lptv")])
print("exit status", status, "(0: the model is consistent with the data)")

# %%
# The report's Bode figure
# ------------------------
# For a time-varying system the measured Y/U on a line holds every excited line's contribution
# through the branches G_k: the points follow the output the model predicts from the measured
# input (over that input), not the branch G_0 alone (third panel). The record's excited lines are
# adjacent, so it cannot separate the branches: the panel says so and draws the model's only.
m = lptv.read_measurements(folder / "rig.csv", u="force", y="displacement", period=T)
res = lptv.identify(m.u, m.y, na=2, nb=0, ka=[1, 0, 0], kb=0, w0=w0)
fig = lptv.plots.bode(res, fig=plt.figure(figsize=(6.4, 7.8), layout="constrained"))

# %%
# The residue tests
# -----------------
# Each test on its own statistic against its own threshold (Holm's level for its rank): the sum
# of normal scores over all rows with signal (z, two-sided) and the score test of one more
# harmonic on each coefficient (F with its own degrees of freedom).
fig = lptv.plots.residue_tests(res, fig=plt.figure(figsize=(6.4, 4.2), layout="constrained"))
