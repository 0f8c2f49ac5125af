"""Records made without lptv, as a rig or another tool would make them: the excitation built by
NumPy, the system simulated by SciPy (solve_ivp of a mass-spring-damper whose stiffness varies
with the period; a difference equation with a periodic coefficient run sample by sample), the
noise added afterwards. Shared by test_inspect.py and bench/python/bench_inspect.py.
"""
import numpy as np
from scipy.integrate import solve_ivp
from scipy.signal import lfilter

MASS, DAMPING, STIFFNESS, VARIATION = 1.0, 2.5, 160.0, 0.3     # resonance near 2 Hz, damping 0.1


def odd_lines(spacing, count, seed, left_out_every=4):
    """Odd multiples j s of ``spacing`` (j = 1, 3, 5, ...), one of every ``left_out_every`` left
    out at random (odd detection lines); ``count`` of them excited."""
    rng = np.random.default_rng(seed)
    j = np.arange(1, 4 * count * 2, 2)
    keep = np.ones(j.size, bool)
    for g in range(0, j.size, left_out_every):
        keep[g + rng.integers(min(left_out_every, j.size - g))] = False
    return spacing * j[keep][:count]


def multisine(lines, period, seed):
    """f(t) = sum_l cos(2 pi l t / period + phi_l), random phases, scaled to rms 1: a function
    of continuous time (the integrator asks for any t)."""
    lines = np.asarray(lines)
    phases = np.random.default_rng(seed).uniform(0, 2 * np.pi, lines.size)
    scale = 1.0 / np.sqrt(lines.size / 2)
    w = 2 * np.pi * lines / period

    def f(t):
        t = np.asarray(t, dtype=float)
        return scale * np.cos(np.multiply.outer(t, w) + phases).sum(axis=-1)

    return f


def mass_spring_damper(period, fs, periods, *, lines, noise=0.01, seed=0, variation=VARIATION,
                       input_noise=None, start=0.0, mass=MASS, damping=DAMPING, stiffness=STIFFNESS):
    """m x'' + c x' + k(t) x = f(t), k(t) = k0 (1 + variation cos(2 pi t / period)), from rest
    at t = 0 (a start-up transient), sampled at fs for ``periods`` periods after ``start`` s;
    noise: standard deviation relative to each channel's rms. Returns (t, f, x)."""
    f = multisine(lines, period, seed)
    wp = 2 * np.pi / period

    def rhs(t, s):
        x, v = s
        k = stiffness * (1 + variation * np.cos(wp * t))
        return [v, (f(t) - damping * v - k * x) / mass]

    n = int(round(period * fs)) * periods
    t = start + np.arange(n) / fs
    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], t_eval=t, method="DOP853", rtol=1e-9, atol=1e-12)
    assert sol.success, sol.message
    return (t,) + _sensor_noise(f(t), sol.y[0], noise, input_noise, seed)


def _sensor_noise(fu, x, noise, input_noise, seed):
    rng = np.random.default_rng(seed + 1000)
    n = fu.size
    fn = noise if input_noise is None else input_noise
    fu = fu + fn * np.std(fu) * rng.standard_normal(n)
    x = x + noise * np.std(x) * rng.standard_normal(n)
    return fu, x


def mass_spring_damper_many(period, fs, periods, *, lines, seeds, noise=0.01, variation=VARIATION,
                            input_noise=None, start=0.0, mass=MASS, damping=DAMPING, stiffness=STIFFNESS):
    """:func:`mass_spring_damper` for each seed of ``seeds`` (each its own multisine phases and
    noise, as that function draws them), the rigs integrated side by side as one system of
    2 len(seeds) states in one solve_ivp call (the same method and tolerances; the error control
    then holds over all of them at once, so each is at least as accurate as alone). Returns a
    list of (t, f, x), one per seed."""
    seeds = list(seeds)
    lines = np.asarray(lines)
    fs_ = [multisine(lines, period, s) for s in seeds]
    phases = np.stack([np.random.default_rng(s).uniform(0, 2 * np.pi, lines.size) for s in seeds])
    scale = 1.0 / np.sqrt(lines.size / 2)
    w = 2 * np.pi * lines / period
    wp = 2 * np.pi / period
    R = len(seeds)

    def rhs(t, s):
        x, v = s[:R], s[R:]
        k = stiffness * (1 + variation * np.cos(wp * t))
        force = scale * np.cos(w * t + phases).sum(axis=1)
        return np.concatenate([v, (force - damping * v - k * x) / mass])

    n = int(round(period * fs)) * periods
    t = start + np.arange(n) / fs
    sol = solve_ivp(rhs, (0.0, t[-1]), np.zeros(2 * R), t_eval=t, method="DOP853", rtol=1e-9, atol=1e-12)
    assert sol.success, sol.message
    return [(t,) + _sensor_noise(f(t), sol.y[r], noise, input_noise, s) for r, (f, s) in enumerate(zip(fs_, seeds))]


def discrete_lines(N):
    """Lines 1..N/2 - 1 but every seventh (left out: detection lines)."""
    lines = np.arange(1, (N - 1) // 2 + 1)
    return lines[lines % 7 != 0]


def discrete_lptv(N, periods, *, noise=0.02, seed=0, warmup=3):
    """A periodic input (one period of a random-phase multisine on :func:`discrete_lines` made
    by NumPy's inverse FFT, repeated and shaped by an LTI filter with scipy.signal.lfilter)
    through y[k] = 1.2 y[k-1] - a2(k) y[k-2] + u[k] + 0.5 u[k-1] with
    a2(k) = 0.5 (1 + 0.4 cos(2 pi k / N)), run sample by sample; ``warmup`` periods are
    dropped so that the filter's start-up is gone but the system's is not. Returns (u, y)."""
    rng = np.random.default_rng(seed)
    spec = np.zeros(N // 2 + 1, complex)
    lines = discrete_lines(N)
    spec[lines] = np.exp(2j * np.pi * rng.uniform(size=lines.size))
    one = np.fft.irfft(spec, N)
    one /= np.std(one)
    total = (warmup + periods) * N
    u = lfilter([1.0, 0.6], [1.0, -0.3], np.tile(one, warmup + periods))[warmup * N:]
    a2 = 0.5 * (1 + 0.4 * np.cos(2 * np.pi * np.arange(u.size) / N))
    y = np.zeros(u.size)
    for k in range(u.size):
        y[k] = (1.2 * y[k - 1] if k >= 1 else 0.0) - (a2[k] * y[k - 2] if k >= 2 else 0.0) \
            + u[k] + (0.5 * u[k - 1] if k >= 1 else 0.0)
    assert total - warmup * N == u.size
    u = u + noise * np.std(u) * rng.standard_normal(u.size)
    y = y + noise * np.std(y) * rng.standard_normal(y.size)
    return u, y


def filtered_noise(n, fs, seed=0):
    """A record that does not repeat: white noise through a band-pass, and the mass-spring's
    response to it (a stand-in for any non-periodic run). Returns (t, u, y)."""
    from scipy.signal import butter

    rng = np.random.default_rng(seed)
    b, a = butter(4, [0.5 / (fs / 2), 10 / (fs / 2)], btype="band")
    u = lfilter(b, a, rng.standard_normal(n + 2000))[2000:]
    bd, ad = butter(2, 3 / (fs / 2))
    y = lfilter(bd, ad, u) + 0.01 * np.std(u) * rng.standard_normal(n)
    return np.arange(n) / fs, u, y


def write_csv(path, t, u, y, header="time [s],force [N],displacement [m]"):
    np.savetxt(path, np.column_stack([t, u, y]), fmt="%.10g", delimiter=",", header=header, comments="")
    return path
