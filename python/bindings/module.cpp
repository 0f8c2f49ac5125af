#include "pybind11.hpp"

#include "lptv/errors.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "lptv compiled core: model, multisines, frequency-domain simulator, estimators, Floquet stability";
  // std::invalid_argument becomes ValueError by pybind11's default translation.
  static py::exception<lptv::NumericalError> numerical_error(m, "NumericalError", PyExc_ArithmeticError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const lptv::NumericalError& e) {
      py::set_error(numerical_error, e.what());
    }
  });
  bind_model(m);
  bind_multisine(m);
  bind_multisine_design(m);
  bind_fds(m);
  bind_noise(m);
  bind_structure(m);
  bind_jacobian(m);
  bind_likelihood(m);
  bind_estimators(m);
  bind_htf_estimate(m);
  bind_distortion(m);
  bind_moderation(m);
  bind_record(m);
  bind_mimo(m);     // before floquet: its MimoModel is an argument type of floquet_mimo
  bind_floquet(m);
}
