"""
Is the periodic system stable? Floquet
======================================

The frozen (instantaneous) poles of an LPTV system do not tell whether it is stable; its
characteristic multipliers over one period do. The damped Mathieu equation
y'' + 2 zeta wn y' + wn^2 (1 + eps cos(w0 t)) y = u, pumped at w0 = 2 wn, has every frozen pole
at real part -zeta wn, yet it is unstable (parametric resonance) once eps exceeds about 4 zeta.
"""
import matplotlib.pyplot as plt
import numpy as np

import lptv
from lptv.examples import mathieu_model

m = mathieu_model(zeta=0.02, wn=1.0, eps=0.1, w0=2.0)
print("largest real part of the frozen poles:",
      lptv.frozen_poles(m, np.linspace(0, m.period, 50)).real.max())
f = lptv.floquet(m)
print("stable:", f.is_stable, " multipliers:", f.multipliers.real.round(4))

# %%
# The stability boundary
# ----------------------
# The spectral radius (the largest multiplier's magnitude) against the pump depth eps, for two
# dampings: it crosses 1 near eps = 4 zeta, where the frozen poles still say "stable".
eps = np.linspace(0.0, 0.3, 31)
fig, ax = plt.subplots()
for zeta in (0.02, 0.05):
    rho = [lptv.floquet(mathieu_model(zeta=zeta, wn=1.0, eps=e, w0=2.0)).spectral_radius for e in eps]
    ax.plot(eps, rho, ".-", label=f"zeta = {zeta}")
    ax.axvline(4 * zeta, color="0.6", lw=0.8, ls=":")
ax.axhline(1.0, color="k", lw=0.8)
ax.set_xlabel("pump depth eps")
ax.set_ylabel("Floquet spectral radius")
ax.legend()
