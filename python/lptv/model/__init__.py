"""The model, the hub every stage reads (METHOD.md sections 1, 12 and 19).

- :mod:`lptv.model.siso`: :class:`lptv.Model`, one input and one output (LTI as its special case),
  its JSON;
- :mod:`lptv.model.mimo`: :class:`lptv.MimoModel`, the matrix model of several inputs and outputs;
- :mod:`lptv.model.floquet`: :func:`lptv.floquet`, the model's stability (characteristic
  multipliers, Floquet exponents), the warnings and the cached stability test the other stages
  share.
"""
