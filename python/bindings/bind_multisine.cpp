#include "lptv/multisine.hpp"
#include "pybind11.hpp"

void bind_multisine(py::module_& m) {
  m.def("multisine_spectrum", &lptv::multisine_spectrum, "lines"_a, "amplitudes"_a, "phases"_a,
        "n_samples"_a);
  m.def("time_signal", &lptv::time_signal, "X"_a, "n_samples"_a);
  m.def("spectrum", &lptv::spectrum, "x"_a);
  m.def("crest_factor", &lptv::crest_factor, "x"_a);
}
