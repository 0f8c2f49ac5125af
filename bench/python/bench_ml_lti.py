"""lptv's SML against FdiTools_Python's ML estimator (mlfdi) on a 4th-order LTI case, timed side by side.

What
----
The LTI case of ``bench_sml.py``: G(s) = 1 / ((s^2 + 0.2 s + 1)(s^2 + 0.6 s + 4)), a 4th-order
denominator over a constant (na = 4, nb = 0: five free real parameters a_0..a_3, b_0 with
a_4 = 1), N = 2048 samples per period, w0 = 0.01 rad/s, a multisine on lines 1..500, P = 8
periods, 40 dB SNR on input and output (``lptv.examples.noisy_periods``).

The comparator is ``mlfdi`` of FdiTools_Python (https://github.com/WataruOhnishi/FdiTools_Python,
a Python port of the FDIDENT / FdiTools toolbox): the errors-in-variables maximum-likelihood
estimator of an LTI transfer function (Levenberg-Marquardt on the ELiS cost
sum |B X - A Y|^2 / (2 s^2), s^2 the variance of a real component of B X - A Y from the noise
(co)variances of the periods). For an LTI model lptv's SML minimises the same cost: its reported
cost is V / (2 |rows|) with V = 2 x the ELiS cost, so both estimators have the same minimiser
(checked: at lptv's estimate, cost x |rows| equals mlfdi's cost function).

How
---
- Same data: mlfdi's classical call ``mlfdi(X, Y, freq, sX2, sY2, cXY, n, mh, ml, iterno, relvar,
  GN, 'c', fs)`` gets lptv's mean spectra of the 8 periods on lines 1..500 (X = U, Y = Y), the
  variances in FdiTools' convention (per real component: sX2 = varU / 2, sY2 = varY / 2) and
  cXY = covYU / 2 = E{dY conj(dU)} / 2 (the convention of mlfdi's variance formula and of MATLAB's
  cov; FdiTools_Python's own time2frf_ml returns the conjugate E{dU conj(dY)} / 2, which changes
  the weights of the cost: the 'fdi records' route below, which uses it as a user would, reaches
  a slightly different estimate, printed in units of lptv's standard deviations),
  freq = l w0 / (2 pi) Hz so that its s = j 2 pi freq is lptv's j l w0.
- Same model: continuous time, n = 4 poles, numerator order 0 (mh = ml = 0), monic denominator
  in both.
- Starting points: neither accepts one through its call, so each starts from its own default:
  lptv's SML from its WGTLS estimate, mlfdi from its linear least-squares estimate (lsfdi).
- Same accuracy: the minimiser theta* of the common cost is computed tightly (mlfdi run for a
  fixed number of Levenberg-Marquardt steps with relvar = 0), each estimate's relative distance
  to theta* is measured, and mlfdi's stopping tolerance relvar (relative change of its cost) is
  the loosest of 1e-4 .. 1e-12 whose estimate is at least as close to theta* as lptv's (at
  lptv's default tol). ``--relvar`` overrides it. Printed: the ladder, the two estimates'
  relative difference (and in units of lptv's parameter standard deviations), each one's
  relative distance to the truth, and the ELiS cost of each estimate.
- Timing: routes take turns in each round, each one's fastest round counts (the machine is
  shared); the load average is printed before and after. The routes:
    lptv core      ``lptv._core.estimate(data, par, lines, method='sml')``: the compiled
                   estimator alone, data and parametrisation built beforehand;
    lptv identify  ``lptv.identify(FrequencyData, na=4, nb=0, lines=..., method='sml')``: as a
                   user calls it on the spectra (estimate, covariance, residue diagnostics);
    lptv periods   ``lptv.identify(u, y, w0=..., ...)``: from the 8 periods of time records;
    fdi mlfdi      ``fditools.mlfdi(...)`` on the spectra and variances (the estimator as a user
                   calls it; its least-squares start and the python-control result included);
    fdi lsfdi      its start alone (the part of mlfdi that can be separated);
    fdi records    ``fditools.time2frf_ml(x, y, fs=, fl=, fh=, df=)`` then ``mlfdi`` on its output,
                   from the time records as a user calls them;
    fdi mlfdi R    mlfdi at the next looser relvar of the ladder (less accurate), and at 1e-10
                   (the value of FdiTools' examples) when the chosen one differs.
  Ratios: mlfdi / lptv core (estimators), mlfdi / lptv identify (estimators as called on the
  spectra), fdi records / lptv periods (from time records). mlfdi computes no covariance;
  lptv.identify does. BLAS threads are left as they are (OPENBLAS_NUM_THREADS=1 made mlfdi
  slower on a 2-core machine).

Usage
-----
    git clone https://github.com/WataruOhnishi/FdiTools_Python /path/to/FdiTools_Python
    python bench/python/bench_ml_lti.py --fditools /path/to/FdiTools_Python [--rounds 7] [--inner 5]

``--fditools`` defaults to the environment variable LPTV_FDITOOLS. FdiTools_Python needs numpy,
scipy and python-control (``pip install control``); it is imported from that folder, not
installed. Without it, only lptv's routes run.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import subprocess
import sys
import warnings

import numpy as np

import lptv
from lptv import _core
from lptv.examples import noisy_periods

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_sml import fastest  # noqa: E402  (the routes take turns; each one's fastest round)

N, W0, P = 2048, 0.01, 8
LINES = list(range(1, 501))
A_TRUE = np.polymul([1, 0.2, 1], [1, 0.6, 4])[::-1]        # a_0 .. a_4 (a_4 = 1)
P_TRUE = np.r_[A_TRUE[:4], 1.0]                              # the free parameters a_0..a_3, b_0
RELVARS = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]


def load_fditools(path):
    """The fditools package imported from the FdiTools_Python folder ``path``, or None (says why)."""
    how = ("  get it with: git clone https://github.com/WataruOhnishi/FdiTools_Python <DIR>\n"
           "  (it needs numpy, scipy and python-control: pip install control), then pass\n"
           "  --fditools <DIR> or set LPTV_FDITOOLS=<DIR>; running lptv's routes only.")
    if not path:
        print("FdiTools_Python: no location given (--fditools or LPTV_FDITOOLS).\n" + how)
        return None
    if not os.path.isfile(os.path.join(path, "fditools", "__init__.py")):
        print(f"FdiTools_Python: {path} holds no fditools/ package.\n" + how)
        return None
    sys.path.insert(0, os.path.abspath(path))
    try:
        import fditools
    except ImportError as e:
        print(f"FdiTools_Python at {path} cannot be imported: {e}\n" + how)
        return None
    return fditools


def fdi_revision(path):
    try:
        out = subprocess.run(["git", "-C", path, "rev-parse", "HEAD"], capture_output=True, text=True,
                             timeout=10)
        if out.returncode == 0:
            return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        pass
    return "not a git checkout"


def make_case():
    model = lptv.Model(A_TRUE[:, None], [[1.0]], w0=W0)
    ms = lptv.multisine(LINES, N, seed=5)
    y0 = lptv.time_signal(lptv.simulate(model, ms.spectrum), N)
    u, y = noisy_periods(ms.signal, y0, P, 40, 40, seed=6)
    return u, y, lptv.FrequencyData.from_periods(u, y, w0=W0)


def rel(p, q):
    return float(np.linalg.norm(p - q) / np.linalg.norm(q))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fditools", default=os.environ.get("LPTV_FDITOOLS", ""),
                    help="folder of a FdiTools_Python checkout (default: $LPTV_FDITOOLS)")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--inner", type=int, default=5)
    ap.add_argument("--relvar", type=float, default=None,
                    help="mlfdi's stopping tolerance (default: the loosest with lptv's accuracy)")
    args = ap.parse_args()
    warnings.simplefilter("ignore")

    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} "
          f"({os.cpu_count()} cores)")
    fdi = load_fditools(args.fditools)

    u, y, d = make_case()
    par = _core.Parametrisation(4, 0, [0] * 5, [0], [], W0, 0.0)
    # the sample variances: the estimate is compared with _core.estimate's and the other tools'
    kw = dict(na=4, nb=0, lines=LINES, method="sml", noise="sample")
    est = _core.estimate(d._cpp, par, LINES, method="sml")
    res = lptv.identify(d, **kw)
    eta = np.asarray(est.eta)
    p_lptv = np.r_[eta[:4], eta[5]]                           # a_0..a_3, b_0 (eta[4] = a_4 = 1)
    std = np.asarray(res.parameter_std)
    std = np.r_[std[:4], std[5]]
    assert np.allclose(np.asarray(res.eta), eta, rtol=1e-12, atol=0), \
        "lptv.identify's SML estimate differs from _core.estimate's beyond 1e-12 relative"
    print(f"case: G(s) = 1/((s^2+0.2s+1)(s^2+0.6s+4)), na = 4, nb = 0, lines 1..500, N = {N}, "
          f"w0 = {W0}, P = {P}, SNR 40 dB in and out")
    print(f"lptv SML (tol 1e-10, from its WGTLS start): {est.iterations} steps, cost "
          f"V/(2|rows|) = {est.cost:.12g}")

    fns = {
        "lptv core": lambda: _core.estimate(d._cpp, par, LINES, method="sml"),
        "lptv identify": lambda: lptv.identify(d, **kw),
        "lptv periods": lambda: lptv.identify(u, y, w0=W0, **kw),
    }
    if fdi is not None:
        print(f"FdiTools_Python {getattr(fdi, '__version__', '?')} from {args.fditools} "
              f"(commit: {fdi_revision(args.fditools)})")
        L = np.array(LINES)
        freq = L * W0 / (2 * np.pi)                          # Hz: s = j 2 pi freq = j l w0
        df = W0 / (2 * np.pi)
        fs = N * df
        X, Y = d.U[L][:, None], d.Y[L][:, None]
        sX2, sY2 = (d.varU[L] / 2)[:, None], (d.varY[L] / 2)[:, None]
        cXY = (d.covYU[L] / 2)[:, None]
        waxis = 1j * 2 * np.pi * freq

        def mlfdi(relvar, iterno=500, verbose=False):
            return fdi.mlfdi(X, Y, freq, sX2, sY2, cXY, 4, [0], [0], iterno, relvar, 0, "c", fs,
                             verbose=verbose)

        def params(H):
            B, A = fdi.hm2ba(H)
            return np.r_[A[::-1][:4], B[0, -1]], B, A

        def elis(p):
            return fdi.mlfdi_res(np.array([[0, 0, 0, 0, p[4]]]), np.r_[1.0, p[3::-1]], freq,
                                 X, Y, sX2, sY2, cXY, waxis)

        def steps(relvar, iterno=500):
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                H, _ = mlfdi(relvar, iterno, verbose=True)
            lines = [s for s in buf.getvalue().splitlines() if s.startswith("Iter")]
            accepted = len({s.split("index = ")[1].split(",")[0] for s in lines})
            return H, len(lines), accepted

        # the minimiser of the common cost, tightly: mlfdi for 60 LM steps with no stopping rule
        p_star = params(mlfdi(0.0, iterno=60)[0])[0]
        c_star = elis(p_star)
        print(f"minimiser theta* (mlfdi, 60 LM steps, relvar 0): ELiS cost {c_star:.12g}; "
              f"lptv's cost x |rows| = {est.cost * len(LINES):.12g}")
        d_lptv = rel(p_lptv, p_star)
        print(f"lptv: |p - theta*|/|theta*| = {d_lptv:.2e}, ELiS cost - min = {elis(p_lptv) - c_star:.2e}")
        print("mlfdi relvar ladder (steps tried/accepted, distance to theta*, ELiS cost above the minimum):")
        ladder = {}
        for rv in RELVARS:
            H, n_it, n_acc = steps(rv)
            p = params(H)[0]
            ladder[rv] = p
            print(f"  relvar {rv:7.0e}: {n_it:2d}/{n_acc:2d} steps, |p - theta*|/|theta*| = "
                  f"{rel(p, p_star):.2e}, cost - min = {elis(p) - c_star:.2e}")
        if args.relvar is not None:
            relvar = args.relvar
            why = "given"
        else:
            ok = [rv for rv in RELVARS if rel(ladder[rv], p_star) <= max(d_lptv, 1e-15)]
            relvar = ok[0] if ok else RELVARS[-1]
            why = ("the loosest as close to theta* as lptv's" if ok
                   else "none as close to theta* as lptv's: the tightest")
        H, n_it, n_acc = steps(relvar)
        p_fdi = params(H)[0]
        print(f"mlfdi relvar = {relvar:g} ({why}), from its LS start: {n_it} steps ({n_acc} accepted)")
        print("accuracy (p = a_0, a_1, a_2, a_3, b_0; a_4 = 1):")
        print(f"  truth  {np.array2string(P_TRUE, precision=6)}")
        print(f"  lptv   {np.array2string(p_lptv, precision=6)}  |p-p0|/|p0| = {rel(p_lptv, P_TRUE):.4e}, "
              f"ELiS cost {elis(p_lptv):.12g}")
        print(f"  mlfdi  {np.array2string(p_fdi, precision=6)}  |p-p0|/|p0| = {rel(p_fdi, P_TRUE):.4e}, "
              f"ELiS cost {elis(p_fdi):.12g}")
        print(f"  |p_mlfdi - p_lptv|/|p_lptv| = {rel(p_fdi, p_lptv):.2e}; max |difference| / std = "
              f"{np.max(np.abs(p_fdi - p_lptv) / std):.2e} (std: lptv's parameter_std, relative "
              f"{' '.join(f'{v:.1e}' for v in std / np.abs(P_TRUE))})")
        same = rel(p_fdi, p_star) <= max(d_lptv, 1e-15)
        print(f"  same accuracy (mlfdi at least as close to theta* as lptv): {'yes' if same else 'NO'}")

        # FdiTools' own nonparametric step from the time records, as a user calls it
        x_rec, y_rec = u.ravel(), y.ravel()

        def records():
            out = fdi.time2frf_ml(x_rec, y_rec, fs=fs, fl=df, fh=LINES[-1] * df, df=df)
            Xs, Ys, _, _, fq, sx, sy, cxy, _ = out
            return fdi.mlfdi(Xs, Ys, fq, sx, sy, cxy, 4, [0], [0], 500, relvar, 0, "c", fs)

        Xs, _, _, _, _, _, _, cxy_rec, _ = fdi.time2frf_ml(x_rec, y_rec, fs=fs, fl=df, fh=LINES[-1] * df,
                                                          df=df)
        p_rec = params(records()[0])[0]
        conj = np.max(np.abs(cxy_rec[:, 0] / N ** 2 - np.conj(d.covYU[L]) / 2))
        print(f"note: time2frf_ml's cXY is conj(covYU)/2 (max deviation {conj:.1e}); mlfdi fed with it "
              f"(the 'fdi records' route) gives |p - p_lptv|/|p_lptv| = {rel(p_rec, p_lptv):.2e}, max "
              f"|difference| / std = {np.max(np.abs(p_rec - p_lptv) / std):.2f} (a different cost: "
              f"the sample cross-covariance enters its weights conjugated)")

        fns.update({
            "fdi mlfdi": lambda: mlfdi(relvar),
            "fdi lsfdi": lambda: fdi.lsfdi(X, Y, freq, 4, [0], [0], "c", fs),
            "fdi records": records,
        })
        if relvar != 1e-10:
            fns["fdi mlfdi 1e-10"] = lambda: mlfdi(1e-10)
        looser = [rv for rv in RELVARS if rv > relvar]
        if looser:
            rv_loose = looser[-1]
            fns[f"fdi mlfdi {rv_loose:.0e}"] = lambda: mlfdi(rv_loose)

    t = fastest(fns, args.rounds, args.inner)
    print(f"times (fastest of {args.rounds} rounds of {args.inner} calls, routes taking turns):")
    for k, v in t.items():
        print(f"  {k:16s} {1e3 * v:8.3f} ms")
    if fdi is not None:
        print("ratios (FdiTools / lptv):")
        print(f"  estimators:                 mlfdi / lptv core     = {t['fdi mlfdi'] / t['lptv core']:.2f}x")
        print(f"  as called on the spectra:   mlfdi / lptv identify = {t['fdi mlfdi'] / t['lptv identify']:.2f}x")
        print(f"  from the time records:      (time2frf_ml + mlfdi) / lptv identify(u, y) = "
              f"{t['fdi records'] / t['lptv periods']:.2f}x")
        if "fdi mlfdi 1e-10" in t:
            print(f"  mlfdi at relvar 1e-10 (FdiTools' examples) / lptv core = "
                  f"{t['fdi mlfdi 1e-10'] / t['lptv core']:.2f}x")
        for k in t:
            if k.startswith("fdi mlfdi ") and k != "fdi mlfdi 1e-10":
                print(f"  {k[4:]} (one step looser, less accurate) / lptv core = "
                      f"{t[k] / t['lptv core']:.2f}x")
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
