"""The verdict of one record (METHOD.md section 17): its size and power by Monte Carlo.

Records are simulated here, outside lptv (a NumPy loop of a difference equation with periodic
coefficients, scipy.signal.lfilter, scipy.integrate.solve_ivp), from rest under filtered noise
(discrete time) or a band-limited sum of sinusoids (continuous time), with white output noise.
Each record is fitted by ``lptv.identify_record`` with the right structure (the rejection rate
is the test's size, nominal 1 %) and with wrong ones (the rejection rate is its power):

- "discrete LPTV": y(t+2) - 1.2 y(t+1) + a0(t) y(t) = 0.5 u(t+1) + b0(t) u(t), a0 = 0.5 + 0.1
  cos(w0 t + 0.3), b0 = 1 + 0.1 cos(w0 t) (a harmonic of 5 % of b0's mean at +-1), 64 samples per
  period, 8 periods, noise 1 % of y's std; wrong: one order too few, b0's harmonic missing;
- "discrete LTI": a third-order Butterworth low-pass (scipy.signal.butter, lfilter), 512 samples,
  noise 2 %; wrong: one order too few;
- "continuous LPTV": m x'' + c x' + k(t) x = f, k = k0 (1 + 0.1 cos(w0 t)) (5 % harmonics),
  integrated by solve_ivp (rtol 1e-10), 8 periods of 128 samples (and 4, "continuous, L = 4"),
  f a sum of 40 sinusoids below a quarter of Nyquist, noise 1 %; wrong: k's harmonic missing,
  one order too few.

    python bench/python/bench_record_verdict.py [runs] [continuous runs]

Prints per system and structure the rejection rate with its binomial standard error, and the
median cost ratio (which does not tell a wrong structure from a right one).
"""
from __future__ import annotations

import sys
import time
import warnings

import numpy as np
from scipy import integrate, signal

import lptv


def discrete_lptv(seed, N0=64, L=8, noise=0.01, harm=0.05):
    rng = np.random.default_rng(seed)
    N, w0 = N0 * L, 2 * np.pi / N0
    t = np.arange(N + 2)
    bf, af = signal.butter(4, 0.4)
    u = signal.lfilter(bf, af, rng.standard_normal(N + 2))
    a0 = 0.5 + 0.1 * np.cos(w0 * t + 0.3)
    b0 = 1.0 + 2 * harm * np.cos(w0 * t)
    y = np.zeros(N + 2)
    for k in range(N):
        y[k + 2] = 0.5 * u[k + 1] + b0[k] * u[k] + 1.2 * y[k + 1] - a0[k] * y[k]
    y = y[:N] + noise * np.std(y[:N]) * rng.standard_normal(N)
    return u[:N], y, dict(w0=w0, ts=1.0)


def discrete_lti(seed, N0=64, L=8, noise=0.02):
    rng = np.random.default_rng(seed)
    N = N0 * L
    b, a = signal.butter(3, 0.3)
    b = np.r_[0.0, b[:-1]]           # a delay: b(t+3) = 0, so nb = 2
    bf, af = signal.butter(4, 0.5)
    u = signal.lfilter(bf, af, rng.standard_normal(N))
    y = signal.lfilter(b, a, u)
    y = y + noise * np.std(y) * rng.standard_normal(N)
    return u, y, dict(w0=2 * np.pi / N0, ts=1.0)


def continuous_lptv(seed, N0=128, L=8, noise=0.01, m=1.0, c=0.4, k0=4.0, harm=0.05):
    rng = np.random.default_rng(seed)
    period = 10.0
    w0, ts = 2 * np.pi / period, period / N0
    N = N0 * L
    wmax = 0.25 * np.pi / ts                      # a quarter of Nyquist
    freqs = rng.uniform(0.05, wmax, 40)
    amps = rng.standard_normal(40) / np.sqrt(20)
    phases = rng.uniform(0, 2 * np.pi, 40)

    def f(t):
        return np.sum(amps * np.cos(freqs * t + phases))

    def rhs(t, s):
        k = k0 * (1 + 2 * harm * np.cos(w0 * t))
        return [s[1], (f(t) - c * s[1] - k * s[0]) / m]

    tt = np.arange(N) * ts
    sol = integrate.solve_ivp(rhs, (0, tt[-1]), [0.0, 0.0], t_eval=tt, rtol=1e-10, atol=1e-12, method="DOP853")
    u = np.array([f(t) for t in tt])
    y = sol.y[0] + noise * np.std(sol.y[0]) * rng.standard_normal(N)
    return u, y, dict(w0=w0, ts=ts, continuous=True)


SYSTEMS = {
    "discrete LPTV": (discrete_lptv, {
        "right (na 2, nb 1, a0 and b0 K 1)": dict(na=2, nb=1, ka=[1, 0, 0], kb=[1, 0]),
        "one order too few (na 1)": dict(na=1, nb=1, ka=[1, 0], kb=[1, 0]),
        "b0's 5 % harmonic missing": dict(na=2, nb=1, ka=[1, 0, 0], kb=[0, 0])}),
    "discrete LTI": (discrete_lti, {
        "right (na 3, nb 2)": dict(na=3, nb=2),
        "one order too few (na 2, nb 1)": dict(na=2, nb=1)}),
    "continuous LPTV": (continuous_lptv, {
        "right (na 2, nb 0, a0 K 1)": dict(na=2, nb=0, ka=[1, 0, 0], kb=0),
        "k's 5 % harmonic missing (LTI)": dict(na=2, nb=0),
        "one order too few (na 1)": dict(na=1, nb=0, ka=[1, 0], kb=0)}),
    "continuous, L = 4": (lambda seed: continuous_lptv(seed, L=4), {
        "right (na 2, nb 0, a0 K 1)": dict(na=2, nb=0, ka=[1, 0, 0], kb=0),
        "k's 5 % harmonic missing (LTI)": dict(na=2, nb=0)}),
}


def main(runs=400, ct_runs=100):
    print(f"The verdict of one record: rejection rates over {runs} records ({ct_runs} continuous-time), "
          f"nominal size {100 * lptv.judgement.one_record_verdict.ALPHA:g} %")
    print(f"{'system':<17} {'structure':<36} {'rejected':>17} {'cost ratio (median)':>20}")
    for system, (make, structures) in SYSTEMS.items():
        n = ct_runs if system.startswith("continuous") else runs
        t0 = time.perf_counter()
        rej = {s: [] for s in structures}
        ratio = {s: [] for s in structures}
        for seed in range(n):
            u, y, kw = make(seed)
            for name, st in structures.items():
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    r = lptv.identify_record(u, y, **kw, **st)
                rej[name].append(not r.model_ok)
                ratio[name].append(r.cost_ratio)
        for name in structures:
            p = float(np.mean(rej[name]))
            se = np.sqrt(max(p * (1 - p), 1 / n) / n)
            print(f"{system:<17} {name:<36} {100 * p:>8.1f} % +- {100 * se:.1f} {np.median(ratio[name]):>20.3f}")
        print(f"{'':<17} ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))
