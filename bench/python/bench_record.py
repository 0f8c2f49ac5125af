"""lptv.identify_record by Monte Carlo: bias, variance against the Cramer-Rao bound, coverage.

The discrete-time example (lptv.examples.discrete_model), one record of L whole periods from a
random initial state under white-noise input (both fixed: the input and state of seed 0), R
realisations of white output noise (std 0.01). For each realisation the record is identified
with the transient term and the noise level from the residual (the defaults). The bound: the
covariance reported for the noise-free record with the true noise variance given (the inverse
Fisher information at the truth for this input). Reported per parameter and pooled: |bias| /
std, the Monte Carlo variance over the bound and over the mean reported variance, and the
coverage of the 95 % intervals; and the same fit without the transient term (noise model of the
fit with it) for the bias it leaves.

    python bench/python/bench_record.py --runs 300 --periods 4 8

With ``--continuous``: the continuous-time third-order example (lptv.examples.third_order_model),
one CVODE record per length (lptv.examples.continuous_record, seed 0: a band-limited sum of
200 sinusoids up to 4 rad/s from a random state, 1312 samples per period, the fitted band at a
quarter of Nyquist), output noise std 0.01, identify_record(..., continuous=True) with its
defaults (transient degree n + 1 = 4).

    python bench/python/bench_record.py --continuous --runs 300 --periods 2 4
"""
from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv import _core  # noqa: E402
from lptv.examples import (DISCRETE_STRUCTURE, THIRD_ORDER_STRUCTURE, continuous_record,  # noqa: E402
                           discrete_model, third_order_model, transient_record)

NOISE = 0.01


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=300)
    ap.add_argument("--periods", type=int, nargs="+", default=None)
    ap.add_argument("--continuous", action="store_true", help="the continuous-time third-order example")
    ap.add_argument("--known-noise", action="store_true",
                    help="give the fits the true noise variance (separates the residual noise model's part)")
    args = ap.parse_args()
    if args.continuous:
        m = third_order_model()
        par = _core.Parametrisation(3, 1, [2, 1, 0, 0], [2, 0], [], m.w0, 0.0)
        periods = args.periods or [2, 4]
    else:
        m = discrete_model()
        par = _core.Parametrisation(2, 1, [2, 1, 0], [2, 0], [], m.w0, 1.0)
        periods = args.periods or [4, 8]
    truth = np.asarray(par.xi_from_theta(par.theta_from_model(m._cpp)))
    for L in periods:
        if args.continuous:
            u, y0, ts = continuous_record(m, periods=L, noise_std=0.0, seed=0)
            kw = dict(THIRD_ORDER_STRUCTURE, w0=m.w0, ts=ts, continuous=True)
        else:
            u, y0 = transient_record(m, periods=L, noise_std=0.0, seed=0)
            kw = dict(DISCRETE_STRUCTURE, w0=m.w0, ts=1.0)
        N = u.size
        true_var = NOISE**2 / N
        crb = lptv.identify_record(u, y0, **kw, noise=true_var)
        free = crb.parameter_std > 0
        names = np.array(crb.eta_names)[free]
        bound = np.diag(crb.covariance)[free]
        rng = np.random.default_rng(1000 + L)
        est, var, inside, est_nt, cost = [], [], [], [], []
        t0 = time.perf_counter()
        for _ in range(args.runs):
            y = y0 + NOISE * rng.standard_normal(N)
            r = lptv.identify_record(u, y, **kw, **(dict(noise=true_var) if args.known_noise else {}))
            e = r.eta[free]
            s = r.parameter_std[free]
            est.append(e)
            var.append(s**2)
            inside.append(np.abs(e - truth[free]) <= 1.959964 * s)
            cost.append(r.cost_ratio)
            nt = lptv.identify_record(u, y, **kw, transient=False, noise=r.noise_var)
            est_nt.append(nt.eta[free])
        el = time.perf_counter() - t0
        est, var, inside, est_nt = map(np.array, (est, var, inside, est_nt))
        R = args.runs
        bias = est.mean(0) - truth[free]
        sd = est.std(0, ddof=1)
        vr_crb = sd**2 / bound
        vr_rep = sd**2 / var.mean(0)
        cov = inside.mean(0)
        bias_nt = est_nt.mean(0) - truth[free]
        print(f"L = {L} periods (N = {N}), R = {R}, noise std {NOISE}: {1e3 * el / (2 * R):.0f} ms per fit; "
              f"mean cost / dof {np.mean(cost):.3f}")
        print(f"{'parameter':>10} {'|bias|/std':>10} {'var/CRB':>8} {'var/rep':>8} {'cover95':>8} "
              f"{'|bias|/std no T':>15}")
        for i, n in enumerate(names):
            print(f"{n:>10} {abs(bias[i]) / sd[i]:10.3f} {vr_crb[i]:8.3f} {vr_rep[i]:8.3f} "
                  f"{100 * cov[i]:7.1f}% {abs(bias_nt[i]) / sd[i]:15.2f}")
        se_cov = 100 * np.sqrt(0.95 * 0.05 / R)
        print(f"pooled: |bias|/std max {np.max(np.abs(bias) / sd):.3f} (a mean of R draws: 1/sqrt(R) = "
              f"{1 / np.sqrt(R):.3f}); var/CRB median {np.median(vr_crb):.3f} range {vr_crb.min():.3f}-"
              f"{vr_crb.max():.3f} (sampling error of a variance ratio: sqrt(2/(R-1)) = "
              f"{np.sqrt(2 / (R - 1)):.3f}); coverage {100 * cov.mean():.1f} % (per parameter "
              f"{100 * cov.min():.1f}-{100 * cov.max():.1f} %, binomial std {se_cov:.1f} %); without T: "
              f"|bias|/std {np.min(np.abs(bias_nt) / sd):.1f}-{np.max(np.abs(bias_nt) / sd):.1f}")
        print(flush=True)


if __name__ == "__main__":
    main()
