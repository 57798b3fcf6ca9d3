#include "core/jacobians/finite_difference.hpp"

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "core/errors.hpp"
#include "core/jacobians/compressed_jacobian.hpp"
#include "core/job_queue.hpp"

namespace backbone::core {

double relative_step(const FiniteDifferenceOptions& options) {
  const bool central = options.scheme == FiniteDifferenceOptions::Scheme::central;
  const double eps = std::numeric_limits<double>::epsilon();
  return options.relative_step > 0 ? options.relative_step
                                   : (central ? std::cbrt(eps) : std::sqrt(eps));
}

double finite_difference_step(double x_j, double scale_j, double relative_step) {
  const double h0 =
      relative_step * std::max(std::abs(x_j), std::abs(scale_j) > 0 ? std::abs(scale_j) : 1.0);
  // Round the step so that x_j + h is exactly representable: the divisor is the step taken.
  volatile double shifted = x_j + h0;
  return shifted - x_j;
}

double fixed_weight(std::uint64_t index) {
  std::uint64_t z = 0x9E3779B97F4A7C15ull * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  const double u = static_cast<double>(z >> 11) * 0x1.0p-53;  // [0, 1)
  return (z & 1) ? 1 + u : -(1 + u);
}

EvalStatus finite_difference_jacobian(const Problem& problem, const Vector& x, Matrix& J,
                                      const FiniteDifferenceOptions& options) {
  const int n = problem.num_unknowns();
  const int m = problem.num_equations();
  J.resize(m, n);
  const bool central = options.scheme == FiniteDifferenceOptions::Scheme::central;
  const double rel = relative_step(options);
  const Vector scale = problem.typical_scale();

  Vector r0;
  if (!central) {
    EvalStatus s = problem.residual(x, r0);
    if (s != EvalStatus::ok) return s;
  }

  std::vector<EvalStatus> status(static_cast<std::size_t>(n), EvalStatus::ok);
  auto column = [&](int j) {
    Vector xp = x;
    const double h = finite_difference_step(x[j], scale[j], rel);
    Vector rp, rm;
    xp[j] = x[j] + h;
    EvalStatus s = problem.residual(xp, rp);
    if (s == EvalStatus::ok && central) {
      xp[j] = x[j] - h;
      s = problem.residual(xp, rm);
      if (s == EvalStatus::ok) J.col(j) = (rp - rm) / (2 * h);
    } else if (s == EvalStatus::ok) {
      J.col(j) = (rp - r0) / h;
    }
    status[static_cast<std::size_t>(j)] = s;
  };

  run_tasks(n, options.threads, column);
  for (EvalStatus s : status)
    if (s != EvalStatus::ok) return s;
  return EvalStatus::ok;
}

namespace {
std::atomic<int> jacobian_threads{1};
}  // namespace

void set_default_jacobian_threads(int threads) {
  if (threads < 1 || threads > max_jacobian_threads)
    throw InputError("threads",
                     fmt::format("must be in 1..{} (got {})", max_jacobian_threads, threads));
  jacobian_threads = threads;
}

int default_jacobian_threads() {
  return jacobian_threads;
}

EvalStatus Problem::compute_jacobian(const Vector& x, Matrix& J) const {
  FiniteDifferenceOptions options;
  options.threads = default_jacobian_threads();
  const std::optional<JacobianPattern> pattern = jacobian_pattern(x);
  if (!pattern) return finite_difference_jacobian(*this, x, J, options);
  CompressedJacobianReport report;
  const EvalStatus s =
      compressed_finite_difference_jacobian(*this, x, *pattern, J, options, &report);
  counters_.compressed_jacobians++;
  if (report.widened) counters_.jacobian_widenings++;
  if (report.fell_back) counters_.jacobian_fallbacks++;
  return s;
}

}  // namespace backbone::core
