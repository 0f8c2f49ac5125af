"""METHOD.md section 19 in plain NumPy: the block band matrices of a matrix LPTV model, built
dense entry by entry, and a dense solve.

The independent route the core's block band FDS (``lptv.simulate`` on a ``MimoModel``) is
tested against: it reads only the model's coefficient arrays (``model.a`` of shape
(na+1, ny, ny, 2Ka+1), ``model.b`` (nb+1, ny, nu, 2Kb+1), ``model.w0``, ``model.ts``) and never
calls the core's computations. Unknowns are numbered as in the core (line index fastest-varying
outside, channel inside: scalar index ny i + p), but every entry is computed from eq. 19.4 on
its own.
"""
from __future__ import annotations

import numpy as np

from .fds import grid, line_variable

__all__ = ["block_matrix_A", "block_matrix_B", "full_spectra", "simulate", "htf", "coefficients_at"]


def coefficients_at(model, t):
    """A_n(t) and B_m(t) at the times t: real arrays (len(t), na+1, ny, ny), (len(t), nb+1, ny, nu)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))

    def evaluate(c):
        K = (c.shape[3] - 1) // 2
        ph = np.exp(1j * np.outer(t, np.arange(-K, K + 1)) * model.w0)  # (len(t), 2K+1)
        return np.einsum("tk,npqk->tnpq", ph, c).real

    return evaluate(np.asarray(model.a)), evaluate(np.asarray(model.b))


def _block_matrix(model, c, L):
    """M[(l, p), (i, q)] = sum_n c[n, p, q, K + l - i] s_i^n for |l - i| <= K (circular in discrete time)."""
    c = np.asarray(c)
    order, ny, nc, width = c.shape
    K = (width - 1) // 2
    lines = grid(model, L)
    size = lines.size
    s = line_variable(model, lines)
    M = np.zeros((size * ny, size * nc), dtype=complex)
    for i in range(size):            # column block: input line index
        for k in range(-K, K + 1):
            l = i + k
            if model.ts:
                l %= size
            elif not 0 <= l < size:
                continue
            block = sum(c[n, :, :, K + k] * s[i] ** n for n in range(order))
            M[l * ny:(l + 1) * ny, i * nc:(i + 1) * nc] += block
    return M


def block_matrix_A(model, L: int = 0) -> np.ndarray:
    """AA of METHOD.md eq. 19.4, dense (grid size ny square)."""
    return _block_matrix(model, model.a, L)


def block_matrix_B(model, L: int = 0) -> np.ndarray:
    """BB of METHOD.md eq. 19.4, dense (grid size ny x grid size nu)."""
    return _block_matrix(model, model.b, L)


def full_spectra(model, U, L: int = 0) -> np.ndarray:
    """One-sided spectra U (lines 0..Lu, nu) -> the grid's vector (grid size nu), conjugate lines
    filled in (DC and a discrete-time Nyquist line real)."""
    U = np.asarray(U, dtype=complex)
    nu = U.shape[1]
    lines = grid(model, L)
    N = lines.size
    F = np.zeros((N, nu), dtype=complex)
    for l in range(U.shape[0]):
        if model.ts:
            if l == 0 or 2 * l == N:
                F[l] = U[l].real
            else:
                F[l] = U[l]
                F[N - l] = np.conj(U[l])
        elif l == 0:
            F[L] = U[0].real
        elif l <= L:
            F[L + l] = U[l]
            F[L - l] = np.conj(U[l])
    return F.reshape(-1)


def simulate(model, U, guard: int = 0, lines_out=None) -> np.ndarray:
    """Steady-state output spectra (lines 0..lines_out, ny) for U (lines 0..Lu, nu) by a dense
    solve of AA Y = BB U; continuous time on the grid -L..L, L = max(Lu, lines_out) + guard."""
    U = np.asarray(U, dtype=complex)
    Lu = U.shape[0] - 1
    lines_out = Lu if lines_out is None else int(lines_out)
    L = 0 if model.ts else max(Lu, lines_out) + int(guard)
    ny = np.asarray(model.a).shape[1]
    Y = np.linalg.solve(block_matrix_A(model, L), block_matrix_B(model, L) @ full_spectra(model, U, L))
    Y = Y.reshape(-1, ny)
    offset = 0 if model.ts else L
    return Y[offset:offset + lines_out + 1]


def htf(model, L: int, lines) -> np.ndarray:
    """G[i, p, j, r]: output p on grid line i for a unit input r on lines[j] (dense AA^-1 BB)."""
    a, b = np.asarray(model.a), np.asarray(model.b)
    ny, nu = a.shape[1], b.shape[2]
    g = grid(model, L)
    G = np.linalg.solve(block_matrix_A(model, L), block_matrix_B(model, L))
    G = G.reshape(g.size, ny, g.size, nu)
    idx = [int(l) % g.size if model.ts else int(l) + int(L) for l in lines]
    return G[:, :, idx, :]
