"""Monte Carlo of the MIMO estimators (METHOD.md section 19) on systems integrated by solve_ivp.

    python bench/python/bench_mimo.py [--runs 300] [--periods 8] [--level 0.03]
        [--systems 2-in-2-out 1-in-2-out 2-in-1-out] [--methods wgtls sml] [--seed 1]
        [--noise auto|sample|moderated] [--colour a]

For each system of lptv.examples.mimo (two masses with a periodic coupling spring, 2 inputs and
2 outputs or 1 input and 2 outputs; one mass with 2 inputs, a periodic input gain and an input
derivative): an orthogonal (Hadamard) design with E = nu experiments on N = 128 samples, the
noise-free periodic steady state of each experiment integrated once by solve_ivp, then per run
independent white noise of ``level`` times each channel's rms on every input and output sample
of P periods. Each run is fitted with each method and the right structure (ka = 1 on A_0, 0 on
A_1, A_2; kb as the system needs), and with two wrong ones: a missing harmonic (ka = 0) and a
missing order (na = 1).

With --known-noise the fits weigh by the true covariance of the means (the verdict's F tests
then do not apply: its rates are printed but not meaningful), which separates the loss of the
sample covariances from the estimator's. Printed per system and method: the Monte Carlo variance of every free parameter over the CRB
(lptv.mimo_crb at the true noise), min / median / max; the mean reported variance over the Monte
Carlo variance; the coverage of the 95 % intervals, pooled and per parameter (min-max), with the
binomial standard error; the verdict's rejection rate on the right structure (its size, goal
<= 1 % + sampling error) and on the wrong ones (its power).
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time
import warnings

import numpy as np

import lptv
from lptv.examples import mimo as mx

N = 128
LINES = np.arange(2, 50, 3)
RIGHT = {"2-in-2-out": dict(na=2, nb=0, ka=[1, 0, 0], kb=0), "1-in-2-out": dict(na=2, nb=0, ka=[1, 0, 0], kb=0),
         "2-in-1-out": dict(na=2, nb=1, ka=[1, 0, 0], kb=[1, 0])}


def wrong(system):
    r = dict(RIGHT[system])
    harmonic = dict(r, ka=0, kb=0)
    order = dict(r, na=1, ka=[1, 0])
    return {"missing harmonic": harmonic, "missing order": order}


def setup(system, seed):
    model = mx.SYSTEMS[system]()[0]
    d = lptv.mimo_multisines(LINES, N, model.n_inputs, design="hadamard", seed=seed)
    ys = [mx.steady_state(system, d.spectra[e], N) for e in range(d.n_experiments)]
    us = [d.signals[e] for e in range(d.n_experiments)]
    sy = np.sqrt(np.mean([np.mean(y ** 2, axis=0) for y in ys], axis=0))
    su = np.sqrt(np.mean([np.mean(u ** 2, axis=0) for u in us], axis=0))
    # the FDS agrees with the integration (the premise of the CRB's noiseless spectra)
    for e in range(d.n_experiments):
        Y = np.asarray(lptv.simulate(model, d.spectra[e], lines_out=N // 2)).reshape(N // 2 + 1, -1)
        Yi = np.fft.rfft(ys[e], axis=0) / N
        assert np.abs(Y - Yi).max() <= 1e-10 * np.abs(Y).max()
    return model, d, us, ys, sy, su


def coloured(rng, P, shape, a):
    """P periods of unit-variance noise of the given (N, channels) shape, white or through
    1 / (1 - a z^-1) (stationary: the filter runs 200 samples before the first period)."""
    if not a:
        return rng.standard_normal((P,) + shape)
    from scipy.signal import lfilter

    e = rng.standard_normal((P * shape[0] + 200, shape[1])) * np.sqrt(1 - a ** 2)
    return lfilter([1.0], [1.0, -a], e, axis=0)[200:].reshape((P,) + shape)


def run(system, args, out):
    t0 = time.time()
    rng = np.random.default_rng(args.seed)
    model, d, us, ys, sy, su = setup(system, args.seed)
    P, level = args.periods, args.level
    sig_y, sig_u = level * sy, level * su
    noise = np.r_[sig_y ** 2, sig_u ** 2] / N
    a = args.colour
    if a:   # every channel's noise through 1 / (1 - a z^-1), its rms kept: the lines' variances follow
        lines = np.arange(N // 2 + 1)
        shape = (1 - a ** 2) / np.abs(1 - a * np.exp(-2j * np.pi * lines / N)) ** 2
        noise = shape[:, None] * noise[None, :]
    s = RIGHT[system]
    bound = lptv.mimo_crb(model, d.spectra, noise=noise, periods=P, ka=s["ka"], kb=s["kb"])
    truth = bound.eta
    free = np.flatnonzero(np.diag(bound.covariance) > 0)
    est = {m: [] for m in args.methods}
    var = {m: [] for m in args.methods}
    ok = {m: [] for m in args.methods}
    power = {k: [] for k in wrong(system)}
    refused = {k: 0 for k in wrong(system)}
    fails = 0
    routes = []
    for r in range(args.runs):
        pairs = []
        for u1, y1 in zip(us, ys):
            u = u1[None] + sig_u * coloured(rng, P, u1.shape, a)
            y = y1[None] + sig_y * coloured(rng, P, y1.shape, a)
            pairs.append((u, y))
        fit_data = pairs
        if args.known_noise:   # the true covariance of the means instead of the periods' sample one
            nz = np.broadcast_to(noise, (N // 2 + 1, noise.shape[-1])).astype(complex)
            C = np.einsum("lc,cd->lcd", nz, np.eye(nz.shape[1])) / P
            fit_data = [dataclasses.replace(lptv.MimoFrequencyData.from_periods(u, y, w0=mx.W0), C=C.copy())
                        for u, y in pairs]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                for m in args.methods:
                    res = lptv.identify(fit_data, w0=mx.W0, method=m, noise=args.noise, **s)
                    routes.append(res.noise)
                    est[m].append(res.eta)
                    var[m].append(res.parameter_std ** 2)
                    ok[m].append(res.model_ok)
            except ValueError as err:
                fails += 1
                print(f"  run {r}: {err}", file=sys.stderr)
                continue
            for k, st in wrong(system).items():
                try:
                    res = lptv.identify(fit_data, w0=mx.W0, method=args.verdict_method, covariance="none",
                                        noise=args.noise, **st)
                    power[k].append(not res.model_ok)
                except ValueError:     # the wrong structure cannot be fitted: refused, counted apart
                    refused[k] += 1
    names = np.array(bound.parameter_names)
    print(f"\n## {system}: {model.n_inputs} in, {model.n_outputs} out; E = {d.n_experiments} Hadamard experiments, "
          f"N = {N}, lines {LINES[0]}..{LINES[-1]} step {LINES[1] - LINES[0]}, P = {P}, noise {level:g} x rms on "
          f"every channel{f' coloured by 1/(1 - {a:g} z^-1)' if a else ''}; {args.runs} runs ({fails} failed), {len(free)} free parameters; "
          f"noise={args.noise} (fits on the moderated route: {routes.count('moderated')} of {len(routes)}); "
          f"{time.time() - t0:.0f} s", file=out)
    z = 1.959963984540054
    for m in args.methods:
        E = np.array(est[m])
        V = np.array(var[m])
        n = E.shape[0]
        mc = E[:, free].var(axis=0, ddof=1)
        crb = np.diag(bound.covariance)[free]
        ratio = mc / crb
        rep = V[:, free].mean(axis=0) / mc
        bias = (E[:, free].mean(axis=0) - truth[free]) / np.sqrt(mc / n)
        cover = np.abs(E[:, free] - truth[free]) <= z * np.sqrt(V[:, free])
        pooled = cover.mean()
        se_pooled = np.sqrt(pooled * (1 - pooled) / cover.size)
        per = cover.mean(axis=0)
        se_per = np.sqrt(0.95 * 0.05 / n)
        rej = 1 - np.mean(ok[m])
        print(f"  {m:5s}  MC var / CRB: min {ratio.min():.3f} median {np.median(ratio):.3f} max {ratio.max():.3f} "
              f"(sampling error of one ratio ~ {np.sqrt(2 / (n - 1)):.2f})  [max at {names[free][np.argmax(ratio)]}]",
              file=out)
        print(f"         reported / MC variance: min {rep.min():.3f} median {np.median(rep):.3f} max {rep.max():.3f}; "
              f"|bias| / its standard error: max {np.abs(bias).max():.2f}", file=out)
        print(f"         95 % coverage: pooled {100 * pooled:.1f} % (+- {100 * se_pooled:.1f}, runs x parameters "
              f"correlated), per parameter {100 * per.min():.1f}-{100 * per.max():.1f} % (one parameter's "
              f"binomial error +- {100 * se_per:.1f})", file=out)
        print(f"         verdict on the right structure: rejects {100 * rej:.1f} % of {n} "
              f"(+- {100 * np.sqrt(max(rej, 0.01) * (1 - rej) / n):.1f}; size goal 1 %)", file=out)
    for k, v in power.items():
        print(f"  verdict ({args.verdict_method}) against a {k}: rejects {100 * np.mean(v):.1f} % of {len(v)}"
              + (f" (and {refused[k]} fits refused with a ValueError)" if refused[k] else ""), file=out)
    out.flush()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=300)
    ap.add_argument("--periods", type=int, default=8)
    ap.add_argument("--level", type=float, default=0.03)
    ap.add_argument("--systems", nargs="+", default=list(mx.SYSTEMS), choices=list(mx.SYSTEMS))
    ap.add_argument("--methods", nargs="+", default=["wgtls", "sml"], choices=["wgtls", "sml"])
    ap.add_argument("--verdict-method", default="wgtls", choices=["wgtls", "sml"])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--colour", type=float, default=0.0,
                    help="noise through 1 / (1 - a z^-1) on every channel (0: white)")
    ap.add_argument("--noise", default="auto", choices=["auto", "sample", "moderated"],
                    help="lptv.identify's noise route (auto: moderated when the noise spectrum is smooth)")
    ap.add_argument("--known-noise", action="store_true",
                    help="fit with the true noise covariance of the means (not the periods' sample one): "
                         "separates the loss of the sample covariances from the estimator's")
    args = ap.parse_args(argv)
    print(f"bench_mimo.py --runs {args.runs} --periods {args.periods} --level {args.level} --systems "
          f"{' '.join(args.systems)} --methods {' '.join(args.methods)} --seed {args.seed} --noise {args.noise}"
          + (f" --colour {args.colour:g}" if args.colour else "")
          + (" --known-noise" if args.known_noise else ""))
    for system in args.systems:
        run(system, args, sys.stdout)


if __name__ == "__main__":
    main()
