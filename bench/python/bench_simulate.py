"""lptv.simulate against scipy.linalg.solve_banded and a dense NumPy solve, side by side.

The paper-like model (METHOD.md section 8, K = 3: 7 diagonals) and a random-phase input on
every line 0..L; the output on lines 0..L. The routes:

- ``simulate``: lptv.simulate as a user calls it (adaptive guard: two or more factorisations);
- ``simulate/g``: lptv.simulate with the guard the adaptive run ended with (one factorisation);
- ``banded``: the same grid -(L+g)..L+g solved with scipy.linalg.solve_banded, A in LAPACK band
  storage built from model.a in NumPy (building A and B U is timed as well);
- ``dense``: numpy.linalg.solve on the dense A (lptv.reference when present), small L only.

Every call is timed whole (Python overhead included); the routes take turns, and each one's
fastest round is reported (the least disturbed by other work on the machine). The routes
must agree to 1e-10 of the output peak (asserted): all solve the same linear system, A is
diagonally dominant (harmonics below 40 % of the DC coefficient in every row), so their
difference is rounding.

Usage: python bench_simulate.py [max_lines]   (default 10^6)
"""
from __future__ import annotations

import sys
import time

import numpy as np
from scipy.linalg import solve_banded

import lptv
import lptv.examples as ex

try:
    from lptv.reference import simulate as dense_simulate
    DENSE_SOURCE = "lptv.reference.simulate"
except ImportError:  # the NumPy reference is optional here
    dense_simulate = None
    DENSE_SOURCE = "inline dense solve"

AGREE = 1e-10
DENSE_MAX_LINES = 1000


def _powers(model, lines, order):
    s = 1j * model.w0 * lines
    return s[None, :] ** np.arange(order + 1)[:, None]


def banded_route(model, U, guard):
    """Y on lines 0..L from solve_banded on the grid -(L+guard)..L+guard."""
    Lu = U.size - 1
    L = Lu + guard
    n = 2 * L + 1
    lines = np.arange(-L, L + 1)
    a, b, Ka, Kb = model.a, model.b, model.ka, model.kb
    pa = _powers(model, lines, model.na)
    # A[i + k, i] = sum_n a_{n,k} (j w_i)^n sits at ab[K + k, i] in LAPACK band storage.
    ab = np.empty((2 * Ka + 1, n), complex)
    for k in range(-Ka, Ka + 1):
        ab[Ka + k] = a[:, Ka + k] @ pa
    F = np.zeros(n, complex)
    F[L:L + Lu + 1] = U
    F[L - Lu:L] = np.conj(U[:0:-1])
    F[L] = U[0].real
    pb = _powers(model, lines, model.nb)
    rhs = np.zeros(n, complex)
    for k in range(-Kb, Kb + 1):
        v = (b[:, Kb + k] @ pb) * F  # column i's contribution to row i + k
        if k >= 0:
            rhs[k:] += v[:n - k]
        else:
            rhs[:n + k] += v[-k:]
    Y = solve_banded((Ka, Ka), ab, rhs, check_finite=False)
    return Y[L:L + Lu + 1]


def dense_route(model, U, guard):
    if dense_simulate is not None:
        return dense_simulate(model, U, guard=guard)
    Lu = U.size - 1
    L = Lu + guard
    n = 2 * L + 1
    lines = np.arange(-L, L + 1)
    K = model.ka
    pa = _powers(model, lines, model.na)
    A = np.zeros((n, n), complex)
    for k in range(-K, K + 1):
        v = model.a[:, K + k] @ pa
        i = np.arange(max(0, -k), min(n, n - k))
        A[i + k, i] = v[i]
    Kb = model.kb
    pb = _powers(model, lines, model.nb)
    B = np.zeros((n, n), complex)
    for k in range(-Kb, Kb + 1):
        v = model.b[:, Kb + k] @ pb
        i = np.arange(max(0, -k), min(n, n - k))
        B[i + k, i] = v[i]
    F = np.zeros(n, complex)
    F[L:L + Lu + 1] = U
    F[L - Lu:L] = np.conj(U[:0:-1])
    F[L] = U[0].real
    return np.linalg.solve(A, B @ F)[L:L + Lu + 1]


def timed(routes, reps):
    """Minimum wall time of each callable over `reps` rounds, and its result.

    The routes take turns within each round, so that a change of the machine's load
    affects them alike; the minimum is the least disturbed run (the machine is shared)."""
    out = [f() for f in routes]  # warm-up, also the results that are compared
    t = np.full((reps, len(routes)), np.inf)
    for r in range(reps):
        for i, f in enumerate(routes):
            t0 = time.perf_counter()
            f()
            t[r, i] = time.perf_counter() - t0
    return t.min(axis=0), out


def main(max_lines: int = 10**6):
    model = ex.paper_model()
    rng = np.random.default_rng(0)
    print(f"lptv.simulate vs scipy.linalg.solve_banded vs dense ({DENSE_SOURCE}); paper-like "
          f"model, input on every line 0..L, output lines 0..L; minimum wall times over interleaved rounds, calls whole")
    print(f"default solver: {lptv.simulate(model, np.ones(3), full_output=True).solver}\n")
    head = (f"{'L':>8} {'guard':>5} {'simulate':>10} {'simulate/g':>10} {'banded':>10} "
            f"{'dense':>10} {'sim/banded':>10} {'sim/g/band':>10} {'dense/sim':>10} {'max diff':>9}")
    print(head)
    L = 1000
    while L <= max_lines:
        U = np.exp(2j * np.pi * rng.uniform(size=L + 1)) / np.sqrt(L)
        U[0] = U[0].real
        reps = int(max(5, min(15, 3e5 / L))) if L < 10**6 else 3
        g = lptv.simulate(model, U, full_output=True).guard
        (t_sim, t_simg, t_band), (r, Yg, Yb) = timed(
            [lambda: lptv.simulate(model, U, full_output=True),
             lambda: lptv.simulate(model, U, guard=g),
             lambda: banded_route(model, U, g)], reps)
        results = [r.Y, Yg, Yb]
        t_dense = np.nan
        if L <= DENSE_MAX_LINES:
            (t_dense,), (Yd,) = timed([lambda: dense_route(model, U, g)], 1)
            results.append(Yd)
        peak = np.abs(Yb).max()
        diff = max(np.abs(Y - Yb).max() for Y in results) / peak
        assert diff <= AGREE, f"routes disagree at L = {L}: {diff:.1e}"
        print(f"{L:>8} {g:>5} {1e3 * t_sim:>8.2f}ms {1e3 * t_simg:>8.2f}ms "
              f"{1e3 * t_band:>8.2f}ms {1e3 * t_dense:>8.1f}ms {t_sim / t_band:>10.2f} "
              f"{t_simg / t_band:>10.2f} {t_dense / t_sim:>10.0f} {diff:>9.1e}")
        L *= 10
    # The fixed cost of one call: a tiny system, where the solve itself is negligible.
    U = np.zeros(11, complex)
    U[10] = 0.5
    g = lptv.simulate(model, U, full_output=True).guard
    (t_small, t_small_g, t_small_b), _ = timed(
        [lambda: lptv.simulate(model, U), lambda: lptv.simulate(model, U, guard=g),
         lambda: banded_route(model, U, g)], 200)
    print(f"\ncall overhead, L = 10 (guard {g}): simulate {1e6 * t_small:.0f} us, simulate/g "
          f"{1e6 * t_small_g:.0f} us, banded {1e6 * t_small_b:.0f} us")
    print("ratios > 1 mean lptv.simulate is slower; goal: sim/banded <= 1 at L = 10^5")


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 10**6)
