"""htf_estimate's overlap flags on the paper's design: how many of the entries biased by the
neighbours' far branches are flagged, and how the unflagged entries compare with the true HTF.

Per seed of lptv.examples.paper_measurements (P = 8), branches -4..4 at the 24 excited lines:
the bias of the noise-free ratio Y0_{l+k} / U0_l against the true HTF (lptv.htf) in units of
the entry's std, the flags, and |z|^2 = |G_est - G_true|^2 / var (F(2, 14), mean 1.17, without
bias).

    python bench/python/bench_htf_overlap.py [seeds]      (default 5)
"""
import sys

import numpy as np

import lptv
from lptv.examples import paper_measurements

seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
ex, Kh, L = np.arange(10, 241, 10), 4, 300
rows = []
for seed in range(seeds):
    d = paper_measurements(seed=seed, periods=8)
    est = lptv.htf_estimate(d["u"], d["y"], w0=d["w0"], excited=ex, branches=Kh)
    G = lptv.htf(d["model"], L, ex)
    Gt = np.array([[G[l + k + L, i] for i, l in enumerate(ex)] for k in range(-Kh, Kh + 1)])
    Gn = np.array([[d["Y0"][l + k] / d["U0"][l] for l in ex] for k in range(-Kh, Kh + 1)])
    rows.append((np.abs(Gn - Gt) / est.std, est.overlapped, np.abs(est.G - Gt) ** 2 / est.std ** 2))
bias, fl, z2 = (np.concatenate([r[i].ravel() for r in rows]) for i in range(3))
print(f"{seeds} seeds, {bias.size} entries: {100 * fl.mean():.1f} % flagged")
print(f"bias > 3 std: {np.sum(bias > 3)}, of which flagged {np.sum(fl & (bias > 3))}")
print(f"bias > 1 std: {np.sum(bias > 1)}, of which flagged {np.sum(fl & (bias > 1))}")
print(f"mean |z|^2 against the true HTF: all entries {z2.mean():.2f}, unflagged {z2[~fl].mean():.2f}, "
      f"flagged {z2[fl].mean():.2f}; largest unflagged bias {bias[~fl].max():.1f} std")
