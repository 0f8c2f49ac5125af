#include "lptv/multisine.hpp"
#include "pybind11.hpp"

void bind_multisine(py::module_& m) {
  m.def("multisine_spectrum", &lptv::multisine_spectrum, "lines"_a, "amplitudes"_a, "phases"_a,
        "n_samples"_a);
  m.def("time_signal", &lptv::time_signal, "X"_a, "n_samples"_a);
  m.def("spectrum", &lptv::spectrum, "x"_a);
  m.def("crest_factor", &lptv::crest_factor, "x"_a);
}

void bind_multisine_design(py::module_& m) {
  py::class_<lptv::CrestResult>(m, "CrestResult")
      .def_readonly("phases", &lptv::CrestResult::phases)
      .def_readonly("crest_factor", &lptv::CrestResult::crest_factor)
      .def_readonly("initial_crest_factor", &lptv::CrestResult::initial_crest_factor)
      .def_readonly("oversample", &lptv::CrestResult::oversample)
      .def_readonly("evaluations", &lptv::CrestResult::evaluations)
      .def_readonly("best_per_p", &lptv::CrestResult::best_per_p);
  m.def("schroeder_phases", &lptv::schroeder_phases, "amplitudes"_a);
  m.def(
      "minimize_crest_factor",
      [](const std::vector<int>& lines, const Eigen::VectorXd& amplitudes, const Eigen::VectorXd& phases,
         int n_samples, int oversample, int max_p, int iterations_per_p) {
        lptv::CrestOptions opt;
        opt.oversample = oversample;
        opt.max_p = max_p;
        opt.iterations_per_p = iterations_per_p;
        py::gil_scoped_release release;
        return lptv::minimize_crest_factor(lines, amplitudes, phases, n_samples, opt);
      },
      "lines"_a, "amplitudes"_a, "phases"_a, "n_samples"_a, "oversample"_a = 0, "max_p"_a = 1024,
      "iterations_per_p"_a = 100);
  m.def(
      "lp_norm_log",
      [](const std::vector<int>& lines, const Eigen::VectorXd& amplitudes, const Eigen::VectorXd& phases,
         int n_samples, int oversample, int p) {
        Eigen::VectorXd grad;
        const double f = lptv::lp_norm_log(lines, amplitudes, phases, n_samples, oversample, p, &grad);
        return py::make_tuple(f, grad);
      },
      "lines"_a, "amplitudes"_a, "phases"_a, "n_samples"_a, "oversample"_a, "p"_a);
}
