// Estimators for several inputs and outputs (METHOD.md section 19, eqs. 19.10-19.15): vector
// residues, WGTLS with the normalisation A_na,0 = I, SML on the exact likelihood of the rows
// (correlated through shared lines), the Fisher information and WGTLS's first-order sandwich.
#pragma once
#include <Eigen/Dense>
#include <complex>
#include <string>
#include <vector>

namespace lptv {

// One experiment: the periods' mean spectra on lines 0..L and the covariance of the means.
struct MimoSpectra {
  Eigen::MatrixXcd Y;  // (L+1) x ny
  Eigen::MatrixXcd U;  // (L+1) x nu
  // (L+1) (ny+nu) x (ny+nu): rows l (ny+nu) .. the covariance E{dz dz^H} of z_l = [Y_l; U_l]
  Eigen::MatrixXcd C;
  // sorted lines 1..L-K; a row l <= K reads line 0 and conjugate lines (WGTLS, GTLS, the
  // sandwich and the residues take them; SML and the Fisher information refuse them)
  std::vector<int> rows;
};

// Row-uniform structure: harmonic count per order and column, ka (na+1) x ny, kb (nb+1) x nu.
// The real parameters xi stack the outputs' rows, each the coefficients (a, n, q) for
// n = 0..na, q = 0..ny-1, then (b, m, r), each as Re c_0, Re c_1, Im c_1, .., Re c_K, Im c_K.
// kb(m, r) = -1 leaves the entry (b, m, r) out (no parameters): the orders of B may differ from
// column to column (the transient's noise-free columns of METHOD.md section 20 use it).
struct MimoStructure {
  int ny = 1, nu = 1;
  Eigen::MatrixXi ka, kb;
  double w0 = 1.0, ts = 0.0;
};

struct MimoEstimate {
  Eigen::VectorXd xi;               // with the normalised entries Re a_{na,pq,0} = delta_pq
  Eigen::VectorXd singular_values;  // WGTLS's generalised singular values, ascending
  Eigen::MatrixXd information;       // SML: the Fisher information over the free entries
  double cost = 0.0;                // SML: sum e^H C_E^-1 e
  int iterations = 0;
  bool converged = true;
  bool noise_free = false;
};

// The free entries of xi (all but the ny^2 normalised ones), ascending.
std::vector<int> mimo_free_indices(const MimoStructure& s);

// WGTLS (weighted = true) or GTLS (false); noise-free data (every C zero) give TLS. Throws
// std::invalid_argument on inconsistent shapes or rows, NumericalError when a decomposition
// fails (a singular CJ_W, a normalisation that cannot be applied).
MimoEstimate mimo_wgtls(const std::vector<MimoSpectra>& data, const MimoStructure& s, double tol,
                        int max_iter, bool weighted = true);

// Levenberg-Marquardt on sum_e e^H C_E^-1 e over the free entries from xi0.
MimoEstimate mimo_sml(const std::vector<MimoSpectra>& data, const MimoStructure& s,
                      const Eigen::VectorXd& xi0, double tol, int max_iter);

// 2 Re(J0^H C_E^-1 J0) over the free entries (J0 at the denoised spectra).
Eigen::MatrixXd mimo_fisher(const std::vector<MimoSpectra>& data, const MimoStructure& s,
                            const Eigen::VectorXd& xi);

// H^-1 (1/2 Re J0^H W C_E W J0) H^-1, H = Re J0^H W J0, W = blockdiag(C_{e,l}^-1).
Eigen::MatrixXd mimo_sandwich(const std::vector<MimoSpectra>& data, const MimoStructure& s,
                              const Eigen::VectorXd& xi);

// The residues e_l (rows x ny) and their covariances C_{e,l} (rows ny x ny, block r) of eq.
// 19.12 of one experiment at xi.
void mimo_residues(const MimoSpectra& d, const MimoStructure& s, const Eigen::VectorXd& xi,
                   Eigen::MatrixXcd& e, Eigen::MatrixXcd& Ce);

// One fit with the rows' terms formed once: WGTLS ("gtls": unweighted; "wgtls"), then SML
// ("sml") from it; the covariance over the free entries (SML: the inverse Fisher information;
// WGTLS: the first-order sandwich; empty without covariance or for noise-free data), without the
// small-sample factor (P-1)/(P-3) that lptv.identify applies; the residues of all experiments'
// rows (rows x ny) and their covariances ((rows ny) x ny).
struct MimoFit {
  MimoEstimate estimate;
  Eigen::MatrixXd covariance;
  Eigen::MatrixXcd residues;
  Eigen::MatrixXcd residue_covariance;
};
MimoFit mimo_fit(const std::vector<MimoSpectra>& data, const MimoStructure& s, const std::string& method, double tol,
                 int max_iter, bool covariance);

}  // namespace lptv
