"""How often the near-unidentifiability warning fires, on the paper's example.

    python bench/python/bench_identifiability.py [R]      (R realisations per case, default 200)

Cases: the correct structure (3 harmonics), one harmonic too many on every coefficient (4: a
common periodic factor of numerator and denominator makes the model non-unique), and an
under-ordered model (na = 1 for the second-order truth), for P = 4 and 8. Printed: quantiles of
sv1^2 / sv0^2 (the two smallest generalised singular values of the WGTLS problem), how often the
residue test passes, and how often lptv.identify warns of near-unidentifiability.
"""
import sys
import warnings

import numpy as np

import lptv
from lptv.examples import (PAPER_NOISE, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, noisy_periods, paper_model,
                           paper_multisine)

CASES = {"correct (K=3)": dict(na=2, ka=3, kb=3, lines=range(1, 244)),
         "K=4, one too many": dict(na=2, ka=4, kb=4, lines=range(1, 243)),
         "na=1, under-ordered": dict(na=1, ka=3, kb=3, lines=range(1, 244))}


def main(R):
    model, ms = paper_model(), paper_multisine(seed=1)
    y0 = lptv.time_signal(lptv.simulate(model, ms.spectrum), ms.n_samples)
    print(f"paper example, WGTLS, R = {R} per row; ratio = sv1^2 / sv0^2 (warning below 1.46 here, unless "
          "too many residues lie above 0 dB)")
    print(f"{'P':>2} {'case':22s} {'ratio min':>9} {'1%':>6} {'50%':>6} {'max':>6} {'residue ok':>10} {'warned':>7}")
    for P in (4, 8):
        rng = np.random.default_rng([P, 7])
        rows = {c: [] for c in CASES}
        for _ in range(R):
            u, y = noisy_periods(ms.signal, y0, P, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, seed=rng, **PAPER_NOISE)
            d = lptv.FrequencyData.from_periods(u, y, w0=model.w0)
            for c, kw in CASES.items():
                with warnings.catch_warnings(record=True) as w:
                    warnings.simplefilter("always")
                    res = lptv.identify(d, nb=1, method="wgtls", **kw)
                warned = any(issubclass(x.category, lptv.IdentifiabilityWarning) for x in w)
                sv = res.singular_values
                rows[c].append((sv[1] ** 2 / sv[0] ** 2, res.residue_ok, warned))
        for c, v in rows.items():
            a = np.array(v, dtype=float)
            q = np.quantile(a[:, 0], [0, 0.01, 0.5, 1])
            print(f"{P:>2} {c:22s} {q[0]:>9.3f} {q[1]:>6.3f} {q[2]:>6.3f} {q[3]:>6.3f} "
                  f"{100 * a[:, 1].mean():>9.1f}% {100 * a[:, 2].mean():>6.1f}%")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200)
