"""
Which orders and how many harmonics? ``lptv.select``
====================================================

A grid of structures (na, nb, k harmonics on every coefficient) is fitted by WGTLS on the same
lines; the best two per harmonic count are refitted by the exact likelihood (SML) and ranked by
MDL, never choosing one the residue test rejects while another passes. The data are the
paper's example; its true structure is (2, 1, 3).
"""
import lptv
from lptv.examples import PAPER_ID_LINES, paper_measurements

m = paper_measurements(seed=1, periods=8)
sel = lptv.select(m["u"], m["y"], w0=m["w0"], na=range(1, 4), nb=range(0, 3), k=range(2, 5),
                  lines=PAPER_ID_LINES, executor="serial", progress=False)
print(sel.summary(6))
print("chosen (na, nb, k):", sel.choice)

# %%
# MDL and AIC of the candidates refined by SML (their costs are on one scale) against the
# number of free parameters: the cost falls as parameters are added, the penalty rises.
import matplotlib.pyplot as plt

refined = [r for r in sel.rows if r["method"] == "sml" and not r["error"]]
fig, ax = plt.subplots()
for key, marker in (("mdl", "o"), ("aic", "s")):
    ax.plot([r["n_free_parameters"] for r in refined], [r[key] for r in refined], marker,
            mfc="none", label=key.upper())
for r in refined:
    ax.annotate(f"({r['na']}, {r['nb']}, {r['k']})", (r["n_free_parameters"], r["mdl"]),
                textcoords="offset points", xytext=(5, 4), fontsize="small")
ax.set_xlabel("free parameters n")
ax.set_ylabel("criterion")
ax.set_title(f"chosen (na, nb, k) = {sel.choice}")
ax.legend()
