"""The transient term of one continuous-time record, measured on the DFT of its samples.

METHOD.md section 17: for the Fourier coefficients of a record's periodic extension the
equation error of a continuous-time LPTV model is E_l = -T(j w_l), T a polynomial of degree
n - 1 (n = max(na, nb)) with real coefficients; the DFT of *samples* aliases the extension's
jump, so the identity holds only approximately. This script measures how well.

A record of L whole parameter periods of a known continuous-time model is integrated with
SUNDIALS CVODE (lptv.simulation.timedomain.free_response, rtol 1e-12) from a random initial state under a
band-limited input: a sum of F sinusoids of random frequencies, uniform in (0, w_max), random
phases, equal amplitudes. Its derivatives are exact, it is not periodic in the record, and it is
band-limited, so for any sampling faster than 2 w_max its samples determine it (a zero-order
hold would not: its steps are not band-limited and the continuous input between the samples
would not be the one the samples describe). The record is sampled with N0 = 2 OS l_fit / L
samples per period, OS the oversampling of the highest fitted line l_fit (the line of w_max +
K w0 on the record's grid of spacing w0 / L): Nyquist = OS w_fit.

On the fitted lines 1..l_fit the equation error E_l of the true model (the band sum of section 3
with harmonic k at k L lines, (j w_i)^n on the signed lines of the DFT) is fitted by real
polynomials of degree d in j w_l, d = n - 1 .. n + 3; reported per d: the residual relative to
|E| (how much of the transient the polynomial leaves), and in output units (divided by the mean
denominator A_0(j w_l)) the output noise std sigma_eq at which the residual's power equals the
noise's on the fitted lines, sum_l |r_l / A_0|^2 = l_fit sigma_eq^2 / N (E |V_l|^2 = sigma^2 / N
for white noise of std sigma on N samples). A fit whose noise std is well above sigma_eq sees
a bias well below its standard deviations (the bias along any direction is at most the
residual's projection, whose chi-square is l_fit (sigma_eq / sigma)^2 ... at most).

    python bench/python/ct_record_aliasing.py --model third_order --periods 2 --os 2 4 8 16 32
"""
from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from lptv.simulation import timedomain  # noqa: E402
from lptv.examples import paper_model, third_order_model  # noqa: E402


def band_limited_input(rng, w_max, F, nb, rms=1.0):
    """u(t) = sum_i A cos(w_i t + phi_i), w_i ~ U(0.02 w_max, w_max): returns the callable
    t -> (u, u', .., u^(nb)) and a vectorised u(t)."""
    w = rng.uniform(0.02 * w_max, w_max, F)
    phi = rng.uniform(0, 2 * np.pi, F)
    A = rms * np.sqrt(2.0 / F)

    def derivs(t):
        ph = w * t + phi
        c = A * np.exp(1j * ph)
        return np.array([(c * (1j * w) ** m).real.sum() for m in range(nb + 1)])

    def values(t):
        return (A * np.cos(np.outer(t, w) + phi)).sum(axis=1)

    return derivs, values


def ct_record(model, L, N0, w_max, seed, F=200, state_std=3.0):
    """Samples u, y of L periods (N = L N0) from a random state; noise-free."""
    rng = np.random.default_rng(seed)
    derivs, values = band_limited_input(rng, w_max, F, model.nb)
    x0 = state_std * rng.standard_normal(model.na)
    N = L * N0
    t = np.arange(N) * (model.period / N0)
    y = timedomain.free_response(model, derivs, t, x0=x0, rtol=1e-12)
    return values(t), y


def equation_error(model, U, Y, L, lines):
    """sum_n sum_k a_{n,k} (j w_{l-kL})^n Y_{l-kL} - (b likewise, U) on the given lines; the
    DFT index i stands for the signed line i (i < N/2) or i - N."""
    N = Y.size
    E = np.zeros(lines.size, dtype=complex)
    for coef, X, sign in ((model.a, Y, 1.0), (model.b, U, -1.0)):
        K = (coef.shape[1] - 1) // 2
        for k in range(-K, K + 1):
            src = lines - k * L
            s = 1j * src * model.w0 / L
            Xs = X[src % N]
            for p in range(coef.shape[0]):
                E += sign * coef[p, k + K] * s**p * Xs
    return E


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--model", choices=["third_order", "paper"], default="third_order")
    ap.add_argument("--periods", type=int, default=2)
    ap.add_argument("--os", type=int, nargs="+", default=[2, 4, 8, 16, 32])
    ap.add_argument("--w-max", type=float, default=None, help="input band (rad/s)")
    ap.add_argument("--seeds", type=int, default=3)
    args = ap.parse_args()
    m = third_order_model() if args.model == "third_order" else paper_model()
    L = args.periods
    w_max = args.w_max if args.w_max is not None else (4.0 if args.model == "third_order" else 0.25 * 240 * m.w0)
    K = max(m.ka, m.kb)
    dl = m.w0 / L                                   # the record's line spacing
    l_fit = int(np.ceil(w_max / dl)) + K * L        # the input band plus the sidebands
    n = max(m.na, m.nb)
    print(f"model {args.model}: na={m.na} nb={m.nb} K={K} w0={m.w0}; L={L}; input band {w_max:.3g} rad/s; "
          f"fitted lines 1..{l_fit} (w_fit = {l_fit * dl:.3g} rad/s); n = {n}")
    degrees = list(range(n - 1, n + 4))
    print(f"{'OS':>4} {'N':>6} {'seed':>4} {'rms y':>8} {'|E| rms':>9}  " +
          "  ".join(f"d={d}: r/E  sig_eq" for d in degrees))
    for os_ in args.os:
        N0 = 2 * os_ * l_fit // L
        N = L * N0
        for seed in range(args.seeds):
            t0 = time.perf_counter()
            u, y = ct_record(m, L, N0, w_max, seed)
            U, Y = np.fft.fft(u) / N, np.fft.fft(y) / N
            lines = np.arange(1, l_fit + 1)
            E = equation_error(m, U, Y, L, lines)
            s = 1j * lines * dl
            A0 = sum(m.a[p, (m.a.shape[1] - 1) // 2].real * s**p for p in range(m.na + 1))
            row = []
            for d in degrees:
                V = np.stack([s**j for j in range(d + 1)], axis=1)
                sc = np.abs(V).max(axis=0)
                Vs = V / sc
                M = np.concatenate([Vs.real, Vs.imag])
                c, *_ = np.linalg.lstsq(M, -np.concatenate([E.real, E.imag]), rcond=None)
                r = E + Vs @ c
                rel = np.linalg.norm(r) / np.linalg.norm(E)
                sig_eq = np.sqrt(np.sum(np.abs(r / A0) ** 2) * N / l_fit)
                row.append(f"{rel:9.2e} {sig_eq:8.2e}")
            print(f"{os_:4d} {N:6d} {seed:4d} {np.std(y):8.3f} {np.sqrt(np.mean(np.abs(E)**2)):9.2e}  "
                  + "  ".join(row) + f"   ({time.perf_counter() - t0:.1f} s)", flush=True)


if __name__ == "__main__":
    main()
