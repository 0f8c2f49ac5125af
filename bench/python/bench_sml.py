"""SML on the exact likelihood against WGTLS, side by side, and SML on a 4th-order LTI case.

    python bench/python/bench_sml.py [--rounds R] [--inner N]   (default 7 rounds of 5 calls)

- the paper's example (lines 1..243, 34 free parameters, P = 8): ``lptv._core.estimate`` with
  method 'wgtls' and 'sml' (the compiled estimators alone, data built beforehand), and
  ``lptv.identify`` with both (estimate, covariance, residue diagnostics);
- an LTI case: G(s) = 1 / ((s^2 + 0.2 s + 1)(s^2 + 0.6 s + 4)), 4th order over a constant
  (na = 4, nb = 0), 500 excited lines, P = 8, SNR 40 dB in and out: the SML estimate alone.
The routes take turns over rounds; each one's fastest round counts (machines are shared).
"""
import argparse
import time
import warnings

import numpy as np

import lptv
from lptv import _core
from lptv.examples import noisy_periods, paper_measurements


def fastest(fns, rounds=7, inner=5):
    best = {k: np.inf for k in fns}
    for _ in range(rounds):
        for k, f in fns.items():
            t0 = time.perf_counter()
            for _ in range(inner):
                f()
            best[k] = min(best[k], (time.perf_counter() - t0) / inner)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--inner", type=int, default=5, help="calls per round")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    m = paper_measurements(seed=1, periods=8)
    data = lptv.FrequencyData.from_periods(m["u"], m["y"], w0=m["w0"])
    par = _core.Parametrisation(2, 1, [3] * 3, [3] * 2, [], m["w0"], 0.0)
    rows = list(range(1, 244))
    kw = dict(na=2, nb=1, ka=3, kb=3, lines=rows)
    t = fastest({
        "core wgtls": lambda: _core.estimate(data._cpp, par, rows, method="wgtls"),
        "core sml": lambda: _core.estimate(data._cpp, par, rows, method="sml"),
        "identify wgtls": lambda: lptv.identify(data, method="wgtls", **kw),
        "identify sml": lambda: lptv.identify(data, method="sml", **kw),
    }, args.rounds, args.inner)
    print(f"paper example, P = 8, 34 free parameters on 243 lines (fastest of {args.rounds} rounds of {args.inner} calls)")
    for k, v in t.items():
        print(f"  {k:15s} {1e3 * v:7.2f} ms")
    print(f"  sml / wgtls: core {t['core sml'] / t['core wgtls']:.2f}x, identify "
          f"{t['identify sml'] / t['identify wgtls']:.2f}x (goal <= 3x)")

    # LTI: 4th order, 500 lines
    N, w0 = 2048, 0.01
    a = np.polymul([1, 0.2, 1], [1, 0.6, 4])[::-1]          # a_0 .. a_4
    model = lptv.Model(a[:, None], [[1.0]], w0=w0)
    ms = lptv.multisine(range(1, 501), N, seed=5)
    y0 = lptv.time_signal(lptv.simulate(model, ms.spectrum), N)
    u, y = noisy_periods(ms.signal, y0, 8, 40, 40, seed=6)
    d = lptv.FrequencyData.from_periods(u, y, w0=w0)
    p4 = _core.Parametrisation(4, 0, [0] * 5, [0], [], w0, 0.0)
    r4 = list(range(1, 501))
    t = fastest({
        "core wgtls": lambda: _core.estimate(d._cpp, p4, r4, method="wgtls"),
        "core sml": lambda: _core.estimate(d._cpp, p4, r4, method="sml"),
        "identify sml": lambda: lptv.identify(d, na=4, nb=0, lines=r4, method="sml"),
    }, args.rounds, args.inner)
    est = _core.estimate(d._cpp, p4, r4, method="sml")
    print("LTI, na = 4, nb = 0, 500 lines, P = 8 (5 free parameters)")
    for k, v in t.items():
        print(f"  {k:15s} {1e3 * v:7.3f} ms")
    print(f"  sml per estimate {1e3 * t['core sml']:.3f} ms (goal <= 1.5 ms); "
          f"{est.iterations} LM steps; a_0..a_3 = {np.round(np.asarray(est.eta)[:4], 3)} "
          f"(true {np.round(a[:4], 3)})")


if __name__ == "__main__":
    main()
