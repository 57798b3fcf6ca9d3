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

int rhs_trampoline(sunrealtype t, N_Vector y, N_Vector dy, void* user_data) {
  const auto* f = static_cast<const OdeRightHandSide*>(user_data);
  (*f)(t, N_VGetArrayPointer(y), N_VGetArrayPointer(dy));
  const long n = N_VGetLength(dy);
  const double* d = N_VGetArrayPointer(dy);
  for (long i = 0; i < n; ++i)
    if (!std::isfinite(d[i])) return 1;  // recoverable: CVODE retries with a smaller step
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
  void clear() {  // in the order the destructor would use
    fixed_point.reset();
    memory.reset();
    abs_tol.reset();
    state.reset();
    context.reset();
    size = -1;
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

IntegrationResult integrate_ode(const OdeRightHandSide& rhs, Vector& y, double t_end,
                                const CvodeOptions& options) {
  const auto n = static_cast<sunindextype>(y.size());
  thread_local Workspace workspace;
  if (workspace.size != n) {
    const std::string problem = create_workspace(workspace, n);
    if (!problem.empty()) {
      workspace.clear();
      return {false, 0, problem};
    }
  }
  void* mem = workspace.memory.get();
  Eigen::Map<Vector>(N_VGetArrayPointer(workspace.state.get()), n) = y;
  Eigen::Map<Vector> tolerance(N_VGetArrayPointer(workspace.abs_tol.get()), n);
  if (options.absolute_tolerance.size() == n)
    tolerance = options.absolute_tolerance;
  else
    tolerance.setConstant(1e-3 * options.relative_tolerance);

  int flag = CVodeReInit(mem, 0.0, workspace.state.get());
  if (flag != CV_SUCCESS) return failure("CVodeReInit", flag);
  flag = CVodeSetUserData(mem, const_cast<OdeRightHandSide*>(&rhs));
  if (flag != CV_SUCCESS) return failure("CVodeSetUserData", flag);
  flag = CVodeSVtolerances(mem, options.relative_tolerance, workspace.abs_tol.get());
  if (flag != CV_SUCCESS) return failure("CVodeSVtolerances", flag);
  flag = CVodeSetMaxNumSteps(mem, options.max_steps);
  if (flag != CV_SUCCESS) return failure("CVodeSetMaxNumSteps", flag);
  flag = CVodeSetStopTime(mem, t_end);
  if (flag != CV_SUCCESS) return failure("CVodeSetStopTime", flag);

  sunrealtype t = 0;
  flag = CVode(mem, t_end, workspace.state.get(), &t, CV_NORMAL);
  IntegrationResult result;
  long steps = 0;
  CVodeGetNumSteps(mem, &steps);
  result.steps = steps;
  if (flag < 0) {
    result.message =
        fmt::format("cvode: CVode failed at t = {} of {} ({})", t, t_end, flag_name(flag));
    return result;
  }
  y = Eigen::Map<Vector>(N_VGetArrayPointer(workspace.state.get()), n);
  result.ok = true;
  return result;
}

}  // namespace backbone::core
