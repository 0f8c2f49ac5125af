"""
The paper's example: simulate, measure, identify
================================================

An LPTV system with na = 2, nb = 1 and 3 harmonics on every coefficient, excited by a
24-line multisine, simulated by the frequency-domain simulator (one sparse solve), measured
over 8 noisy periods (50 dB SNR at the input, 30 dB at the output) and identified by the
weighted GTLS of the paper and by the exact likelihood (SML), with the standard deviation of
every parameter next to its Cramer-Rao bound. This is the README's first example.
"""
import matplotlib.pyplot as plt
import numpy as np

import lptv
import lptv.plots
from lptv.examples import noisy_periods, paper_model, paper_multisine

model = paper_model()                       # na=2, nb=1, 3 harmonics on every coefficient
ms = paper_multisine(seed=1)                # 24 lines, N = 2048 samples per period
Y = lptv.simulate(model, ms.spectrum)       # steady-state output spectrum (one sparse solve)
y0 = lptv.time_signal(Y, ms.n_samples)      # one period in time
u, y = noisy_periods(ms.signal, y0, 8, 50, 30, seed=2)   # 8 periods, SNR 50 dB in / 30 dB out

res = lptv.identify(u, y, na=2, nb=1, ka=3, kb=3, w0=model.w0, lines=range(1, 244), method="wgtls")
print(res.summary())

# %%
# The exact likelihood and the Cramer-Rao bound
# ---------------------------------------------
# SML starts from WGTLS; its standard deviations are close to the bound of the design (the
# noise variances per line of one period's spectrum: white noise of std ``s`` in ``N`` samples
# gives ``s**2 / N``).
sml = lptv.identify(u, y, na=2, nb=1, ka=3, kb=3, w0=model.w0, lines=range(1, 244), method="sml")
su, sy = ms.signal.std() * 10 ** (-50 / 20), y0.std() * 10 ** (-30 / 20)
bound = lptv.crb(model, ms, var_u=su ** 2 / ms.n_samples, var_y=sy ** 2 / ms.n_samples, periods=8)
for name, sd, crb in list(zip(sml.eta_names, sml.parameter_std, bound.std))[:6]:
    print(f"{name:>10}  std {sd:.2e}   CRB {crb:.2e}")

# %%
# Frozen poles and the predicted output
# -------------------------------------
# The instantaneous ("frozen") poles over one period, true and estimated, and the error of the
# output predicted by the estimated model. ``lptv.plots`` draws on the ``ax`` it is given.
t = np.linspace(0, model.period, 100)
fig, ax = plt.subplots()
lptv.plots.frozen_poles_zeros(t, poles_true=lptv.frozen_poles(model, t),
                              poles_est=lptv.frozen_poles(res.model, t), ax=ax)
err = np.abs(lptv.simulate(res.model, ms.spectrum) - Y)[1:244]
print(f"largest predicted-output error {err.max():.2e}, output peak {np.abs(Y).max():.2e}")
