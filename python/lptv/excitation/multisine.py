"""Random-phase multisines (METHOD.md section 2)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core
from .._validate import as_int, as_int_list, as_real_1d, as_seed, as_spectrum


@dataclass(frozen=True)
class Multisine:
    """A periodic multisine: one period of samples and its one-sided spectrum."""

    lines: np.ndarray
    """Excited lines (multiples of the fundamental)."""
    amplitudes: np.ndarray
    """Cosine amplitude A_l of each excited line."""
    phases: np.ndarray
    """Phase phi_l of each excited line (rad)."""
    n_samples: int
    """Samples per period N."""
    spectrum: np.ndarray
    """One-sided spectrum on lines 0..N//2, ``fft(x)[l] / N``."""
    signal: np.ndarray
    """One period, N samples: ``sum_l A_l cos(2 pi l n / N + phi_l)``."""

    @property
    def crest_factor(self) -> float:
        """max |x| / rms(x)."""
        return float(_core.crest_factor(self.signal))

    def periods(self, P: int) -> np.ndarray:
        """P >= 1 consecutive periods, shape (P, N)."""
        P = as_int(P, "P", minimum=1, maximum=max(1, 2**31 // max(self.n_samples, 1)))
        return np.tile(self.signal, (P, 1))


def multisine(lines, n_samples: int, amplitudes=1.0, seed=None) -> Multisine:
    """Random-phase multisine ``u(t) = sum_l A_l cos(l w0 t + phi_l)``, phi_l ~ U[0, 2 pi).

    On line 0 (DC) and, for even N, the Nyquist line N/2 a real signal holds ``A cos(phi)`` only
    (``cos(pi n)`` has no sine partner on the grid), so a random phase would realise a random
    amplitude ``A |cos(phi)|``. There the phase is 0 or pi instead, drawn as the sign of the
    cosine of the uniform phase: the line has the amplitude A with a random sign, and the other
    lines' phases are those the same seed gave before.

    Parameters
    ----------
    lines : sequence of int
        Excited lines in 0..n_samples//2 (distinct).
    n_samples : int
        Samples per period N.
    amplitudes : float or sequence of float
        Cosine amplitude per line (a scalar for all).
    seed : int or numpy.random.Generator, optional
        Seeds the phases.

    Examples
    --------
    >>> import lptv
    >>> ms = lptv.multisine(range(10, 250, 10), 1024, seed=1)
    >>> ms.signal.shape, ms.spectrum.shape
    ((1024,), (513,))
    >>> abs(ms.spectrum[10])
    np.float64(0.5)
    """
    ln, amp, n_samples = _lines_amplitudes(lines, n_samples, amplitudes)
    return _build(ln, amp, as_seed(seed).uniform(0.0, 2 * np.pi, ln.size), n_samples)


def _lines_amplitudes(lines, n_samples, amplitudes):
    """Checked excited lines (int64), amplitudes (float, one per line) and N."""
    n_samples = as_int(n_samples, "n_samples", minimum=1)
    if lines is None or isinstance(lines, (str, bytes)):
        raise ValueError(f"lines must be integers, got {lines!r}")
    ln = np.atleast_1d(np.asarray(lines, dtype=object if _has_big_int(lines) else None))
    if ln.size == 0:
        raise ValueError("lines must not be empty")
    if ln.ndim != 1:
        raise ValueError(f"lines must be 1-D, got shape {ln.shape}")
    if ln.dtype == object:
        try:
            vals = as_int_list(ln, "lines", minimum=-np.inf, maximum=np.inf)
        except ValueError:
            raise ValueError("lines must be integers, got non-numeric values") from None
        if min(vals) < 0 or max(vals) > n_samples // 2:
            raise ValueError(f"lines must lie in 0..{n_samples // 2} (n_samples//2), got {min(vals)}..{max(vals)}")
        ln = np.array(vals, dtype=np.int64)
    if not np.issubdtype(ln.dtype, np.integer):
        if not (np.issubdtype(ln.dtype, np.floating) and np.all(np.isfinite(ln))
                and np.all(ln == np.round(ln))):
            raise ValueError(f"lines must be integers, got {ln.dtype} values")
        if np.any(np.abs(ln.astype(np.float64)) > 2.0**62):
            raise ValueError(f"lines must lie in 0..{n_samples // 2} (n_samples//2), got {ln.min():.0f}..{ln.max():.0f}")
        ln = ln.astype(np.int64)
    if np.any(ln < 0) or np.any(ln > n_samples // 2):
        raise ValueError(f"lines must lie in 0..{n_samples // 2} (n_samples//2), "
                         f"got {ln.min()}..{ln.max()}")
    if np.unique(ln).size != ln.size:
        raise ValueError("lines must be distinct")
    amp = np.broadcast_to(as_real_1d(amplitudes, "amplitudes"), ln.shape).astype(float) \
        if np.ndim(amplitudes) == 0 else as_real_1d(amplitudes, "amplitudes")
    if amp.shape != ln.shape:
        raise ValueError(f"amplitudes must be a scalar or have one entry per line ({ln.size}), "
                         f"got {amp.size}")
    if not np.all(np.isfinite(amp)):
        raise ValueError("amplitudes must be finite")
    return ln, amp, n_samples


def spectrum(x) -> np.ndarray:
    """One-sided spectrum of one period: ``fft(x)[:N//2+1] / N``."""
    return np.asarray(_core.spectrum(as_real_1d(x, "x", min_len=1)))


def time_signal(X, n_samples: int) -> np.ndarray:
    """One period of the real signal whose one-sided spectrum is X (lines 0..L, L <= N/2).

    ``X[0]`` must be real, as for a real signal. For even N the Nyquist line ``X[N/2]`` is made
    real (its real part is kept): the samples of ``exp(j pi n)`` and ``cos(pi n)`` agree, so a
    real signal sampled N times per period cannot carry its imaginary part, and a spectrum from
    :func:`lptv.simulate` (a continuous-time model's response at the frequency N/2 w0) may well
    have one. ``time_signal(simulate(model, U), N)`` thus works for every N.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> x = lptv.time_signal([0.0, 0.0, 1.0 + 1.0j], 4)      # Nyquist line of N = 4
    >>> x.round(12).tolist()
    [1.0, -1.0, 1.0, -1.0]
    """
    n_samples = as_int(n_samples, "n_samples", minimum=1)
    Xa, was_1d = as_spectrum(X, "X")
    if not was_1d:
        raise ValueError(f"X must be 1-D (lines 0..L), got shape {np.shape(X)}")
    Xa = Xa[:, 0]
    if Xa.size > n_samples // 2 + 1:
        raise ValueError(f"X must have between 1 and {n_samples // 2 + 1} lines (0..n_samples//2) "
                         f"for n_samples = {n_samples}, got {Xa.size}")
    scale = max(np.abs(Xa).max(), 1e-300)
    if abs(Xa[0].imag) > 1e-12 * scale:
        raise ValueError(f"X: line 0 must be real for a real signal, got {Xa[0]}")
    if n_samples % 2 == 0 and Xa.size > n_samples // 2:
        Xa = Xa.copy()
        Xa[n_samples // 2] = Xa[n_samples // 2].real
    return np.asarray(_core.time_signal(Xa, n_samples))


def _has_big_int(x) -> bool:
    """Python ints beyond int64 (NumPy would raise OverflowError converting them)."""
    try:
        return any(isinstance(v, int) and not -2**63 <= v < 2**63 for v in np.ravel(np.asarray(x, dtype=object)))
    except Exception:
        return False


# -- excitation design (METHOD.md section 2, "Designing the excitation") ----------------------

def _build(ln, amp, phases, n_samples) -> Multisine:
    """The multisine of these lines, amplitudes and phases; on DC and the Nyquist line the phase
    becomes 0 or pi, the sign of its cosine (see :func:`multisine`)."""
    real = (ln == 0) | ((n_samples % 2 == 0) & (ln == n_samples // 2))
    phases = np.array(phases, dtype=float)
    phases[real] = np.where(np.cos(phases[real]) >= 0, 0.0, np.pi)
    X = np.asarray(_core.multisine_spectrum([int(x) for x in ln], np.ascontiguousarray(amp),
                                            phases, n_samples))
    x = np.asarray(_core.time_signal(X, n_samples))
    return Multisine(lines=ln, amplitudes=np.array(amp), phases=phases, n_samples=n_samples,
                     spectrum=X, signal=x)


def schroeder_multisine(lines, n_samples: int, amplitudes=1.0) -> Multisine:
    """Multisine with Schroeder's phases, ``phi_k = -2 pi sum_{i<k} (k - i) A_i^2 / sum A^2``.

    The classic low-crest start (M. R. Schroeder, IEEE Trans. Inf. Theory 16(1), 1970): about
    1.7 for a flat spectrum of consecutive lines, whatever their number. The lines are taken in
    increasing order.

    Examples
    --------
    >>> import lptv
    >>> ms = lptv.schroeder_multisine(range(1, 51), 1024)
    >>> round(ms.crest_factor, 2)
    1.72
    """
    ln, amp, n_samples = _lines_amplitudes(lines, n_samples, amplitudes)
    order = np.argsort(ln)
    ln, amp = ln[order], amp[order]
    if not np.any(amp != 0):
        raise ValueError("amplitudes must not all be zero")
    return _build(ln, amp, np.asarray(_core.schroeder_phases(np.ascontiguousarray(amp))), n_samples)


@dataclass(frozen=True)
class CrestDesign:
    """How :func:`min_crest_multisine` got its phases."""

    crest_factor: float
    """Crest factor reached, on the evaluation grid (``n_samples * oversample`` points)."""
    initial_crest_factor: float
    """Crest factor of the starting phases on the same grid."""
    oversample: int
    """Evaluation grid factor: the peak is taken on ``n_samples * oversample`` points."""
    evaluations: int
    """Objective evaluations (two FFTs each): the cost."""
    best_per_p: np.ndarray
    """Smallest crest factor met after the L_p stages p = 4, 8, ..., max_p."""


def min_crest_multisine(lines, n_samples: int, amplitudes=1.0, *, start="schroeder", seed=None,
                        oversample=None, max_p: int = 1024, iterations_per_p: int = 100,
                        return_design: bool = False):
    """Multisine of the given amplitude spectrum with phases that minimise its crest factor.

    From the starting phases, L-BFGS minimises the L_p norm of the signal for p = 4, 8, ...,
    max_p in turn (each from the last one's phases), an approach towards the L_inf norm, the
    peak (P. Guillaume, J. Schoukens, R. Pintelon, I. Kollar, IEEE Trans. Instrum. Meas. 40(6),
    1991); the phases with the smallest peak met at any step are returned. The amplitudes are
    untouched: only the phases move. DC and, for even N, the Nyquist line keep their phase
    (0 or pi). The work runs in the compiled core: about 25 ms for 50 lines at N = 1024.

    Parameters
    ----------
    lines, n_samples, amplitudes
        As for :func:`multisine`.
    start : {"schroeder", "random"}
        Schroeder's phases (a deterministic design), or uniform random phases drawn from
        ``seed``: each seed then gives another low-crest realisation of the same amplitude
        spectrum (see :func:`multisine_realisations`).
    seed : int or numpy.random.Generator, optional
        Seeds the random start.
    oversample : int, optional
        The peak is taken on ``n_samples * oversample`` points. Default: the smallest factor
        with 16 points per period of the highest line, so the peak of the band-limited
        continuous signal (after a reconstruction filter) is within 2 % of the one minimised;
        ``oversample=1`` minimises the peak of the samples themselves (a zero-order hold).
    max_p : int
        Last L_p norm (a power of two, 4..2^20).
    iterations_per_p : int
        L-BFGS iterations per p at most: a bound on the cost decided before it starts.
    return_design : bool
        Also return a :class:`CrestDesign` with the crest factors and the cost.

    Examples
    --------
    >>> import lptv
    >>> ms = lptv.min_crest_multisine(range(1, 51), 1024)
    >>> ms.crest_factor < 1.45 < lptv.schroeder_multisine(range(1, 51), 1024).crest_factor
    True
    """
    ln, amp, n_samples = _lines_amplitudes(lines, n_samples, amplitudes)
    if not np.any(amp != 0):
        raise ValueError("amplitudes must not all be zero")
    order = np.argsort(ln)
    ln, amp = ln[order], amp[order]
    if start == "schroeder":
        phi0 = np.asarray(_core.schroeder_phases(np.ascontiguousarray(amp)))
        if seed is not None:
            raise ValueError(f"seed is not used with start='schroeder' (a deterministic design), got {seed!r}; "
                             "use start='random'")
    elif start == "random":
        phi0 = as_seed(seed).uniform(0.0, 2 * np.pi, ln.size)
    else:
        raise ValueError(f"start must be 'schroeder' or 'random', got {start!r}")
    os_ = 0 if oversample is None else as_int(oversample, "oversample", minimum=1,
                                               maximum=max(1, 2**27 // n_samples))
    max_p = as_int(max_p, "max_p", minimum=4, maximum=2**20)
    if max_p & (max_p - 1):
        raise ValueError(f"max_p must be a power of two (4, 8, 16, ...), got {max_p}")
    iterations_per_p = as_int(iterations_per_p, "iterations_per_p", minimum=0, maximum=10**6)
    r = _core.minimize_crest_factor([int(x) for x in ln], np.ascontiguousarray(amp), phi0,
                                    n_samples, os_, max_p, iterations_per_p)
    ms = _build(ln, amp, np.asarray(r.phases), n_samples)
    if not return_design:
        return ms
    return ms, CrestDesign(crest_factor=float(r.crest_factor),
                           initial_crest_factor=float(r.initial_crest_factor),
                           oversample=int(r.oversample), evaluations=int(r.evaluations),
                           best_per_p=np.asarray(r.best_per_p, dtype=float))


def multisine_realisations(lines, n_samples: int, M: int, amplitudes=1.0, *, seed=None,
                           low_crest: bool = False) -> list:
    """M random-phase realisations of one amplitude spectrum (the input of :func:`lptv.distortion`).

    Each realisation has independent uniform phases (one seed spawns them all, so the list is
    reproducible); ``low_crest=True`` then lowers each one's crest factor from its random
    phases (:func:`min_crest_multisine` with ``start="random"``). **Note:** the low-crest
    phases are no longer uniform and independent of the amplitude spectrum in the strict sense
    the theory of the best linear approximation assumes; they are the usual compromise when
    the actuator's range is the limit.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> ms = lptv.multisine_realisations(range(10, 250, 10), 1024, M=4, seed=1)
    >>> len(ms), bool(np.allclose(abs(ms[0].spectrum), abs(ms[3].spectrum)))
    (4, True)
    """
    M = as_int(M, "M", minimum=1, maximum=10**6)
    ln, amp, n_samples = _lines_amplitudes(lines, n_samples, amplitudes)
    rng = as_seed(seed)
    seeds = rng.spawn(M) if hasattr(rng, "spawn") else [np.random.default_rng(rng.integers(2**63))
                                                         for _ in range(M)]
    if low_crest:
        return [min_crest_multisine(ln, n_samples, amp, start="random", seed=s) for s in seeds]
    return [multisine(ln, n_samples, amp, seed=s) for s in seeds]


@dataclass(frozen=True)
class ExcitationLines:
    """Which lines to excite, and which lines then reveal what (METHOD.md section 2)."""

    kind: str
    """"full", "odd" or "odd-odd"."""
    reach: int
    """Sideband reach K: the LPTV sidebands of line l lie on l - K..l + K."""
    spacing: int
    """s = 2 K + 1: excited and detection lines are multiples of s."""
    excited: np.ndarray
    """Lines to excite."""
    odd_detection: np.ndarray
    """Multiples of s left out whose multiple j*s has odd j: odd-order nonlinear distortion only."""
    even_detection: np.ndarray
    """Even multiples of s (j even) in the band: even-order nonlinear distortion only."""
    sideband: np.ndarray
    """Lines within +-K of an excited line that are not multiples of s: the LPTV sidebands (and,
    for a nonlinear LPTV system, its distortion as well)."""

    def role(self, line: int) -> str:
        """What power on ``line`` reveals: 'excited', 'odd nonlinear', 'even nonlinear',
        'LPTV sideband' or 'none' (outside every sideband: noise only for a linear system)."""
        line = as_int(line, "line", minimum=0)
        for name, arr in (("excited", self.excited), ("odd nonlinear", self.odd_detection),
                          ("even nonlinear", self.even_detection), ("LPTV sideband", self.sideband)):
            if np.any(arr == line):
                return name
        return "none"


def excitation_lines(first: int, last: int, *, kind: str = "odd", reach: int = 0, group: int = 3,
                     seed=None) -> ExcitationLines:
    """Excited and detection lines in first..last for a system whose sidebands reach +-K lines.

    All the lines chosen are multiples j s of the spacing s = 2 K + 1, so an LPTV system's
    sidebands l + k (0 < |k| <= K) of an excited line never fall on another multiple, while the
    nonlinear distortion of degree n of the excited lines, sums of n excited lines with signs,
    always does, on multiples with j of the parity of n (j odd on every excited line of the odd
    designs). Hence:

    - ``kind="odd"``: j odd excited, but in each group of ``group`` consecutive odd j one, drawn
      at random, is left out as an odd detection line; even j are even detection lines.
    - ``kind="odd-odd"``: j = 1 mod 4 excited; j = 3 mod 4 are odd detection lines, even j
      even ones.
    - ``kind="full"``: every j excited (no detection line: only random-phase realisations
      tell distortion from noise, :func:`lptv.distortion`).

    K must cover the branches of the HTF that carry power above the noise: for a time-varying
    denominator they decay but never end (measure them with :func:`lptv.htf_estimate`, or take
    K where the sidebands of a first experiment sink into the noise). K = 0 gives the LTI
    designs (odd and odd-odd random-phase multisines).

    Examples
    --------
    >>> import lptv
    >>> d = lptv.excitation_lines(5, 200, kind="odd-odd", reach=2)
    >>> d.spacing, d.excited[:3].tolist(), d.odd_detection[:2].tolist(), d.even_detection[:2].tolist()
    (5, [5, 25, 45], [15, 35], [10, 20])
    >>> d.role(26), d.role(15), d.role(13)
    ('LPTV sideband', 'odd nonlinear', 'none')
    """
    first = as_int(first, "first", minimum=1)
    last = as_int(last, "last", minimum=1)
    if last < first:
        raise ValueError(f"last must be >= first, got first = {first}, last = {last}")
    reach = as_int(reach, "reach", minimum=0, maximum=10**7)
    group = as_int(group, "group", minimum=2, maximum=10**6)
    if kind not in ("full", "odd", "odd-odd"):
        raise ValueError(f"kind must be 'full', 'odd' or 'odd-odd', got {kind!r}")
    s = 2 * reach + 1
    j = np.arange(-(-first // s), last // s + 1)
    j = j[j >= 1]
    if j.size == 0:
        raise ValueError(f"no multiple of the spacing 2 reach + 1 = {s} lies in {first}..{last}")
    rng = as_seed(seed)
    even = j[j % 2 == 0]
    if kind == "full":
        exc, odd_det, even = j, j[:0], j[:0]
    elif kind == "odd-odd":
        exc, odd_det = j[j % 4 == 1], j[j % 4 == 3]
    else:
        odd = j[j % 2 == 1]
        keep = np.ones(odd.size, dtype=bool)
        for g0 in range(0, odd.size - group + 1, group):
            keep[g0 + rng.integers(group)] = False
        exc, odd_det = odd[keep], odd[~keep]
    if exc.size == 0:
        raise ValueError(f"no line to excite in {first}..{last} with kind={kind!r} and spacing {s}")
    excited = exc * s
    side = (excited[:, None] + np.concatenate([np.arange(-reach, 0), np.arange(1, reach + 1)])[None, :]).ravel()
    side = np.unique(side[side >= 0]) if reach else np.zeros(0, dtype=np.int64)
    return ExcitationLines(kind=kind, reach=reach, spacing=s, excited=excited.astype(np.int64),
                           odd_detection=(odd_det * s).astype(np.int64),
                           even_detection=(even * s).astype(np.int64), sideband=side.astype(np.int64))
