"""The input's design (METHOD.md sections 2 and 19).

- :mod:`lptv.excitation.multisine`: random-phase and crest-factor-minimised multisines, the
  detection lines, spectra and time signals;
- :mod:`lptv.excitation.mimo_multisine`: the experiments of several inputs.
"""
