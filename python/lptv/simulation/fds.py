"""The frequency-domain simulator (FDS, METHOD.md section 3)."""
from __future__ import annotations

import warnings
from typing import Optional, Sequence

import numpy as np

from .. import _core
from .._validate import as_bool, as_int, as_positive_float, as_spectrum, as_str

from .fds_types import (CONDITION_MAX, CONDITION_WARN, MAX_GRID_LINES, SOLVERS,  # noqa: F401 - lptv.simulation.fds.*
                        ConditioningWarning, SimulationResult, TruncationWarning)
from ..model.floquet import UnstableModelWarning, unstable_warning_text
from ..model.mimo import MimoModel
from ..model.siso import Model


def _check_model(model, name="model"):
    if not isinstance(model, Model):
        raise ValueError(f"{name} must be an lptv.Model, got {type(model).__name__}")
    return model


def simulate(model: Model, U, *, lines_out: Optional[int] = None, guard: Optional[int] = None,
             tol: float = 1e-13, max_guard: Optional[int] = None, solver: str = "auto",
             full_output: bool = False, warn_unstable: bool = True):
    """Steady-state output spectrum of ``model`` for the input spectrum ``U``.

    Solves the band system ``A Y = B U`` (METHOD.md eq. 5) with one sparse LU. The result is
    the periodic solution of the equation, which exists and is unique whenever no Floquet
    multiplier equals 1, stable or not: for an unstable system (``lptv.floquet(model).is_stable``
    is False) it is still returned, though the system never settles into it.

    Parameters
    ----------
    model : lptv.Model or lptv.MimoModel
    U : array_like, shape (L+1,) or (L+1, n_inputs)
        One-sided Fourier coefficients on lines 0..L: ``U[l] = fft(u)[l] / N`` for N samples
        of one period, so a cosine of amplitude A and phase phi on line l has
        ``U[l] = A/2 exp(j phi)``. ``U[0]`` must be real. Several columns share one factorisation.
        For an :class:`lptv.MimoModel` with nu inputs and ny outputs: shape (L+1, nu), giving
        (lines, ny), or (L+1, nu, E) for E experiments sharing one factorisation, giving
        (lines, ny, E) (METHOD.md section 19: the block band system, channel fastest); the
        stability check is :func:`lptv.floquet`'s on the matrix system.
    lines_out : int, optional
        Highest output line to return (default L).
    guard : int, optional
        Continuous time: a fixed number of guard lines beyond the band. By default the guard
        grows until the returned lines change by less than ``tol`` relative to the largest.
    tol : float
        Relative truncation tolerance of the adaptive guard.
    solver : {'auto', 'band', 'klu', 'umfpack'}
        The factorisation of A: 'auto' is the band LU in continuous time (A has 2K+1
        diagonals; the core's own kernel, LAPACK's for wide bands) and SuiteSparse's KLU in
        discrete time (the band wraps around the corners,
        so 'band' is refused there).
    full_output : bool
        Return a :class:`SimulationResult` instead of ``Y``.
    warn_unstable : bool
        Check the model's stability (the roots of a for an LTI model, :func:`lptv.floquet`
        otherwise; once per model object) and warn when it is unstable. False skips the check.

    Returns
    -------
    Y : ndarray, same shape as U (rows up to ``lines_out``)

    Raises
    ------
    lptv.NumericalError
        A is numerically singular (condition above :data:`CONDITION_MAX` = 1e13 relative to
        the coefficients on a line): a pole on, or within rounding of, a grid line, or a_na(t)
        nearly vanishes; the message names the line.

    Warns
    -----
    lptv.UnstableModelWarning
        The model is unstable: the periodic solution is returned, but a simulation from rest
        never settles into it.
    lptv.ConditioningWarning
        The condition is above :data:`CONDITION_WARN` = 1e8 on a line with output (an LTI
        model: a line with input): a nearly undamped resonance there; the message names the
        line. The result is returned (``condition`` in ``full_output``).
    TruncationWarning
        The adaptive guard did not reach ``tol``.

    Examples
    --------
    >>> import numpy as np, lptv
    >>> m = lptv.Model([[1.0], [1.0]], [[1.0]], w0=1.0)      # 1 / (s + 1)
    >>> U = np.zeros(3, complex); U[1] = 0.5                   # cos(t)
    >>> np.round(lptv.simulate(m, U)[1], 6)                    # 0.5 / (1j + 1)
    np.complex128(0.25-0.25j)
    """
    if isinstance(model, MimoModel):
        from .mimo_fds import simulate_mimo

        out = simulate_mimo(model, U, lines_out=lines_out, guard=guard, tol=tol, max_guard=max_guard,
                            solver=solver, full_output=full_output)
        if as_bool(warn_unstable, "warn_unstable"):
            _warn_unstable(model)
        return out
    _check_model(model)
    Ua, was_1d = as_spectrum(U, "U")
    lines_out = -1 if lines_out is None else as_int(lines_out, "lines_out")
    guard = -1 if guard is None else as_int(guard, "guard")
    max_guard = -1 if max_guard is None else as_int(max_guard, "max_guard")
    tol = as_positive_float(tol, "tol")
    solver = as_str(solver, "solver", SOLVERS)
    full_output = as_bool(full_output, "full_output")
    warn_unstable = as_bool(warn_unstable, "warn_unstable")
    r = _core.simulate(model._cpp, Ua, solver=solver, lines_out=lines_out, guard=guard, tol=tol,
                       max_guard=max_guard)
    Y = np.asarray(r["Y"])
    if was_1d:
        Y = Y[:, 0]
    if not r["converged"] and guard < 0 and not model.discrete and not model.is_lti:
        warnings.warn(
            f"FDS truncation error {r['truncation_error']:.2e} is above tol={tol:g} "
            f"with {r['guard']} guard lines; pass a larger max_guard or guard",
            TruncationWarning, stacklevel=2)
    cl = int(r["condition_line"])
    # a line whose output is exactly zero (no input reaches it) loses nothing to its pole
    silent = cl < Y.shape[0] and not np.any(np.asarray(r["Y"])[cl])
    if r["condition"] > CONDITION_WARN and not silent:
        warnings.warn(
            f"the steady state is nearly singular on line {r['condition_line']} (condition "
            f"{r['condition']:.2g} relative to the model's coefficients there, warning above "
            f"{CONDITION_WARN:.0e}): a pole within a relative distance of about "
            f"{1 / r['condition']:.1g} of that line, e.g. a nearly undamped resonance; the output "
            f"there is amplified about {r['condition']:.1g} times and a relative change of "
            f"{1 / r['condition']:.1g} in the coefficients changes it by its own size",
            ConditioningWarning, stacklevel=2)
    if warn_unstable:
        _warn_unstable(model)
    if full_output:
        return SimulationResult(Y=Y, guard=r["guard"], truncation_error=r["truncation_error"],
                                converged=r["converged"], solver=r["solver"],
                                condition=float(r["condition"]), condition_line=int(r["condition_line"]))
    return Y


def _warn_unstable(model: Model) -> None:
    text = unstable_warning_text(model)
    if text is not None:
        warnings.warn(text, UnstableModelWarning, stacklevel=3)




def htf(model: Model, L: int, lines: Optional[Sequence[int]] = None, solver: str = "auto"):
    """Columns of the truncated harmonic transfer function G = A^-1 B.

    Parameters
    ----------
    model : lptv.Model
    L : int
        Continuous time: the grid is lines -L..L (ignored in discrete time, where the grid is
        the model's N lines 0..N-1).
    lines : sequence of int, optional
        Input lines whose columns to return (default: all).

    Returns
    -------
    G : ndarray (grid size, len(lines)); row i is output line i - L (continuous) or i (discrete).
        For an :class:`lptv.MimoModel`: (grid size, ny, len(lines), nu), G[i, p, j, r] the
        output p on grid line i for a unit input r on lines[j] (METHOD.md eq. 18.5).
    """
    if isinstance(model, MimoModel):
        from .mimo_fds import htf_mimo

        return htf_mimo(model, L, lines, solver)
    _check_model(model)
    # the core's largest grid (2^26 lines each side): checked here too, before the default list
    # of 2 L + 1 input lines below is built
    L = as_int(L, "L", maximum=MAX_GRID_LINES)
    solver = as_str(solver, "solver", SOLVERS)
    n = model.samples_per_period if model.discrete else 2 * L + 1
    if model.discrete and n > 2 * MAX_GRID_LINES + 1:
        # as in the core, and before a default list of n input lines is built
        raise ValueError(f"the grid of the model's {n} samples per period is too large "
                         f"(at most {2 * MAX_GRID_LINES + 1} lines)")
    if lines is None:
        lines = range(n) if model.discrete else range(-L, L + 1)
    try:
        lines = [as_int(x, "lines", minimum=-2**31 + 1) for x in lines]
    except TypeError:
        raise ValueError(f"lines must be a sequence of integers, got {lines!r}") from None
    return np.asarray(_core.htf(model._cpp, L, lines, solver))


def band_matrices(model: Model, L: int = 0):
    """The sparse band matrices (A, B) of METHOD.md eq. 5 as scipy.sparse CSC matrices (for an
    :class:`lptv.MimoModel` the block band matrices of eq. 19.4, channel fastest)."""
    if isinstance(model, MimoModel):
        from .mimo_fds import band_matrices_mimo

        return band_matrices_mimo(model, L)
    _check_model(model)
    L = as_int(L, "L")
    return _core.band_matrix(model._cpp, L, True), _core.band_matrix(model._cpp, L, False)
