"""
From a recorded experiment to a model
=====================================

A record as a rig writes it: one long CSV with columns ``u`` and ``y``, sampled at 100 Hz,
with a multisine of period 10 s repeated 8 times. Here the rig is a mass-spring-damper
1 / (s^2 + 4 s + 100) with noise on both channels. The file is read with its sampling frequency
and period (which split it into whole periods), checked for a start-up transient, and a
continuous-time model is identified by the exact likelihood with the uncertainty of every
parameter, the poles with their damping, a Bode plot with the model's 95 % band and the
simulated against the measured output. ``lptv identify record.csv --fs 100 --period 10 --na 2
--nb 0 --method sml`` does the same from the command line and writes a report.
"""
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import lptv
import lptv.plots

fs, period, P = 100.0, 10.0, 8
N = int(fs * period)
rig = lptv.Model.from_tf([1.0], [1.0, 4.0, 100.0], w0=2 * np.pi / period)
ms = lptv.multisine(range(1, 51), N, seed=0)          # lines 1..50: 0.1 to 5 Hz
y1 = lptv.time_signal(lptv.simulate(rig, ms.spectrum), N)
rng = np.random.default_rng(1)
u = np.tile(ms.signal, P) + 0.01 * ms.signal.std() * rng.standard_normal(P * N)
y = np.tile(y1, P) + 0.03 * y1.std() * rng.standard_normal(P * N)
record = Path(tempfile.mkdtemp()) / "record.csv"
np.savetxt(record, np.column_stack([u, y]), delimiter=",", header="u,y", comments="")

# %%
# Read, check, identify
# ---------------------
m = lptv.read_measurements(record, fs=fs, period=period)
print("periods x samples:", m.u.shape)
check = lptv.check_record(m.u, m.y)   # a start-up transient? periods cut at the wrong length?
print(f"first period against the others: {check.transient_ratio:.2f} (a transient above "
      f"{check.transient_threshold}); findings: {list(check.messages) or 'none'}")
res = lptv.identify(m.u, m.y, na=2, nb=0, w0=2 * np.pi / period, lines="excited", method="sml")
print(res.verdict)
for row in lptv.parameter_table(res):
    print(f"{row['name']:>8} = {row['value']:9.4f} +- {row['std']:.4f}")

# %%
# Poles, natural frequency and damping with their standard deviations (first-order propagation).
tab = lptv.lti_table(res)
for p in tab["poles"]:
    print(f"pole {p['pole']:.4f}: wn = {p['wn']:.4f} +- {p['wn_std']:.4f} rad/s, "
          f"zeta = {p['zeta']:.4f} +- {p['zeta_std']:.4f}   (true: wn = 10, zeta = 0.2)")

# %%
# Bode plot and the simulated output
# ----------------------------------
fig = lptv.plots.bode(res, hz=True, fig=plt.figure(figsize=(6.4, 5.0)))
cmp = lptv.compare(res, m.u, m.y)
fig, ax = plt.subplots()
lptv.plots.compare(cmp, ax=ax)
print(f"fit {cmp['fit']:.1f} %")
