"""The scans behind :func:`lptv.inspect` (METHOD.md section 18): the period (the shortest lag at
which the input repeats, :func:`find_period`), the periods' transient and drift, the record's
spectra and each line's noise level and class (:class:`LineClass`). NumPy and SciPy only."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

REPEAT_LIMIT = 0.2
"""The largest repeat residue r(L) of a period: the repeating part holds at least 80 % of the
input's power (a periodic input below 6 dB of signal-to-noise ratio is not taken as one)."""
SIGMAS = 6.0
"""Standard deviations of the noise's repeat residue a lag may lie above the best one and still
be a repeat (METHOD.md section 18)."""
ALPHA = 0.01
"""The chance that noise alone puts any line of the record above the line test's threshold."""
NOISE_HALF_WINDOW = 20
OWN_LEVEL = 0.01
OWN_HALF_WINDOW = 2
"""Lines on each side pooled into a line's noise level (their median)."""
WHOLE = 0.1
"""A period refined to within this of a whole number of samples is whole (measured: within 0.05
on 234 records with whole periods at 0.5-10 % noise, bench_inspect.py; a near repeat of lines
on multiples of s <= 5 falls 0.2 or more between samples). Among the lags that repeat, the shortest whole
one is the period; a period further from a whole number is reported (the generator and the
sampling clocks are not synchronised: the spectra leak)."""


@dataclass(frozen=True)
class LineClass:
    """The output on one class of unexcited lines."""

    name: str
    """'sidebands', 'odd detection', 'even detection' or 'elsewhere'."""
    lines: np.ndarray
    """The class's lines (multiples of the fundamental of :attr:`Inspection.period`)."""
    above: np.ndarray
    """The lines whose output power stands above the noise (the line test of :func:`inspect`)."""
    excess_db: float
    """The class's output power over what its noise explains, summed over its lines (dB; about
    0 for noise alone)."""
    level_db: float
    """The strongest line above the noise relative to the mean output power of the excited
    lines (dB); nan when no line is above."""

    @property
    def present(self) -> bool:
        return self.above.size > 0


# ------------------------------------------------------------------------------ the period

def repeat_residue(x, max_lag: int) -> np.ndarray:
    """r(L) = sum_i (d_i - mean d)^2 / sum_i ((x[i+L] - m)^2 + (x[i] - m)^2) with d_i = x[i+L] - x[i]
    over the n - L pairs of the record, for L = 0..max_lag, by one FFT autocorrelation, x less
    its straight line (m = 0). With the line and the differences' mean taken out, a slow linear
    drift of the channel (a constant d) does not hide the repetition."""
    x = _detrended(x)
    n = x.size
    c = np.concatenate([[0.0], np.cumsum(x * x)])
    c1 = np.concatenate([[0.0], np.cumsum(x)])
    # NumPy's FFT: scipy.fft's import alone (0.6 s) is most of a command that refuses a record
    nfft = _fast_len(2 * n)
    X = np.fft.rfft(x, nfft)
    R = np.fft.irfft(X.real ** 2 + X.imag ** 2, nfft)[:max_lag + 1]
    lag = np.arange(max_lag + 1)
    energy = c[n - lag] + (c[n] - c[lag])
    drift = (c1[n] - c1[lag]) - c1[n - lag]
    D = np.maximum(energy - 2.0 * R - drift ** 2 / np.maximum(n - lag, 1), 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(energy > 0, D / energy, 1.0)


def _fast_len(n: int) -> int:
    """The smallest 2^a 3^b 5^c >= n (an FFT length pocketfft factors fast)."""
    best = 1 << max(int(n - 1).bit_length(), 0)
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            m = p35
            while m < n:
                m *= 2
            best = min(best, m)
            p35 *= 3
        p5 *= 5
    return best


def _detrended(x):
    """x less its least-squares straight line (a sensor's drift; the periods' shapes stay)."""
    # by NumPy: scipy.signal's import alone costs 0.3-1 s, more than the whole inspection
    x = np.asarray(x, dtype=float)
    t = np.arange(x.size, dtype=float) - (x.size - 1) / 2.0
    tt = float(t @ t)
    return x - x.mean() - (t * (float(t @ x) / tt) if tt > 0 else 0.0)


def _residue_at(x, lag, start=0):
    """r at one lag, summed directly over the pairs from sample ``start`` (no FFT rounding)."""
    x = _detrended(np.asarray(x, dtype=float)[start:])
    a, b = x[lag:], x[:x.size - lag]
    e = float(np.dot(a, a) + np.dot(b, b))
    d = a - b
    return float(np.sum((d - d.mean()) ** 2) / e) if e > 0 else 1.0


def _spread(n, lag):
    """Relative standard deviation of the noise's r at a lag: sum of n - lag squared differences
    of white noise, each pair's difference correlated (-1/2) with the next period's."""
    return np.sqrt(3.0 / np.maximum(n - np.asarray(lag, dtype=float), 1.0))


def _bound(r_best, n, lag_best, lag):
    return r_best * (1.0 + SIGMAS * (_spread(n, lag) + _spread(n, lag_best))) + 1e-12


def _refine(x, L):
    """The period between samples: the vertex of the parabola through r at L - 1, L, L + 1."""
    r = [_residue_at(x, k) for k in (L - 1, L, L + 1)]
    den = r[0] - 2 * r[1] + r[2]
    return L + (0.5 * (r[0] - r[2]) / den if den > 0 else 0.0)


def find_period(x, max_lag=None):
    """(period in samples or None, refined period, r array): the shortest lag at which x repeats.

    Lags start after r first reaches 1 (the correlation of neighbouring samples no longer holds
    x together). A candidate is a local minimum of r below REPEAT_LIMIT such that (a) none of its
    multiples repeats better by more than SIGMAS noise deviations and shows lines off the
    candidate's grid above their own noise (else it is a near repeat, a signal with little power
    on the lines that tell it from the period; without such lines the better repeat is coloured
    noise, the loop's response to a disturbance under feedback), (b) its multiples
    repeat as well as it does on the record without its first quarter (a narrow band of noise
    drifts away), (c) refined between samples it is whole to within WHOLE. The shortest
    candidate is the period; without a whole one the shortest that meets (a) and (b)."""
    x = np.asarray(x, dtype=float)
    n = x.size
    max_lag = n // 2 if max_lag is None else min(max_lag, n // 2)
    if max_lag < 2:
        return None, None, np.ones(max(max_lag, 0) + 1)
    r = repeat_residue(x, max_lag)
    past = np.flatnonzero(r[1:] >= 1.0)
    if not past.size:
        return None, None, r
    lo = int(past[0]) + 1
    if lo >= max_lag:
        return None, None, r
    lag = np.arange(lo, max_lag + 1)
    left = np.r_[np.inf, r[lo:-1]]
    right = np.r_[r[lo + 1:], np.inf]
    candidates = lag[(r[lo:] <= REPEAT_LIMIT) & (r[lo:] <= left) & (r[lo:] <= right)]
    if not candidates.size:
        return None, None, r
    start = n // 4
    tail = repeat_residue(x[start:], min(max_lag, n - start - 1))
    fractional = None
    for L in candidates:
        # the exact sums decide between neighbours (the FFT's rounding may not, at r near 0)
        near = [k for k in (int(L) - 1, int(L), int(L) + 1) if lo <= k <= max_lag]
        L = min(near, key=lambda k: _residue_at(x, k))
        # refined past the first quarter too: a transient there tilts the parabola
        Lf = _refine(x[start:], L) if n - start > L + 1 else _refine(x, L)
        mult = _multiples(r, Lf, max_lag)
        r_L = float(r[L])
        beaten = [int(M) for M in mult if r_L > _bound(float(r[M]), n, int(M), L)]
        # a multiple that leaves fewer than 3 of its periods past the first quarter cannot show
        # its lines above a coloured noise (2 degrees of freedom a line): judged at those it can
        judged = [M for M in beaten if (n - start) // M >= 3]
        if any(_off_grid_lines(x[start:], M, max(2, round(M / Lf))) for M in judged):
            continue                                                      # (a)
        if not _multiples_repeat(tail, Lf, n - start):
            continue                                                      # (b)
        if abs(Lf - L) <= WHOLE:
            return L, Lf, r                                               # (c)
        # a lag the signal nearly repeats at between samples (lines on multiples of s with N not
        # divisible by s: 4/5 of the period is 0.8 N samples): a whole period may follow
        fractional = fractional or (L, Lf)
    if fractional is not None:
        return fractional[0], fractional[1], r
    return None, None, r


def _multiples(r, Lf, max_lag):
    """The lags nearest the multiples 2 Lf, 3 Lf ... up to max_lag, each the best of its three
    neighbours in r (a period between samples drifts by a fraction of a sample per multiple)."""
    out = []
    m = 2
    while round(m * Lf) <= max_lag:
        k = int(round(m * Lf))
        near = [j for j in (k - 1, k, k + 1) if 1 <= j < r.size]
        out.append(min(near, key=lambda j: r[j]))
        m += 1
    return np.array(out, dtype=int)


def _multiples_repeat(r_tail, Lf, n):
    """(b): on the record without its first quarter (n samples, residues r_tail), each multiple
    k L repeats as well as L, to the noise's deviations; what is left of a start-up transient
    raises the residue at k L by at most (n - L) / (n - k L)."""
    L = int(round(Lf))
    if L >= r_tail.size:
        return True
    r_L = float(r_tail[L])
    for k in _multiples(r_tail, Lf, min(r_tail.size - 1, n - L)):
        if r_tail[k] > (n - L) / (n - k) * _bound(r_L, n, L, k):
            return False
    return True


def _output_multiple(y, L, Lf, left, tail):
    """(m, r): the smallest multiple m L at which the output repeats, and its residue: judged
    from sample ``tail`` (past a start-up transient) where that leaves two periods of m L, else
    from ``left`` (the first whole period). A multiple m > 1 must also show in the spectrum:
    lines of the period m L off the input's grid (not multiples of m) that stand above the noise
    of the periods (a disturbance that nearly realigns after m periods lowers r there but
    differs from period to period)."""
    n = y.size - left
    r_all = repeat_residue(y[left:], n // 2)
    r_tail = repeat_residue(y[tail:], (y.size - tail) // 2)
    ms, rs, starts = [], [], []
    for m in range(1, max(1, (n // 2) // L) + 1):
        k = int(round(m * Lf))
        rr, st = (r_tail, tail) if k < r_tail.size else (r_all, left)
        near = [j for j in (k - 1, k, k + 1) if 1 <= j < rr.size]
        if not near:
            break
        ms.append(m)
        rs.append(float(min(rr[j] for j in near)))
        starts.append(st)
    i_best = int(np.argmin(rs))
    for m, r, st in zip(ms, rs, starts):
        if r <= _bound(rs[i_best], n, ms[i_best] * L, m * L):
            if m == 1 or _off_grid_lines(y[st:], int(round(m * Lf)), m):
                return m, r
            break
    return 1, rs[0]


def _off_grid_lines(y, N, m):
    """Whether the output cut into periods of N samples has lines that are not multiples of m
    above the noise of its periods (the line test of :func:`inspect`)."""
    P = y.size // N
    if P < 2:
        return False
    lines, Y, var = _spectra(y[y.size - P * N:].reshape(P, N))
    from .._dist import gamma_sf

    off = lines % m != 0
    p2 = np.abs(Y) ** 2
    noise, nu = _pooled(var, P)
    # where the variances of a line and its neighbours (+-OWN_HALF_WINDOW) stand above the pooled
    # median by more than sample variances' chance (OWN_LEVEL: noise that is not flat there, e.g.
    # the loop's response to a disturbance at a resonance, or a low-pass disturbance), the line is
    # judged against its own variance, |Y|^2 / (var / P) ~ F(2, 2 (P - 1)) for noise; the others
    # against the median, as the line test
    from scipy.ndimage import uniform_filter1d
    w = min(2 * OWN_HALF_WINDOW + 1, var.size)
    local = uniform_filter1d(var, size=w, mode="nearest")
    with np.errstate(divide="ignore", invalid="ignore"):
        dof = w * (P - 1)
        own = gamma_sf(np.where(noise > 0, local / noise, np.inf) * dof, dof) < OWN_LEVEL
        live = p2 > 1e-20 * p2.max()
        z_pool = np.where(live, p2 / (noise / P), 0.0)
        z_own = np.where(live, p2 / (var / P), 0.0)
    n = int(off.sum())
    hit = np.where(own, z_own > _threshold(n, P - 1), z_pool > _threshold(n, nu))
    return bool(np.any(hit[off]))


# ------------------------------------------------------------------------------ the periods

def _drift(xs):
    """(change per period, t) of a straight line through the deviations of the periods from
    their mean, when it stands out of their noise by more than SIGMAS standard errors (the
    deviations taken as white); else None."""
    P, N = xs.shape
    if P < 2:
        return None
    dev = (xs - xs.mean(axis=0)).ravel()
    t = np.arange(dev.size) / N - (dev.size - 1) / (2 * N)
    slope = float(np.dot(t, dev) / np.dot(t, t))
    res = dev - slope * t
    se = math.sqrt(max(float(np.dot(res, res)) / max(dev.size - N - 1, 1), 1e-300) / float(np.dot(t, t)))
    z = abs(slope) / se
    return (slope, z) if z > SIGMAS else None


def _transient(xs, n_ref):
    """Each leading period against the mean of the last n_ref, over the noise those show."""
    P, N = xs.shape
    ref = xs[P - n_ref:]
    mean = ref.mean(axis=0)
    s2 = float(ref.var(axis=0, ddof=1).mean())
    out = []
    for p in range(P - n_ref):
        num = float(np.mean((xs[p] - mean) ** 2))
        if s2 <= 0:
            out.append(np.inf if num > 1e-24 * max(float(np.mean(xs ** 2)), 1e-300) else 1.0)
        else:
            out.append(num / (s2 * (1.0 + 1.0 / n_ref)))
    return np.array(out)


TRANSIENT_LEFT = 0.01
"""The most power a start-up transient may leave in the mean of the kept periods, as a share of
that mean's own noise power (METHOD.md section 18, "Periods and transient"): the periods to drop
are counted until what is left of the transient is below it."""


@dataclass(frozen=True)
class TransientSkip:
    """How many leading periods to drop so that the transient leaves no bias (METHOD.md section 18)."""

    periods: int
    """Leading periods to drop (--skip-periods)."""
    seen: int
    """Leading periods that differ from the steady ones by more than noise does (one period's test)."""
    decay: float
    """The transient's power from one period to the next (rho^2; nan when none is seen)."""
    left: float
    """What the transient leaves in the mean of the kept periods, over that mean's noise power (0
    when none is seen; an upper estimate)."""
    enough: bool
    """False when even the most periods that may be dropped (all but 2) leave more than
    :data:`TRANSIENT_LEFT`: the record is too short for its transient."""


def transient_skip(ratios, limit: float, periods: int, n_ref: int) -> TransientSkip:
    """The leading periods to drop, from each leading period's ratio to the noise (:func:`_transient`)
    of one channel. The periods above ``limit`` are seen; the transient's power in period p,
    e_p = (r_p - 1) in units of one sample's noise, decays by rho^2 per period (fitted to the seen
    periods' log e_p; with one period seen, the slowest decay that leaves the next below the limit).
    Dropping K >= seen periods leaves in the mean of the P - K kept ones a transient of power at
    most e_K (1 + 1/n_ref) ((1 - rho^(P-K)) / (1 - rho))^2 / (P - K)^2, which must be at most
    TRANSIENT_LEFT times the mean's noise power s^2 / (P - K)."""
    r = np.asarray(ratios, float)
    seen = 0
    while seen < r.size and r[seen] > limit:
        seen += 1
    if seen == 0:
        return TransientSkip(0, 0, math.nan, 0.0, True)
    e = np.maximum(r[:seen] - 1.0, 1e-300)
    if seen >= 2:
        slope = float(np.polyfit(np.arange(seen), np.log(e), 1)[0])
    else:
        slope = math.log(max(limit - 1.0, 1e-300) / e[0])
    decay = math.exp(min(slope, 0.0))
    rho = math.sqrt(decay)

    def left(K):
        kept = periods - K
        eK = e[K] if K < seen else e[-1] * decay ** (K - seen + 1)
        gain = kept if rho >= 1 else (1 - rho ** kept) / (1 - rho)
        return float(eK * (1 + 1 / n_ref) * gain ** 2 / kept)

    K = seen
    while K < periods - 2 and left(K) > TRANSIENT_LEFT:
        K += 1
    K = min(K, max(periods - 2, 0))
    return TransientSkip(K, seen, decay, left(K), left(K) <= TRANSIENT_LEFT)


def _spectra(xs):
    """Mean spectrum (DFT / N) on lines 1..N/2 - 1 and the per-line variance over the periods."""
    P, N = xs.shape
    X = np.fft.rfft(xs, axis=1) / N
    lines = np.arange(1, (N - 1) // 2 + 1)
    X = X[:, lines]
    return lines, X.mean(axis=0), X.var(axis=0, ddof=1) if P > 1 else np.zeros(lines.size)


def _pooled(var, P):
    """(noise, nu): the per-line noise variance pooled over w neighbouring lines (their median,
    unbiased for a variance from P periods of complex Gaussian noise, var ~ sigma^2 Gamma(P - 1,
    1 / (P - 1))); the windows at the ends of the band are the first and last w lines. nu: the
    degrees of freedom of a scaled chi-square with the median's variance, 1 / (4 w f(m)^2)
    relative to m^2 (f the density at the median m)."""
    from scipy.ndimage import median_filter
    from .._dist import gamma_median, gamma_pdf

    n = var.size
    w = min(2 * NOISE_HALF_WINDOW + 1, n)
    h = w // 2
    med = median_filter(var, size=w, mode="nearest")
    if n > w:
        med[:h] = np.median(var[:w])
        med[n - h:] = np.median(var[n - w:])
    else:
        med[:] = np.median(var)
    m = gamma_median(P - 1, 1.0 / (P - 1))
    nu = 4.0 * w * (m * gamma_pdf(m, P - 1, 1.0 / (P - 1))) ** 2
    return med / m, nu


def _threshold(n_lines, nu):
    """The line test's threshold t on |X|^2 / (sigma^2 / P): noise alone exceeds it on any of
    n_lines lines with chance ALPHA, sigma^2 being estimated with nu degrees of freedom
    (|X|^2 over it is then F(2, 2 nu): P(F > t) = (1 + t / nu)^-nu)."""
    return float(nu * ((max(n_lines, 1) / ALPHA) ** (1.0 / nu) - 1.0))


def _classify(lines, excited, weak, s, reach, z, Y2, noise, y_excited_power, t):
    lo, hi = int(excited.min()), int(excited.max())
    rest = np.setdiff1d(lines, np.union1d(excited, weak))
    pos = np.searchsorted(excited, rest)
    d_left = np.abs(rest - excited[np.clip(pos - 1, 0, excited.size - 1)])
    d_right = np.abs(excited[np.clip(pos, 0, excited.size - 1)] - rest)
    dist = np.minimum(d_left, d_right)
    in_band = (rest >= lo) & (rest <= hi)
    detect = in_band & (rest % s == 0)
    odd = detect & ((rest // s) % 2 == 1)
    even = detect & ((rest // s) % 2 == 0)
    side = ~detect & (dist >= 1) & (dist <= reach)
    names = (("sidebands", side), ("odd detection", odd), ("even detection", even),
             ("elsewhere", ~(side | odd | even)))
    index = {int(l): i for i, l in enumerate(lines)}
    out = []
    for name, mask in names:
        ls = rest[mask]
        idx = np.array([index[int(l)] for l in ls], dtype=int)
        above = ls[z[idx] > t] if idx.size else ls[:0]
        excess = float(10 * np.log10(Y2[idx].sum() / noise[idx].sum())) if idx.size and noise[idx].sum() > 0 else np.nan
        ia = np.array([index[int(l)] for l in above], dtype=int)
        level = (float(10 * np.log10(Y2[ia].max() / y_excited_power)) if ia.size and y_excited_power > 0 else np.nan)
        out.append(LineClass(name, ls, above, excess, level))
    # the time variation's reach: distances 1, 2, ... with a line above the noise (any class: a
    # design without room for sidebands puts them on its detection lines)
    k = 0
    for d in range(1, reach + 1):
        at = rest[dist == d]
        if at.size and np.any(z[[index[int(l)] for l in at]] > t):
            k = d
        else:
            break
    return tuple(out), k
