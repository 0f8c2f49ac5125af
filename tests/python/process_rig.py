"""Records of a rig with a disturbance that passes through the system, simulated outside lptv
(shared by tests/python/test_process_noise.py and bench/python/bench_process_noise.py).

The rig: m x'' + c x' + k(t) x = F + d, k(t) = k0 (1 + 0.25 cos w0 t), m = 1 kg, c = 1 N s/m,
k0 = 30 N/m (a mode at 5.5 rad/s), T0 = 4 s, sampled at 32 Hz (N = 128 a period). The reference
r is an odd random-phase multisine on the odd lines 1 .. 21 (0.25 .. 5.25 Hz). The force is
F = Kp r in open loop and F = Kp (r - x) under proportional feedback (Kp = 20 N/m). The
disturbance d is a smooth, low-pass random force that does not repeat: a sum of 200 cosines at
frequencies drawn uniformly in (0, 3 Hz) with random phases, amplitudes shaped by a second-order
roll-off at 1.5 Hz (a Gaussian process to a good approximation, analytic in t, whose spectrum
is continuous, so that no period repeats it). The measured input is u = F + e_u, the measured
output y = x + e_y, e_u and e_y white with ``sensor`` times the rms of F and of x.

Integrated by SciPy's solve_ivp (DOP853, rtol 1e-10) from rest for ``skip`` periods of
transient, then ``periods`` periods kept (the Floquet modes decay as exp(-0.5 t), e^-12 over
the default six periods of transient).

The true model in lptv's normalisation (a_2 = 1): a_1 = c / m, a_0 = k(t) / m (harmonics 0 and
+-1: k0 / m and 0.125 k0 / m), b_0 = 1 / m, the structure na = 2, nb = 0, ka = [1, 0, 0], kb = 0.
"""
from __future__ import annotations

import numpy as np
from scipy import integrate

M, C, K0, DEPTH = 1.0, 1.0, 30.0, 0.25
T0, FS, N = 4.0, 32.0, 128
W0 = 2 * np.pi / T0
KP = 20.0
LINES = np.arange(1, 22, 2)
STRUCTURE = dict(na=2, nb=0, ka=[1, 0, 0], kb=0)


def truth() -> np.ndarray:
    """The true real parameters in lptv's order for STRUCTURE: a0.re0, a0.re1, a0.im1, a1.re0,
    a2.re0 (= 1), b0.re0."""
    return np.array([K0 / M, 0.5 * DEPTH * K0 / M, 0.0, C / M, 1.0, 1.0 / M])


def reference(seed: int = 0):
    """The reference's lines, amplitudes and phases (one realisation per seed)."""
    rng = np.random.default_rng([seed, 4801])
    ph = rng.uniform(0, 2 * np.pi, LINES.size)
    amp = np.full(LINES.size, 1.0)
    return LINES, amp, ph


def _disturbance(rng, level: float, n: int = 200, fmax: float = 3.0, fc: float = 1.5):
    """(frequencies in rad/s, amplitudes, phases) of one disturbance."""
    f = rng.uniform(0, fmax, n)
    ph = rng.uniform(0, 2 * np.pi, n)
    shape = 1.0 / np.abs(1 + 1j * np.sqrt(2) * f / fc - (f / fc) ** 2)
    amp = shape * np.sqrt(2.0 / np.sum(shape ** 2)) * level   # rms = level
    return 2 * np.pi * f, amp, ph


def records(seeds, *, periods: int = 8, loop: str = "open", process: float = 1.0, sensor: float = 0.01,
            skip: int = 6, ref_seed: int = 0, k_scale: float = 1.0, second: float = 0.0):
    """Records of the rig, one per seed, integrated together (one solve_ivp call on the stacked
    states): a list of dict(u, y (periods, N), w0, fs, lines, loop, x, F (noise-free force and
    displacement)).

    ``process``: the disturbance's rms in N (the reference's force has rms Kp sqrt(11/2) = 47 N in
    open loop); 0 leaves it out. ``loop``: "open" or "feedback"."""
    if loop not in ("open", "feedback"):
        raise ValueError(f"loop must be 'open' or 'feedback', got {loop!r}")
    seeds = list(seeds)
    R = len(seeds)
    rngs = [np.random.default_rng([s, 4802]) for s in seeds]
    lines, amp, ph = reference(ref_seed)
    wl = lines * W0
    dist = [_disturbance(g, process) for g in rngs]
    dw = np.array([x[0] for x in dist]); da = np.array([x[1] for x in dist]); dp = np.array([x[2] for x in dist])
    if process <= 0:
        da[:] = 0.0
    k0 = K0 * k_scale

    def r_of(t):
        return np.dot(amp, np.cos(wl * t + ph))

    def force(t, x):
        return KP * r_of(t) if loop == "open" else KP * (r_of(t) - x)

    def f(t, s):
        x, v = s[:R], s[R:]
        k = k0 * (1 + DEPTH * np.cos(W0 * t) + second * np.cos(2 * W0 * t))
        d = np.einsum("rn,rn->r", da, np.cos(dw * t + dp))
        return np.concatenate([v, (force(t, x) + d - C * v - k * x) / M])

    n_total = (skip + periods) * N
    t_eval = np.arange(n_total) / FS
    sol = integrate.solve_ivp(f, (0.0, t_eval[-1] + 0.5 / FS), np.zeros(2 * R), method="DOP853", rtol=1e-10,
                              atol=1e-12, t_eval=t_eval)
    keep = slice(skip * N, None)
    out = []
    rvals = np.array([r_of(t) for t in t_eval])
    for i, g in enumerate(rngs):
        x = sol.y[i]
        F = KP * rvals if loop == "open" else KP * (rvals - x)
        x, F = x[keep], F[keep]
        u = F + sensor * np.std(F) * g.standard_normal(F.size)
        y = x + sensor * np.std(x) * g.standard_normal(x.size)
        out.append(dict(u=u.reshape(periods, N), y=y.reshape(periods, N), w0=W0, fs=FS, lines=lines, loop=loop,
                        x=x.reshape(periods, N), F=F.reshape(periods, N)))
    return out


def record(seed, **kw):
    """One record (see :func:`records`)."""
    return records([seed], **kw)[0]


def fit_lines() -> np.ndarray:
    """The rows of the fits: the excited lines and their +-1 neighbours, from line 2 (rows read
    lines >= 1)."""
    K = 1
    rows = np.unique(np.concatenate([LINES + k for k in range(-K, K + 1)]))
    return rows[(rows > K) & (rows < N // 2 - K)]
