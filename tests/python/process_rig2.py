"""Records of a 2 x 2 rig with disturbances that pass through the system, simulated outside lptv
(shared by tests/python/test_process_rig2.py and bench/python/bench_process_noise_mimo.py; the
one-mass rig is process_rig.py).

The rig: two masses coupled by a spring, each held by its own spring whose stiffness varies with
the period,

    m1 x1'' + c1 x1' + k1(t) x1 + kc (x1 - x2) = F1 + d1,
    m2 x2'' + c2 x2' + k2(t) x2 + kc (x2 - x1) = F2 + d2,

k1(t) = k10 (1 + 0.25 cos w0 t), k2(t) = k20 (1 + 0.25 cos(w0 t + PHASE)), m1 = 1 kg, m2 = 1.5 kg,
c_i = m_i x 1 /s (so M^-1 C = I and every free motion decays as exp(-t/2)), k10 = 30 N/m,
k20 = 45 N/m, kc = 10 N/m (modes at 5.5 and 6.8 rad/s), T0 = 4 s, sampled at 32 Hz (N = 128 a
period). The references are two independent odd random-phase multisines s1, s2 on the odd lines
1 .. 21 (0.25 .. 5.25 Hz), applied in two experiments by the orthogonal (Hadamard) pattern of
METHOD.md section 19: r = (s1, s2) in experiment 0 and r = (s1, -s2) in experiment 1, so that
the two inputs are separated on every line. The force on mass i is F_i = Kp r_i in open loop and
F_i = Kp (r_i - x_i) under decentralised proportional feedback (Kp = 20 N/m). The disturbances
d1, d2 are independent smooth low-pass random forces that do not repeat (process_rig.py's: 200
cosines at frequencies drawn uniformly in (0, 3 Hz), random phases, a second-order roll-off at
1.5 Hz), drawn afresh for each mass, experiment and record (evaluated on a 64 Hz grid and integrated as
its quintic spline, within about 1e-8 of its rms). The measured inputs are
u_i = F_i + e_ui, the measured outputs y_i = x_i + e_yi, every e white with ``sensor`` times
the rms of its channel.

Integrated by SciPy's solve_ivp (DOP853, rtol 1e-10) from rest for ``skip`` periods of
transient, then ``periods`` periods kept (every Floquet mode decays as exp(-t/2) in open loop,
e^-12 over the default six periods; the feedback adds Kp to the stiffness, not to the damping).

The true model in lptv's normalisation (A_2,0 = I, METHOD.md eq. 19.7): the equation multiplied
by M^-1, A_2 = I, A_1 = M^-1 C, A_0(t) = M^-1 K(t) with
K(t) = [[k1(t) + kc, -kc], [-kc, k2(t) + kc]], B_0 = M^-1; the structure na = 2, nb = 0,
ka = [1, 0, 0] (the stiffness's first harmonic), kb = 0.
"""
from __future__ import annotations

import numpy as np
from scipy import integrate, interpolate

M1, M2 = 1.0, 1.5
C1, C2 = 1.0, 1.5
K10, K20, KC = 30.0, 45.0, 10.0
DEPTH, PHASE = 0.25, np.pi / 3
T0, FS, N = 4.0, 32.0, 128
W0 = 2 * np.pi / T0
KP = 20.0
LINES = np.arange(1, 22, 2)
PATTERN = np.array([[1.0, 1.0], [1.0, -1.0]])    # T[q, e]: the sign of reference q in experiment e
DIST_RATE = 64.0
STRUCTURE = dict(na=2, nb=0, ka=[1, 0, 0], kb=0)


def truth() -> np.ndarray:
    """The true real parameters in lptv's order for STRUCTURE (METHOD.md section 19, 'How the
    estimators are built'): row p = 0, 1 of the equation in turn, and per row the coefficients
    a0[p,0] (re0, re1, im1), a0[p,1] (re0, re1, im1), a1[p,0], a1[p,1], a2[p,0], a2[p,1],
    b0[p,0], b0[p,1] (re0 each): 24 numbers, a2[p,q].re0 = delta_pq the normalised ones."""
    h1 = 0.5 * DEPTH * K10                        # harmonic +1 of k1(t): k10 D / 2
    h2 = 0.5 * DEPTH * K20 * np.exp(1j * PHASE)   # of k2(t): k20 D / 2 e^{j PHASE}
    row0 = [(K10 + KC) / M1, h1 / M1, 0.0, -KC / M1, 0.0, 0.0, C1 / M1, 0.0, 1.0, 0.0, 1.0 / M1, 0.0]
    row1 = [-KC / M2, 0.0, 0.0, (K20 + KC) / M2, h2.real / M2, h2.imag / M2, 0.0, C2 / M2, 0.0, 1.0, 0.0,
            1.0 / M2]
    return np.array(row0 + row1)


NAMES = tuple(f"{c}[{p},{q}].{part}" for p in range(2) for c, q, part in
              [("a0", 0, "re0"), ("a0", 0, "re1"), ("a0", 0, "im1"), ("a0", 1, "re0"), ("a0", 1, "re1"),
               ("a0", 1, "im1"), ("a1", 0, "re0"), ("a1", 1, "re0"), ("a2", 0, "re0"), ("a2", 1, "re0"),
               ("b0", 0, "re0"), ("b0", 1, "re0")])
"""The names of truth()'s entries, as lptv's results name them (a0[p,q].re1: Re of harmonic 1)."""


def reference(seed: int = 0):
    """The references' lines, amplitudes (per line) and phases (2, lines): s1 and s2."""
    rng = np.random.default_rng([seed, 4811])
    ph = rng.uniform(0, 2 * np.pi, (2, LINES.size))
    amp = np.full(LINES.size, 1.0)
    return LINES, amp, ph


def _disturbance(rng, level: float, n: int = 200, fmax: float = 3.0, fc: float = 1.5):
    """(frequencies in rad/s, amplitudes, phases) of one disturbance (as process_rig.py's)."""
    f = rng.uniform(0, fmax, n)
    ph = rng.uniform(0, 2 * np.pi, n)
    shape = 1.0 / np.abs(1 + 1j * np.sqrt(2) * f / fc - (f / fc) ** 2)
    amp = shape * np.sqrt(2.0 / np.sum(shape ** 2)) * level   # rms = level
    return 2 * np.pi * f, amp, ph


def records(seeds, *, periods: int = 8, loop: str = "open", process: float = 1.0, sensor: float = 0.01,
            skip: int = 6, ref_seed: int = 0, rtol: float = 1e-10):
    """Records of the rig, one per seed, all integrated together (one solve_ivp call on the
    stacked states of every record and experiment): a list of dict(experiments = [(u, y)] * 2
    with u, y of shape (periods, N, 2), x, F (the noise-free displacements and forces, shape
    (2, periods, N, 2): experiment, period, sample, mass), w0, fs, lines, loop).

    ``process``: each disturbance's rms in N (each reference force has rms Kp sqrt(11/2) = 47 N
    in open loop); 0 leaves them out. ``loop``: "open" or "feedback"."""
    if loop not in ("open", "feedback"):
        raise ValueError(f"loop must be 'open' or 'feedback', got {loop!r}")
    seeds = list(seeds)
    R, E = len(seeds), PATTERN.shape[1]
    rngs = [np.random.default_rng([s, 4812]) for s in seeds]
    lines, amp, ph = reference(ref_seed)
    wl = lines * W0
    dist = [[[_disturbance(g, process) for _ in range(2)] for _ in range(E)] for g in rngs]
    dw = np.array([[[x[0] for x in de] for de in dr] for dr in dist])     # (R, E, 2, n)
    da = np.array([[[x[1] for x in de] for de in dr] for dr in dist])
    dp = np.array([[[x[2] for x in de] for de in dr] for dr in dist])
    if process <= 0:
        da[:] = 0.0
    n_total = (skip + periods) * N
    t_eval = np.arange(n_total) / FS
    t_end = t_eval[-1] + 0.5 / FS
    dist_of = None
    if process > 0:
        # the sums of cosines on a grid of DIST_RATE Hz and their quintic spline (band-limited to
        # 3 Hz: the spline's error is about 1e-8 of the rms), evaluated at solve_ivp's times
        tg = np.arange(-4, int(np.ceil(t_end * DIST_RATE)) + 5) / DIST_RATE
        dg = np.concatenate([np.einsum("rein,trein->trei", da, np.cos(dw * tc[:, None, None, None, None] + dp))
                             for tc in np.array_split(tg, max(1, tg.size // 128))])
        dist_of = interpolate.make_interp_spline(tg, dg, k=5)
    minv = np.array([1 / M1, 1 / M2])
    cdamp = np.array([C1, C2])
    kmean = np.array([K10, K20])
    kphase = np.array([0.0, PHASE])
    n = R * E * 2
    feedback = loop == "feedback"
    out = np.empty(2 * n)

    def r_of(t):
        """The references of every experiment at t, shape (E, 2): r[e, q] = T[q, e] s_q(t)."""
        s = np.cos(wl * t + ph) @ amp
        return PATTERN.T * s[None, :]

    def f(t, state):
        x = state[:n].reshape(R, E, 2)
        v = state[n:].reshape(R, E, 2)
        k = kmean * (1 + DEPTH * np.cos(W0 * t + kphase)) + KC      # k_i(t) + kc
        force = KP * r_of(t)
        if feedback:
            force = force - KP * x
        if dist_of is not None:
            force = force + dist_of(t)
        acc = (force - cdamp * v - k * x + KC * x[..., ::-1]) * minv
        out[:n] = state[n:]
        out[n:] = acc.ravel()
        return out.copy()

    sol = integrate.solve_ivp(f, (0.0, t_end), np.zeros(4 * R * E), method="DOP853", rtol=rtol,
                              atol=1e-12, t_eval=t_eval)
    if not sol.success:
        raise RuntimeError(f"solve_ivp: {sol.message}")
    keep = slice(skip * N, None)
    xs = sol.y[:R * E * 2].reshape(R, E, 2, n_total)[..., keep]          # (R, E, 2, samples)
    rvals = np.array([r_of(t) for t in t_eval[keep]])                     # (samples, E, 2)
    rvals = np.moveaxis(rvals, 0, -1)                                     # (E, 2, samples)
    out = []
    for i, g in enumerate(rngs):
        x = xs[i]
        F = KP * rvals if loop == "open" else KP * (rvals - x)
        exps, X, Fs = [], [], []
        for e in range(E):
            ue = F[e] + sensor * np.std(F[e], axis=1, keepdims=True) * g.standard_normal(F[e].shape)
            ye = x[e] + sensor * np.std(x[e], axis=1, keepdims=True) * g.standard_normal(x[e].shape)
            exps.append((ue.T.reshape(periods, N, 2), ye.T.reshape(periods, N, 2)))
            X.append(x[e].T.reshape(periods, N, 2))
            Fs.append(F[e].T.reshape(periods, N, 2))
        out.append(dict(experiments=exps, x=np.array(X), F=np.array(Fs), w0=W0, fs=FS, lines=lines, loop=loop))
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
