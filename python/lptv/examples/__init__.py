"""Models and excitations the documentation, tests, benchmarks and demo share: the one-channel
systems of :mod:`lptv.examples.siso`, re-exported here, and the mechanical systems with several
channels of :mod:`lptv.examples.mimo`.

The paper's simulation example (METHOD.md section 8) does not give its harmonic
amplitudes, w0 or number of periods; the choices below are ours, stated here:

- mean (DC) system (s + 1) / (s^2 + s + 1), i.e. a = (1, 1, 1), b = (1, 1);
- 3 harmonics on each of a0, a1, a2, b0, b1 with the amplitudes in ``PAPER_HARMONICS``
  (3 to 19 % of the DC values, falling with k; a_2(t) >= 0.82 > 0, a_0(t) >= 0.48 and every
  frozen system is stable). Harmonics of only a few % were tried first: then a common
  periodic factor of numerator and denominator, truncated to 3 harmonics, changes the residue
  by less than the noise (the two smallest generalised singular values of WGTLS were 1.0 and
  1.9 instead of 1.0 and 5), and the harmonics are poorly determined at 50/30 dB SNR;
- w0 = 0.04 rad/s (T0 = 157 s), so the excited lines 10, 20, ..., 240 span 0.4 .. 9.6 rad/s
  around the resonance at 1 rad/s (line 25);
- the multisine has 24 lines of equal amplitude sqrt(2/24) (rms 1, whatever the number of
  lines) and N = 2048 samples per period;
- the measurement noise (``paper_measurements``): 50 dB mean SNR on the input, 30 dB on the
  output, first-order low-pass noise with poles 0.6 (input) and 0.8 (output), the output noise
  sharing half of its driving sequence with the input noise (``PAPER_NOISE``);
  ``noise_variances`` gives the true per-line (co)variances of that noise, for :func:`lptv.crb`.
"""
from .siso import (  # noqa: F401 - the systems' constants, importable from lptv.examples
    PAPER_W0, PAPER_N, PAPER_EXCITED, PAPER_ID_LINES, PAPER_SNR_IN_DB, PAPER_SNR_OUT_DB,
    PAPER_NOISE, PAPER_DC, PAPER_HARMONICS, THIRD_ORDER_W0, THIRD_ORDER_N, THIRD_ORDER_EXCITED,
    THIRD_ORDER_ID_LINES, THIRD_ORDER_STRUCTURE, DISCRETE_N, DISCRETE_EXCITED, DISCRETE_ID_LINES,
    DISCRETE_STRUCTURE, SYSTEMS, BLA_SYSTEMS, paper_model, mathieu_model, paper_multisine,
    noisy_periods, noise_variances, paper_measurements, third_order_model, discrete_model,
    system_measurements, cubic_realisations, actuator_gain, exact_bla, transient_record,
    continuous_record,
)

__all__ = [
    "paper_model", "mathieu_model", "paper_multisine", "noisy_periods", "noise_variances",
    "paper_measurements", "third_order_model", "discrete_model", "system_measurements",
    "cubic_realisations", "actuator_gain", "exact_bla", "transient_record", "continuous_record",
]
