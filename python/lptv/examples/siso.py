"""The one-channel systems and data of :mod:`lptv.examples`, which re-exports them; its docstring
states the choices of the paper's example."""
from __future__ import annotations

import numpy as np

from .._validate import as_int
from ..simulation.fds import simulate
from ..model.siso import Model
from ..excitation.multisine import multisine, time_signal

PAPER_W0 = 0.04
PAPER_N = 2048
PAPER_EXCITED = np.arange(10, 241, 10)
PAPER_ID_LINES = np.arange(1, 244)
PAPER_SNR_IN_DB = 50.0
PAPER_SNR_OUT_DB = 30.0
# keyword arguments of noisy_periods: the colour and the correlation of the noise
PAPER_NOISE = dict(pole_in=0.6, pole_out=0.8, correlation=0.5)

# harmonic k = 1, 2, 3 of each coefficient (harmonic -k is the conjugate); DC values below
PAPER_DC = {"a0": 1.0, "a1": 1.0, "a2": 1.0, "b0": 1.0, "b1": 1.0}
PAPER_HARMONICS = {
    "a0": [0.15 + 0.09j, -0.06 + 0.06j, 0.03 - 0.045j],
    "a1": [0.12 - 0.06j, 0.045 + 0.03j, -0.03 + 0.015j],
    "a2": [-0.09 + 0.06j, 0.03 - 0.06j, 0.024 + 0.018j],
    "b0": [0.18 + 0.06j, -0.09 - 0.03j, 0.03 + 0.03j],
    "b1": [-0.12 + 0.09j, 0.06 + 0.045j, -0.03 - 0.03j],
}


def _coefficient_row(dc, harmonics):
    K = len(harmonics)
    row = np.zeros(2 * K + 1, complex)
    row[K] = dc
    for k, c in enumerate(harmonics, start=1):
        row[K + k] = c
        row[K - k] = np.conj(c)
    return row


def paper_model() -> Model:
    """The paper-like LPTV model: na=2, nb=1, 3 harmonics on every coefficient (35 parameters)."""
    a = np.array([_coefficient_row(PAPER_DC[n], PAPER_HARMONICS[n]) for n in ("a0", "a1", "a2")])
    b = np.array([_coefficient_row(PAPER_DC[n], PAPER_HARMONICS[n]) for n in ("b0", "b1")])
    return Model(a, b, w0=PAPER_W0)


def mathieu_model(zeta: float = 0.02, wn: float = 1.0, eps: float = 0.1, w0: float = 2.0) -> Model:
    """The damped Mathieu equation y'' + 2 zeta wn y' + wn^2 (1 + eps cos(w0 t)) y = u.

    The example where the frozen poles say stable and Floquet theory says unstable (METHOD.md
    section 12): for 0 < zeta < 1 and |eps| < 1 - zeta^2 every frozen pole has real part
    -zeta wn, but with the pump w0 near 2 wn the stiffness modulation feeds the oscillation
    (parametric resonance) once eps exceeds about 2 sqrt((1 - (w0 / 2 wn)^2)^2 + (zeta w0 / wn)^2),
    i.e. 4 zeta at w0 = 2 wn (first-order harmonic balance for a solution of period 2 T0). The
    defaults (zeta = 0.02, eps = 0.1 = 1.25 * 4 zeta, w0 = 2 wn) are unstable.

    Returns
    -------
    lptv.Model
        na = 2, nb = 0, one harmonic on a_0: a = [[wn^2 eps/2, wn^2, wn^2 eps/2], [0, 2 zeta wn,
        0], [0, 1, 0]], b = [[1]].

    Examples
    --------
    >>> import numpy as np, lptv
    >>> from lptv.examples import mathieu_model
    >>> m = mathieu_model(zeta=0.02, wn=1.0, eps=0.1, w0=2.0)
    >>> np.unique(lptv.frozen_poles(m, np.linspace(0, m.period, 9)).real.round(12))
    array([-0.02])
    >>> lptv.floquet(m).is_stable
    False
    """
    for name, v in (("zeta", zeta), ("wn", wn), ("eps", eps), ("w0", w0)):
        if not np.isfinite(v):
            raise ValueError(f"{name} must be finite, got {v!r}")
    if wn <= 0:
        raise ValueError(f"wn must be positive (rad/s), got {wn!r}")
    k = wn ** 2
    a = np.array([[k * eps / 2, k, k * eps / 2], [0.0, 2 * zeta * wn, 0.0], [0.0, 1.0, 0.0]],
                 dtype=complex)
    return Model(a, [[1.0]], w0=w0)


def paper_multisine(seed: int = 0, n_samples: int = PAPER_N):
    """The paper-like excitation: lines 10, 20, ..., 240, amplitude sqrt(2/24) each (rms 1)."""
    return multisine(PAPER_EXCITED, n_samples, amplitudes=np.sqrt(2.0 / PAPER_EXCITED.size),
                     seed=seed)


def _colored(rng, n, pole):
    """Unit-rms first-order low-pass noise 1/(1 - pole z^-1), started in its steady state."""
    from scipy.signal import lfilter

    burn = int(10 / max(1e-3, 1 - abs(pole))) if pole else 0
    e = rng.standard_normal(n + burn)
    x = lfilter([1.0], [1.0, -pole], e)[burn:] if pole else e
    return x / np.sqrt(np.mean(x ** 2))


def noisy_periods(u0, y0, periods: int, snr_in_db: float, snr_out_db: float, seed=None,
                  pole_in: float = 0.0, pole_out: float = 0.0, correlation: float = 0.0):
    """P noisy periods of the noise-free one-period signals u0, y0.

    Input and output noise are first-order low-pass noise (``pole_in``, ``pole_out``; 0 is
    white) scaled to the given mean SNRs (20 log10 of signal rms over noise rms); the output
    noise shares a fraction ``correlation`` of its driving sequence with the input noise, so
    that the two are correlated line by line.

    Returns
    -------
    u, y : ndarrays (P, N)
    """
    u0 = np.asarray(u0, float)
    y0 = np.asarray(y0, float)
    if u0.shape != y0.shape or u0.ndim != 1:
        raise ValueError("u0 and y0 must be 1-D periods of the same length")
    if not -1.0 <= correlation <= 1.0:
        raise ValueError(f"correlation must lie in [-1, 1], got {correlation}")
    P, N = int(periods), u0.size
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    su = np.sqrt(np.mean(u0 ** 2)) * 10 ** (-snr_in_db / 20)
    sy = np.sqrt(np.mean(y0 ** 2)) * 10 ** (-snr_out_db / 20)
    cu = _colored(rng, P * N, pole_in)
    # The output noise: a part driven by the input noise sequence, the rest its own.
    own = _colored(rng, P * N, pole_out)
    cy = correlation * cu + np.sqrt(1 - correlation ** 2) * own
    cy = cy / np.sqrt(np.mean(cy ** 2))
    u = np.tile(u0, (P, 1)) + su * cu.reshape(P, N)
    y = np.tile(y0, (P, 1)) + sy * cy.reshape(P, N)
    return u, y


def noise_variances(u0, y0, snr_in_db: float, snr_out_db: float, pole_in: float = 0.0,
                    pole_out: float = 0.0, correlation: float = 0.0):
    """True per-line (co)variances of ONE period's noise spectra for :func:`noisy_periods`.

    First-order low-pass noise 1 / (1 - a z^-1) scaled to unit variance has the power spectrum
    (1 - a^2) / |1 - a e^{-jw}|^2; one period's DFT ``X_l = fft(x)[l] / N`` of noise with
    standard deviation ``s`` then has the variance ``s**2 S(w_l) / N``. The output noise is
    ``correlation`` times the input noise's colour plus the rest of its own, so
    ``E{dY conj(dU)} = s_u s_y correlation S_in(w_l) / N``. These are what :func:`lptv.crb`
    takes (``var_u``, ``var_y``, ``cov_yu``) to give the bound of a design with this noise.

    Parameters
    ----------
    u0, y0 : array_like, shape (N,)
        One noise-free period of the input and the output (the SNRs refer to their rms).
    snr_in_db, snr_out_db, pole_in, pole_out, correlation :
        As for :func:`noisy_periods` (``inf`` dB: no noise on that side).

    Returns
    -------
    var_u, var_y : ndarrays (N//2 + 1,)
    cov_yu : ndarray (N//2 + 1,)
        Lines 0 .. N//2.

    Examples
    --------
    >>> import numpy as np
    >>> from lptv.examples import noise_variances
    >>> u0 = np.sqrt(2) * np.cos(2 * np.pi * 5 * np.arange(64) / 64)      # rms 1
    >>> var_u, var_y, cov_yu = noise_variances(u0, u0, 20.0, np.inf)        # white, s = 0.1
    >>> bool(np.allclose(var_u, 0.01 / 64)), float(var_y.max()), float(abs(cov_yu).max())
    (True, 0.0, 0.0)
    """
    u0 = np.asarray(u0, float)
    y0 = np.asarray(y0, float)
    if u0.shape != y0.shape or u0.ndim != 1:
        raise ValueError("u0 and y0 must be 1-D periods of the same length")
    if not -1.0 <= correlation <= 1.0:
        raise ValueError(f"correlation must lie in [-1, 1], got {correlation}")
    N = u0.size
    w = 2 * np.pi * np.arange(N // 2 + 1) / N

    def shape(a):
        return (1 - a ** 2) / np.abs(1 - a * np.exp(-1j * w)) ** 2

    su = np.sqrt(np.mean(u0 ** 2)) * 10 ** (-snr_in_db / 20)
    sy = np.sqrt(np.mean(y0 ** 2)) * 10 ** (-snr_out_db / 20)
    s_in, s_out = shape(pole_in), shape(pole_out)
    var_u = su ** 2 * s_in / N
    var_y = sy ** 2 * (correlation ** 2 * s_in + (1 - correlation ** 2) * s_out) / N
    cov_yu = (su * sy * correlation * s_in / N).astype(complex)
    return var_u, var_y, cov_yu


def paper_measurements(seed=2024, periods: int = 8) -> dict:
    """The paper's example as measured: P noisy periods of the input and output, and the truth.

    The model is :func:`paper_model`, the excitation :func:`paper_multisine`, the noise-free
    output its steady state by :func:`lptv.simulate`, and the noise that of
    :func:`noisy_periods` at ``PAPER_SNR_IN_DB``, ``PAPER_SNR_OUT_DB`` with ``PAPER_NOISE``.
    ``lptv demo`` identifies these data.

    Parameters
    ----------
    seed : int, sequence of int or numpy.random.Generator
        Seeds the multisine's phases and then the noise.
    periods : int
        Number of measured periods P.

    Returns
    -------
    dict
        ``u``, ``y`` (P, N) the measured periods; ``w0`` (rad/s); ``u0``, ``y0`` one noise-free
        period; ``U0``, ``Y0`` their one-sided spectra; ``model`` the true :class:`lptv.Model`;
        ``multisine`` the excitation (:class:`lptv.Multisine`).

    Examples
    --------
    >>> import lptv
    >>> from lptv.examples import paper_measurements
    >>> m = paper_measurements(seed=1, periods=4)
    >>> m["u"].shape, m["w0"]
    ((4, 2048), 0.04)
    >>> res = lptv.identify(m["u"], m["y"], na=2, nb=1, ka=3, kb=3, w0=m["w0"],
    ...                     lines=range(1, 244))
    >>> res.n_free_parameters
    34
    """
    rng = np.random.default_rng(seed)
    model = paper_model()
    ms = paper_multisine(seed=rng)
    Y0 = simulate(model, ms.spectrum)
    y0 = time_signal(Y0, PAPER_N)
    u, y = noisy_periods(ms.signal, y0, periods, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB, seed=rng,
                         **PAPER_NOISE)
    return dict(u=u, y=y, w0=model.w0, u0=ms.signal, y0=y0, U0=ms.spectrum, Y0=Y0, model=model,
                multisine=ms)


# --- two more systems, for statistical claims beyond the paper's example ---------------------
#
# Chosen to differ from the paper's example in every respect the statistics could depend on:
# order, which coefficients vary and by how many harmonics, time domain, excitation spacing,
# white uncorrelated noise instead of coloured correlated noise, SNR.

THIRD_ORDER_W0 = 0.05
THIRD_ORDER_N = 1024
THIRD_ORDER_EXCITED = np.arange(8, 161, 8)
THIRD_ORDER_ID_LINES = np.arange(1, 171)
THIRD_ORDER_STRUCTURE = dict(na=3, nb=1, ka=[2, 1, 0, 0], kb=[2, 0])


def third_order_model() -> Model:
    """A third-order continuous-time LPTV system: na = 3, nb = 1, harmonics on a0 (K = 2),
    a1 (K = 1) and b0 (K = 2); a2, a3 and b1 constant (``THIRD_ORDER_STRUCTURE``).

    Mean system (s + 2) / ((s + 1)(s^2 + s + 1)) = (s + 2) / (s^3 + 2 s^2 + 2 s + 1), w0 = 0.05
    rad/s (T0 = 126 s), excited every 8th line (0.4 .. 8 rad/s, ``THIRD_ORDER_EXCITED``).
    Every frozen system is stable and so is the periodic one (a_3 = 1).

    Examples
    --------
    >>> import lptv
    >>> from lptv.examples import third_order_model
    >>> m = third_order_model()
    >>> m.na, m.nb, m.ka, m.kb, lptv.floquet(m).is_stable
    (3, 1, 2, 2, True)
    """
    a = np.array([_coefficient_row(1.0, [0.2 + 0.1j, 0.08 - 0.05j]),
                  _coefficient_row(2.0, [0.15 - 0.1j, 0.0]),
                  _coefficient_row(2.0, [0.0, 0.0]),
                  _coefficient_row(1.0, [0.0, 0.0])])
    b = np.array([_coefficient_row(2.0, [0.3 + 0.2j, -0.1 + 0.1j]),
                  _coefficient_row(1.0, [0.0, 0.0])])
    return Model(a, b, w0=THIRD_ORDER_W0)


DISCRETE_N = 256
DISCRETE_EXCITED = np.arange(6, 121, 6)
DISCRETE_ID_LINES = np.arange(1, 126)
DISCRETE_STRUCTURE = dict(na=2, nb=1, ka=[2, 1, 0], kb=[2, 0])


def discrete_model() -> Model:
    """A second-order discrete-time LPTV system (forward shift, ts = 1 s, N = 256 samples per
    period): a2 y[t+2] + a1[t] y[t+1] + a0[t] y[t] = b1 u[t+1] + b0[t] u[t] with harmonics on a0
    (K = 2), a1 (K = 1) and b0 (K = 2) (``DISCRETE_STRUCTURE``).

    Mean system (0.5 z + 1) / (z^2 - 1.2 z + 0.5) (poles at |z| = 0.71), excited every 6th line
    (``DISCRETE_EXCITED``). The periodic system is stable (Floquet multipliers below 1e-25 per
    period), though the frozen systems are not over part of the period (a frozen pole reaches 1.13
    near t = 142): frozen poles say nothing of stability (METHOD.md section 12).

    Examples
    --------
    >>> import lptv
    >>> from lptv.examples import discrete_model
    >>> m = discrete_model()
    >>> m.na, m.nb, m.samples_per_period, lptv.floquet(m).is_stable
    (2, 1, 256, True)
    """
    a = np.array([_coefficient_row(0.5, [0.08 + 0.05j, 0.04j]),
                  _coefficient_row(-1.2, [0.1 - 0.05j, 0.0]),
                  _coefficient_row(1.0, [0.0, 0.0])])
    b = np.array([_coefficient_row(1.0, [0.2, 0.1j]),
                  _coefficient_row(0.5, [0.0, 0.0])])
    return Model(a, b, w0=2 * np.pi / DISCRETE_N, ts=1.0)


SYSTEMS = ("paper", "third_order", "discrete")
"""Names of the systems :func:`system_measurements` knows."""


def system_measurements(system: str = "paper", seed=0, periods: int = 8) -> dict:
    """P noisy periods of one of the test systems, with everything a study needs.

    ``system``: 'paper' (:func:`paper_model`, its excitation and coloured correlated noise at
    50/30 dB), 'third_order' (:func:`third_order_model`, 20 lines, white uncorrelated noise at
    40/25 dB) or 'discrete' (:func:`discrete_model`, 20 lines, white noise at 45/30 dB with
    correlation 0.3).

    Returns
    -------
    dict
        As :func:`paper_measurements`, plus ``structure`` (the keyword arguments na, nb, ka, kb
        of the true structure), ``lines`` (the identification rows), ``ts`` (None or the sample
        period) and ``noise`` (the keyword arguments of :func:`noisy_periods`).

    Examples
    --------
    >>> import lptv
    >>> from lptv.examples import system_measurements
    >>> d = system_measurements("discrete", seed=1, periods=4)
    >>> res = lptv.identify(d["u"], d["y"], **d["structure"], w0=d["w0"], ts=d["ts"],
    ...                     lines=d["lines"], method="sml")
    >>> res.n_free_parameters
    14
    """
    if system not in SYSTEMS:
        raise ValueError(f"system must be one of {SYSTEMS}, got {system!r}")
    rng = np.random.default_rng(seed)
    if system == "paper":
        model, ms = paper_model(), paper_multisine(seed=rng)
        N, lines, ts = PAPER_N, PAPER_ID_LINES, None
        structure = dict(na=2, nb=1, ka=3, kb=3)
        noise = dict(snr_in_db=PAPER_SNR_IN_DB, snr_out_db=PAPER_SNR_OUT_DB, **PAPER_NOISE)
    elif system == "third_order":
        model, N, lines, ts = third_order_model(), THIRD_ORDER_N, THIRD_ORDER_ID_LINES, None
        ms = multisine(THIRD_ORDER_EXCITED, N, amplitudes=np.sqrt(2.0 / THIRD_ORDER_EXCITED.size), seed=rng)
        structure = dict(THIRD_ORDER_STRUCTURE)
        noise = dict(snr_in_db=40.0, snr_out_db=25.0)
    else:
        model, N, lines, ts = discrete_model(), DISCRETE_N, DISCRETE_ID_LINES, 1.0
        ms = multisine(DISCRETE_EXCITED, N, amplitudes=np.sqrt(2.0 / DISCRETE_EXCITED.size), seed=rng)
        structure = dict(DISCRETE_STRUCTURE)
        noise = dict(snr_in_db=45.0, snr_out_db=30.0, correlation=0.3)
    Y0 = simulate(model, ms.spectrum)
    y0 = time_signal(Y0, N)
    u, y = noisy_periods(ms.signal, y0, periods, seed=rng, **noise)
    return dict(u=u, y=y, w0=model.w0, ts=ts, u0=ms.signal, y0=y0, U0=ms.spectrum, Y0=Y0,
                model=model, multisine=ms, structure=structure, lines=lines, noise=noise)


# The systems of cubic_realisations: (model factory, excited lines, N, identification rows,
# structure, keyword arguments of noisy_periods: white noise at these SNRs).
BLA_SYSTEMS = {
    "paper": (paper_model, PAPER_EXCITED, PAPER_N, PAPER_ID_LINES, dict(na=2, nb=1, ka=3, kb=3),
              dict(snr_in_db=50.0, snr_out_db=30.0)),
    "third_order": (third_order_model, THIRD_ORDER_EXCITED, THIRD_ORDER_N, THIRD_ORDER_ID_LINES,
                    THIRD_ORDER_STRUCTURE, dict(snr_in_db=40.0, snr_out_db=25.0)),
    "discrete": (discrete_model, DISCRETE_EXCITED, DISCRETE_N, DISCRETE_ID_LINES, DISCRETE_STRUCTURE,
                 dict(snr_in_db=45.0, snr_out_db=30.0, correlation=0.3)),
}


def cubic_realisations(system: str = "paper", cubic: float = 0.05, where: str = "input", realisations: int = 6,
                       periods: int = 4, seed=None) -> dict:
    """M random-phase realisations x P noisy periods of a test system with a cubic nonlinearity:
    data for :func:`lptv.distortion` and the best linear time-periodic approximation (BLA).

    ``where='input'``: an actuator before the LPTV system (Hammerstein), x = u + c u^3, whose BLA
    is the system with its b times the actuator's linear gain (:func:`actuator_gain`): inside the
    fitted class, known exactly. ``where='output'``: a cubic after it (Wiener), y + c y^3, whose
    BLA is outside the class. Each realisation: a multisine of flat amplitudes sqrt(2 / L) on the
    system's excited lines with random phases, then :func:`noisy_periods` with the system's noise
    (white; 50/30 dB for 'paper', 40/25 dB 'third_order', 45/30 dB with correlation 0.3
    'discrete'). ``seed``: an int, a sequence or a Generator, drawn from in one order (phases,
    then noise, realisation by realisation), so that the same seed gives the same data.

    Returns
    -------
    dict
        ``u``, ``y`` (M, P, N); ``model`` (the LPTV part), ``w0``, ``ts``, ``excited``,
        ``lines`` (identification rows), ``structure`` (na, nb, ka, kb), ``noise`` (the keyword
        arguments of :func:`noisy_periods`), ``cubic``, ``where``.

    Examples
    --------
    >>> import lptv
    >>> from lptv.examples import cubic_realisations
    >>> r = cubic_realisations("third_order", cubic=0.05, where="input", realisations=6, periods=8, seed=1)
    >>> r["u"].shape
    (6, 8, 1024)
    >>> bool(lptv.distortion(r["u"], r["y"], w0=r["w0"]).detected)
    True
    """
    if system not in BLA_SYSTEMS:
        raise ValueError(f"system must be one of {SYSTEMS}, got {system!r}")
    if not isinstance(where, str) or where not in ("input", "output"):
        raise ValueError(f"where must be 'input' (an actuator before the system) or 'output', got {where!r}")
    try:
        cubic = float(cubic)
    except (TypeError, ValueError):
        raise ValueError(f"cubic must be a real number, got {cubic!r}") from None
    if not np.isfinite(cubic):
        raise ValueError(f"cubic must be finite, got {cubic!r}")
    M, P = as_int(realisations, "realisations", minimum=1), as_int(periods, "periods", minimum=1)
    make, excited, N, lines, structure, noise = BLA_SYSTEMS[system]
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    m = make()
    u, y = [], []
    for _ in range(M):
        ms = multisine(excited, N, amplitudes=np.sqrt(2 / excited.size), seed=rng)
        if where == "input":
            y0 = time_signal(simulate(m, np.fft.rfft(ms.signal + cubic * ms.signal ** 3) / N), N)
        else:
            y0 = time_signal(simulate(m, ms.spectrum), N)
            y0 = y0 + cubic * y0 ** 3
        a, b = noisy_periods(ms.signal, y0, P, seed=rng, **noise)
        u.append(a)
        y.append(b)
    return dict(u=np.array(u), y=np.array(y), model=m, w0=m.w0, ts=m.ts, excited=excited, lines=lines,
                structure=dict(structure), noise=dict(noise), cubic=cubic, where=where)


def actuator_gain(system: str = "paper", cubic: float = 0.05, n: int = 400, seed=12345) -> float:
    """The linear gain g of the actuator x = u + c u^3 for the flat random-phase multisine of
    :func:`cubic_realisations` (the mean over ``n`` realisations of the cross-spectrum on the
    excited lines over the input's power): the exact BLA of that Hammerstein system is the LPTV
    system with b times g (:func:`exact_bla`). Its sampling error falls as 1 / sqrt(n).

    >>> from lptv.examples import actuator_gain
    >>> round(actuator_gain("third_order", 0.05), 2)
    1.15
    """
    if system not in BLA_SYSTEMS:
        raise ValueError(f"system must be one of {SYSTEMS}, got {system!r}")
    _, excited, N, *_ = BLA_SYSTEMS[system]
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    num = den = 0.0
    for _ in range(as_int(n, "n", minimum=1)):
        ms = multisine(excited, N, amplitudes=np.sqrt(2 / excited.size), seed=rng)
        X = np.fft.rfft(ms.signal + cubic * ms.signal ** 3) / N
        num += np.sum(X[excited] * np.conj(ms.spectrum[excited]))
        den += np.sum(np.abs(ms.spectrum[excited]) ** 2)
    return float(np.real(num / den))


def exact_bla(system: str = "paper", cubic: float = 0.05, n: int = 400, seed=12345) -> Model:
    """The exact BLA of the system of :func:`cubic_realisations` behind the actuator
    x = u + c u^3: the LPTV model with its b times :func:`actuator_gain`."""
    m = BLA_SYSTEMS[system][0]() if system in BLA_SYSTEMS else None
    if m is None:
        raise ValueError(f"system must be one of {SYSTEMS}, got {system!r}")
    g = actuator_gain(system, cubic, n, seed)
    return Model(np.array(m.a), np.array(m.b) * g, w0=m.w0, ts=m.ts)


def transient_record(model: Model, periods: int = 4, noise_std: float = 0.01, seed=None,
                     state_std: float = 3.0, input_std: float = 1.0):
    """One record of a discrete-time LPTV model under white noise, from a random initial state.

    ``periods`` whole parameter periods of ``model.samples_per_period`` samples; the input is
    white Gaussian noise of standard deviation ``input_std`` (not periodic), the initial state
    (y[0..na-1]) Gaussian of ``state_std``: a start-up transient; white Gaussian noise of
    ``noise_std`` is added to the output. Returns (u, y), the data :func:`lptv.identify_record`
    takes. The recursion is a_na(t) y[t+na] = sum_m b_m(t) u[t+m] - sum_{n<na} a_n(t) y[t+n].

    Examples
    --------
    >>> from lptv.examples import discrete_model, transient_record
    >>> u, y = transient_record(discrete_model(), periods=2, seed=0)
    >>> u.shape, y.shape
    ((512,), (512,))
    """
    if not isinstance(model, Model) or not model.discrete:
        raise ValueError("model must be a discrete-time lptv.Model (the recursion is in discrete time)")
    periods = as_int(periods, "periods", minimum=1, maximum=10**6)
    rng = np.random.default_rng(seed)
    na, nb = model.na, model.nb
    N = periods * model.samples_per_period
    u = input_std * rng.standard_normal(N + nb)
    y = np.zeros(N + na)
    y[:na] = state_std * rng.standard_normal(na)
    A = np.asarray(model.a_at(np.arange(N) * model.ts))
    B = np.asarray(model.b_at(np.arange(N) * model.ts))
    for t in range(N - na):
        rhs = B[t] @ u[t:t + nb + 1] - A[t, :na] @ y[t:t + na]
        y[t + na] = rhs / A[t, na]
    return u[:N], y[:N] + noise_std * rng.standard_normal(N)


def continuous_record(model: Model, periods: int = 2, samples_per_period: int = 1312, band: float = 4.0,
                      noise_std: float = 0.01, seed=None, state_std: float = 3.0, input_std: float = 1.0,
                      sinusoids: int = 200, rtol: float = 1e-12):
    """One sampled record of a continuous-time LPTV model from a random state, band-limited input.

    The input is a sum of ``sinusoids`` sinusoids of equal amplitude, random frequencies uniform
    in (0.02 ``band``, ``band``) rad/s and random phases (rms ``input_std``): not periodic in the
    record, band-limited, so its samples describe it whenever the Nyquist frequency pi / ts
    exceeds ``band`` (a zero-order hold would not: the continuous input between its samples
    is not the one they describe), and its derivatives are exact. The state (y, y', ...) at
    t = 0 is Gaussian of ``state_std``; the output is integrated by SUNDIALS CVODE
    (:func:`lptv.timedomain.free_response`, relative tolerance ``rtol``) at the times
    k T0 / ``samples_per_period``, k = 0 .. ``periods`` ``samples_per_period`` - 1, and white
    Gaussian noise of ``noise_std`` is added. Returns (u, y, ts), the data
    :func:`lptv.identify_record` takes with ``continuous=True``. The default 1312 samples per
    period put the third-order example's band (4 rad/s plus its sidebands) at a quarter of the
    Nyquist frequency (METHOD.md section 17).

    Examples
    --------
    >>> from lptv.examples import third_order_model, continuous_record
    >>> u, y, ts = continuous_record(third_order_model(), periods=2, seed=0)
    >>> u.shape, round(ts, 4)
    ((2624,), 0.0958)
    """
    from ..simulation import timedomain

    if not isinstance(model, Model) or model.discrete:
        raise ValueError("model must be a continuous-time lptv.Model")
    periods = as_int(periods, "periods", minimum=1, maximum=10**6)
    samples_per_period = as_int(samples_per_period, "samples_per_period", minimum=2, maximum=10**8)
    sinusoids = as_int(sinusoids, "sinusoids", minimum=1, maximum=10**5)
    ts = model.period / samples_per_period
    if not (np.isfinite(band) and 0 < band < np.pi / ts):
        raise ValueError(f"band must lie in (0, pi / ts) = (0, {np.pi / ts:.6g}) rad/s, got {band!r}")
    rng = np.random.default_rng(seed)
    w = rng.uniform(0.02 * band, band, sinusoids)
    phi = rng.uniform(0, 2 * np.pi, sinusoids)
    amp = input_std * np.sqrt(2.0 / sinusoids)
    orders = np.arange(model.nb + 1)

    def derivatives(t):
        c = amp * np.exp(1j * (w * t + phi))
        return ((1j * w)[None, :] ** orders[:, None] * c[None, :]).real.sum(axis=1)

    x0 = state_std * rng.standard_normal(model.na)
    t = np.arange(periods * samples_per_period) * ts
    y = timedomain.free_response(model, derivatives, t, x0=x0, rtol=rtol)
    u = (amp * np.cos(np.outer(t, w) + phi)).sum(axis=1)
    return u, y + noise_std * rng.standard_normal(t.size), ts
