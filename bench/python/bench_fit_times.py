"""The fit's times on the paper's example, for side-by-side runs of two builds under farm-bench.

Prints one line: the fastest of 7 rounds of 40 calls, per call, of ``_core.estimate`` (WGTLS,
on spectra built beforehand), ``lptv.identify`` (WGTLS from the periods, as a user calls it)
and ``_core.estimate`` (SML). Seed 1 of ``lptv.examples.paper_measurements`` (P = 8), lines
1..243, tol 1e-12. With ``--lti``: the 4th-order LTI case of bench_ml_lti.py (500 lines, P = 8),
``_core.estimate`` (SML) and ``lptv.identify`` on its spectra (SML), as that bench calls them.
``--rounds R --calls N`` change the 7 rounds of 40 calls.
To compare two builds, append each one's lines to a file of its own:

    OPENBLAS_NUM_THREADS=1 farm-bench -n 5 \\
        --vs "sh -c 'exec OLD/.venv/bin/python bench/python/bench_fit_times.py >> /tmp/B.txt 2>&1'" \\
        -- sh -c 'PYTHONPATH=python exec .venv/bin/python bench/python/bench_fit_times.py >> /tmp/A.txt 2>&1'
"""
import argparse
import os
import sys
import time

import lptv
from lptv import _core
from lptv.spectra.frequency_data import FrequencyData
from lptv.examples import paper_measurements

ROUNDS, CALLS, TOL = 7, 40, 1e-12


def lti_routes():
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import bench_ml_lti as b

    _, _, data = b.make_case()
    par = _core.Parametrisation(4, 0, [0] * 5, [0], [], b.W0, 0.0)
    kw = dict(na=4, nb=0, lines=b.LINES, method="sml")
    return {
        "lti sml core": lambda: _core.estimate(data._cpp, par, b.LINES, method="sml"),
        "lti identify": lambda: lptv.identify(data, **kw),
    }


def main(argv=None):
    global ROUNDS, CALLS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lti", action="store_true", help="the LTI case of bench_ml_lti.py")
    ap.add_argument("--rounds", type=int, default=ROUNDS)
    ap.add_argument("--calls", type=int, default=CALLS, help="calls per round")
    args = ap.parse_args(argv)
    ROUNDS, CALLS = args.rounds, args.calls
    if args.lti:
        report(lti_routes())
        return
    m = paper_measurements(1, periods=8)
    u, y, w0 = m["u"], m["y"], m["w0"]
    data = FrequencyData.from_periods(u, y, w0=w0)
    par = _core.Parametrisation(2, 1, [3] * 3, [3] * 2, [], w0, 0.0)
    rows = list(range(1, 244))
    kw = dict(na=2, nb=1, ka=3, kb=3, w0=w0, lines=range(1, 244), tol=TOL)
    routes = {
        "core": lambda: _core.estimate(data._cpp, par, rows, method="wgtls", tol=TOL, max_iter=50),
        "identify": lambda: lptv.identify(u, y, **kw),
        "sml core": lambda: _core.estimate(data._cpp, par, rows, method="sml", tol=TOL, max_iter=50),
    }
    report(routes)


def report(routes):
    best = {k: float("inf") for k in routes}
    for _ in range(ROUNDS):
        for k, call in routes.items():
            t0 = time.perf_counter()
            for _ in range(CALLS):
                call()
            best[k] = min(best[k], (time.perf_counter() - t0) / CALLS)
    print(" ".join(f"{k} {1e3 * v:.3f} ms" for k, v in best.items()))


if __name__ == "__main__":
    main()
