"""What a fit is worth (METHOD.md sections 7, 17 and 19).

- :mod:`lptv.judgement.result`: :class:`lptv.IdentificationResult`, the estimate, its covariance,
  its residues and the verdict read from them; :mod:`lptv.judgement.verdict` the residue tests
  behind ``res.model_ok``; :mod:`lptv.judgement.mimo_result` the result and verdict of several
  channels;
- :mod:`lptv.judgement.one_record_verdict` and :mod:`lptv.judgement.one_record_score`: the
  verdict of a one-record fit and its score tests;
- :mod:`lptv.judgement.validation`: normalised residues, frozen poles and zeros;
- :mod:`lptv.judgement.parameters`: the parameters with their uncertainty, the measured output
  against the predicted one.
"""
