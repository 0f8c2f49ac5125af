"""The same mathematics as the compiled core, written plainly with NumPy.

An independent route for the tests and benchmarks: dense matrices, dense solves, ``numpy.fft``.
It reads a model's coefficient arrays and never calls the core's computations.

- :mod:`lptv.reference.fds` (re-exported here): model, band matrices, FDS, multisines;
- :mod:`lptv.reference.identification`: noise model, Jacobian, residue variance, column
  covariance, LS / TLS / GTLS / WGTLS;
- :mod:`lptv.reference.likelihood`: the exact likelihood of LPTV rows (real noise vector,
  residue covariance S, cost r^T S^-1 r and its gradient), its minimiser and the Cramer-Rao
  bound, all dense;
- :mod:`lptv.reference.distortion`: the regression of random-phase realisations per output line
  behind :func:`lptv.distortion` (residual and noise variances, the BLA and its variance);
- :mod:`lptv.reference.moderation`: the noise (co)variances moderated across lines behind
  :func:`lptv.moderated_noise` (SciPy's polygamma and F quantile, NumPy's window sums);
- :mod:`lptv.reference.mimo`: the block band matrices of a matrix model (several inputs and
  outputs) and the dense solve behind :func:`lptv.simulate` on a :class:`lptv.MimoModel`;
- :mod:`lptv.reference.floquet`: the monodromy matrix by solve_ivp (the product in discrete time)
  and the exponents' derivative by central differences (METHOD.md section 22);
- :mod:`lptv.reference.record`: one record with its transient behind
  :func:`lptv.identify_record` (equation-error start, SciPy's Levenberg-Marquardt on the output
  error, dense LU per residue class of the record's lines, the residual's noise level).
"""
from . import distortion, excitation, floquet, identification, likelihood, mimo, moderation, record
from .fds import (
    band_matrix_A,
    band_matrix_B,
    coefficients_at,
    crest_factor,
    full_spectrum,
    grid,
    htf,
    line_variable,
    multisine_spectrum,
    samples_per_period,
    simulate,
    spectrum,
    time_signal,
)

__all__ = [
    "distortion", "excitation", "floquet", "identification", "likelihood", "mimo", "moderation", "record", "band_matrix_A", "band_matrix_B", "coefficients_at",
    "crest_factor", "full_spectrum", "grid", "htf", "line_variable", "multisine_spectrum",
    "samples_per_period", "simulate", "spectrum", "time_signal",
]
