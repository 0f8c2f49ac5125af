"""The periods' spectra and what they say without a parametric model (METHOD.md sections 4, 7,
11, 16 and 19).

- :mod:`lptv.spectra.frequency_data`: :class:`lptv.FrequencyData`, the mean spectra and the noise
  (co)variances from the periods; :mod:`lptv.spectra.mimo_frequency_data` the same for several
  channels;
- :mod:`lptv.spectra.moderation`: :func:`lptv.moderated_noise`, the noise (co)variances moderated
  across lines; :mod:`lptv.spectra.mimo_moderation` the covariance matrices of several channels;
- :mod:`lptv.spectra.disturbances`: :func:`lptv.disturbances`, sinusoids off the period's grid;
- :mod:`lptv.spectra.distortion`: :func:`lptv.distortion`, noise, nonlinear distortion and the
  best linear approximation from random-phase realisations;
- :mod:`lptv.spectra.htf_estimate`: :func:`lptv.htf_estimate`, the HTF's branches without a
  model; :mod:`lptv.spectra.mimo_htf_estimate` the HTF matrix from several experiments.
"""
