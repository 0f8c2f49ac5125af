"""Monte Carlo of WGTLS and SML on the paper's example: bias, variance against the Cramer-Rao
bound and coverage of the reported 95 % intervals, for P = 4, 8, 16, 32 periods.

    python bench/python/bench_uncertainty.py [R] [P ...]     (R realisations per P, default 400)

The design is fixed (model, multisine, lines 1..243); each realisation draws new noise from the
paper's coloured, correlated noise model. The CRB uses the true per-line noise (co)variances of
that model (first-order low-pass noise 1/(1 - a z^-1) normalised to unit variance has the
spectrum (1 - a^2) / |1 - a e^{-jw}|^2; a period's DFT X_l = fft / N has variance S(w_l) / N).
"""
import sys
import time
import warnings

import numpy as np

import lptv
from lptv.examples import (PAPER_ID_LINES, PAPER_NOISE, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, noise_variances,
                           noisy_periods, paper_model, paper_multisine)


def true_noise(ms, y0):
    """Per-line (co)variances of one period's noise spectra, lines 0..N/2."""
    return noise_variances(ms.signal, y0, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, **PAPER_NOISE)


def study(P, R, model, ms, y0, crb, seeds):
    kw = dict(na=2, nb=1, ka=3, kb=3, w0=model.w0, lines=PAPER_ID_LINES)
    est = {m: [] for m in ("wgtls", "sml")}
    std = {m: [] for m in est}
    fails = {m: 0 for m in est}
    t = {m: 0.0 for m in est}
    for s in seeds.spawn(R):
        u, y = noisy_periods(ms.signal, y0, P, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, seed=np.random.default_rng(s),
                             **PAPER_NOISE)
        data = lptv.FrequencyData.from_periods(u, y, w0=model.w0)
        for m in est:
            t0 = time.perf_counter()
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    res = lptv.identify(data, method=m, **{k: v for k, v in kw.items() if k != "w0"})
            except Exception:  # noqa: BLE001 - counted and reported
                fails[m] += 1
                continue
            t[m] += time.perf_counter() - t0
            est[m].append(res.eta)
            std[m].append(res.parameter_std)
    free = crb.std > 0
    out = {}
    for m in est:
        E, S = np.array(est[m])[:, free], np.array(std[m])[:, free]
        truth = crb.eta[free]
        err = E - truth
        var = E.var(axis=0, ddof=1)
        ratio = var / crb.std[free] ** 2
        bias = np.abs(err.mean(axis=0)) / np.sqrt(var / len(E))   # in standard errors
        cover = np.abs(err) <= 1.959964 * S
        out[m] = dict(n=len(E), fails=fails[m], ratio_median=np.median(ratio), ratio_max=ratio.max(),
                      coverage=cover.mean(), coverage_min=cover.mean(axis=0).min(),
                      coverage_max=cover.mean(axis=0).max(), bias_max=bias.max(),
                      std_ratio_median=np.median(S.mean(axis=0) / np.sqrt(var)), ms=1e3 * t[m] / max(1, len(E)))
    return out


def main():
    R = int(sys.argv[1]) if len(sys.argv) > 1 else 400
    Ps = [int(p) for p in sys.argv[2:]] or [4, 8, 16, 32]
    model = paper_model()
    ms = paper_multisine(seed=1)
    y0 = lptv.time_signal(lptv.simulate(model, ms.spectrum), ms.n_samples)
    var_u, var_y, cov_yu = true_noise(ms, y0)
    root = np.random.SeedSequence(20261123)
    print(f"paper example, lines 1..243, 34 free parameters, R = {R} realisations per P")
    print("variance / CRB: median and max over the parameters (sampling error of one ratio about "
          f"{100 * np.sqrt(2 / (R - 1)):.0f} %); coverage of 95 % intervals pooled over parameters and per "
          f"parameter (min-max; binomial std of one {100 * np.sqrt(0.95 * 0.05 / R):.1f} %); "
          "|bias| max in standard errors of the mean; reported std / empirical std (median)")
    print(f"{'P':>3} {'method':6} {'var/CRB med':>11} {'max':>6} {'goal':>6} {'cover':>6} {'min':>6} {'max':>6} "
          f"{'|bias|':>6} {'std/emp':>7} {'ms/fit':>6} {'fails':>5}")
    for P, seeds in zip(Ps, root.spawn(len(Ps))):
        crb = lptv.crb(model, ms, var_u=var_u, var_y=var_y, cov_yu=cov_yu, periods=P, lines=PAPER_ID_LINES)
        res = study(P, R, model, ms, y0, crb, seeds)
        goal = 1.05 * (P - 2) / (P - 3)
        for m, r in res.items():
            print(f"{P:>3} {m:6} {r['ratio_median']:>11.3f} {r['ratio_max']:>6.3f} {goal if m == 'sml' else float('nan'):>6.3f} "
                  f"{100 * r['coverage']:>5.1f}% {100 * r['coverage_min']:>5.1f}% {100 * r['coverage_max']:>5.1f}% "
                  f"{r['bias_max']:>6.2f} {r['std_ratio_median']:>7.3f} {r['ms']:>6.1f} {r['fails']:>5}", flush=True)


if __name__ == "__main__":
    main()
