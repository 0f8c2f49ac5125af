"""lptv: identification of linear periodically time-varying systems in the frequency domain.

The public API:

- :class:`Model` - the LPTV model (and LTI as its special case), JSON save/load;
- :func:`multisine`, :func:`spectrum`, :func:`time_signal` - excitation and spectra;
- :func:`simulate`, :func:`htf`, :func:`band_matrices` - the frequency-domain simulator;
- :mod:`lptv.reference` - the same mathematics in plain NumPy;
- :mod:`lptv.timedomain` - time integration with SUNDIALS CVODE.
"""
from ._core import NumericalError
from .fds import SimulationResult, TruncationWarning, band_matrices, htf, simulate
from .model import Model
from .multisine import Multisine, multisine, spectrum, time_signal

__version__ = "0.1.0"

__all__ = [
    "Model", "Multisine", "NumericalError", "SimulationResult", "TruncationWarning",
    "band_matrices", "htf", "multisine", "simulate", "spectrum", "time_signal",
]
