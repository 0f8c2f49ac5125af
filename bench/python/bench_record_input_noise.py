"""One record with a noisy input: the output-error fit's bias, and what ``input_noise_std``
makes of it (METHOD.md section 17, "A noisy input" and "A noisy input: the covariance and the
verdict"), by Monte Carlo.

The discrete LPTV system of bench_record_verdict.py (a NumPy loop of its difference equation,
from rest, 8 periods of 64 samples, output noise 1 %), its input measured with white noise of
2, 4, 6, 8 and 10 % of its std (``--levels``). Each record is fitted by ``lptv.identify_record``
with the right structure and ``input_noise_std`` the true level (8 draws). Per parameter: the
mean error of the estimate over its reported std (the bias in std), the same for
``eta_corrected`` over ``std_corrected``, the coverage of the 95 % intervals of each (the
corrected ones are ``RecordResult.confidence_interval``), and the Monte Carlo variance of
``eta_corrected`` over the mean of ``std_corrected ** 2``. The verdict: the share of records
whose right structure ``model_ok`` rejects (nominal size 1 %), with input_noise_std ("now") and
without it ("no s_u": the verdict as it was before the input noise entered it), with their
binomial standard errors, and how many of the rejections came from the score tests.

``--system continuous``: the continuous-time mass-spring system of bench_record_verdict.py
(solve_ivp, 4 periods of 128 samples, the input a band-limited sum of sinusoids) instead.

    python bench/python/bench_record_input_noise.py [runs] [--levels 2 4 6 8 10] [--system continuous]
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import lptv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_record_verdict import continuous_lptv, discrete_lptv  # noqa: E402

SYSTEMS = {
    # the discrete LPTV system of bench_record_verdict.py: 8 periods of 64 samples
    "discrete": (discrete_lptv,
                 {"a0.re0": 0.5, "a0.re1": 0.05 * np.cos(0.3), "a0.im1": 0.05 * np.sin(0.3), "a1.re0": -1.2,
                  "a2.re0": 1.0, "b0.re0": 1.0, "b0.re1": 0.05, "b0.im1": 0.0, "b1.re0": 0.5},
                 dict(na=2, nb=1, ka=[1, 0, 0], kb=[1, 0])),
    # its continuous-time mass-spring system (solve_ivp), 4 periods of 128 samples
    "continuous": (lambda seed: continuous_lptv(seed, L=4),
                   {"a0.re0": 4.0, "a0.re1": 0.2, "a0.im1": 0.0, "a1.re0": 0.4, "a2.re0": 1.0, "b0.re0": 1.0},
                   dict(na=2, nb=0, ka=[1, 0, 0], kb=0)),
}


def _rate(flags):
    n = len(flags)
    p = float(np.mean(flags))
    return p, np.sqrt(max(p * (1 - p), 1 / n) / n)


def _score_rejected(r):
    return any("score test" in e for e in r.model_errors)


def main(runs=200, levels=(2, 4, 6, 8, 10), system="discrete"):
    make, TRUTH, STRUCTURE = SYSTEMS[system]
    print(f"One record with a noisy input: {runs} records per level, {system} LPTV system, output noise 1 %")
    records = [make(seed) for seed in range(runs)]
    summary = []
    for pct in levels:
        rel = pct / 100
        t0 = time.perf_counter()
        raw, cor, ci_in, rej, rej_score, rej0 = [], [], [], [], [], []
        est, var = [], []
        for seed, (u0, y, kw) in enumerate(records):
            rng = np.random.default_rng(10_000 + seed)
            su = rel * np.std(u0)
            u = u0 + su * rng.standard_normal(u0.size)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = lptv.identify_record(u, y, **kw, **STRUCTURE, input_noise_std=su,
                                        seed=1_000_000 + seed)   # not the stream that made the record
                r0 = lptv.identify_record(u, y, **kw, **STRUCTURE)
            truth = np.array([TRUTH[n] for n in r.eta_names])
            free = r.parameter_std > 0
            raw.append(((r.eta - truth)[free] / r.parameter_std[free]))
            cor.append(((r.eta_corrected - truth)[free] / r.std_corrected[free]))
            ci = r.confidence_interval(0.95)[free]
            ci_in.append((ci[:, 0] < truth[free]) & (truth[free] < ci[:, 1]))
            est.append(r.eta_corrected[free])
            var.append(r.std_corrected[free] ** 2)
            rej.append(not r.model_ok)
            rej_score.append(_score_rejected(r))
            rej0.append(not r0.model_ok)
        names = [n for n, f in zip(r.eta_names, free) if f]
        R, C, CI = np.array(raw), np.array(cor), np.array(ci_in)
        ratio = np.var(np.array(est), axis=0, ddof=1) / np.mean(np.array(var), axis=0)
        se = 1 / np.sqrt(runs)
        print(f"\ninput noise {pct:g} % of u's std ({time.perf_counter() - t0:.0f} s); "
              f"sampling error of a mean ~{se:.2f} std, of a coverage ~{100 * np.sqrt(0.95 * 0.05 / runs):.1f} %, "
              f"of a variance ratio ~{np.sqrt(2 / (runs - 1)):.2f}")
        print(f"{'parameter':<10} {'bias/std':>9} {'corrected':>10} {'cover 95':>9} {'corrected':>10} {'MC/reported':>12}")
        for j, n in enumerate(names):
            print(f"{n:<10} {R[:, j].mean():>9.2f} {C[:, j].mean():>10.2f} {100 * np.mean(np.abs(R[:, j]) < 1.96):>8.1f}% "
                  f"{100 * np.mean(CI[:, j]):>9.1f}% {ratio[j]:>12.2f}")
        pooled = 100 * np.mean(CI)
        print(f"{'all':<10} {np.abs(R.mean(0)).max():>9.2f} {np.abs(C.mean(0)).max():>10.2f} "
              f"{100 * np.mean(np.abs(R) < 1.96):>8.1f}% {pooled:>9.1f}% {np.median(ratio):>12.2f}"
              "   (largest |mean|, pooled coverage, median ratio)")
        p, pse = _rate(rej)
        p0, p0se = _rate(rej0)
        print(f"verdict on the right structure: rejected {100 * p:.1f} % +- {100 * pse:.1f} "
              f"({int(np.sum(rej_score))} of {int(np.sum(rej))} by a score test); "
              f"without input_noise_std {100 * p0:.1f} % +- {100 * p0se:.1f}; nominal 1 %")
        summary.append((pct, pooled, 100 * CI.mean(0).min(), 100 * CI.mean(0).max(), 100 * p, 100 * pse,
                        100 * p0, 100 * p0se))
    print("\nlevel  pooled  per parameter  rejected (now)  rejected (no s_u)")
    for pct, pooled, lo, hi, p, pse, p0, p0se in summary:
        print(f"{pct:>4g} % {pooled:>6.1f} % {lo:>5.1f}-{hi:.1f} % {p:>7.1f} +- {pse:.1f} % {p0:>8.1f} +- {p0se:.1f} %")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="?", type=int, default=200)
    ap.add_argument("--levels", nargs="+", type=float, default=[2, 4, 6, 8, 10],
                    help="input noise levels, %% of the input's std")
    ap.add_argument("--system", choices=sorted(SYSTEMS), default="discrete")
    a = ap.parse_args()
    main(a.runs, tuple(a.levels), a.system)
