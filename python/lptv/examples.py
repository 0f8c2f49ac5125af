"""Models and excitations the documentation, tests, benchmarks and demo share.

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
  lines) and N = 2048 samples per period.
"""
from __future__ import annotations

import numpy as np

from .model import Model
from .multisine import multisine

PAPER_W0 = 0.04
PAPER_N = 2048
PAPER_EXCITED = np.arange(10, 241, 10)
PAPER_ID_LINES = np.arange(1, 244)

# harmonic k = 1, 2, 3 of each coefficient (harmonic -k is the conjugate); DC values below
PAPER_DC = {"a0": 1.0, "a1": 1.0, "a2": 1.0, "b0": 1.0, "b1": 1.0}
PAPER_HARMONICS = {
    "a0": [0.15 + 0.09j, -0.06 + 0.06j, 0.03 - 0.045j],
    "a1": [0.12 - 0.06j, 0.045 + 0.03j, -0.03 + 0.015j],
    "a2": [-0.09 + 0.06j, 0.03 - 0.06j, 0.024 + 0.018j],
    "b0": [0.18 + 0.06j, -0.09 - 0.03j, 0.03 + 0.03j],
    "b1": [-0.12 + 0.09j, 0.06 + 0.045j, -0.03 - 0.03j],
}


def _coefficient_row(dc, harmonics):
    K = len(harmonics)
    row = np.zeros(2 * K + 1, complex)
    row[K] = dc
    for k, c in enumerate(harmonics, start=1):
        row[K + k] = c
        row[K - k] = np.conj(c)
    return row


def paper_model() -> Model:
    """The paper-like LPTV model: na=2, nb=1, 3 harmonics on every coefficient (35 parameters)."""
    a = np.array([_coefficient_row(PAPER_DC[n], PAPER_HARMONICS[n]) for n in ("a0", "a1", "a2")])
    b = np.array([_coefficient_row(PAPER_DC[n], PAPER_HARMONICS[n]) for n in ("b0", "b1")])
    return Model(a, b, w0=PAPER_W0)


def paper_multisine(seed: int = 0, n_samples: int = PAPER_N):
    """The paper-like excitation: lines 10, 20, ..., 240, amplitude sqrt(2/24) each (rms 1)."""
    return multisine(PAPER_EXCITED, n_samples, amplitudes=np.sqrt(2.0 / PAPER_EXCITED.size),
                     seed=seed)
