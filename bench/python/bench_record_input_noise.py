"""One record with a noisy input: the output-error fit's bias, and what ``input_noise_std``
makes of it (METHOD.md section 17, "A noisy input"), by Monte Carlo.

The discrete LPTV system of bench_record_verdict.py (a NumPy loop of its difference equation,
from rest, 8 periods of 64 samples, output noise 1 %), its input measured with white noise of
3, 5 and 10 % of its std. Each record is fitted by ``lptv.identify_record`` with the right
structure and ``input_noise_std`` the true level (8 draws). Per parameter: the mean error of the
estimate over its reported std (the bias in std), the same for ``eta_corrected`` over
``std_corrected``, and the coverage of the 95 % intervals of each.

    python bench/python/bench_record_input_noise.py [runs]
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import lptv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_record_verdict import discrete_lptv  # noqa: E402

TRUTH = {"a0.re0": 0.5, "a0.re1": 0.05 * np.cos(0.3), "a0.im1": 0.05 * np.sin(0.3), "a1.re0": -1.2,
         "a2.re0": 1.0, "b0.re0": 1.0, "b0.re1": 0.05, "b0.im1": 0.0, "b1.re0": 0.5}
STRUCTURE = dict(na=2, nb=1, ka=[1, 0, 0], kb=[1, 0])


def main(runs=200):
    print(f"One record with a noisy input: {runs} records per level, discrete LPTV system, output noise 1 %")
    for rel in (0.03, 0.05, 0.10):
        t0 = time.perf_counter()
        raw, cor = [], []
        for seed in range(runs):
            u0, y, kw = discrete_lptv(seed)
            rng = np.random.default_rng(10_000 + seed)
            su = rel * np.std(u0)
            u = u0 + su * rng.standard_normal(u0.size)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = lptv.identify_record(u, y, w0=kw["w0"], ts=1.0, **STRUCTURE, input_noise_std=su,
                                        seed=1_000_000 + seed)   # not the stream that made the record
            truth = np.array([TRUTH[n] for n in r.eta_names])
            free = r.parameter_std > 0
            raw.append(((r.eta - truth)[free] / r.parameter_std[free]))
            cor.append(((r.eta_corrected - truth)[free] / r.std_corrected[free]))
        names = [n for n, f in zip(r.eta_names, free) if f]
        R, C = np.array(raw), np.array(cor)
        se = 1 / np.sqrt(runs)
        print(f"\ninput noise {100 * rel:g} % of u's std ({time.perf_counter() - t0:.0f} s); "
              f"sampling error of a mean ~{se:.2f} std, of a coverage ~{100 * np.sqrt(0.95 * 0.05 / runs):.1f} %")
        print(f"{'parameter':<10} {'bias/std':>9} {'corrected':>10} {'cover 95':>9} {'corrected':>10}")
        for j, n in enumerate(names):
            print(f"{n:<10} {R[:, j].mean():>9.2f} {C[:, j].mean():>10.2f} {100 * np.mean(np.abs(R[:, j]) < 1.96):>8.1f}% "
                  f"{100 * np.mean(np.abs(C[:, j]) < 1.96):>9.1f}%")
        print(f"{'all':<10} {np.abs(R.mean(0)).max():>9.2f} {np.abs(C.mean(0)).max():>10.2f} "
              f"{100 * np.mean(np.abs(R) < 1.96):>8.1f}% {100 * np.mean(np.abs(C) < 1.96):>9.1f}%   (largest |mean|, pooled coverage)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
