"""lptv.distortion by Monte Carlo: size on purely LPTV systems, power against a cubic output
nonlinearity, and the BLA's branches against the true HTF (next to htf_estimate's ratio).

For each system (the paper's design, lines 10 apart; the third-order system, lines 8 apart)
and P, R data sets of M = 6 random-phase realisations:

- size: the fraction of data sets in which a purely LPTV system is "detected" at the 1 % level
  (goal <= 5 %), and the fraction of the lines' p-values below 0.05 (5 % if calibrated);
- power: the same with y + c y^3 (a Wiener system) for a few c;
- BLA: the mean over entries of |G_BLA - G_true|^2 / var * (nu - 2) / nu (1 if unbiased and
  the variance right), and of |G_ratio - G_true|^2 / var for htf_estimate on one realisation.

    python bench/python/bench_distortion.py --runs 200
"""
from __future__ import annotations

import argparse
import os

import numpy as np

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import lptv  # noqa: E402
from lptv.examples import (DISCRETE_EXCITED, DISCRETE_N, THIRD_ORDER_EXCITED, discrete_model,  # noqa: E402
                           noisy_periods, paper_model, third_order_model)

SYSTEMS = {
    "paper": (paper_model, np.arange(10, 241, 10), 2048, (50.0, 30.0)),
    "third_order": (third_order_model, THIRD_ORDER_EXCITED, 1024, (40.0, 25.0)),
    # strongly time-varying (a frozen pole reaches 1.13): its HTF has branches out to +-20 near DC
    "discrete": (discrete_model, DISCRETE_EXCITED, DISCRETE_N, (45.0, 30.0)),
}


def data(system, M, P, rng, cubic=0.0):
    make, ex, N, snr = SYSTEMS[system]
    m = make()
    u, y = [], []
    for _ in range(M):
        ms = lptv.multisine(ex, N, amplitudes=np.sqrt(2.0 / ex.size), seed=rng)
        y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), N)
        a, b = noisy_periods(ms.signal, y0 + cubic * y0 ** 3, P, *snr, seed=rng)
        u.append(a)
        y.append(b)
    return m, ex, np.array(u), np.array(y)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--systems", nargs="*", default=["paper", "third_order"], choices=tuple(SYSTEMS))
    ap.add_argument("--periods", type=int, nargs="*", default=[4, 8, 16])
    ap.add_argument("--realisations", type=int, nargs="*", default=[6], help="M (one row per value)")
    args = ap.parse_args()
    R = args.runs
    print(f"R = {R} data sets per cell")
    print("| system | M | Kh | P | detected (pure LPTV) | lines with p < 0.05 | BLA mean scaled |z|^2 | ratio estimate "
          "mean |z|^2 | detected, c = 0.01 | c = 0.02 | c = 0.05 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for system, M, P in ((s_, M_, P_) for s_ in args.systems for M_ in args.realisations for P_ in args.periods):
        if True:
            rng = np.random.default_rng([P, list(SYSTEMS).index(system)] + ([M] if M != 6 else []))
            det, frac, bla, ratio = [], [], [], []
            for _ in range(R):
                m, ex, u, y = data(system, M, P, rng)
                d = lptv.distortion(u, y, w0=m.w0, ts=m.ts)
                det.append(d.detected)
                p = d.p_value[np.isfinite(d.p_value)]
                frac.append((np.sum(p < 0.05), p.size))
                if m.ts is not None:   # the branches against the true HTF: continuous time only (no wrap-around)
                    continue
                L = int(ex.max()) + 60
                G = lptv.htf(m, L, ex)
                for k in range(-d.branches, d.branches + 1):
                    for i, l in enumerate(ex):
                        b = d.bla[d.branches + k, i]
                        if np.isfinite(b):
                            nu = 2.0 * d.dof[l + k - 1]
                            bla.append(abs(b - G[l + k + L, i]) ** 2 / d.bla_var[d.branches + k, i] * (nu - 2) / nu)
                Kr = 3
                est = lptv.htf_estimate(u[0], y[0], w0=m.w0, ts=m.ts, excited=ex, branches=Kr)
                for kk in range(2 * Kr + 1):
                    ratio.extend(np.abs(est.G[kk] - G[ex + kk - Kr + L, np.arange(ex.size)]) ** 2 / est.std[kk] ** 2)
            power = []
            for c in (0.01, 0.02, 0.05):
                hits = []
                for _ in range(max(R // 4, 20)):
                    m, ex, u, y = data(system, M, P, rng, cubic=c)
                    hits.append(lptv.distortion(u, y, w0=m.w0, ts=m.ts).detected)
                power.append(np.mean(hits))
            det = np.mean(det)
            k, n = np.sum([f[0] for f in frac]), np.sum([f[1] for f in frac])
            print(f"| {system} | {M} | {d.branches} | {P} | {100 * det:.1f} +- {100 * np.sqrt(max(det * (1 - det), 1e-4) / R):.1f} % "
                  f"| {100 * k / n:.2f} % of {n} | "
                  + (f"{np.mean(bla):.3f} (median {np.median(bla):.3f}) | {np.mean(ratio):.2f} | " if bla else "- | - | ")
                  + " | ".join(f"{100 * p:.0f} %" for p in power) + " |", flush=True)


if __name__ == "__main__":
    main()
