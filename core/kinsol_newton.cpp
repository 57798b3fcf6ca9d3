#include "core/kinsol_newton.hpp"

namespace backbone::core {

KinsolNewton::KinsolNewton(const NewtonOptions& options) : options_(options) {
  options_.validate();
}

NewtonSummary KinsolNewton::solve(const Problem&, Vector&) {
  NewtonSummary s;
  s.status = NewtonStatus::linear_solver_failed;
  s.message = "kinsol: not implemented yet";
  return s;
}

}  // namespace backbone::core
