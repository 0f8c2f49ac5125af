"""The block band FDS of a :class:`lptv.MimoModel` (METHOD.md section 19): what :func:`lptv.simulate`,
:func:`lptv.htf` and :func:`lptv.band_matrices` do for several inputs and outputs."""
from __future__ import annotations

import warnings

import numpy as np

from .. import _core
from .._validate import _array, as_bool, as_int, as_positive_float, as_str, check_finite
from ..model.mimo import MimoModel

_SOLVERS = ("auto", "band", "klu", "umfpack")


def as_mimo_spectrum(U, nu, name="U"):
    """Input spectra of a model with nu inputs: (lines, nu) or (lines, nu, E) (and (lines,) for
    nu = 1) -> the core's (lines, E nu) columns, E, and the shape to give the outputs."""
    arr = _array(U, name)
    if arr.ndim == 1 and nu == 1:
        arr3, kind = arr[:, None, None], 1
    elif arr.ndim == 2 and arr.shape[1] == nu:
        arr3, kind = arr[:, :, None], 2
    elif arr.ndim == 3 and arr.shape[1] == nu:
        arr3, kind = arr, 3
    else:
        raise ValueError(f"{name} must have shape (lines, n_inputs={nu}) or (lines, n_inputs={nu}, experiments)"
                         f"{' or (lines,)' if nu == 1 else ''}, got shape {arr.shape}")
    if min(arr3.shape) < 1:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    arr3 = arr3.astype(complex)
    check_finite(arr3, name)
    E = arr3.shape[2]
    cols = np.ascontiguousarray(arr3.transpose(0, 2, 1).reshape(arr3.shape[0], E * nu))
    return cols, E, kind


def _outputs(Y, ny, E, kind):
    Y = np.asarray(Y).reshape(Y.shape[0], E, ny).transpose(0, 2, 1)
    return Y[:, :, 0] if kind in (1, 2) else Y


def simulate_mimo(model: MimoModel, U, *, lines_out, guard, tol, max_guard, solver, full_output):
    """lptv.simulate for a MimoModel (its arguments checked and documented there)."""
    from .fds_types import CONDITION_WARN, ConditioningWarning, SimulationResult, TruncationWarning

    cols, E, kind = as_mimo_spectrum(U, model.n_inputs)
    lines_out = -1 if lines_out is None else as_int(lines_out, "lines_out")
    guard = -1 if guard is None else as_int(guard, "guard")
    max_guard = -1 if max_guard is None else as_int(max_guard, "max_guard")
    tol = as_positive_float(tol, "tol")
    solver = as_str(solver, "solver", _SOLVERS)
    full_output = as_bool(full_output, "full_output")
    r = _core.simulate_mimo(model._cpp, cols, solver=solver, lines_out=lines_out, guard=guard, tol=tol,
                            max_guard=max_guard)
    Yc = np.asarray(r["Y"])
    if not r["converged"] and guard < 0 and not model.discrete and not model.is_lti:
        warnings.warn(f"FDS truncation error {r['truncation_error']:.2e} is above tol={tol:g} with "
                      f"{r['guard']} guard lines; pass a larger max_guard or guard", TruncationWarning, stacklevel=3)
    cl = int(r["condition_line"])
    silent = cl < Yc.shape[0] and not np.any(Yc[cl])
    if r["condition"] > CONDITION_WARN and not silent:
        warnings.warn(f"the steady state is nearly singular on line {cl} (condition {r['condition']:.2g} "
                      f"relative to the model's coefficients there, warning above {CONDITION_WARN:.0e}): a pole "
                      f"within a relative distance of about {1 / r['condition']:.1g} of that line",
                      ConditioningWarning, stacklevel=3)
    Y = _outputs(Yc, model.n_outputs, E, kind)
    if full_output:
        return SimulationResult(Y=Y, guard=r["guard"], truncation_error=r["truncation_error"],
                                converged=r["converged"], solver=r["solver"], condition=float(r["condition"]),
                                condition_line=cl)
    return Y


def htf_mimo(model: MimoModel, L: int, lines, solver: str) -> np.ndarray:
    """lptv.htf for a MimoModel: G of shape (grid lines, ny, len(lines), nu)."""
    from .fds_types import MAX_GRID_LINES

    L = as_int(L, "L", maximum=MAX_GRID_LINES)
    solver = as_str(solver, "solver", _SOLVERS)
    n = model.samples_per_period if model.discrete else 2 * L + 1
    if lines is None:
        lines = range(n) if model.discrete else range(-L, L + 1)
    try:
        lines = [as_int(x, "lines", minimum=-2**31 + 1) for x in lines]
    except TypeError:
        raise ValueError(f"lines must be a sequence of integers, got {lines!r}") from None
    G = np.asarray(_core.mimo_htf(model._cpp, L, lines, solver))
    return G.reshape(n, model.n_outputs, len(lines), model.n_inputs)


def band_matrices_mimo(model: MimoModel, L: int):
    """lptv.band_matrices for a MimoModel: AA and BB of METHOD.md eq. 19.4, channel fastest."""
    L = as_int(L, "L")
    return _core.mimo_band_matrix(model._cpp, L, True), _core.mimo_band_matrix(model._cpp, L, False)
