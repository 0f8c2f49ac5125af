"""Figures of the method (the paper's Figs. 2-6).

Every function takes an optional matplotlib ``ax`` and returns it. Without ``ax`` a new
:class:`matplotlib.figure.Figure` is made (not through pyplot, so no global state is touched
and nothing is shown); ``ax.figure`` gives it. Nothing here calls ``plt.show()`` or changes
matplotlib's settings.
"""
from __future__ import annotations

from ._base import MARGINS, _axes, _db, _figure, _freq_axis, _log_x, _options, _series, _z_of  # noqa: F401
from .fit import (bode, coefficient_bands, coefficients, htf_branches, inspection,  # noqa: F401
                  _branch_color, _branches_panel, _predicted_ratio, _ratio_std)
from .spectra import (compare, disturbances, distortion, frozen_poles_zeros, lack_of_fit, model_fit,  # noqa: F401
                      moderated_noise, normalized_residue, output_spectrum, prediction_error)
from .residues import residue_test_label, residue_test_thresholds, residue_tests, _f2_dof  # noqa: F401

__all__ = ["bode", "coefficient_bands", "coefficients", "compare", "distortion", "disturbances", "frozen_poles_zeros",
           "htf_branches", "inspection", "lack_of_fit", "model_fit", "moderated_noise", "normalized_residue",
           "output_spectrum", "prediction_error", "residue_test_label", "residue_test_thresholds", "residue_tests"]
