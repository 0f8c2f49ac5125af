"""lptv.inspect over random records made outside lptv: how often it finds the period, how often it
says a record repeats that does not, and how often the check of lptv identify lets a wrong period
through.

Records (tests/python/outside_records.py's generators, random settings per record):
- periodic, discrete time: the difference equation with a periodic coefficient under a periodic
  input (a multisine NumPy builds: every line, odd lines with some left out, or multiples of 3
  or 5 so that the input repeats every N / s samples and only the output every N), N = 64..2000
  samples a period, P = 2..10 periods, from rest (a start-up transient), half of them cut
  mid-period, a third with the input faded in over its first half period;
- periodic, continuous time: the mass-spring-damper with k(t) = k0 (1 + 0.3 cos(2 pi t / T))
  integrated by solve_ivp, T = 1.2..4.7 s at 100-250 Hz;
- not periodic: band-pass noise through a filter, a lightly damped resonance driven by noise
  (it nearly repeats at its own period), a multisine whose phases are drawn anew every period,
  a chirp.
Noise: a relative standard deviation drawn log-uniformly in 0.5-10 % on both channels.

Per record: the period found (the input's; the output's multiple), exactly or a multiple, the
excited lines exactly; a wrong period (N - 1, N + 1, 0.8 N, 1.25 N samples) accepted by
``Inspection.agrees_with``; a record that does not repeat taken for periodic.

    python bench/python/bench_inspect.py --runs 400 --workers 2
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.signal import butter, chirp, lfilter  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "python"))
import outside_records as rec  # noqa: E402

import lptv  # noqa: E402


def design(rng, N):
    """Excited lines of a random design and the input's own period divisor s."""
    top = int(rng.integers(8, max(9, min(N // 2 - 1, 200))))
    kind = rng.choice(["full", "odd", "multiples"])
    if kind == "full":
        lines = np.arange(1, top + 1)
    elif kind == "odd":
        j = np.arange(1, top + 1, 2)
        keep = rng.random(j.size) > 0.25
        keep[0] = True
        lines = j[keep]
    else:
        s = int(rng.choice([3, 5]))
        lines = s * np.arange(1, max(2, top // s) + 1, 2)
    # cosines on multiples of g repeat every N / gcd(N, g) samples
    return lines, int(np.gcd(N, int(np.gcd.reduce(lines))))


def multisine(rng, N, lines, periods, fresh=False):
    spec = np.zeros((periods, N // 2 + 1), complex)
    phases = rng.uniform(0, 2 * np.pi, (periods if fresh else 1, lines.size))
    spec[:, lines] = np.exp(1j * phases)
    x = np.fft.irfft(spec, N, axis=1).ravel()
    return x / np.std(x)


def lptv_response(u, N, rng):
    """y[k] = a1 y[k-1] - a2(k) y[k-2] + u[k] + 0.5 u[k-1], a2 periodic with N, from rest."""
    a1 = rng.uniform(0.6, 1.4)
    depth = rng.uniform(0.1, 0.4)
    a2 = 0.5 * (1 + depth * np.cos(2 * np.pi * np.arange(u.size) / N))
    b = np.r_[u[:1], u[1:] + 0.5 * u[:-1]]
    y = np.zeros(u.size)
    y[0] = b[0]
    y[1] = a1 * y[0] + b[1]
    for k in range(2, u.size):
        y[k] = a1 * y[k - 1] - a2[k] * y[k - 2] + b[k]
    return y


def noisy(rng, x, level):
    return x + level * np.std(x) * rng.standard_normal(x.size)


def one(seed):
    rng = np.random.default_rng([seed, 35])
    level = float(np.exp(rng.uniform(np.log(0.005), np.log(0.10))))
    kind = rng.choice(["discrete"] * 6 + ["msd"] + ["noise"] * 2)
    out = dict(seed=seed, kind=str(kind), noise=level)
    if kind == "noise":
        n = int(rng.integers(2000, 12000))
        sub = str(rng.choice(["bandpass", "resonance", "fresh-phases", "chirp"]))
        if sub == "bandpass":
            lo = rng.uniform(0.01, 0.1)
            b, a = butter(4, [lo, lo + rng.uniform(0.05, 0.5)], btype="band")
            u = lfilter(b, a, rng.standard_normal(n + 3000))[3000:]
        elif sub == "resonance":
            r, f = 1 - rng.uniform(0.002, 0.02), rng.uniform(0.01, 0.2)
            u = lfilter([1.0], [1, -2 * r * np.cos(2 * np.pi * f), r * r], rng.standard_normal(n + 5000))[5000:]
        elif sub == "fresh-phases":
            N = int(rng.integers(100, 1000))
            u = multisine(rng, N, design(rng, N)[0], n // N + 1, fresh=True)[:n]
        else:
            t = np.arange(n)
            u = chirp(t, f0=0.001, t1=n, f1=rng.uniform(0.05, 0.4))
        y = lfilter([0.3, 0.2], [1, -0.5], u)
        out.update(sub=sub, truth=None)
    elif kind == "msd":
        T = float(rng.uniform(1.2, 4.7))
        fs = float(rng.choice([100.0, 125.0, 200.0, 250.0]))
        N = int(round(T * fs))
        T = N / fs
        lines = rec.odd_lines(1, int(rng.integers(8, 30)), seed=seed)
        P = int(rng.integers(3, 9))
        t, u, y = rec.mass_spring_damper(T, fs, P, lines=lines, noise=level, seed=seed)
        out.update(sub="msd", truth=N, input_truth=N, lines=lines)
    else:
        N = int(rng.integers(64, 2001))
        P = int(rng.integers(2, 11))
        lines, s = design(rng, N)
        u0 = multisine(rng, N, lines, P)
        if rng.random() < 1 / 3:          # the generator fades in over half a period
            ramp = np.minimum(np.arange(u0.size) / (N / 2), 1.0)
            u0 = u0 * ramp
        y0 = lptv_response(u0, N, rng)
        u, y = noisy(rng, u0, level), noisy(rng, y0, level)
        if P > 2 and rng.random() < 0.5:   # the recording starts mid-period
            cut = int(rng.integers(1, N))
            u, y = u[cut:], y[cut:]
        out.update(sub="discrete", truth=N, input_truth=N // s, lines=lines)
    t0 = time.perf_counter()
    r = lptv.inspect(u=u, y=y)
    out["seconds"] = time.perf_counter() - t0
    out["repeats"] = r.repeats
    if out["truth"] is None:
        return out
    N, L = out["truth"], out["input_truth"]
    out["input_exact"] = r.repeats and r.input_period_samples == L
    out["input_multiple"] = r.repeats and r.input_period_samples % L == 0 and r.input_period_samples != L
    out["joint_exact"] = r.repeats and r.period_samples == N
    out["lines_exact"] = r.repeats and r.period_samples == N and np.array_equal(r.lines, out.pop("lines"))
    out.pop("lines", None)
    wrong = {N - 1, N + 1, int(round(0.8 * N)), int(round(1.25 * N))}
    wrong = {w for w in wrong if w % L != 0}
    out["wrong_tried"] = len(wrong)
    out["wrong_accepted"] = sum(r.agrees_with(w) for w in wrong) if r.repeats else 0
    out["right_accepted"] = r.repeats and r.agrees_with(N)
    return out


def table(rows):
    def pct(k, n):
        return f"{100 * k / n:.1f} %" if n else "-"

    print("| records | noise | n | period found exactly | a multiple | not found | lines exact | "
          "right period accepted | wrong period accepted |")
    print("|---|---|---|---|---|---|---|---|---|")
    bins = [(0.005, 0.01), (0.01, 0.03), (0.03, 0.1001)]
    for sub in ("discrete", "msd"):
        for lo, hi in bins:
            g = [r for r in rows if r.get("sub") == sub and lo <= r["noise"] < hi]
            n = len(g)
            tried = sum(r["wrong_tried"] for r in g)
            print(f"| {sub} | {100 * lo:g}-{100 * min(hi, 0.1):g} % | {n} | "
                  f"{pct(sum(r['joint_exact'] for r in g), n)} | "
                  f"{pct(sum(r['repeats'] and not r['joint_exact'] for r in g), n)} | "
                  f"{pct(sum(not r['repeats'] for r in g), n)} | {pct(sum(r['lines_exact'] for r in g), n)} | "
                  f"{pct(sum(r['right_accepted'] for r in g), n)} | "
                  f"{pct(sum(r['wrong_accepted'] for r in g), tried)} of {tried} |")
    print()
    print("| records that do not repeat | n | said to repeat |")
    print("|---|---|---|")
    for sub in ("bandpass", "resonance", "fresh-phases", "chirp"):
        g = [r for r in rows if r.get("sub") == sub]
        print(f"| {sub} | {len(g)} | {pct(sum(r['repeats'] for r in g), len(g))} |")
    inputs = [r for r in rows if r["truth"] is not None and r["input_truth"] != r["truth"]]
    print()
    print(f"input repeating every N / s (s = 3, 5): {len(inputs)} records; the input's own period found in "
          f"{pct(sum(r['input_exact'] for r in inputs), len(inputs))}, the output's N in "
          f"{pct(sum(r['joint_exact'] for r in inputs), len(inputs))}")
    t = np.array([r["seconds"] for r in rows])
    print(f"lptv.inspect per record: median {1e3 * np.median(t):.1f} ms, max {1e3 * t.max():.1f} ms")
    bad = [r for r in rows if r["truth"] is not None and not r["joint_exact"]]
    if bad:
        print("missed (seed, kind, noise): " + ", ".join(f"({r['seed']}, {r['sub']}, {100 * r['noise']:.1f} %)"
                                                        for r in bad[:20]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=400)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--first-seed", type=int, default=0)
    args = ap.parse_args(argv)
    seeds = range(args.first_seed, args.first_seed + args.runs)
    t0 = time.perf_counter()
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as ex:
            rows = list(ex.map(one, seeds, chunksize=4))
    else:
        rows = [one(s) for s in seeds]
    print(f"{len(rows)} records, seeds {seeds.start}..{seeds.stop - 1}, {time.perf_counter() - t0:.0f} s\n")
    table(rows)
    periodic = [r for r in rows if r["truth"] is not None]
    assert all(r["right_accepted"] or not r["repeats"] or not r["joint_exact"] for r in periodic), \
        "a period found exactly was not accepted by agrees_with"
    return 0


if __name__ == "__main__":
    sys.exit(main())
