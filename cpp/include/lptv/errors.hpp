// Error types shared by the whole core.
#pragma once
#include <stdexcept>
#include <string>

namespace lptv {

// A computation that could not be carried out on valid input: a singular system,
// a failed factorisation or decomposition. Python sees it as lptv.NumericalError.
class NumericalError : public std::runtime_error {
 public:
  explicit NumericalError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace lptv
