"""Random-phase multisines (METHOD.md section 2)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from ._validate import as_int, as_real_1d, as_spectrum


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
        """P consecutive periods, shape (P, N)."""
        return np.tile(self.signal, (int(P), 1))


def multisine(lines, n_samples: int, amplitudes=1.0, seed=None) -> Multisine:
    """Random-phase multisine ``u(t) = sum_l A_l cos(l w0 t + phi_l)``, phi_l ~ U[0, 2 pi).

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
    n_samples = as_int(n_samples, "n_samples", minimum=1)
    ln = np.atleast_1d(np.asarray(lines))
    if ln.size == 0:
        raise ValueError("lines must not be empty")
    if not np.issubdtype(ln.dtype, np.integer):
        if not (np.issubdtype(ln.dtype, np.floating) and np.all(np.isfinite(ln))
                and np.all(ln == np.round(ln))):
            raise ValueError(f"lines must be integers, got {ln.dtype} values")
        if np.any(ln < 0) or np.any(ln > n_samples // 2):  # before a cast that would wrap them
            raise ValueError(f"lines must lie in 0..{n_samples // 2} (n_samples//2), "
                             f"got {ln.min():.6g}..{ln.max():.6g}")
        ln = ln.astype(int)
    if ln.ndim != 1:
        raise ValueError(f"lines must be 1-D, got shape {ln.shape}")
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
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    phases = rng.uniform(0.0, 2 * np.pi, ln.size)
    X = np.asarray(_core.multisine_spectrum([int(x) for x in ln], np.ascontiguousarray(amp),
                                            phases, n_samples))
    x = np.asarray(_core.time_signal(X, n_samples))
    return Multisine(lines=ln, amplitudes=np.array(amp), phases=phases, n_samples=n_samples,
                     spectrum=X, signal=x)


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
