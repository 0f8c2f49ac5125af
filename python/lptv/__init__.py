"""lptv: identification of linear periodically time-varying systems in the frequency domain.

The public API:

- :class:`Model` - the LPTV model (and LTI as its special case), JSON save/load;
- :class:`MimoModel`, :func:`mimo_multisines`, :func:`mimo_htf_estimate` - several inputs and
  outputs: the matrix model (simulated by :func:`simulate`), the experiments' multisines and the
  nonparametric HTF matrix from them; :class:`MimoFrequencyData`, :func:`mimo_crb` and
  :func:`identify` on (P, N, nu) / (P, N, ny) arrays for their estimation;
- :func:`multisine`, :func:`spectrum`, :func:`time_signal` - excitation and spectra;
- :func:`min_crest_multisine`, :func:`schroeder_multisine`, :func:`excitation_lines`,
  :func:`multisine_realisations` - excitation design (crest factor, detection lines, realisations);
- :func:`simulate`, :func:`htf`, :func:`band_matrices` - the frequency-domain simulator;
- :class:`FrequencyData`, :func:`identify` - noise model and estimators (LS, TLS, GTLS, WGTLS,
  SML on the exact likelihood) with the covariance of the estimate;
- :func:`crb` - the Cramer-Rao bound of a design, to plan an experiment;
- :func:`identify_record` - one non-periodic record with its transient;
- :func:`inspect` - a record before any model: its period, transient, excited lines and what the
  output holds between them;
- :func:`htf_estimate` - the harmonic transfer function's branches from data, without a model;
- :func:`select` - the orders and harmonic count from the data (a ranked grid of structures);
- :func:`floquet` - characteristic multipliers and Floquet exponents: is the periodic system stable;
- :func:`normalized_residue`, :func:`frozen_poles`, :func:`frozen_zeros` - validation;
- :func:`predict`, :func:`validate` - a saved model used: its output for an input (from rest or
  in steady state), and the model fixed against a fresh record (:mod:`lptv.use`);
- :func:`montecarlo`, :func:`identify_many` - Monte Carlo studies and many records at once, on
  local processes or a Dask cluster (:mod:`lptv.batch`);
- :mod:`lptv.reference` - the same mathematics in plain NumPy;
- :mod:`lptv.simulation.timedomain` - time integration with SUNDIALS CVODE.
"""
from ._core import NumericalError
from .simulation.fds import ConditioningWarning, SimulationResult, TruncationWarning, band_matrices, htf, simulate
from .spectra.frequency_data import FrequencyData, LineCorrelation, correlated_lines
from .estimation.identify import METHODS, IdentifiabilityWarning, IdentificationResult, identify
from .estimation.crb import CramerRaoBound, crb
from .spectra.htf_estimate import HtfEstimate, htf_estimate
from .spectra.distortion import DistortionResult, LackOfFit, distortion
from .estimation.one_record import RecordResult, identify_record
from .model.floquet import FloquetResult, StabilityUndecidedWarning, UnstableModelWarning, floquet
from .batch.selection import SelectionResult, select
from .records.measurements import Measurements, RecordCheck, RecordWarning, check_record, read_measurements
from .records.inspection import Inspection, LineClass, inspect
from .model.siso import Model
from .model.mimo import MimoModel
from .excitation.mimo_multisine import MimoMultisines, mimo_multisines
from .spectra.mimo_htf_estimate import MimoHtfEstimate, mimo_htf_estimate
from .spectra.mimo_frequency_data import MimoFrequencyData
from .judgement.mimo_result import MimoIdentificationResult
from .estimation.mimo_identify import MimoCramerRaoBound, mimo_crb
from .judgement.parameters import compare, freqresp_band, lti_table, parameter_table
from .judgement.validation import expected_fraction_above_0db, frozen_poles, frozen_zeros, normalized_residue
from .excitation.multisine import (CrestDesign, ExcitationLines, Multisine, excitation_lines, min_crest_multisine,
                        multisine, multisine_realisations, schroeder_multisine, spectrum, time_signal)
from .spectra.moderation import ModeratedNoise, moderated_noise
from .spectra.disturbances import Disturbance, DisturbanceResult, disturbances
from .batch import BatchResult, MonteCarloResult, identify_many, montecarlo
from .use import CoefficientTest, ValidationResult, predict, validate

__version__ = "0.1.0"

__all__ = [
    "BatchResult", "ConditioningWarning", "CramerRaoBound", "DistortionResult", "distortion", "LackOfFit", "FloquetResult", "FrequencyData", "LineCorrelation", "correlated_lines", "HtfEstimate", "IdentifiabilityWarning", "METHODS",
    "IdentificationResult", "Model", "MonteCarloResult", "Multisine", "NumericalError", "SimulationResult", "StabilityUndecidedWarning", "TruncationWarning", "UnstableModelWarning",
    "band_matrices", "crb", "expected_fraction_above_0db", "floquet", "frozen_poles", "frozen_zeros", "htf", "htf_estimate",
    "identify", "identify_many", "montecarlo", "normalized_residue", "read_measurements", "Measurements", "multisine",
    "select", "SelectionResult", "simulate", "spectrum", "time_signal", "check_record", "RecordCheck", "RecordWarning",
    "lti_table", "parameter_table", "compare", "freqresp_band",
    "CrestDesign", "ExcitationLines", "excitation_lines", "min_crest_multisine", "multisine_realisations",
    "schroeder_multisine", "RecordResult", "identify_record", "ModeratedNoise", "moderated_noise",
    "Disturbance", "DisturbanceResult", "disturbances", "Inspection", "LineClass", "inspect",
    "MimoModel", "MimoMultisines", "mimo_multisines", "MimoHtfEstimate", "mimo_htf_estimate",
    "MimoFrequencyData", "MimoIdentificationResult", "MimoCramerRaoBound", "mimo_crb",
    "predict", "validate", "ValidationResult", "CoefficientTest",
]
