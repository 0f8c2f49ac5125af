"""The parametric best linear time-periodic approximation by Monte Carlo: do its intervals,
which include the nonlinear variance, cover?

An LPTV model followed by a cubic, y + c y^3 (a Wiener system, as the README's "From a real
rig"): the paper's model with its amplitude spectrum and noise (50/30 dB), or the third-order
model of lptv.examples with its 20 lines and white noise (40/25 dB). M random-phase
realisations of one amplitude spectrum, P periods each. Each run draws new phases and noise,
estimates the distortion (lptv.distortion) and fits SML over the M realisations as experiments:

- "analytic": the experiments of DistortionResult.experiments(), output variances raised by the
  nonlinear level, with the analytic covariance (the lines' distortions taken independent);
- "realisations": the same fit with covariance='realisations', the leave-one-realisation-out
  jackknife times (M-1)/(M-3) (METHOD.md section 16);
- "noise only": the same records with the periods' noise variances alone (analytic).

The BLA's parameters are those of the expected fit over the random phases; they are not known in
closed form, so the target is the Monte Carlo mean of the BLA fits (its own standard error,
std / sqrt(R), is printed). Per parameter: variance over the runs / mean reported variance, and
the coverage of the 95 % intervals eta +- 1.96 std around the target. With a correct jackknife the
variance ratio is (M-3)/(M-1) (0.6 at M = 6: the reported variance is that of Student's t with
M - 1 degrees of freedom) and the coverage that of the t interval, 94.7 % at M = 6.

    python bench/python/bench_bla.py --runs 1000 --cubic 0.02 --periods 4
    python bench/python/bench_bla.py --runs 1000 --cubic 0.02 --periods 16
    python bench/python/bench_bla.py --system third_order --runs 1000 --cubic 0.1 --periods 8
    python bench/python/bench_bla.py --system discrete --kind hammerstein --referred input --first plain \
        --realisations 12 --runs 400 --cubic 0.05 --periods 8
    python bench/python/bench_bla.py --system discrete --kind hammerstein --referred none \
        --realisations 12 --runs 2000 --cubic 0.05 --periods 8

The discrete-time system (lptv.examples.discrete_model) is strongly time-varying: its
realisations' outputs differ widely with the phases (one common output level swamps the weak
ones, so the level is referred to the input, through the plain fit with --first plain or where
the output-referred first fit is refused) and its far branches need M >= 12.
"""
from __future__ import annotations

import argparse
import json
import os
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import lptv  # noqa: E402
from lptv import examples as ex  # noqa: E402

SYSTEMS = ex.BLA_SYSTEMS   # model, excited lines, N, fit rows, structure, noise (snr_in, snr_out, correlation)
actuator_gain = ex.actuator_gain   # the exact BLA's gain: one definition (lptv.examples)


def exact_bla_eta(system, g, names):
    """The exact BLA's parameters (Hammerstein) in the fit's parameter names."""
    m = SYSTEMS[system][0]()
    a, b = np.array(m.a), np.array(m.b) * g
    out = []
    for name in names:
        c, rest = name[0], name[1:]
        n, part = rest.split(".")
        arr = a if c == "a" else b
        K = (arr.shape[1] - 1) // 2
        k = int(part[2:])
        z = arr[int(n), K + k] if k <= K else 0.0
        out.append(np.real(z) if part.startswith("re") else np.imag(z))
    return np.array(out)


def one(args):
    run, c, P, M, system, kind, fitted, referred, first_fit = args
    rows, structure = SYSTEMS[system][3:5]
    structure = fitted or structure
    r = ex.cubic_realisations(system, c, "input" if kind == "hammerstein" else "output", M, P, seed=[run, 77])
    m, u, y = r["model"], r["u"], r["y"]
    rows = [rows] * M
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = lptv.distortion(u, y, w0=m.w0, ts=m.ts)
        plain = lptv.identify([(u[i], y[i]) for i in range(M)], w0=m.w0, ts=m.ts, lines=rows, method="sml", **structure)
        exps = d.experiments()
        first_plain = False
        if referred == "none":     # the realisations with their noise alone (the jackknife brings the distortion)
            exps = d.experiments(referred="none")
        elif referred == "input" and first_fit == "plain":   # through the fit of the realisations' noise alone
            exps, first_plain = d.experiments(referred="input", model=plain), True
        elif referred == "input":   # through a first, output-referred fit; the plain one where that is refused
            try:               # (one common level above a weak realisation's output, or branches unreliable)
                exps = d.experiments(referred="input", model=lptv.identify(exps, lines=rows, method="sml",
                                                                          **structure))
            except ValueError:
                exps, first_plain = d.experiments(referred="input", model=plain), True
        try:
            bla = lptv.identify(exps, lines=rows, method="sml", **structure)
        except ValueError as e:   # refused: said in the output, left out of the statistics
            return (None, None, None, None, None, bool(d.detected), 0, (), False, " ".join(str(e).split())[:160])
        jk = lptv.identify(exps, lines=rows, method="sml", covariance="realisations", **structure)
    return (bla.eta, bla.parameter_std, jk.parameter_std, plain.eta, plain.parameter_std, bool(d.detected),
            exps[0].periods, bla.eta_names, first_plain, None)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--cubic", type=float, default=0.02)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--periods", type=int, default=4)
    ap.add_argument("--realisations", type=int, default=6, help="M (at least 4 for the jackknife)")
    ap.add_argument("--system", default="paper", choices=tuple(SYSTEMS))
    ap.add_argument("--save", metavar="NPZ", help="keep every run's estimates and stds in this file")
    ap.add_argument("--structure", type=json.loads, default=None,
                    help='the fitted structure as JSON, e.g. \'{"na": 3, "nb": 1, "ka": [2, 1, 0, 1], "kb": [3, 0]}\' '
                         "(default: the system's own)")
    ap.add_argument("--referred", default="output", choices=("output", "input", "none"),
                    help="DistortionResult.experiments(referred=...): the nonlinear level on the output variances, "
                         "referred to the input through a first fit (for a nonlinearity before the dynamics), or "
                         "none (the realisations with their noise alone: the 'analytic' column is then the noise's "
                         "covariance only, the 'realisations' column the jackknife's)")
    ap.add_argument("--first", default="output", choices=("output", "plain"),
                    help="--referred input: the first fit that refers the level, output-referred (the plain fit where "
                         "that is refused) or the plain fit of the realisations with their noise alone")
    ap.add_argument("--kind", default="wiener", choices=("wiener", "hammerstein"),
                    help="the cubic after the LPTV system (y + c y^3) or before it (x = u + c u^3: the exact BLA "
                         "is then known, and the coverage around it is printed too)")
    args = ap.parse_args()
    M = args.realisations
    t0 = time.time()
    with ProcessPoolExecutor(args.workers) as pool:
        out = list(pool.map(one, [(r, args.cubic, args.periods, M, args.system, args.kind, args.structure, args.referred,
                                   args.first)
                             for r in range(args.runs)],
                            chunksize=4))
    refused = [r for r, o in enumerate(out) if o[9] is not None]
    if refused:
        print(f"# runs whose BLA fit was refused ({len(refused)}; left out): {refused[:20]}; the first's reason: "
              f"{out[refused[0]][9]}")
    plain_first = sum(o[8] for o in out)
    if plain_first:
        print(f"# runs whose level was referred through the plain fit (noise only): {plain_first}"
              + (" (the output-referred first fit refused)" if args.first == "output" else " (--first plain)"))
    n = max(len(o[0]) for o in out if o[0] is not None)
    bad = [r for r, o in enumerate(out) if r not in set(refused) and any(x is None or np.shape(x) != (n,) for x in o[:5])]
    if bad:   # a fit without covariance: said, and left out of the statistics
        print(f"# runs left out (a fit without a covariance or of another size): {bad}")
        for r in bad[:5]:
            print(f"#   run {r}: " + ", ".join("None" if x is None else str(np.shape(x)) for x in out[r][:5]))
    bad = sorted(set(bad) | set(refused))
    out = [o for r, o in enumerate(out) if r not in set(bad)]
    R = len(out)
    eb, sb, sj, ep, sp, det, pe = (np.array([o[i] for o in out]) for i in range(7))
    if args.save:
        np.savez(args.save, eta=eb, std_analytic=sb, std_realisations=sj, eta_noise_only=ep, std_noise_only=sp,
                 names=np.array(out[0][7]))
    free = sb[0] > 0
    names = np.array(out[0][7])[free]
    target = eb.mean(0)[free]
    z95 = 1.959964
    truth = None
    if args.kind == "hammerstein":
        g = actuator_gain(args.system, args.cubic)
        truth = exact_bla_eta(args.system, g, out[0][7])[free]
        print(f"# Hammerstein: the actuator's linear gain g = {g:.5f}; the exact BLA is the LPTV system with b times g")
    if args.structure:
        print(f"# fitted structure {args.structure}")
    print(f"# the nonlinear level referred to the {args.referred}" + (f" (first fit: {args.first})" if args.referred == "input" else ""))
    print(f"# {R} runs in {time.time() - t0:.0f} s; system {args.system} ({args.kind}), cubic c = {args.cubic}, M = {M}, "
          f"P = {args.periods}; distortion detected in {100 * det.mean():.0f} % of the runs; effective periods "
          f"{pe.min()}-{pe.max()}")
    print(f"{'parameter':>10} {'target':>10} {'se(target)':>10} {'analytic var/rep':>16} {'cover':>6} "
          f"{'realis. var/rep':>15} {'cover':>6} {'noise-only var/rep':>18} {'cover':>6}")
    rows = []
    huge = np.zeros(names.size, int)
    for j, n in enumerate(names):
        col = np.flatnonzero(free)[j]
        err = np.abs(eb[:, col] - target[j])
        var_mc = eb[:, col].var(ddof=1)
        vr_b, cov_b = var_mc / np.mean(sb[:, col] ** 2), np.mean(err <= z95 * sb[:, col])
        vr_j, cov_j = var_mc / np.mean(sj[:, col] ** 2), np.mean(err <= z95 * sj[:, col])
        huge[j] = np.sum(sj[:, col] > 10 * np.median(sj[:, col]))
        vr_p = ep[:, col].var(ddof=1) / np.mean(sp[:, col] ** 2)
        cov_p = np.mean(np.abs(ep[:, col] - ep[:, col].mean()) <= z95 * sp[:, col])
        rows.append((vr_b, cov_b, vr_j, cov_j, vr_p, cov_p))
        print(f"{n:>10} {target[j]:10.5f} {np.sqrt(var_mc / R):10.5f} {vr_b:16.3f} {100 * cov_b:5.1f}% "
              f"{vr_j:15.3f} {100 * cov_j:5.1f}% {vr_p:18.3f} {100 * cov_p:5.1f}%")
    a = np.array(rows)
    pct = lambda k: f"{100 * a[:, k].mean():.1f} % (per parameter {100 * a[:, k].min():.1f}-{100 * a[:, k].max():.1f} %)"  # noqa: E731
    print(f"coverage of 95 % intervals, binomial std per parameter {100 * np.sqrt(0.95 * 0.05 / R):.2f} %, pooled "
          f"about {100 * np.sqrt(0.95 * 0.05 / R / a.shape[0]):.2f} % if independent; variance ratio sampling error "
          f"sqrt(2/(R-1)) = {np.sqrt(2 / (R - 1)):.3f}")
    print(f"  analytic:     {pct(1)}, var/rep median {np.median(a[:, 0]):.2f} (range {a[:, 0].min():.2f}-"
          f"{a[:, 0].max():.2f})")
    print(f"  realisations: {pct(3)}, var/rep median {np.median(a[:, 2]):.2f} (range {a[:, 2].min():.2f}-"
          f"{a[:, 2].max():.2f}; (M-3)/(M-1) = {(M - 3) / (M - 1):.2f} when right)")
    print(f"  noise only:   {pct(5)}, var/rep median {np.median(a[:, 4]):.2f}")
    if truth is not None:   # the intervals around the exact BLA, and the estimate's bias against it
        ej = np.abs(eb[:, free] - truth)
        cov_t = np.mean(ej <= z95 * sj[:, free], axis=0)
        bias = np.abs(eb[:, free].mean(0) - truth) / eb[:, free].std(0, ddof=1)
        worst = names[np.argmax(bias)]
        print(f"  around the exact BLA: realisations {100 * cov_t.mean():.1f} % (per parameter {100 * cov_t.min():.1f}-"
              f"{100 * cov_t.max():.1f} %); the SML estimate's |bias| / std median {np.median(bias):.2f}, largest "
              f"{bias.max():.2f} ({worst}; the standard error of a mean is {1 / np.sqrt(R):.3f} std)")
    if huge.any():
        print(f"  realisations: runs with a std above 10 times its median, per parameter: {huge.min()}-{huge.max()} "
              "(a leave-one-out refit far from the others; var/rep is then dominated by them)")


if __name__ == "__main__":
    main()
