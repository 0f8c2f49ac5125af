"""
Several experiments, one model
==============================

Two records of the same LPTV system with different multisines (low lines, then high lines),
samples per period N and numbers of periods P, fitted into one model by the exact likelihood:
the rows of each record use its own spectra and noise, and the information of both adds up.
The standard deviations are compared with the Cramer-Rao bound of the two designs together and
of each alone.
"""
import numpy as np

import lptv
from lptv.examples import noisy_periods, paper_model

m = paper_model()                                  # w0 = 0.04 rad/s, 34 free parameters
records, designs = [], []
for lines, N, P, seed in ((range(10, 121, 10), 2048, 8, 1), (range(130, 241, 10), 1024, 5, 2)):
    ms = lptv.multisine(lines, N, seed=seed)       # low lines, then high lines
    y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), N)
    records.append(noisy_periods(ms.signal, y0, P, 50, 30, seed=seed))
    designs.append(ms)
res = lptv.identify(records, na=2, nb=1, ka=3, kb=3, w0=m.w0, lines=[range(1, 244)] * 2,
                    method="sml")
print("experiments:", res.n_experiments, " rows per record:", np.bincount(res.experiment))
print(res.verdict)

# %%
# Each record alone determines the parameters less well than both together; the high lines
# alone leave the model nearly unidentifiable (the warning below).
import matplotlib.pyplot as plt

free = res.parameter_std > 0
fig, ax = plt.subplots()
for i, (u, y) in enumerate(records):
    one = lptv.identify(u, y, na=2, nb=1, ka=3, kb=3, w0=m.w0, lines=range(1, 244), method="sml")
    print(f"record {i + 1} alone: median std {np.median(one.parameter_std[free]):.2e}")
    ax.semilogy(one.parameter_std[free], ".", label=f"record {i + 1} alone")
print(f"both records:     median std {np.median(res.parameter_std[free]):.2e}")
ax.semilogy(res.parameter_std[free], "k_", ms=10, label="both records")
ax.set_xlabel("parameter (eta_names order)")
ax.set_ylabel("standard deviation")
ax.legend()
