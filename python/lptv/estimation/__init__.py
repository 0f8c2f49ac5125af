"""The fits (METHOD.md sections 5-10, 17 and 19).

- :mod:`lptv.estimation.identify`: :func:`lptv.identify` (LS, TLS, GTLS, WGTLS, SML) with the
  covariance of the estimate; :mod:`lptv.estimation.bootstrap` its parametric bootstrap;
  :mod:`lptv.estimation.mimo_identify` and :mod:`lptv.estimation.mimo_fit` the route for several
  inputs and outputs (:func:`lptv.mimo_crb`);
- :mod:`lptv.estimation.one_record`: :func:`lptv.identify_record`, one record with its transient;
- :mod:`lptv.estimation.crb`: :func:`lptv.crb`, the Cramer-Rao bound of a design.

An estimator returns its result from :mod:`lptv.judgement` (DESIGN.md, "The Python package's
stages").
"""
