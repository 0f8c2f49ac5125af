"""Using a saved model (METHOD.md section 21): predict a record's output, validate the model on a
fresh record with the model fixed, export an LTI model to scipy.signal and python-control.

- :func:`predict` (predict.py): the output for given input samples, from rest or in periodic
  steady state;
- :func:`validate` (validate.py): the model fixed against a fresh record: its residues against
  that record's noise, the verdict's tests with the model's own error in place of the fit's
  projection, a score test per coefficient, the simulation fit in percent;
- modelfile.py: the ``context`` a model.json keeps for these uses, and its checks;
- export.py: :meth:`lptv.Model.to_scipy` and the reason an LPTV model is refused there.
"""
from .predict import predict
from .validate import CoefficientTest, ValidationResult, validate

__all__ = ["predict", "validate", "ValidationResult", "CoefficientTest"]
