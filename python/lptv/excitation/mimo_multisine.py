"""Multisines for several inputs (METHOD.md section 19, the experiment design): nu or more
experiments whose input spectra determine the HTF matrix on every excited line."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from .._validate import as_int, as_seed, as_str
from .multisine import _lines_amplitudes, multisine, time_signal

DESIGNS = ("hadamard", "random")


@dataclass(frozen=True)
class MimoMultisines:
    """The inputs of E experiments with nu inputs each (:func:`mimo_multisines`)."""

    lines: np.ndarray
    """Excited lines (every input of every experiment)."""
    n_samples: int
    """Samples per period N."""
    design: str
    """'hadamard' (orthogonal multisines, eq. 19.9) or 'random' (independent random phases)."""
    amplitudes: np.ndarray
    """Cosine amplitude of each input on each excited line, shape (nu, len(lines))."""
    pattern: Optional[np.ndarray]
    """The nu x E matrix T of eq. 19.9 (T T^H = E I): Sylvester's Hadamard matrix's first nu rows
    (+-1) when E is a power of 2, the DFT matrix's otherwise; None for the random design."""
    spectra: np.ndarray
    """One-sided input spectra, shape (E, N//2+1, nu): ``fft(u)[l] / N`` per experiment and input."""
    signals: np.ndarray
    """One period of every input, shape (E, N, nu)."""

    @property
    def n_inputs(self) -> int:
        return self.signals.shape[2]

    @property
    def n_experiments(self) -> int:
        return self.signals.shape[0]

    def input_matrix(self, line: int) -> np.ndarray:
        """UU_l of eq. 19.8: the nu x E matrix of the experiments' input spectra on a line."""
        line = as_int(line, "line", maximum=self.n_samples // 2)
        return self.spectra[:, line, :].T.copy()

    def noise_gain(self) -> np.ndarray:
        """Per excited line and input, the variance of an HTF matrix entry estimated by eq. 19.8
        relative to the output noise variance: the diagonal of (UU_l UU_l^H)^-1, shape
        (len(lines), nu). The orthogonal design gives 1 / (E |U_{l,q}|^2), the least for its
        amplitudes."""
        out = np.empty((self.lines.size, self.n_inputs))
        for i, l in enumerate(self.lines):
            UU = self.input_matrix(int(l))
            out[i] = np.real(np.diag(np.linalg.inv(UU @ UU.conj().T)))
        return out

    def periods(self, P: int) -> np.ndarray:
        """P >= 1 periods of every experiment, shape (E, P, N, nu)."""
        P = as_int(P, "P", minimum=1, maximum=max(1, 2**31 // max(self.n_samples, 1)))
        return np.repeat(self.signals[:, None], P, axis=1)


def _pattern(nu: int, E: int) -> np.ndarray:
    """nu x E with T T^H = E I: rows of Sylvester's Hadamard matrix (E a power of 2) or of the DFT matrix."""
    if E & (E - 1) == 0:
        H = np.ones((1, 1))
        while H.shape[0] < E:
            H = np.block([[H, H], [H, -H]])
        return H[:nu].astype(complex)
    q, e = np.meshgrid(np.arange(nu), np.arange(E), indexing="ij")
    return np.exp(-2j * np.pi * q * e / E)


def mimo_multisines(lines, n_samples: int, n_inputs: int, *, design: str = "hadamard",
                    n_experiments: Optional[int] = None, amplitudes=1.0, seed=None) -> MimoMultisines:
    """Input signals of E >= nu experiments for a system with nu inputs (METHOD.md section 19).

    With ``design="hadamard"`` (orthogonal multisines) each input q has one random-phase multisine
    U_{l,q} on the lines and experiment e applies ``T[q, e] U_{l,q}`` (eq. 19.9), so the nu x E
    matrix of input spectra on every line is ``diag(U_l) T`` with ``T T^H = E I``: the HTF
    matrix G_k(w_l) = YY UU_l^+ is determined on every excited line with the least noise its
    amplitudes allow. T is Sylvester's Hadamard matrix (a sign per input and experiment) when E
    is a power of 2, else the DFT matrix (a phase per input and experiment); a complex T cannot
    act on DC or the Nyquist line, which it then refuses. With ``design="random"`` every input of
    every experiment is an independent random-phase multisine (:func:`lptv.multisine`): the
    matrix is invertible with probability one but ill-conditioned on some lines.

    Parameters
    ----------
    lines : sequence of int
        Excited lines in 0..n_samples//2, the same for every input.
    n_samples : int
        Samples per period N.
    n_inputs : int
        Number of inputs nu.
    design : {'hadamard', 'random'}
    n_experiments : int, optional
        E >= nu (default nu).
    amplitudes : float, (len(lines),) or (nu, len(lines))
        Cosine amplitudes, per line or per input and line.
    seed : int or numpy.random.Generator, optional

    Examples
    --------
    >>> import numpy as np, lptv
    >>> d = lptv.mimo_multisines(range(5, 100, 10), 512, 2, seed=1)
    >>> d.signals.shape, d.pattern.real.tolist()
    ((2, 512, 2), [[1.0, 1.0], [1.0, -1.0]])
    >>> np.allclose(d.noise_gain(), 1 / (2 * 0.5 ** 2))    # |U_l| = 1/2: every line equally good
    True
    """
    n_inputs = as_int(n_inputs, "n_inputs", minimum=1, maximum=4096)
    design = as_str(design, "design", DESIGNS)
    E = n_inputs if n_experiments is None else as_int(n_experiments, "n_experiments", minimum=n_inputs,
                                                      maximum=65536)
    ln, _, n_samples = _lines_amplitudes(lines, n_samples, 1.0)
    amp = np.asarray(amplitudes, dtype=float) if np.ndim(amplitudes) == 2 else None
    if amp is None:
        amp = np.vstack([_lines_amplitudes(ln, n_samples, amplitudes)[1]] * n_inputs)
    elif amp.shape != (n_inputs, ln.size) or not np.all(np.isfinite(amp)):
        raise ValueError(f"amplitudes must be a scalar, one per line ({ln.size}) or finite values of shape "
                         f"(n_inputs, lines) = ({n_inputs}, {ln.size}), got shape {amp.shape}")
    rng = as_seed(seed)
    H = n_samples // 2 + 1
    spectra = np.zeros((E, H, n_inputs), complex)
    pattern = None
    if design == "random":
        for e in range(E):
            for q in range(n_inputs):
                spectra[e, :, q] = multisine(ln, n_samples, amp[q], seed=rng).spectrum
    else:
        pattern = _pattern(n_inputs, E)
        edge = (ln == 0) | (2 * ln == n_samples)
        if np.any(edge) and np.iscomplexobj(pattern) and np.any(pattern.imag != 0):
            raise ValueError(f"design='hadamard' with E = {E} experiments (not a power of 2) shifts phases, "
                             f"which DC and the Nyquist line cannot carry: leave out line(s) "
                             f"{ln[edge].tolist()}")
        for q in range(n_inputs):
            base = multisine(ln, n_samples, amp[q], seed=rng).spectrum
            for e in range(E):
                spectra[e, :, q] = pattern[q, e] * base
    signals = np.stack([np.stack([time_signal(spectra[e, :, q], n_samples) for q in range(n_inputs)], axis=1)
                        for e in range(E)])
    return MimoMultisines(lines=ln, n_samples=n_samples, design=design, amplitudes=amp, pattern=pattern,
                          spectra=spectra, signals=signals)
