"""
A Monte Carlo study of the estimators
=====================================

R noise realisations of the paper's example, each fitted by WGTLS and SML: failures, residue
test rejections, the variance over the Cramer-Rao bound and the coverage of the 95 % intervals
per method. The README's study uses 100 realisations on all cores; 20 here keep the page quick.
The results are the same, bit for bit, on every executor and number of workers.
"""
import matplotlib.pyplot as plt

import lptv
from lptv.examples import PAPER_ID_LINES, PAPER_NOISE, paper_model, paper_multisine

mc = lptv.montecarlo(paper_model(), paper_multisine(seed=1), periods=8, runs=20, snr_in_db=50,
                     snr_out_db=30, methods="wgtls,sml", lines=PAPER_ID_LINES, seed=1,
                     executor="serial", progress=False, **PAPER_NOISE)
print(mc.report())

# %%
# Per parameter: bias, RMS, std, the bound and the coverage (a pandas table).
summary = mc.summary()
print(summary.head(8).to_string())

# %%
# The errors of one parameter over the realisations, and the coverage of every parameter.
fig, ax = plt.subplots()
mc.plot_errors(ax=ax)
fig, ax = plt.subplots()
mc.plot_coverage(ax=ax)
