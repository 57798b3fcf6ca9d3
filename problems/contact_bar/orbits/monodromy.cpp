#include "problems/contact_bar/orbits/monodromy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/errors.hpp"
#include "core/job_queue.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"

namespace backbone::contact_bar {

using core::EvalStatus;
using core::Matrix;
using core::Vector;

void MonodromyOptions::validate() const {
  if (elements < 0)
    throw core::InputError("stability_elements",
                           fmt::format("must be >= 0 (0: the shooting grid; got {})", elements));
  if (!(relative_step > 0 && relative_step < 1e-2))
    throw core::InputError("stability_step",
                           fmt::format("must be in (0, 1e-2) (got {})", relative_step));
  if (!(courant > 0 && courant <= 1))
    throw core::InputError("stability_courant", fmt::format("must be in (0, 1] (got {})", courant));
  if (threads < 1) throw core::InputError("threads", "must be >= 1");
}

namespace {

int grid_of(const ContactBarOrbitProblem& problem, int elements) {
  return elements > 0 ? elements : problem.options().elements;
}

// Nodal values 0, s_1..s_N on the uniform grid as a bar::PiecewiseLinear.
bar::PiecewiseLinear nodal_function(double length, const double* values, int n) {
  std::vector<double> x(static_cast<std::size_t>(n) + 1), y(x.size());
  for (int i = 0; i <= n; ++i) {
    x[static_cast<std::size_t>(i)] = length * i / n;
    y[static_cast<std::size_t>(i)] = i == 0 ? 0.0 : values[i - 1];
  }
  return bar::PiecewiseLinear(std::move(x), std::move(y));
}

// Solves M v = b for the P1 mass matrix of nodes 1..N (uniform, node 0 fixed): rows
// dx/6 [1 4 1], the last dx/6 [1 2]; symmetric positive definite and tridiagonal (Thomas).
Vector solve_mass(double length, const Vector& b) {
  const int n = static_cast<int>(b.size());
  const double h = length / n;
  const double off = h / 6;
  Vector diagonal(n), rhs = b, v(n);
  for (int i = 0; i < n; ++i) diagonal[i] = (i == n - 1 ? 2.0 : 4.0) * h / 6;
  for (int i = 1; i < n; ++i) {
    const double w = off / diagonal[i - 1];
    diagonal[i] -= w * off;
    rhs[i] -= w * rhs[i - 1];
  }
  v[n - 1] = rhs[n - 1] / diagonal[n - 1];
  for (int i = n - 2; i >= 0; --i) v[i] = (rhs[i] - off * v[i + 1]) / diagonal[i];
  return v;
}

}  // namespace

Vector full_state(const ContactBarOrbitProblem& problem, const Vector& x, int elements) {
  const int n = grid_of(problem, elements);
  const bar::BarSetup s = problem.setup_at(x);
  const double length = s.material.length;
  Vector state = Vector::Zero(2 * n);
  for (int i = 1; i <= n; ++i) state[i - 1] = s.u0(length * i / n);
  return state;
}

double full_state_time_step(const ContactBarOrbitProblem& problem, double period, int elements,
                            double courant) {
  const bar::Material& m = problem.setup_template().material;
  const double dx = m.length / grid_of(problem, elements);
  const double target = std::min(problem.time_step(period), courant * dx / m.wave_speed());
  return period / std::ceil(period / target - 1e-9);
}

EvalStatus full_state_map(const ContactBarOrbitProblem& problem, double period, double dt,
                          const Vector& state, Vector& mapped) {
  const int n = static_cast<int>(state.size() / 2);
  if (n < 1 || state.size() != 2 * n || !(period > 0)) return EvalStatus::failed;
  bar::BarSetup s = problem.setup_template();
  const double length = s.material.length;
  s.u0 = nodal_function(length, state.data(), n);
  s.v0 = nodal_function(length, state.data() + n, n);
  bar::SnapshotRequest request;
  request.elements = n;
  request.dt = dt;
  request.nodal_u = true;
  request.projected_v = true;
  bar::FieldSnapshot snap;
  try {
    snap = problem.solver().snapshot(s, period, request);
  } catch (const core::InputError&) {
    return EvalStatus::failed;
  }
  if (!snap.ok || static_cast<int>(snap.u.size()) != n + 1 ||
      static_cast<int>(snap.v_projected.size()) != n + 1)
    return EvalStatus::failed;
  mapped.resize(2 * n);
  for (int i = 1; i <= n; ++i) mapped[i - 1] = snap.u[static_cast<std::size_t>(i)];
  Vector b(n);
  for (int i = 1; i <= n; ++i) b[i - 1] = snap.v_projected[static_cast<std::size_t>(i)];
  mapped.tail(n) = solve_mass(length, b);
  return mapped.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
}

EvalStatus full_state_monodromy(const ContactBarOrbitProblem& problem, const Vector& x,
                                const MonodromyOptions& options, Matrix& M) {
  options.validate();
  const int n = grid_of(problem, options.elements);
  const double period = x[problem.period_index()];
  if (!(period > 0) || !std::isfinite(period)) return EvalStatus::failed;
  const Vector base = full_state(problem, x, n);
  const bar::Material& material = problem.setup_template().material;
  const double u_scale = std::max(base.head(n).cwiseAbs().maxCoeff(), problem.displacement_scale());
  const double h_u = options.relative_step * u_scale;
  const double h_v = h_u * material.wave_speed() / material.length;
  const double dt = full_state_time_step(problem, period, n, options.courant);
  M.resize(2 * n, 2 * n);
  std::vector<EvalStatus> status(static_cast<std::size_t>(2 * n), EvalStatus::ok);
  core::run_tasks(2 * n, options.threads, [&](int j) {
    const double h = j < n ? h_u : h_v;
    Vector plus = base, minus = base, f_plus, f_minus;
    plus[j] += h;
    minus[j] -= h;
    EvalStatus a = full_state_map(problem, period, dt, plus, f_plus);
    EvalStatus b = a == EvalStatus::ok ? full_state_map(problem, period, dt, minus, f_minus) : a;
    status[static_cast<std::size_t>(j)] = b;
    if (b == EvalStatus::ok) M.col(j) = (f_plus - f_minus) / (2 * h);
  });
  for (EvalStatus s : status)
    if (s != EvalStatus::ok) return s;
  return M.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
}

}  // namespace backbone::contact_bar
