#include "core/problem.hpp"

#include <chrono>
#include <limits>

namespace backbone::core {

double observable_value(const Observables& observables, const std::string& name) {
  for (const auto& [key, value] : observables)
    if (key == name) return value;
  return std::numeric_limits<double>::quiet_NaN();
}

const char* to_string(EvalStatus s) {
  switch (s) {
    case EvalStatus::ok:
      return "ok";
    case EvalStatus::non_finite:
      return "non-finite value";
    case EvalStatus::failed:
      return "evaluation failed";
  }
  return "?";
}

void EvaluationCounters::reset() {
  residuals = 0;
  jacobians = 0;
  residual_nanoseconds = 0;
  jacobian_nanoseconds = 0;
  compressed_jacobians = 0;
  jacobian_widenings = 0;
  jacobian_fallbacks = 0;
}

namespace {
long elapsed_ns(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() -
                                                              start)
      .count();
}
}  // namespace

EvalStatus Problem::residual(const Vector& x, Vector& r) const {
  const auto start = std::chrono::steady_clock::now();
  r.resize(num_equations());
  EvalStatus s = compute_residual(x, r);
  counters_.residuals++;
  counters_.residual_nanoseconds += elapsed_ns(start);
  if (s == EvalStatus::ok && !r.allFinite()) s = EvalStatus::non_finite;
  return s;
}

EvalStatus Problem::jacobian(const Vector& x, Matrix& J) const {
  const auto start = std::chrono::steady_clock::now();
  J.resize(num_equations(), num_unknowns());
  EvalStatus s = compute_jacobian(x, J);
  counters_.jacobians++;
  counters_.jacobian_nanoseconds += elapsed_ns(start);
  if (s == EvalStatus::ok && !J.allFinite()) s = EvalStatus::non_finite;
  return s;
}

}  // namespace backbone::core
