// Every CVODE call of backbone. SUNDIALS objects are owned by RAII handles; Eigen maps
// over N_VGetArrayPointer instead of copying.
#include "core/orbits/cvode_integrator.hpp"

#include <cvode/cvode.h>
#include <fmt/format.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <vector>

namespace backbone::core {

namespace {

struct ContextDeleter {
  void operator()(SUNContext c) const { SUNContext_Free(&c); }
};
struct VectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct SolverDeleter {
  void operator()(SUNNonlinearSolver s) const { SUNNonlinSolFree(s); }
};
struct CvodeDeleter {
  void operator()(void* mem) const { CVodeFree(&mem); }
};
using ContextHandle = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using VectorHandle = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;
using SolverHandle = std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, SolverDeleter>;
using CvodeHandle = std::unique_ptr<void, CvodeDeleter>;

// What CVODE's user data points to: the right-hand side and, with events, the root functions.
struct Callbacks {
  const OdeRightHandSide* rhs = nullptr;
  const OdeRootFunctions* roots = nullptr;
};

int rhs_trampoline(sunrealtype t, N_Vector y, N_Vector dy, void* user_data) {
  const auto* f = static_cast<const Callbacks*>(user_data)->rhs;
  (*f)(t, N_VGetArrayPointer(y), N_VGetArrayPointer(dy));
  const long n = N_VGetLength(dy);
  const double* d = N_VGetArrayPointer(dy);
  for (long i = 0; i < n; ++i)
    if (!std::isfinite(d[i])) return 1;  // recoverable: CVODE retries with a smaller step
  return 0;
}

int root_trampoline(sunrealtype t, N_Vector y, sunrealtype* g, void* user_data) {
  const auto* roots = static_cast<const Callbacks*>(user_data)->roots;
  (*roots)(t, N_VGetArrayPointer(y), g);
  return 0;
}

// CVODE allocates the name; copy and free it.
std::string flag_name(int flag) {
  char* raw = CVodeGetReturnFlagName(flag);
  std::string name = raw ? raw : "unknown flag";
  std::free(raw);
  return name;
}

IntegrationResult failure(const char* what, int flag) {
  IntegrationResult r;
  r.ok = false;
  r.message = fmt::format("cvode: {} failed ({})", what, flag_name(flag));
  return r;
}

// The CVODE memory of one thread, created on the first call for a state size and re-initialised
// (CVodeReInit) by the next ones: a fresh CVodeCreate, vectors and fixed-point solver cost
// about a tenth of a short flow. Members are destroyed in reverse order, the context last.
struct Workspace {
  ContextHandle context;
  VectorHandle state;
  VectorHandle abs_tol;
  CvodeHandle memory;
  SolverHandle fixed_point;
  sunindextype size = -1;
  int roots = 0;  // root functions CVodeRootInit set up last
  void clear() {  // in the order the destructor would use
    fixed_point.reset();
    memory.reset();
    abs_tol.reset();
    state.reset();
    context.reset();
    size = -1;
    roots = 0;
  }
};

// (Re)creates the workspace for n unknowns; empty message on success.
std::string create_workspace(Workspace& w, sunindextype n) {
  w.clear();
  SUNContext raw_context = nullptr;
  if (SUNContext_Create(nullptr, &raw_context) != 0) return "cvode: SUNContext_Create failed";
  w.context.reset(raw_context);
  w.state.reset(N_VNew_Serial(n, raw_context));
  w.abs_tol.reset(N_VNew_Serial(n, raw_context));
  if (!w.state || !w.abs_tol) return "cvode: N_VNew_Serial failed";
  N_VConst(0.0, w.state.get());
  w.memory.reset(CVodeCreate(CV_ADAMS, raw_context));
  if (!w.memory) return "cvode: CVodeCreate failed";
  int flag = CVodeInit(w.memory.get(), rhs_trampoline, 0.0, w.state.get());
  if (flag != CV_SUCCESS) return failure("CVodeInit", flag).message;
  w.fixed_point.reset(SUNNonlinSol_FixedPoint(w.state.get(), 0, raw_context));
  if (!w.fixed_point) return "cvode: SUNNonlinSol_FixedPoint failed";
  flag = CVodeSetNonlinearSolver(w.memory.get(), w.fixed_point.get());
  if (flag != CV_SUCCESS) return failure("CVodeSetNonlinearSolver", flag).message;
  w.size = n;
  return {};
}

}  // namespace

namespace {

// The calling thread's workspace for y's size, re-initialised at (t0, y) with the options and
// the root functions (none: root finding off); empty message on success.
std::string prepare(Workspace& workspace, const Vector& y, double t0, double t_end,
                    const CvodeOptions& options, const Callbacks& callbacks,
                    const std::vector<int>& directions) {
  const auto n = static_cast<sunindextype>(y.size());
  if (workspace.size != n) {
    const std::string problem = create_workspace(workspace, n);
    if (!problem.empty()) {
      workspace.clear();
      return problem;
    }
  }
  void* mem = workspace.memory.get();
  Eigen::Map<Vector>(N_VGetArrayPointer(workspace.state.get()), n) = y;
  Eigen::Map<Vector> tolerance(N_VGetArrayPointer(workspace.abs_tol.get()), n);
  if (options.absolute_tolerance.size() == n)
    tolerance = options.absolute_tolerance;
  else
    tolerance.setConstant(1e-3 * options.relative_tolerance);

  int flag = CVodeReInit(mem, t0, workspace.state.get());
  if (flag != CV_SUCCESS) return failure("CVodeReInit", flag).message;
  flag = CVodeSetUserData(mem, const_cast<Callbacks*>(&callbacks));
  if (flag != CV_SUCCESS) return failure("CVodeSetUserData", flag).message;
  flag = CVodeSVtolerances(mem, options.relative_tolerance, workspace.abs_tol.get());
  if (flag != CV_SUCCESS) return failure("CVodeSVtolerances", flag).message;
  flag = CVodeSetMaxNumSteps(mem, options.max_steps);
  if (flag != CV_SUCCESS) return failure("CVodeSetMaxNumSteps", flag).message;
  flag = CVodeSetMaxStep(mem, options.max_step > 0 ? options.max_step : 0.0);
  if (flag != CV_SUCCESS) return failure("CVodeSetMaxStep", flag).message;
  flag = CVodeSetStopTime(mem, t_end);
  if (flag != CV_SUCCESS) return failure("CVodeSetStopTime", flag).message;
  const int roots = static_cast<int>(directions.size());
  if (roots > 0 || workspace.roots > 0) {
    flag = CVodeRootInit(mem, roots, roots > 0 ? root_trampoline : nullptr);
    if (flag != CV_SUCCESS) return failure("CVodeRootInit", flag).message;
    workspace.roots = roots;
  }
  if (roots > 0) {
    std::vector<int> copy = directions;
    flag = CVodeSetRootDirection(mem, copy.data());
    if (flag != CV_SUCCESS) return failure("CVodeSetRootDirection", flag).message;
    // A root function that is zero at t0 (the state a reset left on its surface) is inactive
    // until it leaves zero: that is the behaviour wanted, not a warning.
    flag = CVodeSetNoInactiveRootWarn(mem);
    if (flag != CV_SUCCESS) return failure("CVodeSetNoInactiveRootWarn", flag).message;
  }
  return {};
}

}  // namespace

SegmentResult integrate_to_event(const OdeRightHandSide& rhs, const OdeRootFunctions& roots,
                                 const std::vector<int>& directions, Vector& y, double t0,
                                 double t_end, const CvodeOptions& options) {
  thread_local Workspace workspace;
  const Callbacks callbacks{&rhs, &roots};
  SegmentResult result;
  const std::string problem = prepare(workspace, y, t0, t_end, options, callbacks, directions);
  if (!problem.empty()) {
    result.message = problem;
    return result;
  }
  void* mem = workspace.memory.get();
  sunrealtype t = t0;
  const int flag = CVode(mem, t_end, workspace.state.get(), &t, CV_NORMAL);
  long steps = 0;
  CVodeGetNumSteps(mem, &steps);
  result.steps = steps;
  result.t = t;
  if (flag < 0) {
    result.message =
        fmt::format("cvode: CVode failed at t = {} of {} ({})", t, t_end, flag_name(flag));
    return result;
  }
  y = Eigen::Map<Vector>(N_VGetArrayPointer(workspace.state.get()), y.size());
  if (flag == CV_ROOT_RETURN) {
    std::vector<int> found(directions.size(), 0);
    CVodeGetRootInfo(mem, found.data());
    for (std::size_t k = 0; k < found.size(); ++k)
      if (found[k] != 0) result.roots.push_back(static_cast<int>(k));
  }
  result.ok = true;
  return result;
}

IntegrationResult integrate_ode(const OdeRightHandSide& rhs, Vector& y, double t_end,
                                const CvodeOptions& options) {
  return integrate_to_event(rhs, {}, {}, y, 0.0, t_end, options);
}

}  // namespace backbone::core
