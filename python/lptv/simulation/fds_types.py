"""What the simulator's routes share (the SISO FDS of :mod:`lptv.simulation.fds` and the block band FDS of
:mod:`lptv.simulation.mimo_fds`): its result type, its warnings, its solvers and limits."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core

SOLVERS = ("auto", "band", "klu", "umfpack")

MAX_GRID_LINES = 2 ** 26
"""The largest grid :func:`lptv.htf` builds (lines)."""


class TruncationWarning(UserWarning):
    """The adaptive guard did not bring the truncation error below the tolerance."""


class ConditioningWarning(UserWarning):
    """The band system is nearly singular next to a line that carries output: a pole within a
    relative distance of about 1 / condition of the line (a nearly undamped resonance). The
    output there is amplified about ``condition`` times and is as sensitive to the
    coefficients; more than half of the 16 digits are lost."""


CONDITION_WARN = float(_core.FDS_WARN_CONDITION)
"""Condition number (relative to the coefficients on the line) above which :func:`simulate`
warns (1e8: more than half the digits lost, 1 / sqrt(eps) = 6.7e7 rounded up)."""
CONDITION_MAX = float(_core.FDS_MAX_CONDITION)
"""Above this :func:`simulate` refuses with :class:`lptv.NumericalError` (1e13: fewer than 3 digits)."""


@dataclass(frozen=True)
class SimulationResult:
    """Output of :func:`simulate` with ``full_output=True``."""

    Y: np.ndarray
    """One-sided output spectra on lines 0..lines_out."""
    guard: int
    """Guard lines used beyond the band (continuous time)."""
    truncation_error: float
    """Estimated error from dropping lines beyond the grid, relative to the largest output line."""
    converged: bool
    """Whether the truncation error met ``tol``."""
    solver: str
    """Factorisation used ('band', 'klu' or 'umfpack')."""
    condition: float = float("nan")
    """Componentwise condition number of the band system relative to the model's coefficients
    (max over the lines of sum |terms| / |result|; an LTI model: over the lines with input), a
    lower estimate: about log10(condition) of the 16 digits are lost."""
    condition_line: int = 0
    """The line where ``condition`` peaks."""
