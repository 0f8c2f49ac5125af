"""What the stability check and the data diagnostics cost, measured side by side in one run.

- lptv.simulate on the paper's model and multisine with warn_unstable=False and True: the same
  model object (the answer cached) and a new model object every call (the check paid each time);
- lptv.identify on the paper's data (P = 4, lines 1..243) per method: LS and TLS now also solve
  the GTLS problem for the identifiability test; every method runs the data diagnostics, timed
  alone here.

The routes agree (asserted): the simulated spectra are identical with and without the check.

    PYTHONPATH=python python bench/python/bench_checks.py [--rounds R] [--calls N]

R repetitions of the simulate comparison (default 2); N calls per median for simulate on one model
(default 200; N / 4 with a new model each call and for the diagnostics, N / 20 per identify).
"""
import argparse
import os
import time
import warnings

import numpy as np

import lptv
from lptv import _core
from lptv.examples import PAPER_ID_LINES, paper_measurements, paper_model, paper_multisine


def median_time(f, n):
    t = []
    for _ in range(n):
        t0 = time.perf_counter()
        f()
        t.append(time.perf_counter() - t0)
    return float(np.median(t))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2, help="repetitions of the simulate comparison")
    ap.add_argument("--calls", type=int, default=200, help="calls per median (simulate on one model)")
    args = ap.parse_args(argv)
    n, n4, n20 = args.calls, max(1, args.calls // 4), max(1, args.calls // 20)
    print(f"load average {os.getloadavg()[0]:.2f}")
    m, U = paper_model(), paper_multisine(0).spectrum
    a, b, w0 = m.a, m.b, m.w0
    assert np.array_equal(lptv.simulate(m, U, warn_unstable=False), lptv.simulate(m, U)), \
        "simulate's output differs with and without the stability check"
    for rep in range(args.rounds):
        off = median_time(lambda: lptv.simulate(m, U, warn_unstable=False), n)
        on = median_time(lambda: lptv.simulate(m, U), n)
        off_new = median_time(lambda: lptv.simulate(lptv.Model(a, b, w0=w0), U, warn_unstable=False), n4)
        on_new = median_time(lambda: lptv.simulate(lptv.Model(a, b, w0=w0), U), n4)
        print(f"simulate, paper model: check off {1e3 * off:.3f} ms, on (same model) {1e3 * on:.3f} ms "
              f"(x{on / off:.2f}); new model each call: off {1e3 * off_new:.3f} ms, on {1e3 * on_new:.3f} ms "
              f"(x{on_new / off_new:.2f})")
    d = paper_measurements(seed=1, periods=4)
    kw = dict(na=2, nb=1, ka=3, kb=3, w0=d["w0"], lines=PAPER_ID_LINES)
    data = lptv.FrequencyData.from_periods(d["u"], d["y"], w0=d["w0"])
    st = _core.Structure(2, 1, [3] * 3, [3] * 2, [], d["w0"], 0.0)
    rows = [int(x) for x in PAPER_ID_LINES]
    diag = median_time(lambda: _core.diagnose_data(data._cpp, st, rows), n4)
    print(f"diagnose_data alone: {1e3 * diag:.3f} ms")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for method in ("ls", "tls", "gtls", "wgtls"):
            t = median_time(lambda: lptv.identify(data, method=method, **{k: v for k, v in kw.items() if k != "w0"}), n20)
            print(f"identify {method:5s}: {1e3 * t:.1f} ms")
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
