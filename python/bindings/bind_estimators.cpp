#include "lptv/diagnostics.hpp"
#include "lptv/estimators.hpp"
#include "pybind11.hpp"

void bind_estimators(py::module_& m) {
  m.def("weighted_r_factor", &lptv::weighted_r_factor, "data"_a, "par"_a, "rows"_a, "weights"_a);
  m.def("real_column_covariance", &lptv::real_column_covariance, "data"_a, "par"_a, "rows"_a, "weights"_a);
  m.def("expected_fraction_above_0db", [](int n_rows, int n_free, int periods) {
    const auto f = lptv::expected_fraction_above_0db(n_rows, n_free, periods);
    return py::make_tuple(f.p, py::make_tuple(f.lo, f.hi));
  }, "n_rows"_a, "n_free"_a, "periods"_a);
  m.def("covariance_correction", &lptv::covariance_correction, "periods"_a);

  py::class_<lptv::EstimateResult>(m, "EstimateResult", "The estimate alone (lptv::estimate).")
      .def_readonly("theta", &lptv::EstimateResult::theta)
      .def_readonly("eta", &lptv::EstimateResult::eta)
      .def_readonly("iterations", &lptv::EstimateResult::iterations)
      .def_readonly("start_iterations", &lptv::EstimateResult::start_iterations,
                    "SML: the weighted solves of its WGTLS start (stopped at a relative change of 1e-6)")
      .def_readonly("converged", &lptv::EstimateResult::converged)
      .def_readonly("cost", &lptv::EstimateResult::cost)
      .def_readonly("cost_history", &lptv::EstimateResult::cost_history)
      .def_readonly("singular_values", &lptv::EstimateResult::singular_values)
      .def_readonly("noise_free", &lptv::EstimateResult::noise_free);
  m.def("estimate", [](const lptv::FrequencyData& d, const lptv::Parametrisation& p, const std::vector<int>& rows,
                       const std::string& method, double tol, int max_iter) {
    lptv::EstimateOptions opt;
    opt.method = lptv::method_from_string(method);
    opt.tol = tol;
    opt.max_iter = max_iter;
    py::gil_scoped_release release;  // the whole estimation is C++
    return lptv::estimate(d, p, rows, opt);
  }, "data"_a, "par"_a, "rows"_a, "method"_a = "wgtls", "tol"_a = 1e-10, "max_iter"_a = 50);

  py::class_<lptv::Identification>(m, "Identification", "The result of lptv::identify.")
      .def_readonly("model", &lptv::Identification::model)
      .def_property_readonly("method", [](const lptv::Identification& r) { return lptv::method_name(r.method); })
      .def_readonly("rows", &lptv::Identification::rows)
      .def_readonly("experiment", &lptv::Identification::experiment)
      .def_readonly("n_experiments", &lptv::Identification::n_experiments)
      .def_readonly("theta", &lptv::Identification::theta)
      .def_readonly("eta", &lptv::Identification::eta)
      .def_readonly("eta_names", &lptv::Identification::eta_names)
      .def_readonly("n_free", &lptv::Identification::n_free)
      .def_readonly("iterations", &lptv::Identification::iterations)
      .def_readonly("converged", &lptv::Identification::converged)
      .def_readonly("cost", &lptv::Identification::cost)
      .def_readonly("cost_history", &lptv::Identification::cost_history)
      .def_readonly("singular_values", &lptv::Identification::singular_values)
      .def_readonly("residue", &lptv::Identification::residue)
      .def_readonly("residue_variance", &lptv::Identification::residue_variance)
      .def_readonly("normalized_residue", &lptv::Identification::normalized_residue)
      .def_readonly("fraction_above_0db", &lptv::Identification::fraction_above_0db)
      .def_property_readonly("fraction_expected",
                             [](const lptv::Identification& r) { return r.fraction_expected.p; })
      .def_property_readonly("fraction_band", [](const lptv::Identification& r) {
        return py::make_tuple(r.fraction_expected.lo, r.fraction_expected.hi);
      })
      .def_readonly("residue_ok", &lptv::Identification::residue_ok)
      .def_readonly("nearly_unidentifiable", &lptv::Identification::nearly_unidentifiable)
      .def_readonly("noise_free", &lptv::Identification::noise_free)
      .def_property_readonly("covariance", [](const lptv::Identification& r) -> py::object {
        if (r.covariance.size() == 0) return py::none();
        return py::cast(r.covariance);
      })
      .def_readonly("warnings", &lptv::Identification::warnings);

  m.def("identify", [](const lptv::FrequencyData& d, const lptv::Structure& s, const std::string& method,
                       double tol, int max_iter, std::vector<int> rows, bool covariance, bool full_rows) {
    lptv::IdentifyOptions opt;
    opt.method = lptv::method_from_string(method);
    opt.tol = tol;
    opt.max_iter = max_iter;
    opt.rows = std::move(rows);
    opt.covariance = covariance;
    opt.full_rows = full_rows;
    py::gil_scoped_release release;  // the whole identification is C++
    return lptv::identify(d, s, opt);
  }, "data"_a, "structure"_a, "method"_a = "wgtls", "tol"_a = 1e-10, "max_iter"_a = 50,
        "rows"_a = std::vector<int>(), "covariance"_a = true, "full_rows"_a = false);

  m.def("identify_experiments", [](const std::vector<lptv::FrequencyData>& experiments, const lptv::Structure& s,
                                   const std::string& method, double tol, int max_iter,
                                   std::vector<std::vector<int>> rows, bool covariance, bool full_rows) {
    lptv::IdentifyOptions opt;
    opt.method = lptv::method_from_string(method);
    opt.tol = tol;
    opt.max_iter = max_iter;
    opt.experiment_rows = std::move(rows);
    opt.covariance = covariance;
    opt.full_rows = full_rows;
    py::gil_scoped_release release;  // the whole identification is C++
    return lptv::identify(experiments, s, opt);
  }, "experiments"_a, "structure"_a, "method"_a = "wgtls", "tol"_a = 1e-10, "max_iter"_a = 50,
        "rows"_a = std::vector<std::vector<int>>(), "covariance"_a = true, "full_rows"_a = false,
        R"doc(Several experiments of one system fitted into one model (lptv::identify on a list).

rows: one list of rows per experiment (an empty list: that experiment's default rows), or
empty for every experiment's default.)doc");

  py::class_<lptv::ChannelPower>(m, "ChannelPower", "Signal of one channel on a set of lines (lptv::channel_power).")
      .def_readonly("lines", &lptv::ChannelPower::lines)
      .def_readonly("above", &lptv::ChannelPower::above)
      .def_readonly("power", &lptv::ChannelPower::power)
      .def_readonly("noise", &lptv::ChannelPower::noise)
      .def_readonly("limit", &lptv::ChannelPower::limit)
      .def_readonly("clear", &lptv::ChannelPower::clear)
      .def_readonly("present", &lptv::ChannelPower::present);
  py::class_<lptv::DataDiagnosis>(m, "DataDiagnosis", "What the data can say before estimating (lptv::diagnose_data).")
      .def_readonly("region", &lptv::DataDiagnosis::region)
      .def_readonly("input", &lptv::DataDiagnosis::input)
      .def_readonly("output", &lptv::DataDiagnosis::output)
      .def_readonly("excited", &lptv::DataDiagnosis::excited)
      .def_readonly("informative_rows", &lptv::DataDiagnosis::informative_rows)
      .def_readonly("warnings", &lptv::DataDiagnosis::warnings);
  m.def("diagnose_data", &lptv::diagnose_data, "data"_a, "structure"_a, "rows"_a, "check_row_count"_a = true,
        "The data diagnostics lptv::identify runs first: raises ValueError naming the argument and the "
        "cause for degenerate data (METHOD.md section 15).");
}
