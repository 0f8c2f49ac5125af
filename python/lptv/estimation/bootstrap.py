"""The parametric bootstrap covariance of an estimate (``lptv.identify(..., covariance="bootstrap")``,
METHOD.md section 10).

The analytic covariance of WGTLS and SML is a sandwich (an inverse information) times a
small-sample factor (P-1)/(P-3) that the theory gives for rows whose weights have 2(P-1)
degrees of freedom; at P = 4 that factor is 3 and the reported variance is 1.2-1.9 times the
Monte Carlo variance on three systems (bench/HISTORY.md): the variance of the estimate is then
dominated by the randomness of the weights, which a factor cannot follow from one system to
the next. The bootstrap follows it by doing what the data did: B data sets are drawn from the
fitted model and the measured noise (co)variances, each of P periods per line (complex
Gaussian, input and output correlated as measured; line 0 real), so that their means and their
sample (co)variances, hence the weights, are as random as the data's; each is fitted by the
same method from the same start, and the covariance of the B estimates is reported.
"""
from __future__ import annotations

import numpy as np

from ..spectra.frequency_data import FrequencyData


SMOOTH = 5


def smooth(v, width: int = SMOOTH):
    """The mean over lines l - width .. l + width (fewer at the ends): the noise (co)variances of
    the bootstrap's world. **(choice)** A noise spectrum is smooth in frequency, while each
    line's sample variance has only 2(P-1) degrees of freedom; taken line by line as the world's
    truth, its scatter (some lines nearly noise-free) made the refits agree more than the
    estimate varies (reported / Monte Carlo variance 0.71-0.89 at P = 4 on three systems)."""
    v = np.asarray(v)
    if v.size <= 2 * width:
        return np.full_like(v, v.mean())
    k = np.ones(2 * width + 1)
    num = np.convolve(v, k, mode="same")
    den = np.convolve(np.ones(v.size), k, mode="same")
    return num / den


def draw(data: FrequencyData, U0, Y0, rng) -> FrequencyData:
    """One data set of P periods with the spectra U0, Y0 (lines 0..max_line) and the noise
    (co)variances of ``data`` smoothed over neighbouring lines (:func:`smooth`; of the means: one
    period's are P times larger)."""
    P = data.periods
    n = data.max_line + 1
    vU, vY, c = (smooth(np.asarray(x)) * P for x in (data.varU, data.varY, data.covYU))
    # per line the 2 x 2 complex covariance [[vY, c], [conj c, vU]] of (dY, dU) per period
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.where(vU > 0, c / vU, 0.0)                      # dY = rho dU + independent part
    rest = np.maximum(vY - np.abs(rho) ** 2 * vU, 0.0)
    g = (rng.standard_normal((4, P, n)) * np.sqrt(0.5))
    dU = np.sqrt(vU) * (g[0] + 1j * g[1])
    dY = rho * dU + np.sqrt(rest) * (g[2] + 1j * g[3])
    dU[:, 0] = np.sqrt(vU[0]) * rng.standard_normal(P)           # line 0 is real
    dY[:, 0] = rho[0].real * dU[:, 0] + np.sqrt(rest[0]) * rng.standard_normal(P)
    Up, Yp = np.asarray(U0)[None, :n] + dU, np.asarray(Y0)[None, :n] + dY
    Um, Ym = Up.mean(axis=0), Yp.mean(axis=0)
    s = 1.0 / (P * (P - 1))
    varU = s * np.sum(np.abs(Up - Um) ** 2, axis=0)
    varY = s * np.sum(np.abs(Yp - Ym) ** 2, axis=0)
    cov = s * np.sum((Yp - Ym) * np.conj(Up - Um), axis=0)
    cov[0] = cov[0].real
    return FrequencyData(Um, Ym, varU, varY, cov, w0=data.w0, ts=data.ts, periods=P)


def bootstrap_covariance(res, data: FrequencyData, fit, B: int, seed) -> np.ndarray:
    """Covariance of ``res.eta`` from B parametric bootstrap refits; ``fit(FrequencyData)`` returns
    an estimate's eta (the same method, structure and rows). Failed refits are skipped; fewer
    than B / 2 successes raise ValueError."""
    from ..simulation.fds import simulate

    rng = np.random.default_rng(seed)
    U0 = np.asarray(data.U)
    Y0 = np.asarray(simulate(res.model, U0, warn_unstable=False))
    etas = []
    for _ in range(B):
        try:
            etas.append(fit(draw(data, U0, Y0, rng)))
        except (ValueError, ArithmeticError):
            continue
    if len(etas) < B / 2:
        raise ValueError(f"covariance='bootstrap': only {len(etas)} of {B} refits succeeded")
    return np.cov(np.array(etas), rowvar=False)
