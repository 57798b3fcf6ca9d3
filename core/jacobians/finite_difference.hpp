// Finite-difference Jacobians: the default derivative of every Problem.
//
// Step rule (documented once, used everywhere): column j uses
//     h_j = relative_step * max(|x_j|, typical_scale_j)
// with relative_step = sqrt(machine epsilon) ~ 1.5e-8 for forward differences (truncation
// O(h) balances round-off O(eps/h)) and cbrt(machine epsilon) ~ 6e-6 for central differences
// (truncation O(h^2)). h_j is then rounded so that x_j + h_j is exactly representable.
// Columns are independent: with threads > 1 they are evaluated concurrently
// (Problem::compute_residual is const and must be thread-safe); every column is computed by
// the same operations whatever the thread count, so J is bit-identical to one thread's.
// The default Jacobian of every Problem (Problem::compute_jacobian) uses
// default_jacobian_threads(), a process-wide execution setting like Eigen::setNbThreads (the
// `threads` key of a trace sets it for the run, continuation/cli/scene_options.hpp).
//
//   FiniteDifferenceOptions fd; fd.scheme = FiniteDifferenceOptions::Scheme::central;
//   Matrix J;
//   EvalStatus s = finite_difference_jacobian(problem, x, J, fd);
//   set_default_jacobian_threads(2);    // problem.jacobian(x, J) now uses two threads
#pragma once

#include <cstdint>

#include "core/job_queue.hpp"  // run_tasks: the columns (and colours) on threads
#include "core/problem.hpp"

namespace backbone::core {

struct FiniteDifferenceOptions {
  enum class Scheme { forward, central };
  Scheme scheme = Scheme::forward;
  double relative_step = 0;  // 0: the rule above
  int threads = 1;
};

// The step rule above for one unknown: relative_step(options) * max(|x_j|, |scale_j|) (1 when
// scale_j is 0), rounded so that x_j + h is exactly x_j + h in floating point.
double relative_step(const FiniteDifferenceOptions& options);
double finite_difference_step(double x_j, double scale_j, double relative_step);

// A fixed pseudo-random weight +-(1..2) for each index: splitmix64 of index + 1, the same for
// every x and run (the compressed Jacobian's check direction, the rank report's start blocks).
double fixed_weight(std::uint64_t index);

EvalStatus finite_difference_jacobian(const Problem& problem, const Vector& x, Matrix& J,
                                      const FiniteDifferenceOptions& options = {});

// Threads of the default finite-difference Jacobian, 1 at start. Throws InputError("threads")
// unless 1 <= threads <= max_jacobian_threads.
constexpr int max_jacobian_threads = 256;
void set_default_jacobian_threads(int threads);
int default_jacobian_threads();

}  // namespace backbone::core
