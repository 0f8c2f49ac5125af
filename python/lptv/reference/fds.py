"""METHOD.md sections 1-3 in plain NumPy: dense band matrices and a dense solve.

This is the independent route the compiled core is tested against, so it reads only a
model's coefficient arrays (``model.a``, ``model.b``, ``model.w0``, ``model.ts``) and never
calls the core's computations. Every function favours the formula over speed: the band
matrices are built dense, entry by entry along their diagonals, and solved with
``numpy.linalg.solve``; spectra use ``numpy.fft`` with the scaling X_l = fft(x)[l] / N.

Grids (METHOD.md section 3):

- continuous time: lines -L..L, matrix index i <-> line i - L; lines beyond L are dropped;
- discrete time: the circular grid of N = 2 pi / (w0 ts) lines, index i <-> line i for
  i = 0..N-1 (line l and l + N are the same line), so the band wraps around the corners.
"""
from __future__ import annotations

import numpy as np

__all__ = [
    "samples_per_period", "grid", "line_variable", "band_matrix_A", "band_matrix_B",
    "full_spectrum", "simulate", "htf", "coefficients_at",
    "multisine_spectrum", "time_signal", "spectrum", "crest_factor",
]


# -- the model (METHOD.md section 1) -------------------------------------------------------

def samples_per_period(model) -> int:
    """N = 2 pi / (w0 ts) of a discrete-time model, rounded (the model checked it is whole)."""
    return int(round(2 * np.pi / (model.w0 * model.ts)))


def coefficients_at(model, t):
    """a_n(t) and b_m(t) (eq. 2) at the times t: two real arrays (len(t), na+1), (len(t), nb+1).

    a_n(t) = sum_k a_{n,k} exp(j k w0 t), summed over all 2K+1 harmonics; the imaginary part
    vanishes by conjugate symmetry and is dropped.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))

    def evaluate(c):
        K = (c.shape[1] - 1) // 2
        k = np.arange(-K, K + 1)
        phasors = np.exp(1j * np.outer(t, k) * model.w0)  # (len(t), 2K+1)
        return (phasors @ c.T).real

    return evaluate(np.asarray(model.a)), evaluate(np.asarray(model.b))


# -- the frequency grid and the band matrices (METHOD.md eq. 5) -----------------------------

def grid(model, L: int = 0) -> np.ndarray:
    """The lines of the band system, in matrix-index order.

    Continuous time: -L..L. Discrete time: 0..N-1 (L is ignored).
    """
    if model.ts:
        return np.arange(samples_per_period(model))
    return np.arange(-int(L), int(L) + 1)


def line_variable(model, lines) -> np.ndarray:
    """The Laplace / z variable on each line: j w_l (continuous) or z_l = exp(j w_l ts) (discrete)."""
    w = model.w0 * np.asarray(lines, dtype=float)
    if model.ts:
        return np.exp(1j * w * model.ts)
    return 1j * w


def _band_matrix(model, c, L):
    """M_{l,i} = sum_n c_{n,l-i} s_i^n for |l-i| <= K, dense; the band wraps on a circular grid."""
    c = np.asarray(c)
    K = (c.shape[1] - 1) // 2
    lines = grid(model, L)
    size = lines.size
    s = line_variable(model, lines)
    powers = s[None, :] ** np.arange(c.shape[0])[:, None]  # (order+1, size): s_i^n
    M = np.zeros((size, size), dtype=complex)
    cols = np.arange(size)
    for k in range(-K, K + 1):
        # Harmonic k moves input line i to output line i + k: the k-th subdiagonal.
        values = c[:, K + k] @ powers
        rows = cols + k
        if model.ts:
            rows = rows % size
            keep = np.ones(size, dtype=bool)
        else:
            keep = (rows >= 0) & (rows < size)
        # += rather than =: with 2K+1 > N two harmonics would land on the same entry
        # (the model forbids that, but the sum is what the circular convolution means).
        np.add.at(M, (rows[keep], cols[keep]), values[keep])
    return M


def band_matrix_A(model, L: int = 0) -> np.ndarray:
    """A of METHOD.md eq. 5: A_{l,i} = sum_n a_{n,l-i} (j w_i)^n (z_i^n in discrete time)."""
    return _band_matrix(model, model.a, L)


def band_matrix_B(model, L: int = 0) -> np.ndarray:
    """B of METHOD.md eq. 5, built like A from the b coefficients."""
    return _band_matrix(model, model.b, L)


# -- the simulator (METHOD.md section 3) ----------------------------------------------------

def full_spectrum(model, U, L: int = 0) -> np.ndarray:
    """One-sided spectra on lines 0..Lu (rows) -> spectra on the whole grid (conjugate lines).

    A real signal has X_{-l} = conj(X_l), so X_0 is real; in discrete time with even N the
    Nyquist line N/2 is its own conjugate and holds the real X_{N/2} once. The real parts of
    those self-conjugate lines are used (their imaginary parts describe no real signal).
    """
    U = np.asarray(U, dtype=complex)
    U = U.reshape(U.shape[0], -1)
    lines = grid(model, L)
    F = np.zeros((lines.size, U.shape[1]), dtype=complex)
    if model.ts:
        N = lines.size
        for l in range(U.shape[0]):
            if l == 0 or 2 * l == N:
                F[l] = U[l].real
            else:
                F[l] = U[l]
                F[N - l] = np.conj(U[l])
    else:
        L = int(L)
        for l in range(U.shape[0]):
            if l == 0:
                F[L] = U[0].real
            else:
                F[L + l] = U[l]
                F[L - l] = np.conj(U[l])
    return F


def simulate(model, U, guard: int = 0, lines_out=None) -> np.ndarray:
    """Steady-state output spectra Y = A^-1 B U with a dense solve (eq. 5).

    Parameters
    ----------
    model : lptv.Model (only its coefficient arrays, w0 and ts are read)
    U : array_like, (Lu+1,) or (Lu+1, n_inputs)
        One-sided input spectra on lines 0..Lu, X_l = fft(x)[l] / N.
    guard : int
        Continuous time: the grid is -L..L with L = max(Lu, lines_out) + guard; the lines
        beyond it are taken as zero. Ignored in discrete time (the grid is circular and exact).
    lines_out : int, optional
        Highest output line returned (default Lu).

    Returns
    -------
    Y : ndarray, one-sided output spectra on lines 0..lines_out, shaped like U.
    """
    U = np.asarray(U, dtype=complex)
    was_1d = U.ndim == 1
    U2 = U.reshape(U.shape[0], -1)
    Lu = U2.shape[0] - 1
    lines_out = Lu if lines_out is None else int(lines_out)
    L = 0 if model.ts else max(Lu, lines_out) + int(guard)
    A = band_matrix_A(model, L)
    B = band_matrix_B(model, L)
    Y_full = np.linalg.solve(A, B @ full_spectrum(model, U2, L))
    # Line l sits at index l on the circular grid and at index l + L on -L..L.
    offset = 0 if model.ts else L
    Y = Y_full[offset:offset + lines_out + 1]
    return Y[:, 0] if was_1d else Y


def htf(model, L: int, lines) -> np.ndarray:
    """Columns of the truncated harmonic transfer function G = A^-1 B for the input lines.

    Rows follow :func:`grid` (continuous: line i - L; discrete: line i). Discrete-time input
    lines are taken modulo N.
    """
    g = grid(model, L)
    G = np.linalg.solve(band_matrix_A(model, L), band_matrix_B(model, L))
    if model.ts:
        cols = [int(l) % g.size for l in lines]
    else:
        cols = [int(l) + int(L) for l in lines]
    return G[:, cols]


# -- multisines and spectra (METHOD.md section 2) -------------------------------------------

def multisine_spectrum(lines, amplitudes, phases, N: int) -> np.ndarray:
    """One-sided spectrum (lines 0..N//2) of x[t] = sum_l A_l cos(2 pi l t / N + phi_l).

    Computed the long way round: sample the sum of cosines, then fft(x)[l] / N.
    """
    x = np.zeros(int(N))
    t = np.arange(int(N))
    for l, A, phi in zip(np.atleast_1d(lines), np.broadcast_to(amplitudes, np.shape(lines)),
                         np.atleast_1d(phases)):
        x += A * np.cos(2 * np.pi * l * t / N + phi)
    return spectrum(x)


def spectrum(x) -> np.ndarray:
    """One-sided spectrum of one period of N samples: fft(x)[l] / N for l = 0..N//2."""
    x = np.asarray(x, dtype=float)
    return np.fft.fft(x)[: x.size // 2 + 1] / x.size


def time_signal(X, N: int) -> np.ndarray:
    """One period (N samples) of the real signal with one-sided spectrum X on lines 0..L <= N/2.

    x[t] = sum_{l=-L}^{L} X_l exp(j 2 pi l t / N): the two-sided spectrum is filled in by
    conjugate symmetry (lines 0 and N/2 once, real parts) and inverted with ifft.
    """
    X = np.asarray(X, dtype=complex).ravel()
    N = int(N)
    F = np.zeros(N, dtype=complex)
    for l, v in enumerate(X):
        if l == 0 or 2 * l == N:
            F[l] = v.real
        else:
            F[l] = v
            F[N - l] = np.conj(v)
    return (np.fft.ifft(F) * N).real


def crest_factor(x) -> float:
    """max |x| / rms(x)."""
    x = np.asarray(x, dtype=float)
    return float(np.max(np.abs(x)) / np.sqrt(np.mean(x ** 2)))
