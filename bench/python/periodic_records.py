"""Periodic records of systems simulated outside lptv, for the noise-route benchmarks.

Each system gives one noise-free steady-state period of input and output, computed without lptv:

- ``"ct3"``: a third-order continuous-time LPTV system,
  y''' + 2.2 y'' + (3.1 + 0.6 cos w0 t) y' + (1.5 + 0.4 sin w0 t) y = (1.2 + 0.3 cos(w0 t + 0.4)) u,
  T = 20 s, 512 samples a period, u a random-phase multisine on lines 1, 4, 7, .., 34 (up to
  10.7 rad/s), integrated by SciPy's solve_ivp (DOP853, rtol 1e-11) for four periods from rest
  (the slowest Floquet mode decays by e^-12 or more a period) and the last period kept;
- ``"dt2"``: a second-order discrete-time LPTV system,
  y[t+2] - 1.1 y[t+1] + (0.45 + 0.08 cos(w0 t + 0.3)) y[t] = 0.6 u[t+1] + (1 + 0.1 cos w0 t) u[t],
  N = 256 samples a period, lines 1, 4, .., 97, run by a NumPy loop for 60 periods from rest;
- ``"lti4"``: a fourth-order continuous-time LTI system (two lightly damped modes,
  H(s) = 1 / ((s^2 + 0.3 s + 1)(s^2 + 0.5 s + 6.25))), N = 1024, T = 50 s, lines 2, 5, .., 98,
  its steady state the exact transfer function on the lines (inverse FFT).

The noise is drawn per record: the input's white with a standard deviation of ``snr_in`` of its
rms, the output's coloured (``"smooth"``: white noise through a second-order Butterworth low-pass
at 0.2 of Nyquist, over a white floor 20 dB below its pass band: a spectrum with a knee, a slope
and a floor; without the floor the periods' leakage dominates the lines 40 dB down, see
METHOD.md section 7) or with a spectrum that is not smooth (``"rough"``: white noise through
eight resonators from 0.05 to 0.4 of Nyquist, each about three lines wide, over a floor), at
``snr_out`` of the output's rms. Periods are cut from one long noise sequence (after a warm-up of its filter).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import integrate, signal

SYSTEMS = ("ct3", "dt2", "lti4")

# name -> structure keyword arguments of lptv.identify, and the harmonic count K of the rows
STRUCTURES = {
    "ct3": dict(na=3, nb=0, ka=[1, 1, 0, 0], kb=[1]),
    "dt2": dict(na=2, nb=1, ka=[1, 0, 0], kb=[1, 0]),
    "lti4": dict(na=4, nb=0, ka=0, kb=0),
}


def _multisine(lines, N, rng):
    lines = np.asarray(lines)
    ph = rng.uniform(0, 2 * np.pi, lines.size)
    amp = np.sqrt(2.0 / lines.size)
    return lines, amp, ph


@lru_cache(maxsize=None)
def steady_state(system: str, seed: int = 0):
    """(u0, y0, w0, ts, excited lines) of one noise-free period, simulated outside lptv."""
    rng = np.random.default_rng([seed, SYSTEMS.index(system), 17])
    if system == "ct3":
        N, T = 512, 20.0
        w0 = 2 * np.pi / T
        lines, amp, ph = _multisine(np.arange(1, 35, 3), N, rng)

        def u_of(t):
            return amp * np.cos(np.multiply.outer(t, lines * w0) + ph).sum(-1)

        def f(t, x):
            y, dy, ddy = x
            a1 = 3.1 + 0.6 * np.cos(w0 * t)
            a0 = 1.5 + 0.4 * np.sin(w0 * t)
            b0 = 1.2 + 0.3 * np.cos(w0 * t + 0.4)
            return [dy, ddy, b0 * u_of(np.array(t)) - 2.2 * ddy - a1 * dy - a0 * y]

        t_eval = 3 * T + np.arange(N) * T / N
        sol = integrate.solve_ivp(f, (0.0, 4 * T), [0.0, 0.0, 0.0], method="DOP853", rtol=1e-11, atol=1e-13,
                                  t_eval=t_eval)
        return u_of(np.arange(N) * T / N), sol.y[0], w0, None, lines
    if system == "dt2":
        N = 256
        w0 = 2 * np.pi / N
        lines, amp, ph = _multisine(np.arange(1, 98, 3), N, rng)
        n = np.arange(N)
        u1 = amp * np.cos(np.outer(n, lines * w0) + ph).sum(-1)
        reps = 60
        u = np.tile(u1, reps + 1)
        t = np.arange(u.size)
        a0 = 0.45 + 0.08 * np.cos(w0 * t + 0.3)
        b0 = 1.0 + 0.1 * np.cos(w0 * t)
        y = np.zeros(u.size)
        for k in range(u.size - 2):
            y[k + 2] = 1.1 * y[k + 1] - a0[k] * y[k] + 0.6 * u[k + 1] + b0[k] * u[k]
        return u1, y[(reps - 1) * N:reps * N], w0, 1.0, lines
    if system == "lti4":
        N, T = 1024, 50.0
        w0 = 2 * np.pi / T
        lines, amp, ph = _multisine(np.arange(2, 99, 3), N, rng)
        s = 1j * lines * w0
        H = 1.0 / ((s ** 2 + 0.3 * s + 1.0) * (s ** 2 + 0.5 * s + 6.25))
        U = np.zeros(N // 2 + 1, complex)
        U[lines] = amp * np.exp(1j * ph) * N / 2
        Y = np.zeros_like(U)
        Y[lines] = H * U[lines]
        return np.fft.irfft(U, N), np.fft.irfft(Y, N), w0, None, lines
    raise ValueError(f"system must be one of {SYSTEMS}, got {system!r}")


def _shaped(rng, n, kind, N):
    warm = 4000
    e = rng.standard_normal(n + warm)
    if kind == "white":
        return e[warm:]
    if kind == "smooth":
        b, a = signal.butter(2, 0.2)
        x = signal.lfilter(b, a, e) + 0.1 * rng.standard_normal(e.size)
    elif kind == "rough":
        x = np.zeros_like(e)
        for fc in np.linspace(0.05, 0.4, 8):          # eight bumps about three lines wide over the band
            b, a = signal.iirpeak(fc, max(fc * (N / 2) / 3.0, 0.7))
            x += signal.lfilter(b, a, e) * 3.0
        x += 0.3 * e
    else:
        raise ValueError(f"noise kind must be 'white', 'smooth' or 'rough', got {kind!r}")
    x = x[warm:]
    return x / np.std(x)


def record(system: str, periods: int, seed, *, noise: str = "smooth", snr_in: float = 0.01,
           snr_out: float = 0.05):
    """P noisy periods of ``system``: dict(u, y (P, N), w0, ts, rows, structure, excited)."""
    u0, y0, w0, ts, lines = steady_state(system)
    rng = np.random.default_rng(seed)
    N = u0.size
    nu = snr_in * np.std(u0) * rng.standard_normal(periods * N)
    ny = snr_out * np.std(y0) * _shaped(rng, periods * N, noise, N)
    u = np.tile(u0, periods) + nu
    y = np.tile(y0, periods) + ny
    st = STRUCTURES[system]
    K = max(np.max(st["ka"]), np.max(st["kb"]))
    rows = np.unique(np.concatenate([lines + k for k in range(-K, K + 1)]))
    rows = rows[(rows > K) & (rows < N // 2 - K)]
    return dict(u=u.reshape(periods, N), y=y.reshape(periods, N), w0=w0, ts=ts, rows=rows,
                structure=dict(st), excited=lines)


def truth(system: str):
    """The true coefficients as (a rows, b rows), each a list of {harmonic k: complex coefficient}
    per coefficient a_0 .. a_na (b_0 .. b_nb), a_na's mean 1."""
    if system == "ct3":
        a = [{0: 1.5, 1: -0.2j}, {0: 3.1, 1: 0.3}, {0: 2.2}, {0: 1.0}]
        b = [{0: 1.2, 1: 0.15 * np.exp(0.4j)}]
    elif system == "dt2":
        a = [{0: 0.45, 1: 0.04 * np.exp(0.3j)}, {0: -1.1}, {0: 1.0}]
        b = [{0: 1.0, 1: 0.05}, {0: 0.6}]
    elif system == "lti4":
        p1, p2 = np.array([1, 0.3, 1.0]), np.array([1, 0.5, 6.25])
        den = np.polymul(p1, p2)[::-1]
        a = [{0: c} for c in den]
        b = [{0: 1.0}]
    else:
        raise ValueError(f"system must be one of {SYSTEMS}, got {system!r}")
    return a, b


def main() -> int:
    """A check of the records against their stated truth: each system's record with noise 1e-6
    of its rms, fitted by lptv (SML, the true structure); the largest error of a coefficient."""
    import warnings

    import lptv

    for system in SYSTEMS:
        d = record(system, 4, 0, snr_in=1e-6, snr_out=1e-6)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"], lines=d["rows"],
                                method="sml")
        a, b = truth(system)
        Ka, Kb = (res.model.a.shape[1] - 1) // 2, (res.model.b.shape[1] - 1) // 2
        err = max(max(abs(res.model.a[n, Ka + k] - v) for n, row in enumerate(a) for k, v in row.items()),
                  max(abs(res.model.b[n, Kb + k] - v) for n, row in enumerate(b) for k, v in row.items()))
        print(f"{system}: largest coefficient error {err:.2e} (noise 1e-6 of the rms)")
        if not err < 1e-3:
            print(f"{system}: the record does not follow its stated equation", file=__import__("sys").stderr)
            return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
