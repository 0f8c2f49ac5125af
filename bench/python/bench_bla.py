"""The parametric best linear time-periodic approximation by Monte Carlo: do its intervals,
which include the nonlinear variance, cover?

The paper's LPTV model followed by a cubic, y + c y^3 (a Wiener system, as the README's "From a
real rig"), M = 6 random-phase realisations of the paper's amplitude spectrum, P periods,
the paper's noise (50/30 dB). Each run draws new phases and noise, estimates the distortion
(lptv.distortion) and fits SML twice over the 6 realisations as experiments:

- "BLA": the experiments of DistortionResult.experiments(), output variances raised by the
  nonlinear level, so the covariance includes the stochastic distortion;
- "noise only": the same records with the periods' noise variances alone.

The BLA's parameters are those of the expected fit over the random phases; they are not known in
closed form, so the target is the Monte Carlo mean of the BLA fits (its own standard error,
std / sqrt(R), is reported). Per parameter: variance over the runs / mean reported variance, and
the coverage of the 95 % intervals around the target.

    python bench/python/bench_bla.py --runs 400 --cubic 0.02 --periods 4
    python bench/python/bench_bla.py --runs 400 --cubic 0.02 --periods 16
"""
from __future__ import annotations

import argparse
import os
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv.examples import PAPER_EXCITED, PAPER_N, noisy_periods, paper_model  # noqa: E402

M = 6
ROWS = [range(1, 244)] * M


def one(args):
    run, c, P = args
    rng = np.random.default_rng([run, 77])
    m = paper_model()
    u, y = [], []
    for _ in range(M):
        ms = lptv.multisine(PAPER_EXCITED, PAPER_N, amplitudes=np.sqrt(2 / PAPER_EXCITED.size), seed=rng)
        y0 = lptv.time_signal(lptv.simulate(m, ms.spectrum), PAPER_N)
        a, b = noisy_periods(ms.signal, y0 + c * y0**3, P, 50, 30, seed=rng)
        u.append(a)
        y.append(b)
    u, y = np.array(u), np.array(y)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = lptv.distortion(u, y, w0=m.w0)
        bla = lptv.identify(d.experiments(), na=2, nb=1, ka=3, kb=3, lines=ROWS, method="sml")
        plain = lptv.identify([(u[i], y[i]) for i in range(M)], na=2, nb=1, ka=3, kb=3, w0=m.w0,
                              lines=ROWS, method="sml")
    return (bla.eta, bla.parameter_std, plain.eta, plain.parameter_std, bool(d.detected))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--cubic", type=float, default=0.02)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--periods", type=int, default=4)
    args = ap.parse_args()
    t0 = time.time()
    with ProcessPoolExecutor(args.workers) as ex:
        out = list(ex.map(one, [(r, args.cubic, args.periods) for r in range(args.runs)], chunksize=4))
    R = len(out)
    eb, sb, ep, sp, det = (np.array([o[i] for o in out]) for i in range(5))
    free = sb[0] > 0
    names = np.array(lptv.identify.__globals__["_core"].Parametrisation(2, 1, [3] * 3, [3] * 2, [], 1.0, 0.0)
                     .eta_names)[free]
    target = eb.mean(0)[free]
    print(f"# {R} runs in {time.time() - t0:.0f} s; cubic c = {args.cubic}, M = {M}, P = {args.periods}; "
          f"distortion detected in {100 * det.mean():.0f} % of the runs")
    print(f"{'parameter':>10} {'target':>10} {'se(target)':>10} {'BLA var/rep':>11} {'BLA cover':>9} "
          f"{'noise-only var/rep':>18} {'noise-only cover':>16}")
    rows = []
    for j, n in enumerate(names):
        col = np.flatnonzero(free)[j]
        sd_mc = eb[:, col].std(ddof=1)
        vr_b = sd_mc**2 / np.mean(sb[:, col] ** 2)
        cov_b = np.mean(np.abs(eb[:, col] - target[j]) <= 1.959964 * sb[:, col])
        sd_p = ep[:, col].std(ddof=1)
        vr_p = sd_p**2 / np.mean(sp[:, col] ** 2)
        cov_p = np.mean(np.abs(ep[:, col] - ep[:, col].mean()) <= 1.959964 * sp[:, col])
        rows.append((vr_b, cov_b, vr_p, cov_p))
        print(f"{n:>10} {target[j]:10.5f} {sd_mc / np.sqrt(R):10.5f} {vr_b:11.3f} {100 * cov_b:8.1f}% "
              f"{vr_p:18.3f} {100 * cov_p:15.1f}%")
    a = np.array(rows)
    print(f"pooled: BLA coverage {100 * a[:, 1].mean():.1f} % (per parameter {100 * a[:, 1].min():.1f}-"
          f"{100 * a[:, 1].max():.1f} %, binomial std {100 * np.sqrt(0.95 * 0.05 / R):.1f} %), var/rep median "
          f"{np.median(a[:, 0]):.2f}; noise-only coverage {100 * a[:, 3].mean():.1f} %, var/rep median "
          f"{np.median(a[:, 2]):.2f} (sampling error of a variance ratio sqrt(2/(R-1)) = "
          f"{np.sqrt(2 / (R - 1)):.2f})")


if __name__ == "__main__":
    main()
