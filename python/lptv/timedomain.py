"""The earlier path of :mod:`lptv.simulation.timedomain` (time integration with SUNDIALS CVODE),
kept so that ``import lptv.timedomain`` and ``from lptv.timedomain import periodic_steady_state``
go on working: the same objects, nothing of its own."""
from .simulation.timedomain import Response, SteadyState, free_response, periodic_steady_state

__all__ = ["SteadyState", "Response", "periodic_steady_state", "free_response"]
