// A small RAII adapter over SUNDIALS CVODE for non-stiff ODE systems y' = f(t, y).
//
// Every CVODE call of backbone lives in cvode_integrator.cpp (ode_orbit.hpp builds periodic-orbit
// problems on it; see core/README.md). The integrator uses the
// variable-order Adams-Moulton method (orders up to 12) with a fixed-point corrector: the
// problems here are smooth and non-stiff, where high-order Adams needs far fewer steps than
// BDF (order <= 5) at the tight tolerances (rtol ~ 1e-13) a period accurate to 1e-9 asks for.
// The end time is imposed as a stop time, so the solution is never interpolated. Each thread
// keeps one CVODE memory and re-initialises it per call (CVodeReInit: the same integration as a
// fresh CVodeCreate, without its allocations), so concurrent calls from different threads are
// safe; a right-hand side must not call integrate_ode itself.
//
//   CvodeOptions opt; opt.relative_tolerance = 1e-13;
//   opt.absolute_tolerance = Vector::Constant(2, 1e-16);
//   auto rhs = [](double, const double* y, double* dy) { dy[0] = y[1]; dy[1] = -y[0]; };
//   Vector y(2); y << 1.0, 0.0;
//   IntegrationResult r = integrate_ode(rhs, y, 2 * std::numbers::pi, opt);  // y ~ (1, 0)
//   if (!r.ok) fmt::print("{}\n", r.message);
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace backbone::core {

struct CvodeOptions {
  double relative_tolerance = 1e-13;
  Vector absolute_tolerance;  // one per component; empty: 1e-3 * relative_tolerance each
  long max_steps = 1000000;
  double max_step = 0;  // largest step size; 0: no limit
};

struct IntegrationResult {
  bool ok = false;
  long steps = 0;
  std::string message;  // CVODE's flag name on failure
};

// dy = f(t, y); y and dy have the size of the initial state.
using OdeRightHandSide = std::function<void(double t, const double* y, double* dy)>;

// Integrates from t = 0 to t_end > 0; y holds the initial state on entry, y(t_end) on return.
IntegrationResult integrate_ode(const OdeRightHandSide& rhs, Vector& y, double t_end,
                                const CvodeOptions& options);

// Root functions g_k(t, y), k < directions.size(), written into g.
using OdeRootFunctions = std::function<void(double t, const double* y, double* g)>;

struct SegmentResult : IntegrationResult {
  double t = 0;            // where the segment ended: t_end, or the first root found
  std::vector<int> roots;  // the root functions that vanished at t (empty: t = t_end)
};

// Integrates from t0 to t_end > t0 with CVODE's root finding on g (directions[k]: +1 only
// rising zeros of g_k, -1 only falling ones, 0 both), stopping at the first root: y holds y(t),
// t the root, roots which functions vanished there. A function that is zero at t0 is not reported
// until it has left zero. CVODE finds a zero by a change of sign over a step, or a value of
// exactly 0 at a step's end: a zero at t_end is reported (t = t_end, roots not empty), while a
// zero the solution touches without crossing, or crosses twice within one step, is not; callers
// that must not lose one add the derivative of g_k as a root function of its own (its zero is the
// extremum between the two crossings; hybrid_orbit.cpp).
SegmentResult integrate_to_event(const OdeRightHandSide& rhs, const OdeRootFunctions& roots,
                                 const std::vector<int>& directions, Vector& y, double t0,
                                 double t_end, const CvodeOptions& options);

}  // namespace backbone::core
