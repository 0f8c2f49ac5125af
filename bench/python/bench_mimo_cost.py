"""The cost of one MIMO fit against ny * nu single-input single-output fits of the same lines, and
against the LAPACK floor of its main factorisation (METHOD.md section 19).

    OPENBLAS_NUM_THREADS=1 python bench/python/bench_mimo_cost.py [--rounds 15] [--n 128 512]

The two-mass system with two inputs and two outputs (lptv.examples.mimo, FDS steady state, 3 %
noise on every channel, P = 8, Hadamard design with E = 2 experiments, lines 2..N/2-14 step 3)
is fitted by lptv.identify with WGTLS and SML (covariance included); the yardstick is ny * nu =
4 fits of a one-mass system (y'' + 0.8 y' + 4 (1 + 0.3 cos t) y = u) on the same lines, rows,
P and structure (na = 2, nb = 0, ka = [1, 0, 0]) by the C++ core. The floor: WGTLS's main
factorisation is the QR of the whitened real Jacobian (LAPACK dgeqrf of its shape, once per
iteration: (iterations + 1) QRs); SML's the banded Cholesky of the rows' residue covariance
(LAPACK zpbtrf, once per cost evaluation: at least 2 per accepted step and experiment). Timings
in the process, interleaved round by round, medians.
"""
from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
import scipy.linalg

import lptv
from lptv.examples import mimo as mx

P = 8


def data(n, seed=0):
    model = mx.SYSTEMS["2-in-2-out"]()[0]
    rng = np.random.default_rng(seed)
    lines = np.arange(2, n // 2 - 14, 3)
    d = lptv.mimo_multisines(lines, n, 2, seed=rng)
    pairs = []
    for e in range(2):
        Y = np.asarray(lptv.simulate(model, d.spectra[e], lines_out=n // 2)).reshape(n // 2 + 1, -1)
        y1 = np.fft.irfft(Y * n, n, axis=0)
        u1 = d.signals[e]
        pairs.append((u1[None] + 0.03 * u1.std(0) * rng.standard_normal((P, n, 2)),
                      y1[None] + 0.03 * y1.std(0) * rng.standard_normal((P, n, 2))))
    siso = lptv.Model([[0.6, 4.0, 0.6], [0.0, 0.8, 0.0], [0.0, 1.0, 0.0]], [[0.0, 1.0, 0.0]], w0=1.0)
    ms = lptv.multisine(lines, n, seed=1)
    y1 = lptv.time_signal(lptv.simulate(siso, ms.spectrum), n)
    u = ms.periods(P) + 0.03 * ms.periods(1).std() * rng.standard_normal((P, n))
    y = np.tile(y1, (P, 1)) + 0.03 * y1.std() * rng.standard_normal((P, n))
    return pairs, (u, y)


def median_time(f, rounds):
    return float(np.median([_once(f) for _ in range(rounds)]))


def _once(f):
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--n", type=int, nargs="+", default=[128, 512])
    args = ap.parse_args(argv)
    kw = dict(na=2, nb=0, ka=[1, 0, 0], kb=0, w0=1.0)
    print(f"bench_mimo_cost.py --rounds {args.rounds} --n {' '.join(map(str, args.n))}")
    for n in args.n:
        pairs, (u, y) = data(n)
        warnings.simplefilter("ignore")
        for method in ("wgtls", "sml"):
            res = lptv.identify(pairs, method=method, **kw)
            times = {"mimo": [], "siso": []}
            for _ in range(args.rounds):       # interleaved: one MIMO fit, then the 4 SISO fits
                times["mimo"].append(_once(lambda: lptv.identify(pairs, method=method, **kw)))
                times["siso"].append(_once(lambda: [lptv.identify(u, y, method=method, **kw) for _ in range(4)]))
            t_m, t_s = np.median(times["mimo"]), np.median(times["siso"])
            rows = res.lines.size
            n_xi = res.eta.size
            if method == "wgtls":
                J = np.random.default_rng(0).standard_normal((2 * rows * 2, n_xi))
                t_f = median_time(lambda: scipy.linalg.qr(J, mode="r", overwrite_a=False), args.rounds * 5)
                count = res.iterations + 1
                what = f"dgeqrf of {J.shape[0]} x {J.shape[1]}"
            else:
                per = rows // 2
                u_bw = 3 * 2 - 1
                A = np.zeros((u_bw + 1, per * 2), complex)
                A[-1] = 10.0
                A[:-1] = 0.1 * (1 + 1j)
                t_f = median_time(lambda: scipy.linalg.cholesky_banded(A, lower=False), args.rounds * 5)
                count = 2 * (2 * res.iterations + 1)
                what = f"zpbtrf of {per * 2} rows, half bandwidth {u_bw}, 2 experiments"
            print(f"N = {n} ({rows} rows over 2 experiments, {n_xi} parameters), {method}: one MIMO fit "
                  f"{1e3 * t_m:.2f} ms, 4 SISO fits (core) {1e3 * t_s:.2f} ms, ratio {t_m / t_s:.2f}; floor "
                  f"{count} x {1e6 * t_f:.1f} us ({what}) = {1e3 * count * t_f:.3f} ms, fit / floor "
                  f"{t_m / (count * t_f):.1f}")


if __name__ == "__main__":
    main()
