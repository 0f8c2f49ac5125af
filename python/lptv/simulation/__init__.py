"""The model's response to an input (METHOD.md sections 3 and 19, eq. 1).

- :mod:`lptv.simulation.fds`: the frequency-domain simulator (:func:`lptv.simulate`,
  :func:`lptv.htf`, :func:`lptv.band_matrices`); :mod:`lptv.simulation.fds_types` what its routes
  share; :mod:`lptv.simulation.mimo_fds` the block band FDS of a :class:`lptv.MimoModel`;
- :mod:`lptv.simulation.timedomain`: the equation integrated in time with SUNDIALS CVODE, an
  independent route that uses no computation of the compiled core.
"""
