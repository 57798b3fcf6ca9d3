// The only file of backbone that talks to SUNDIALS KINSOL.
#include "core/solvers/kinsol_newton.hpp"

#include <fmt/format.h>
#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <chrono>
#include <cstdlib>
#include <memory>

namespace backbone::core {

namespace {

// RAII handles for every SUNDIALS object; each deleter is the matching SUNDIALS destructor.
struct ContextDeleter {
  void operator()(SUNContext ctx) const { SUNContext_Free(&ctx); }
};
struct VectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix A) const { SUNMatDestroy(A); }
};
struct LinearSolverDeleter {
  void operator()(SUNLinearSolver LS) const { SUNLinSolFree(LS); }
};
struct KinsolDeleter {
  void operator()(void* mem) const { KINFree(&mem); }
};
using ContextHandle = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using VectorHandle = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;
using MatrixHandle = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;
using LinearSolverHandle =
    std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinearSolverDeleter>;
using KinsolHandle = std::unique_ptr<void, KinsolDeleter>;

std::string flag_name(long flag) {
  char* raw = KINGetReturnFlagName(flag);  // malloc'ed by SUNDIALS
  std::string name = raw ? raw : fmt::format("flag {}", flag);
  std::free(raw);
  return name;
}

Eigen::Map<Vector> as_eigen(N_Vector v) {
  return {N_VGetArrayPointer(v), static_cast<Eigen::Index>(N_VGetLength(v))};
}

// Everything the callbacks need; workspace allocated once per solve.
struct CallbackData {
  const Problem* problem = nullptr;
  void* kinsol = nullptr;
  Vector x, r;  // Problem::residual takes Eigen vectors: one copy of the iterate in
  Matrix J;
  Vector last_x;  // the last point whose residual was evaluated, and its ||F||_inf
  double last_norm = -1;
  std::vector<double>* history = nullptr;
  EvalStatus failure = EvalStatus::ok;
  std::string error_message;  // KINSOL's own error text, captured instead of printed
};

int residual_callback(N_Vector u, N_Vector f, void* user_data) {
  auto& d = *static_cast<CallbackData*>(user_data);
  try {
    d.x = as_eigen(u);
    const EvalStatus s = d.problem->residual(d.x, d.r);
    if (s != EvalStatus::ok) {
      d.failure = s;
      return 1;  // recoverable: KINSOL's line search may shorten the step
    }
    as_eigen(f) = d.r;
    d.last_x = d.x;
    d.last_norm = d.r.lpNorm<Eigen::Infinity>();
    return 0;
  } catch (...) {
    d.failure = EvalStatus::failed;
    return -1;
  }
}

// fu = F(u) at the current iterate: its norm is the residual history entry of this iteration.
int jacobian_callback(N_Vector u, N_Vector fu, SUNMatrix J, void* user_data, N_Vector, N_Vector) {
  auto& d = *static_cast<CallbackData*>(user_data);
  try {
    long iteration = 0;
    KINGetNumNonlinSolvIters(d.kinsol, &iteration);
    const double norm = as_eigen(fu).lpNorm<Eigen::Infinity>();
    auto& h = *d.history;
    if (static_cast<std::size_t>(iteration) < h.size())
      h[static_cast<std::size_t>(iteration)] = norm;
    else
      h.push_back(norm);
    d.x = as_eigen(u);
    const EvalStatus s = d.problem->jacobian(d.x, d.J);
    if (s != EvalStatus::ok) {
      d.failure = s;
      return -1;
    }
    Eigen::Map<Matrix>(SUNDenseMatrix_Data(J), SUNDenseMatrix_Rows(J), SUNDenseMatrix_Columns(J)) =
        d.J;
    return 0;
  } catch (...) {
    d.failure = EvalStatus::failed;
    return -1;
  }
}

void error_callback(int, const char* module, const char* function, char* message, void* user_data) {
  auto& d = *static_cast<CallbackData*>(user_data);
  d.error_message = fmt::format("{} {}: {}", module ? module : "", function ? function : "",
                                message ? message : "");
}

// KINSOL's settings for one solve: the callbacks on data, the tolerances and iteration budget
// of options, exact Newton. The first flag that is not KIN_SUCCESS, or KIN_SUCCESS.
int configure(void* mem, CallbackData& data, N_Vector u, SUNLinearSolver LS, SUNMatrix A,
              const NewtonOptions& options) {
  int flag = KINSetErrHandlerFn(mem, error_callback, &data);
  if (flag == KIN_SUCCESS) flag = KINInit(mem, residual_callback, u);
  if (flag == KIN_SUCCESS) flag = KINSetUserData(mem, &data);
  if (flag == KIN_SUCCESS) flag = KINSetLinearSolver(mem, LS, A);
  if (flag == KIN_SUCCESS) flag = KINSetJacFn(mem, jacobian_callback);
  if (flag == KIN_SUCCESS) flag = KINSetFuncNormTol(mem, options.residual_tolerance);
  if (flag == KIN_SUCCESS) flag = KINSetScaledStepTol(mem, options.step_tolerance);
  if (flag == KIN_SUCCESS) flag = KINSetNumMaxIters(mem, options.max_iterations);
  // Exact Newton: a fresh Jacobian at every iterate (KINSOL's default reuses it 10 times).
  if (flag == KIN_SUCCESS) flag = KINSetMaxSetupCalls(mem, 1);
  return flag;
}

// The corrector's status for KINSol's return flag (final_norm: ||F||_inf at the returned
// iterate, negative when not evaluable; failure: what the callbacks saw fail).
NewtonStatus status_of(int flag, double final_norm, EvalStatus failure,
                       const NewtonOptions& options) {
  switch (flag) {
    case KIN_SUCCESS:
    case KIN_INITIAL_GUESS_OK:
      return NewtonStatus::converged;
    case KIN_STEP_LT_STPTOL:
      return final_norm >= 0 && final_norm <= options.residual_tolerance ? NewtonStatus::converged
                                                                         : NewtonStatus::stalled;
    case KIN_MAXITER_REACHED:
      return NewtonStatus::max_iterations;
    case KIN_LINESEARCH_NONCONV:
    case KIN_LINESEARCH_BCFAIL:
    case KIN_MXNEWT_5X_EXCEEDED:
      return failure != EvalStatus::ok ? NewtonStatus::evaluation_failed : NewtonStatus::diverged;
    case KIN_SYSFUNC_FAIL:
    case KIN_FIRST_SYSFUNC_ERR:
    case KIN_REPTD_SYSFUNC_ERR:
      return NewtonStatus::evaluation_failed;
    default:
      return failure != EvalStatus::ok ? NewtonStatus::evaluation_failed
                                       : NewtonStatus::linear_solver_failed;
  }
}

}  // namespace

KinsolNewton::KinsolNewton(const NewtonOptions& options) : options_(options) {
  options_.validate();
}

NewtonSummary KinsolNewton::solve(const Problem& problem, Vector& x) {
  const SummaryRecorder recorder(problem);
  NewtonSummary summary;
  auto finish = [&](NewtonStatus status, std::string message) {
    return recorder.finish(summary, status, std::move(message));
  };

  const int n = problem.num_unknowns();
  const int m = problem.num_equations();
  if (m != n)
    return finish(NewtonStatus::linear_solver_failed,
                  fmt::format("kinsol needs a square system ({} equations vs {} unknowns); use "
                              "the eigen corrector or add constraints",
                              m, n));
  if (x.size() != n)
    return finish(
        NewtonStatus::evaluation_failed,
        fmt::format("kinsol: starting point has {} entries, problem has {} unknowns", x.size(), n));

  CallbackData data;
  data.problem = &problem;
  data.history = &summary.residual_history;
  data.x.resize(n);
  data.r.resize(m);

  SUNContext raw_context = nullptr;
  if (SUNContext_Create(nullptr, &raw_context) != 0)
    return finish(NewtonStatus::linear_solver_failed, "kinsol: SUNContext_Create failed");
  ContextHandle context(raw_context);
  // The solution vector wraps x's storage: KINSOL writes its iterates straight into x.
  VectorHandle u(N_VMake_Serial(n, x.data(), context.get()));
  VectorHandle u_scale(N_VNew_Serial(n, context.get()));
  VectorHandle f_scale(N_VNew_Serial(n, context.get()));
  MatrixHandle A(SUNDenseMatrix(n, n, context.get()));
  if (!u || !u_scale || !f_scale || !A)
    return finish(NewtonStatus::linear_solver_failed, "kinsol: could not allocate vectors");
  LinearSolverHandle LS(SUNLinSol_Dense(u.get(), A.get(), context.get()));
  KinsolHandle kinsol(KINCreate(context.get()));
  if (!LS || !kinsol)
    return finish(NewtonStatus::linear_solver_failed, "kinsol: could not create the solver");
  data.kinsol = kinsol.get();

  // Scaled step: relative to max(|x_j|, typical scale_j) at the starting point, as eigen does.
  const Vector scale = problem.typical_scale().cwiseAbs();
  as_eigen(u_scale.get()) = x.cwiseAbs().cwiseMax(scale).cwiseMax(1e-300).cwiseInverse();
  as_eigen(f_scale.get()).setOnes();  // so that KINSOL's fnormtol tests ||F||_inf

  void* mem = kinsol.get();
  int flag = configure(mem, data, u.get(), LS.get(), A.get(), options_);
  if (flag != KIN_SUCCESS)
    return finish(
        NewtonStatus::linear_solver_failed,
        fmt::format("kinsol: setup failed with {} ({})", flag_name(flag), data.error_message));

  const int strategy = options_.line_search ? KIN_LINESEARCH : KIN_NONE;
  flag = KINSol(mem, u.get(), strategy, u_scale.get(), f_scale.get());
  long iterations = 0;
  KINGetNumNonlinSolvIters(mem, &iterations);
  summary.iterations = static_cast<int>(iterations);

  // Final entry of the history: the norm at the returned iterate. KINSOL has usually just
  // evaluated F there; evaluate once more only when it has not.
  double final_norm = -1;
  if (data.last_norm >= 0 && data.last_x.size() == n && data.last_x == x) {
    final_norm = data.last_norm;
  } else {
    Vector r;
    if (problem.residual(x, r) == EvalStatus::ok) final_norm = r.lpNorm<Eigen::Infinity>();
  }
  summary.residual_history.resize(static_cast<std::size_t>(iterations));
  if (final_norm >= 0) summary.residual_history.push_back(final_norm);

  const std::string name = flag_name(flag);
  const std::string detail =
      data.error_message.empty() ? std::string() : fmt::format(" ({})", data.error_message);
  const std::string norm_text =
      final_norm >= 0 ? fmt::format("{:.3e}", final_norm) : std::string("not evaluable");
  const std::string message = fmt::format("kinsol: {} after {} iterations, ||F||_inf = {}{}", name,
                                          iterations, norm_text, detail);

  return finish(status_of(flag, final_norm, data.failure, options_), message);
}

}  // namespace backbone::core
