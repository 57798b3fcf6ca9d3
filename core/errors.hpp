// Bad configuration is an exception; numerical failure is a value.
//
// InputError is thrown while a scene, an option set or a problem is being *constructed* from
// user input (unknown key, negative gap, NaN, unreadable file...). Its message names the key
// and the constraint, so a user can act on it. The CLI maps it to exit code 2 and writes
// nothing. Numerical failures (Newton divergence, NaN residual) are never exceptions: they are
// status values returned by the solvers (see problem.hpp, newton.hpp).
//
//   if (!(gap >= 0)) throw InputError("gap", fmt::format("must be >= 0 (got {})", gap));
//   // what(): "gap: must be >= 0 (got -1)"
#pragma once

#include <stdexcept>
#include <string>

namespace backbone::core {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& key, const std::string& constraint)
      : std::runtime_error(key.empty() ? constraint : key + ": " + constraint), key_(key) {}
  const std::string& key() const { return key_; }

 private:
  std::string key_;
};

// Exit codes of the CLI, one place.
enum ExitCode : int { exit_ok = 0, exit_numerical_failure = 1, exit_bad_input = 2 };

}  // namespace backbone::core
