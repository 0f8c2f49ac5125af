"""
lptv compiled core: model, multisines, frequency-domain simulator, estimators, Floquet stability
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import scipy.sparse
import typing
__all__: list[str] = ['ChannelPower', 'CrestResult', 'DataDiagnosis', 'DistortionLines', 'EstimateResult', 'ExactLikelihood', 'FDS_MAX_CONDITION', 'FDS_WARN_CONDITION', 'Floquet', 'FloquetSensitivity', 'FrequencyData', 'HtfEstimate', 'Identification', 'MODERATION_MAX_PRIOR_DOF', 'MODERATION_OUTLIER_RATE', 'MimoEstimate', 'MimoFit', 'MimoModel', 'MimoStructure', 'Model', 'ModeratedCovariances', 'ModeratedNoise', 'NumericalError', 'Parametrisation', 'ProductRadius', 'RecordFit', 'Structure', 'band_matrix', 'column_covariance', 'covariance_correction', 'cramer_rao_bound', 'cramer_rao_bound_experiments', 'crest_factor', 'default_solver', 'diagnose_data', 'digamma', 'distortion_lines', 'estimate', 'eta_covariance', 'excited_lines', 'expected_fraction_above_0db', 'f_upper_quantile', 'fit_record', 'floquet', 'floquet_mimo', 'floquet_sensitivity', 'full_real_column_covariance', 'full_residue_variance', 'gsvd_pairs', 'has_row_noise', 'htf', 'htf_estimate', 'identify', 'identify_experiments', 'incomplete_beta', 'jacobian', 'lp_norm_log', 'mimo_band_matrix', 'mimo_fisher', 'mimo_fit', 'mimo_free_indices', 'mimo_htf', 'mimo_residues', 'mimo_row_degrees', 'mimo_sandwich', 'mimo_sml', 'mimo_state_matrix', 'mimo_wgtls', 'minimize_crest_factor', 'moderated_covariances', 'moderated_noise', 'monodromy', 'monodromy_mimo', 'multisine_spectrum', 'product_spectral_radius', 'real_column_covariance', 'record_prediction', 'record_regression', 'residue', 'residue_variance', 'residue_variance_gradient', 'row_noise_scale', 'row_noise_variance', 'schroeder_phases', 'simulate', 'simulate_mimo', 'spectrum', 'tetragamma', 'time_signal', 'trigamma', 'trigamma_inverse', 'weighted_r_factor']
class NumericalError(ArithmeticError):
    pass
class Model:
    """
    Validated LPTV model (see lptv.Model for the documented API).
    """
    def __init__(self, a: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], w0: typing.SupportsFloat | typing.SupportsIndex, ts: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def a_at(self, t: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        a_n(t) on a time grid: array (len(t), na+1)
        """
    def b_at(self, t: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        b_m(t) on a time grid: array (len(t), nb+1)
        """
    def samples_per_period(self) -> int:
        ...
    @property
    def a(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def b(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def ka(self) -> int:
        ...
    @property
    def kb(self) -> int:
        ...
    @property
    def na(self) -> int:
        ...
    @property
    def nb(self) -> int:
        ...
    @property
    def ts(self) -> float:
        ...
    @property
    def w0(self) -> float:
        ...
class CrestResult:
    @property
    def best_per_p(self) -> list[float]:
        ...
    @property
    def crest_factor(self) -> float:
        ...
    @property
    def evaluations(self) -> int:
        ...
    @property
    def initial_crest_factor(self) -> float:
        ...
    @property
    def oversample(self) -> int:
        ...
    @property
    def phases(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class FrequencyData:
    """
    Mean spectra on lines 0..Lmax and the (co)variances of the means.
    """
    @staticmethod
    def from_period_spectra(Up: typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]", "flags.c_contiguous"], Yp: typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]", "flags.c_contiguous"]) -> FrequencyData:
        """
        The statistics of from_periods from the periods' spectra: Up, Yp of shape (P, lines), row p the spectrum of period p (fft / N) on lines 0..Lmax.
        """
    @staticmethod
    def from_periods(u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> FrequencyData:
        ...
    @staticmethod
    def from_record_spectra(Up: typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]", "flags.c_contiguous"], Yp: typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]", "flags.c_contiguous"], Ur: typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"], Yr: typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"], n_per_period: typing.SupportsInt | typing.SupportsIndex) -> FrequencyData:
        """
        The statistics from the record's bins between the lines (METHOD.md section 20): Up, Yp the periods' spectra (P, lines), Ur, Yr the rfft of the P periods concatenated / (P N).
        """
    @staticmethod
    def with_realisations(data: FrequencyData, noiseU: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], noiseY: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], like: FrequencyData) -> FrequencyData:
        """
        A copy of data with the noise realisations noiseU, noiseY on the lines and offsets of like's.
        """
    def __init__(self, U: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], Y: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], varU: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], varY: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], covYU: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], periods: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    @property
    def U(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def Y(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def covYU(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def max_line(self) -> int:
        ...
    @property
    def noiseU(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def noiseY(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def noise_first(self) -> int:
        ...
    @property
    def noise_last(self) -> int:
        ...
    @property
    def noise_offset(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def periods(self) -> int:
        ...
    @property
    def varU(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def varY(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class Structure:
    """
    Orders, harmonic counts per coefficient, known coefficients, w0 and ts.
    """
    @staticmethod
    def of(model: Model) -> Structure:
        """
        The model's own orders and harmonic counts.
        """
    def __init__(self, na: typing.SupportsInt | typing.SupportsIndex, nb: typing.SupportsInt | typing.SupportsIndex, ka: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], kb: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], known: collections.abc.Sequence[tuple[bool, typing.SupportsInt | typing.SupportsIndex, typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]]], w0: typing.SupportsFloat | typing.SupportsIndex, ts: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    @property
    def ka(self) -> list[int]:
        ...
    @property
    def kb(self) -> list[int]:
        ...
    @property
    def kmax(self) -> int:
        ...
    @property
    def na(self) -> int:
        ...
    @property
    def nb(self) -> int:
        ...
    @property
    def ts(self) -> float:
        ...
    @property
    def w0(self) -> float:
        ...
class Parametrisation:
    @typing.overload
    def __init__(self, na: typing.SupportsInt | typing.SupportsIndex, nb: typing.SupportsInt | typing.SupportsIndex, ka: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], kb: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], known: collections.abc.Sequence[tuple[bool, typing.SupportsInt | typing.SupportsIndex, typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]]], w0: typing.SupportsFloat | typing.SupportsIndex, ts: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    @typing.overload
    def __init__(self, structure: Structure) -> None:
        ...
    def check_rows(self, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], max_line: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def default_rows(self, max_line: typing.SupportsInt | typing.SupportsIndex) -> list[int]:
        ...
    def theta_from_model(self, model: Model) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    def theta_from_xi(self, xi: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    def to_model(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> Model:
        ...
    def xi_from_theta(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def T(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def Text(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def d(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def eta_names(self) -> list[str]:
        ...
    @property
    def free_indices(self) -> list[int]:
        ...
    @property
    def has_known(self) -> bool:
        ...
    @property
    def n_eta(self) -> int:
        ...
    @property
    def n_theta(self) -> int:
        ...
    @property
    def n_xi(self) -> int:
        ...
    @property
    def norm_index(self) -> int:
        ...
    @property
    def params(self) -> list[tuple[bool, int, int]]:
        ...
    @property
    def structure(self) -> Structure:
        ...
class ExactLikelihood:
    """
    The exact residue likelihood V = r^T S^-1 r (METHOD.md eq. 17).
    """
    def __init__(self, data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> None:
        ...
    def cost(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> float:
        ...
    def denoised(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> FrequencyData:
        """
        the spectra nearest to the data that the model explains exactly
        """
    def fisher_information(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def gradient(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        dV/dxi over every entry of xi
        """
    def residue_covariance(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def sandwich_covariance(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def second_order_meat(self, par: Parametrisation, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Cov(q - lambda CJ_W xi) over the free entries of xi: the second-order noise of WGTLS's estimating equation (METHOD.md section 10), one experiment.
        """
    def set_row_scale(self, scale: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        S = D S_line D with D = diag(scale), one entry per row in the caller's order (METHOD.md section 20).
        """
    @property
    def half_bandwidth(self) -> int:
        ...
    @property
    def sorted_rows(self) -> list[int]:
        ...
class EstimateResult:
    """
    The estimate alone (lptv::estimate).
    """
    @property
    def converged(self) -> bool:
        ...
    @property
    def cost(self) -> float:
        ...
    @property
    def cost_history(self) -> list[float]:
        ...
    @property
    def eta(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def iterations(self) -> int:
        ...
    @property
    def noise_free(self) -> bool:
        ...
    @property
    def singular_values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def start_iterations(self) -> int:
        """
        SML: the weighted solves of its WGTLS start (stopped at a relative change of 1e-6)
        """
    @property
    def theta(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
class Identification:
    """
    The result of lptv::identify.
    """
    @property
    def converged(self) -> bool:
        ...
    @property
    def cost(self) -> float:
        ...
    @property
    def cost_history(self) -> list[float]:
        ...
    @property
    def covariance(self) -> typing.Any:
        ...
    @property
    def eta(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def eta_names(self) -> list[str]:
        ...
    @property
    def experiment(self) -> list[int]:
        ...
    @property
    def fraction_above_0db(self) -> float:
        ...
    @property
    def fraction_band(self) -> tuple[float, float]:
        ...
    @property
    def fraction_expected(self) -> float:
        ...
    @property
    def iterations(self) -> int:
        ...
    @property
    def method(self) -> str:
        ...
    @property
    def model(self) -> Model:
        ...
    @property
    def n_experiments(self) -> int:
        ...
    @property
    def n_free(self) -> int:
        ...
    @property
    def nearly_unidentifiable(self) -> bool:
        ...
    @property
    def noise_free(self) -> bool:
        ...
    @property
    def normalized_residue(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def residue(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def residue_ok(self) -> bool:
        ...
    @property
    def residue_variance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def rows(self) -> list[int]:
        ...
    @property
    def singular_values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def theta(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def warnings(self) -> list[str]:
        ...
class ChannelPower:
    """
    Signal of one channel on a set of lines (lptv::channel_power).
    """
    @property
    def above(self) -> int:
        ...
    @property
    def clear(self) -> bool:
        ...
    @property
    def limit(self) -> float:
        ...
    @property
    def lines(self) -> int:
        ...
    @property
    def noise(self) -> float:
        ...
    @property
    def power(self) -> float:
        ...
    @property
    def present(self) -> bool:
        ...
class DataDiagnosis:
    """
    What the data can say before estimating (lptv::diagnose_data).
    """
    @property
    def excited(self) -> list[int]:
        ...
    @property
    def informative_rows(self) -> int:
        ...
    @property
    def input(self) -> ChannelPower:
        ...
    @property
    def output(self) -> ChannelPower:
        ...
    @property
    def region(self) -> list[int]:
        ...
    @property
    def warnings(self) -> list[str]:
        ...
class HtfEstimate:
    """
    Nonparametric HTF branches (lptv::htf_estimate).
    """
    @property
    def G(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def branch_statistic(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def branches(self) -> int:
        ...
    @property
    def lines(self) -> list[int]:
        ...
    @property
    def variance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
class DistortionLines:
    """
    Per output line: the regression of the realisations' Y_j on the excited lines within +-Kh (lptv::distortion_lines).
    """
    @property
    def bla(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def bla_var(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def branches(self) -> int:
        ...
    @property
    def dof(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        ...
    @property
    def excited(self) -> list[int]:
        ...
    @property
    def lines(self) -> list[int]:
        ...
    @property
    def noise(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def realisations(self) -> int:
        ...
    @property
    def regressors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        ...
    @property
    def signal(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def total(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class ModeratedNoise:
    """
    Noise (co)variances moderated across neighbouring lines (lptv::moderated_noise).
    """
    def error_covariance(self, lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Covariance of the relative sampling errors of the moderated variances on lines.
        """
    @property
    def data(self) -> FrequencyData:
        ...
    @property
    def dof(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def half_width(self) -> int:
        ...
    @property
    def moderated(self) -> bool:
        ...
    @property
    def neighbour(self) -> typing.Annotated[numpy.typing.NDArray[numpy.bool], "[m, 1]"]:
        ...
    @property
    def outliers(self) -> list[int]:
        ...
    @property
    def own_weight(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def prior_dof(self) -> float:
        ...
    @property
    def source_varU(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def source_varY(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def trend_residual_u(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def trend_residual_y(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class ModeratedCovariances:
    """
    Covariance matrices of several channels moderated across neighbouring lines (lptv::moderated_covariances).
    """
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def dof(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def half_width(self) -> int:
        ...
    @property
    def moderated(self) -> bool:
        ...
    @property
    def neighbour(self) -> typing.Annotated[numpy.typing.NDArray[numpy.bool], "[m, 1]"]:
        ...
    @property
    def outliers(self) -> list[int]:
        ...
    @property
    def own_weight(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def prior_dof(self) -> float:
        ...
class RecordFit:
    """
    One record with its transient (lptv::fit_record).
    """
    @property
    def Y_fit(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def converged(self) -> bool:
        ...
    @property
    def cost(self) -> float:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        of eta: the inverse Fisher information of the output error at the estimate
        """
    @property
    def dof(self) -> int:
        ...
    @property
    def eta(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        xi with xi[norm_index] = 1
        """
    @property
    def evaluations(self) -> int:
        """
        factorisations of A, all fits
        """
    @property
    def fits(self) -> int:
        ...
    @property
    def iterations(self) -> int:
        """
        Levenberg-Marquardt iterations of the last fit
        """
    @property
    def noise_dof(self) -> int:
        ...
    @property
    def noise_var(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def start(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        [free eta, c] from the weighted equation error
        """
    @property
    def theta(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def transient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        c_1..c_n of T(z) = sum c_j z^j; continuous time c_0..c_d of sum c_j (j w ts)^j
        """
    @property
    def transient_std(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class MimoModel:
    """
    Validated matrix LPTV model (see lptv.MimoModel for the documented API).
    """
    def __init__(self, a: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], n_outputs: typing.SupportsInt | typing.SupportsIndex, n_inputs: typing.SupportsInt | typing.SupportsIndex, w0: typing.SupportsFloat | typing.SupportsIndex, ts: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def a_at(self, t: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        entries of A_n(t): array (len(t), (na+1) ny ny)
        """
    def b_at(self, t: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        entries of B_m(t): array (len(t), (nb+1) ny nu)
        """
    def samples_per_period(self) -> int:
        ...
    @property
    def a(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def b(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def ka(self) -> int:
        ...
    @property
    def kb(self) -> int:
        ...
    @property
    def n_inputs(self) -> int:
        ...
    @property
    def n_outputs(self) -> int:
        ...
    @property
    def na(self) -> int:
        ...
    @property
    def nb(self) -> int:
        ...
    @property
    def ts(self) -> float:
        ...
    @property
    def w0(self) -> float:
        ...
class MimoStructure:
    """
    Row-uniform structure of a MIMO fit: ka (na+1) x ny, kb (nb+1) x nu.
    """
    def __init__(self, ny: typing.SupportsInt | typing.SupportsIndex, nu: typing.SupportsInt | typing.SupportsIndex, ka: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[m, n]"], kb: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[m, n]"], w0: typing.SupportsFloat | typing.SupportsIndex, ts: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    @property
    def nu(self) -> int:
        ...
    @property
    def ny(self) -> int:
        ...
class MimoEstimate:
    """
    A MIMO WGTLS or SML estimate (see lptv.mimo_fit).
    """
    @property
    def converged(self) -> bool:
        ...
    @property
    def cost(self) -> float:
        ...
    @property
    def information(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def iterations(self) -> int:
        ...
    @property
    def noise_free(self) -> bool:
        ...
    @property
    def singular_values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def xi(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class MimoFit:
    """
    One MIMO fit: estimate, covariance (free entries), residues.
    """
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def estimate(self) -> MimoEstimate:
        ...
    @property
    def residue_covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
    @property
    def residues(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
        ...
class Floquet:
    """
    Characteristic multipliers and Floquet exponents (lptv::floquet).
    """
    @property
    def convergence(self) -> float:
        ...
    @property
    def error_estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def exponents(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def harmonics(self) -> int:
        ...
    @property
    def is_stable(self) -> bool:
        ...
    @property
    def method(self) -> str:
        ...
    @property
    def multipliers(self) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
        ...
    @property
    def spectral_radius(self) -> float:
        ...
    @property
    def truncation(self) -> int:
        ...
class FloquetSensitivity:
    """
    Floquet exponents with their first-order sensitivity to a(t) (lptv::floquet_sensitivity).
    """
    @property
    def condition(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def floquet(self) -> Floquet:
        ...
    @property
    def gradient(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]]:
        ...
class ProductRadius:
    """
    The spectral radius of the monodromy matrix by products (lptv::product_spectral_radius).
    """
    @property
    def reason(self) -> str:
        ...
    @property
    def rho(self) -> float:
        ...
    @property
    def settled(self) -> bool:
        ...
    @property
    def steps(self) -> int:
        ...
def band_matrix(model: Model, L: typing.SupportsInt | typing.SupportsIndex, a: bool = True) -> scipy.sparse.csc_matrix:
    ...
def column_covariance(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
    ...
def covariance_correction(periods: typing.SupportsInt | typing.SupportsIndex) -> float:
    ...
def cramer_rao_bound(noiseless: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    ...
def cramer_rao_bound_experiments(noiseless: collections.abc.Sequence[FrequencyData], par: Parametrisation, rows: collections.abc.Sequence[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    The Cramer-Rao bound of several independent experiments: their informations add.
    """
def crest_factor(x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> float:
    ...
def default_solver(discrete: bool = False) -> str:
    ...
def diagnose_data(data: FrequencyData, structure: Structure, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], check_row_count: bool = True) -> DataDiagnosis:
    """
    The data diagnostics lptv::identify runs first: raises ValueError naming the argument and the cause for degenerate data (METHOD.md section 15).
    """
def digamma(x: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    The digamma function psi(x), x > 0.
    """
def distortion_lines(U: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], Y: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], varU: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], varY: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], covYU: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], excited: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], branches: typing.SupportsInt | typing.SupportsIndex) -> DistortionLines:
    """
    Noise, residual variance and BLA per output line from M random-phase realisations.
    
    Parameters
    ----------
    U, Y : ndarray, shape (M, L + 1), complex
        Period-mean spectra of each realisation on lines 0..L.
    varU, varY : ndarray, shape (M, L + 1), float
        Noise variances of those means.
    covYU : ndarray, shape (M, L + 1), complex
        E{dY conj(dU)} of the means.
    excited : list of int
        Excited lines, ascending, within 1..L.
    branches : int
        Kh: line j regresses on the excited lines c (and conjugates -c) with |j - c| <= Kh.
    
    Returns
    -------
    DistortionLines
    """
def estimate(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], method: str = 'wgtls', tol: typing.SupportsFloat | typing.SupportsIndex = 1e-10, max_iter: typing.SupportsInt | typing.SupportsIndex = 50) -> EstimateResult:
    ...
def eta_covariance(par: Parametrisation, cov_free: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    ...
def excited_lines(data: FrequencyData, ratio: typing.SupportsFloat | typing.SupportsIndex = 100.0) -> list[int]:
    ...
def expected_fraction_above_0db(n_rows: typing.SupportsInt | typing.SupportsIndex, n_free: typing.SupportsInt | typing.SupportsIndex, periods: typing.SupportsInt | typing.SupportsIndex) -> tuple[float, tuple[float, float]]:
    ...
def f_upper_quantile(p: typing.SupportsFloat | typing.SupportsIndex, d1: typing.SupportsFloat | typing.SupportsIndex, d2: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    f with P(F(d1, d2) > f) = p.
    """
def fit_record(par: Parametrisation, U: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], Y: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], periods: typing.SupportsInt | typing.SupportsIndex, lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], transient: bool = True, noise_var: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] | None = None, noise_width: typing.SupportsInt | typing.SupportsIndex = 10, reweightings: typing.SupportsInt | typing.SupportsIndex = 2, max_iterations: typing.SupportsInt | typing.SupportsIndex = 100, tol: typing.SupportsFloat | typing.SupportsIndex = 1e-12, ts: typing.SupportsFloat | typing.SupportsIndex = 0.0, transient_degree: typing.SupportsInt | typing.SupportsIndex = -1) -> RecordFit:
    """
    An LPTV model and the transient term fitted to one record (METHOD.md section 17).
    
    Parameters
    ----------
    par : Parametrisation
        The structure: discrete time (its ts the record's sample time), or continuous time (ts = 0)
        with the record's sample time in ``ts``.
    U, Y : ndarray, shape (N,), complex
        The record's DFT on all N = periods N0 lines: X_l = fft(x)[l] / N.
    periods : int
        L, whole parameter periods in the record.
    lines : list of int
        The lines fitted, ascending, within 1..(N-1)/2.
    transient : bool
        Fit T(z) = sum_{j=1}^{n} c_j z^j, n = max(na, nb); continuous time
        T = sum_{j=0}^{d} c_j (j w_l ts)^j.
    noise_var : ndarray, optional
        E|V_l|^2 per fitted line; None: from the fit's residual, each line's over its share
        1 - h_l (h_l its leverage), averaged over 2 noise_width + 1 lines, then the fit repeated
        ``reweightings`` times.
    noise_width, reweightings : int
    max_iterations : int
        Levenberg-Marquardt iterations per fit.
    tol : float
        Relative tolerance of the cost's decrease, the step and the gradient's cosine.
    ts : float
        Continuous time: the record's sample time (> 0); discrete time: 0 or the structure's ts.
    transient_degree : int
        Continuous time: d (>= n - 1), -1 for n + 1; discrete time: -1 only.
    
    Returns
    -------
    RecordFit
    """
def floquet(model: Model, tol: typing.SupportsFloat | typing.SupportsIndex = 1e-11, min_truncation: typing.SupportsInt | typing.SupportsIndex = 8, max_truncation: typing.SupportsInt | typing.SupportsIndex = 256) -> Floquet:
    """
    Multipliers and exponents of the homogeneous equation (see lptv.floquet for the documented API).
    """
def floquet_mimo(model: MimoModel, tol: typing.SupportsFloat | typing.SupportsIndex = 1e-11, min_truncation: typing.SupportsInt | typing.SupportsIndex = 8, max_truncation: typing.SupportsInt | typing.SupportsIndex = 256) -> Floquet:
    """
    Multipliers and exponents of the matrix system (see lptv.floquet for the documented API).
    """
def floquet_sensitivity(model: Model, tol: typing.SupportsFloat | typing.SupportsIndex = 1e-11, min_truncation: typing.SupportsInt | typing.SupportsIndex = 8, max_truncation: typing.SupportsInt | typing.SupportsIndex = 256) -> FloquetSensitivity:
    """
    Floquet exponents with d lambda_i / d a_{n,h} (gradient[i], (na+1) x (2Ka+1)) and each eigenvalue's
    condition number (see lptv.floquet of an identification result).
    """
def full_real_column_covariance(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    ...
def full_residue_variance(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    var e_l from the data's noise realisations, each row at its bins' own frequencies (METHOD.md section 20); eq. 15 on rows that read a line without realisations.
    """
def gsvd_pairs(A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], B: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], int]:
    ...
def has_row_noise(data: FrequencyData) -> bool:
    ...
def htf(model: Model, L: typing.SupportsInt | typing.SupportsIndex, lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], solver: str = 'auto') -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
    ...
def htf_estimate(data: FrequencyData, excited: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], branches: typing.SupportsInt | typing.SupportsIndex) -> HtfEstimate:
    ...
def identify(data: FrequencyData, structure: Structure, method: str = 'wgtls', tol: typing.SupportsFloat | typing.SupportsIndex = 1e-10, max_iter: typing.SupportsInt | typing.SupportsIndex = 50, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] = [], covariance: bool = True, full_rows: bool = False) -> Identification:
    ...
def identify_experiments(experiments: collections.abc.Sequence[FrequencyData], structure: Structure, method: str = 'wgtls', tol: typing.SupportsFloat | typing.SupportsIndex = 1e-10, max_iter: typing.SupportsInt | typing.SupportsIndex = 50, rows: collections.abc.Sequence[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]] = [], covariance: bool = True, full_rows: bool = False) -> Identification:
    """
    Several experiments of one system fitted into one model (lptv::identify on a list).
    
    rows: one list of rows per experiment (an empty list: that experiment's default rows), or
    empty for every experiment's default.
    """
def incomplete_beta(a: typing.SupportsFloat | typing.SupportsIndex, b: typing.SupportsFloat | typing.SupportsIndex, x: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    The regularized incomplete beta function I_x(a, b).
    """
def jacobian(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
    ...
def lp_norm_log(lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], amplitudes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], phases: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], n_samples: typing.SupportsInt | typing.SupportsIndex, oversample: typing.SupportsInt | typing.SupportsIndex, p: typing.SupportsInt | typing.SupportsIndex) -> tuple[float, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
    ...
def mimo_band_matrix(model: MimoModel, L: typing.SupportsInt | typing.SupportsIndex, a: bool = True) -> scipy.sparse.csc_matrix:
    ...
def mimo_fisher(data: collections.abc.Sequence[tuple[typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]]], structure: MimoStructure, xi: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    Fisher information over the free entries
    """
def mimo_fit(data: collections.abc.Sequence[tuple[typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]]], structure: MimoStructure, method: str, tol: typing.SupportsFloat | typing.SupportsIndex, max_iter: typing.SupportsInt | typing.SupportsIndex, covariance: bool = True) -> MimoFit:
    """
    WGTLS ('gtls', 'wgtls') or SML ('sml') from WGTLS with the covariance and the residues, the rows' terms formed once
    """
def mimo_free_indices(structure: MimoStructure) -> list[int]:
    ...
def mimo_htf(model: MimoModel, L: typing.SupportsInt | typing.SupportsIndex, lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], solver: str = 'auto') -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
    ...
def mimo_residues(data: tuple[typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]], structure: MimoStructure, xi: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> tuple:
    """
    (residues rows x ny, their covariances (rows ny) x ny) of one experiment
    """
def mimo_row_degrees(model: MimoModel) -> list[int]:
    """
    The row degrees d_p of A(t, s).
    """
def mimo_sandwich(data: collections.abc.Sequence[tuple[typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]]], structure: MimoStructure, xi: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    WGTLS's first-order sandwich covariance
    """
def mimo_sml(data: collections.abc.Sequence[tuple[typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]]], structure: MimoStructure, xi0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], tol: typing.SupportsFloat | typing.SupportsIndex, max_iter: typing.SupportsInt | typing.SupportsIndex) -> MimoEstimate:
    """
    Levenberg-Marquardt on the rows' exact likelihood from xi0
    """
def mimo_state_matrix(model: MimoModel, t: typing.SupportsFloat | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    The state (one-step) matrix of the matrix system's observer form at time t.
    """
def mimo_wgtls(data: collections.abc.Sequence[tuple[typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]]], structure: MimoStructure, tol: typing.SupportsFloat | typing.SupportsIndex, max_iter: typing.SupportsInt | typing.SupportsIndex, weighted: bool = True) -> MimoEstimate:
    """
    WGTLS with vector residues and A_na,0 = I; data: list of (Y, U, C, rows), C of shape ((L+1)(ny+nu), ny+nu)
    """
def minimize_crest_factor(lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], amplitudes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], phases: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], n_samples: typing.SupportsInt | typing.SupportsIndex, oversample: typing.SupportsInt | typing.SupportsIndex = 0, max_p: typing.SupportsInt | typing.SupportsIndex = 1024, iterations_per_p: typing.SupportsInt | typing.SupportsIndex = 100) -> CrestResult:
    ...
def moderated_covariances(C: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], n_outputs: typing.SupportsInt | typing.SupportsIndex, periods: typing.SupportsInt | typing.SupportsIndex, half_width: typing.SupportsInt | typing.SupportsIndex) -> ModeratedCovariances:
    """
    The covariance matrices of the means of c channels (outputs first) moderated across lines.
    
    Parameters
    ----------
    C : complex array, shape ((L+1) c, c)
        Rows l c .. l c + c - 1: the covariance matrix of the mean [Y_l; U_l] on line l.
    n_outputs : int
        ny, 1..c-1.
    periods : int
        P (returned unchanged below 2).
    half_width : int
        The neighbours of a line: the lines within +-half_width (>= 1).
    
    Returns
    -------
    ModeratedCovariances
    """
def moderated_noise(data: FrequencyData, half_width: typing.SupportsInt | typing.SupportsIndex) -> ModeratedNoise:
    """
    The noise (co)variances of data moderated across the lines within +-half_width.
    
    Parameters
    ----------
    data : FrequencyData
        Spectra and noise statistics from P >= 2 periods (otherwise returned unchanged).
    half_width : int
        The neighbours of a line: the lines within +-half_width (>= 1).
    
    Returns
    -------
    ModeratedNoise
    """
def monodromy(model: Model, steps: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    Monodromy matrix by the product of matrix exponentials (continuous time, `steps` Magnus steps
    and Richardson) or of the one-step companion matrices (discrete time).
    """
def monodromy_mimo(model: MimoModel, steps: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    Monodromy matrix of the matrix system's state form by products (Magnus steps and Richardson, or the
    one-step matrices in discrete time).
    """
def multisine_spectrum(lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], amplitudes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], phases: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], n_samples: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
    ...
def product_spectral_radius(model: Model, first_steps: typing.SupportsInt | typing.SupportsIndex, max_steps: typing.SupportsInt | typing.SupportsIndex) -> ProductRadius:
    """
    Monodromy products with first_steps, 2 first_steps, ... steps until two successive spectral radii
    differ by less than a tenth of their distance to 1 (lptv.floquet.stability_check's first route).
    """
def real_column_covariance(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    ...
def record_prediction(par: Parametrisation, U: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], periods: typing.SupportsInt | typing.SupportsIndex, eta_free: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], c: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], ts: typing.SupportsFloat | typing.SupportsIndex = 0.0, transient_degree: typing.SupportsInt | typing.SupportsIndex = -1) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
    """
    Y_hat = A^-1 (B U - T(c)) on all N lines of the record's grid (continuous time: the lines -M..M, M = (N - 1) // 2, at index l + M; eta_free: the free parameters).
    """
def record_regression(par: Parametrisation, U: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], Y: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], periods: typing.SupportsInt | typing.SupportsIndex, lines: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], transient: bool = True, ts: typing.SupportsFloat | typing.SupportsIndex = 0.0, transient_degree: typing.SupportsInt | typing.SupportsIndex = -1) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]]:
    """
    The equation error on the lines, E = M x + e0 for x = [free eta, c]: (M, e0).
    """
def residue(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
    ...
def residue_variance(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def residue_variance_gradient(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, n]"]:
    ...
def row_noise_scale(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def row_noise_variance(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    The rows' variances the record's routes weigh by: eq. 15 times row_noise_scale^2 (METHOD.md section 20).
    """
def schroeder_phases(amplitudes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def simulate(model: Model, U: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], solver: str = 'auto', lines_out: typing.SupportsInt | typing.SupportsIndex = -1, guard: typing.SupportsInt | typing.SupportsIndex = -1, tol: typing.SupportsFloat | typing.SupportsIndex = 1e-13, max_guard: typing.SupportsInt | typing.SupportsIndex = -1) -> dict:
    ...
def simulate_mimo(model: MimoModel, U: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], solver: str = 'auto', lines_out: typing.SupportsInt | typing.SupportsIndex = -1, guard: typing.SupportsInt | typing.SupportsIndex = -1, tol: typing.SupportsFloat | typing.SupportsIndex = 1e-13, max_guard: typing.SupportsInt | typing.SupportsIndex = -1) -> dict:
    ...
def spectrum(x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]:
    ...
def tetragamma(x: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    The tetragamma function psi''(x), x > 0.
    """
def time_signal(X: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"], n_samples: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def trigamma(x: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    The trigamma function psi'(x), x > 0.
    """
def trigamma_inverse(x: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    y > 0 with trigamma(y) = x.
    """
def weighted_r_factor(data: FrequencyData, par: Parametrisation, rows: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    ...
FDS_MAX_CONDITION: float = 10000000000000.0
FDS_WARN_CONDITION: float = 100000000.0
MODERATION_MAX_PRIOR_DOF: float = 1000000.0
MODERATION_OUTLIER_RATE: float = 0.001
