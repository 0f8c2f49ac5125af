"""lptv.simulate against scipy.linalg.solve_banded and a dense NumPy solve, side by side.

The paper-like model (METHOD.md section 8, K = 3: 7 diagonals) and a random-phase input on
every line 0..L; the output on lines 0..L. The routes:

- ``simulate``: lptv.simulate as a user calls it (solver 'auto', adaptive guard: two or more
  factorisations);
- ``sim/g``: lptv.simulate with the guard the adaptive run ended with (one factorisation);
- ``klu``, ``klu/g``: the same two with solver='klu';
- ``banded``: the same grid -(L+g)..L+g solved with scipy.linalg.solve_banded, A in LAPACK band
  storage built from model.a in NumPy (building A and B U is timed as well);
- ``prebuilt``: solve_banded alone on that band and right-hand side, built beforehand;
- ``dense``: numpy.linalg.solve on the dense A (lptv.reference.simulate), small L only.

Every call is timed whole (Python overhead included); the routes take turns, and each one's
fastest round is reported (the least disturbed by other work on the machine). A route whose
first call takes more than 2 s is timed by that call alone, and a route is not run at the next
L when its time, extrapolated with the growth seen between the last two L, would exceed
BUDGET_S. The routes must agree to 1e-10 of the output peak (asserted): all solve the same
linear system, A is diagonally dominant (harmonics below 40 % of the DC coefficient in every
row), so their difference is rounding.

Usage: python bench_simulate.py [max_lines] [first_L]   (default 10^6 1000: L = 1000, 10^4, ... up to max_lines)
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np
from scipy.linalg import solve_banded

import lptv
import lptv.examples as ex
from lptv.reference import simulate as dense_simulate

AGREE = 1e-10
DENSE_MAX_LINES = 1000
SLOW_S = 2.0      # a first call slower than this is the route's only call at that L
BUDGET_S = 120.0  # skip a route whose extrapolated call would take longer


def _powers(model, lines, order):
    s = 1j * model.w0 * lines
    return s[None, :] ** np.arange(order + 1)[:, None]


def banded_route(model, U, guard):
    """Y on lines 0..L from solve_banded on the grid -(L+guard)..L+guard."""
    return prebuilt_banded(model, U, guard)()


def prebuilt_banded(model, U, guard):
    """The band and right-hand side of banded_route built now; returns the solve alone
    (solve_banded on the prebuilt band, and the output lines 0..L)."""
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
    return lambda: solve_banded((Ka, Ka), ab, rhs, check_finite=False)[L:L + Lu + 1]


class Route:
    def __init__(self, name, make):
        self.name, self.make = name, make  # make(U, guard) -> callable returning Y
        self.history = []                  # (L, seconds) of the sizes run

    def predicted(self, L):
        """The time at L extrapolated from the last two sizes (t ~ L^p), None without two."""
        if len(self.history) < 2:
            return None
        (L1, t1), (L2, t2) = self.history[-2:]
        p = max(1.0, math.log(t2 / t1) / math.log(L2 / L1))
        return t2 * (L / L2) ** p


def timed(calls, reps):
    """Fastest wall time of each callable over `reps` interleaved rounds, and its result.

    The first call of each is the warm-up and gives the result that is compared; a callable
    whose first call took more than SLOW_S seconds keeps that time and is not repeated."""
    out, t, slow = [], np.full(len(calls), np.inf), []
    for i, f in enumerate(calls):
        t0 = time.perf_counter()
        out.append(f())
        first = time.perf_counter() - t0
        slow.append(first > SLOW_S)
        if slow[i]:
            t[i] = first
    for _ in range(reps):
        for i, f in enumerate(calls):
            if slow[i]:
                continue
            t0 = time.perf_counter()
            f()
            t[i] = min(t[i], time.perf_counter() - t0)
    return t, out


def main(max_lines: int = 10**6, first: int = 1000):
    model = ex.paper_model()
    rng = np.random.default_rng(0)
    solver = lptv.simulate(model, np.ones(3), full_output=True).solver
    print("lptv.simulate vs scipy.linalg.solve_banded vs dense (lptv.reference.simulate); "
          "paper-like model, input on every line 0..L, output lines 0..L")
    print(f"solver 'auto' picks: {solver}; sim = lptv.simulate (adaptive guard), sim/g = fixed "
          "guard g (the adaptive run's), klu = solver='klu'")
    print(f"fastest of interleaved rounds, calls timed whole; a route slower than {SLOW_S:g} s "
          f"is timed by one call, one predicted above {BUDGET_S:g} s is not run\n")
    routes = [
        Route("sim", lambda U, g: (lambda: lptv.simulate(model, U))),
        Route("sim/g", lambda U, g: (lambda: lptv.simulate(model, U, guard=g))),
        Route("klu", lambda U, g: (lambda: lptv.simulate(model, U, solver="klu"))),
        Route("klu/g", lambda U, g: (lambda: lptv.simulate(model, U, guard=g, solver="klu"))),
        Route("banded", lambda U, g: (lambda: banded_route(model, U, g))),
        Route("prebuilt", lambda U, g: prebuilt_banded(model, U, g)),
        Route("dense", lambda U, g: (lambda: dense_simulate(model, U, guard=g))),
    ]
    head = f"{'L':>8} {'guard':>5}" + "".join(f" {r.name:>10}" for r in routes) + \
        f" {'sim/band':>9} {'sim/g/band':>10} {'klu/band':>9} {'klu/g/band':>10} {'sim/pre':>8}" \
        f" {'max diff':>9}"
    print(head)
    L = first
    skipped = []
    while L <= max_lines:
        U = np.exp(2j * np.pi * rng.uniform(size=L + 1)) / np.sqrt(L)
        U[0] = U[0].real
        g = lptv.simulate(model, U, full_output=True, solver="klu").guard
        active = []
        for r in routes:
            pred = r.predicted(L)
            if r.name == "dense" and L > DENSE_MAX_LINES:
                continue
            if pred is not None and pred > BUDGET_S:
                (L1, t1), (L2, t2) = r.history[-2:]
                skipped.append(f"{r.name} at L = {L}: extrapolated {pred:.0f} s per call "
                               f"(t ~ L^{math.log(t2 / t1) / math.log(L2 / L1):.1f} from L = "
                               f"{L1} to {L2})")
            else:
                active.append(r)
        reps = int(max(5, min(15, 3e5 / L))) if L < 10**6 else 3
        t, results = timed([r.make(U, g) for r in active], reps)
        times = {}
        for r, ti in zip(active, t):
            r.history.append((L, ti))
            times[r.name] = ti
        Yb = results[[r.name for r in active].index("banded")]
        peak = np.abs(Yb).max()
        diff = max(np.abs(Y - Yb).max() for Y in results) / peak
        assert diff <= AGREE, f"routes disagree at L = {L}: {diff:.1e}"

        def cell(name):
            return f"{1e3 * times[name]:>8.2f}ms" if name in times else f"{'-':>10}"

        def ratio(name, width):
            return f"{times[name] / times['banded']:>{width}.2f}" if name in times else f"{'-':>{width}}"

        print(f"{L:>8} {g:>5}" + "".join(f" {cell(r.name)}" for r in routes) +
              f" {ratio('sim', 9)} {ratio('sim/g', 10)} {ratio('klu', 9)} {ratio('klu/g', 10)}"
              f" {times['sim'] / times['prebuilt']:>8.2f} {diff:>9.1e}", flush=True)
        L *= 10
    for s in skipped:
        print(f"not run: {s}")
    # The fixed cost of one call: a tiny system, where the solve itself is negligible.
    U = np.zeros(11, complex)
    U[10] = 0.5
    g = lptv.simulate(model, U, full_output=True).guard
    t, _ = timed([lambda: lptv.simulate(model, U), lambda: lptv.simulate(model, U, guard=g),
                  lambda: banded_route(model, U, g)], 200)
    print(f"\ncall overhead, L = 10 (guard {g}): sim {1e6 * t[0]:.0f} us, sim/g {1e6 * t[1]:.0f} us, "
          f"banded {1e6 * t[2]:.0f} us")
    print("ratios > 1 mean lptv.simulate is slower than solve_banded; sim/pre = lptv.simulate / "
          "solve_banded alone on the prebuilt band\n(prebuilt: A and B U built beforehand, not timed); "
          "goal: sim/pre <= 0.5 at L = 10^5 (the default solver)")


if __name__ == "__main__":
    main(*(int(float(a)) for a in sys.argv[1:3]))
