#include "problems/contact_bar/periodic_bar.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/errors.hpp"

namespace backbone::contact_bar {

using core::EvalStatus;
using core::InputError;
using core::Vector;

namespace {
const bar::BarSolver& solver_or_throw(const std::shared_ptr<const bar::BarSolver>& solver) {
  if (!solver) throw InputError("solver", "no bar solver given (null pointer)");
  return *solver;
}
}  // namespace

void OrbitOptions::validate() const {
  if (elements < 2) throw InputError("elements", fmt::format("must be >= 2 (got {})", elements));
  if (free_knots < 0 || free_knots > 1)
    throw InputError("free_knots", fmt::format("must be 0 or 1 (got {})", free_knots));
  if (free_knots == 1 && (knot_node < 0 || knot_node >= elements))
    throw InputError("knot_node", fmt::format("must be in 1..elements-1 = 1..{}, or 0 for "
                                              "round(elements/3) (got {})",
                                              elements - 1, knot_node));
  if (steps_per_period < 2 || steps_per_period % 2 != 0)
    throw InputError(
        "steps_per_period",
        fmt::format("must be even and >= 2 so that T/2 is a step (got {})", steps_per_period));
  if (test_elements != 0 && test_elements < elements + free_knots)
    throw InputError("test_elements",
                     fmt::format("must be 0 (square system) or >= elements + free_knots = {} "
                                 "(got {})",
                                 elements + free_knots, test_elements));
  if (!std::isfinite(fixed_dt) || fixed_dt < 0)
    throw InputError("fixed_dt", fmt::format("must be >= 0 (0: dt = T / steps_per_period; "
                                             "got {})",
                                             fixed_dt));
}

ContactBarOrbitProblem::ContactBarOrbitProblem(bar::BarSetup setup, const bar::BarSolver& solver,
                                               OrbitOptions options)
    : setup_(std::move(setup)), solver_(solver), options_(options) {
  options_.validate();
  setup_.u0 = bar::PiecewiseLinear::zero(setup_.material.length);
  setup_.v0 = bar::PiecewiseLinear::zero(setup_.material.length);
  setup_.validate();
  if (setup_.left.type != bar::EndType::fixed)
    throw InputError("left", fmt::format("the orbit problem needs a fixed left end (got {})",
                                         bar::to_string(setup_.left.type)));
  if (setup_.right.type == bar::EndType::fixed)
    throw InputError("right", "the orbit problem needs a contact or free right end (got fixed)");
  if (setup_.body_force != 0)
    throw InputError("body_force", fmt::format("the orbit problem is conservative without body "
                                               "force (got {})",
                                               setup_.body_force));
}

ContactBarOrbitProblem::ContactBarOrbitProblem(bar::BarSetup setup,
                                               std::shared_ptr<const bar::BarSolver> solver,
                                               OrbitOptions options)
    : ContactBarOrbitProblem(std::move(setup), solver_or_throw(solver), options) {
  owned_solver_ = std::move(solver);
}

int ContactBarOrbitProblem::reference_knot_node() const {
  if (options_.knot_node > 0) return options_.knot_node;
  const int m = static_cast<int>(std::lround(options_.elements / 3.0));
  return std::clamp(m, 1, options_.elements - 1);
}

double ContactBarOrbitProblem::gap() const {
  return setup_.right.type == bar::EndType::contact ? setup_.right.gap : 0.0;
}

double ContactBarOrbitProblem::displacement_scale() const {
  return gap() > 0 ? gap() : 1e-3 * setup_.material.length;
}

Vector ContactBarOrbitProblem::node_positions(const Vector& x) const {
  const int n = options_.elements;
  const double length = setup_.material.length;
  Vector y(n + options_.free_knots);
  if (options_.free_knots == 0) {
    for (int i = 1; i <= n; ++i) y[i - 1] = length * i / n;
    return y;
  }
  const int m = reference_knot_node();
  const double knot = x[n];
  for (int i = 1; i <= n; ++i)
    y[i - 1] = i <= m ? knot * i / m : knot + (length - knot) * (i - m) / (n - m);
  y[n] = knot;
  return y;
}

Vector ContactBarOrbitProblem::state_coordinates() const {
  const int n = options_.elements;
  const double length = setup_.material.length;
  Vector y(state_size());
  for (int i = 1; i <= n; ++i) y[i - 1] = length * i / n;
  if (options_.free_knots == 1) y[n] = length * reference_knot_node() / n;
  return y;
}

void ContactBarOrbitProblem::initial_state_samples(const Vector& x, Vector& coordinates,
                                                   Vector& values) const {
  const bar::PiecewiseLinear u0 = initial_displacement(x);
  coordinates =
      Eigen::Map<const Vector>(u0.knots().data(), static_cast<Eigen::Index>(u0.knots().size()));
  values =
      Eigen::Map<const Vector>(u0.values().data(), static_cast<Eigen::Index>(u0.values().size()));
}

bar::PiecewiseLinear ContactBarOrbitProblem::initial_displacement(const Vector& x) const {
  const int n = options_.elements;
  const Vector y = node_positions(x);
  std::vector<double> knots(n + 1), values(n + 1);
  knots[0] = 0;
  values[0] = 0;
  for (int i = 1; i <= n; ++i) {
    knots[i] = y[i - 1];
    values[i] = x[i - 1];
  }
  knots[n] = setup_.material.length;  // exactly L, whatever the rounding of the map
  return bar::PiecewiseLinear(std::move(knots), std::move(values));
}

bar::BarSetup ContactBarOrbitProblem::setup_at(const Vector& x) const {
  bar::BarSetup s = setup_;
  s.u0 = initial_displacement(x);
  s.v0 = bar::PiecewiseLinear::zero(setup_.material.length);
  return s;
}

double ContactBarOrbitProblem::time_step(double period) const {
  return options_.fixed_dt > 0 ? options_.fixed_dt : period / options_.steps_per_period;
}

double ContactBarOrbitProblem::energy(const Vector& x) const {
  const int n = options_.elements;
  const Vector y = node_positions(x);
  double sum = 0, y_prev = 0, u_prev = 0;
  for (int i = 1; i <= n; ++i) {
    const double h = (i == n ? setup_.material.length : y[i - 1]) - y_prev;
    const double strain = (x[i - 1] - u_prev) / h;
    sum += strain * strain * h;
    y_prev = y[i - 1];
    u_prev = x[i - 1];
  }
  return 0.5 * setup_.material.axial_stiffness() * sum;
}

core::Observables ContactBarOrbitProblem::observables(const Vector& x) const {
  core::Observables o = PeriodicOrbitProblem::observables(x);
  o.emplace_back("end_amplitude", std::abs(x[options_.elements - 1]));
  if (options_.free_knots == 1) o.emplace_back("knot", x[options_.elements]);
  return o;
}

Vector ContactBarOrbitProblem::typical_scale() const {
  // Displacements scale with the gap (homogeneity: only E/g0^2 matters), lengths with L,
  // the period with the travel time.
  const double length = setup_.material.length;
  Vector s = Vector::Constant(num_unknowns(), displacement_scale());
  if (options_.free_knots == 1) s[options_.elements] = length;
  s[period_index()] = setup_.material.travel_time();
  return s;
}

Vector ContactBarOrbitProblem::step_weights() const {
  // Trapezoid rule on the reference grid: sum_i w_i^2 u0_i^2 = int_0^L u0^2 dx / L for a
  // piecewise-linear u0 up to O(dx^2) (u0(0) = 0 has no unknown).
  const int n = options_.elements;
  Vector w = Vector::Ones(num_unknowns());
  w.head(n).setConstant(std::sqrt(1.0 / n));
  w[n - 1] = std::sqrt(0.5 / n);
  return w;
}

EvalStatus ContactBarOrbitProblem::compute_residual(const Vector& x, Vector& r) const {
  const int n = options_.elements;
  const int m = num_equations();  // equations = snapshot grid elements
  const double length = setup_.material.length;
  const double period = x[period_index()];
  if (!std::isfinite(period) || !(period > 0)) return EvalStatus::failed;
  if (options_.free_knots == 1) {
    const double knot = x[n];
    if (!std::isfinite(knot) || !(knot > 0) || !(knot < length)) return EvalStatus::failed;
  }
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(x[i])) return EvalStatus::non_finite;
  // A u0 through the wall is outside the admissible set: no orbit starts there.
  if (setup_.right.type == bar::EndType::contact && x[n - 1] > setup_.right.gap)
    return EvalStatus::failed;

  const bar::BarSetup s = setup_at(x);
  bar::SnapshotRequest request;
  request.elements = m;
  request.dt = time_step(period);
  request.nodal_u = false;
  bar::FieldSnapshot snap;
  const bool paper = formulation() == core::ShootingFormulation::displacement_periodicity;
  try {
    if (paper) {
      request.nodal_u = true;
      snap = solver_.snapshot(s, period, request);
    } else {
      request.projected_v = true;
      snap = solver_.snapshot(s, 0.5 * period, request);
    }
  } catch (const InputError&) {
    return EvalStatus::failed;  // the solver rejected this state (e.g. a step it cannot take)
  }
  if (!snap.ok) return EvalStatus::failed;

  r.resize(m);
  const double u_scale = displacement_scale();
  if (paper) {
    if (static_cast<int>(snap.u.size()) != m + 1) return EvalStatus::failed;
    for (int i = 1; i <= m; ++i) r[i - 1] = (s.u0(snap.x[i]) - snap.u[i]) / u_scale;
  } else {
    if (static_cast<int>(snap.v_projected.size()) != m + 1) return EvalStatus::failed;
    // (L / c) * hat-weighted average of v: a displacement, comparable with the paper's f.
    const double dx = length / m;
    const double scale = setup_.material.travel_time() / u_scale;
    for (int i = 1; i <= m; ++i) {
      const double mass = i == m ? 0.5 * dx : dx;
      r[i - 1] = scale * snap.v_projected[i] / mass;
    }
  }
  return EvalStatus::ok;
}

Vector ContactBarOrbitProblem::linear_mode_guess(int mode, double amplitude_ratio) const {
  if (mode < 1) throw InputError("mode", fmt::format("must be >= 1 (got {})", mode));
  if (!(amplitude_ratio > 0))
    throw InputError("amplitude_ratio", fmt::format("must be > 0 (got {})", amplitude_ratio));
  const double length = setup_.material.length;
  const double k = (2 * mode - 1) * std::numbers::pi / (2 * length);
  const double sign_at_end = (mode % 2 == 1) ? 1.0 : -1.0;  // sin((2k-1) pi / 2)
  const double amplitude = -amplitude_ratio * displacement_scale() * sign_at_end;  // u0(L) < 0
  Vector x(num_unknowns());
  const int n = options_.elements;
  if (options_.free_knots == 1) x[n] = length / (2 * mode - 1);  // first crest of the sine
  const Vector y = node_positions(x);
  for (int i = 1; i <= n; ++i) x[i - 1] = amplitude * std::sin(k * y[i - 1]);
  x[period_index()] = 4 * setup_.material.travel_time() / (2 * mode - 1);
  return x;
}

Vector ContactBarOrbitProblem::contact_family_guess(int mode, double amplitude_ratio) const {
  if (mode != 1 && mode != 2)
    throw InputError("mode",
                     fmt::format("the contact family is known for modes 1 and 2 (got {})", mode));
  if (!(amplitude_ratio > 0))
    throw InputError("amplitude_ratio", fmt::format("must be > 0 (got {})", amplitude_ratio));
  const double length = setup_.material.length;
  const double g0 = displacement_scale();
  const double tau = setup_.material.travel_time();
  const int n = options_.elements;
  Vector x(num_unknowns());
  if (mode == 1) {
    // u0 = eps x, end at -amplitude_ratio g0; T = (3L + g0/|eps|)/c (README.md, 'Mode 1').
    const double slope = amplitude_ratio * g0 / length;
    if (options_.free_knots == 1) x[n] = length * reference_knot_node() / n;
    const Vector y = node_positions(x);
    for (int i = 1; i <= n; ++i) x[i - 1] = -slope * y[i - 1];
    const double ratio = std::max(amplitude_ratio, 1.0);  // below grazing: linear period 4L/c
    x[period_index()] = tau * (3 + 1 / ratio);
    return x;
  }
  // Mode 2: tent of slopes +s, -s with crest at b L; |u0(L)| = (s L - g0) / 2 above grazing.
  const double ratio = std::max(amplitude_ratio, 1.0);
  const double slope = (2 * ratio + 1) * g0 / length;
  const double b = 0.25 * (1 + g0 / (slope * length));
  if (options_.free_knots == 1) x[n] = b * length;
  const Vector y = node_positions(x);
  for (int i = 1; i <= n; ++i) {
    const double yi = y[i - 1];
    x[i - 1] = yi <= b * length ? slope * yi : slope * (2 * b * length - yi);
  }
  x[period_index()] = tau * (1 + b);
  return x;
}

ReturnError return_error(const ContactBarOrbitProblem& problem, const Vector& x,
                         const bar::BarSolver& oracle, int elements) {
  const double nan = std::nan("");
  if (elements < 1) throw InputError("elements", fmt::format("must be >= 1 (got {})", elements));
  const double period = x[problem.period_index()];
  const bar::BarSetup s = problem.setup_at(x);
  bar::SnapshotRequest request;
  request.elements = elements;
  request.dt = problem.time_step(period);
  request.nodal_u = true;
  request.projected_v = true;
  const bar::FieldSnapshot snap = oracle.snapshot(s, period, request);
  if (!snap.ok || static_cast<int>(snap.u.size()) != elements + 1) return {nan, nan};
  const double dx = s.material.length / elements;
  double u_max = 0, du = 0, v_max = 0;
  for (int i = 0; i <= elements; ++i) {
    const double mass = (i == 0 || i == elements) ? 0.5 * dx : dx;
    u_max = std::max(u_max, std::abs(s.u0(snap.x[i])));
    du = std::max(du, std::abs(snap.u[i] - s.u0(snap.x[i])));
    v_max = std::max(v_max, std::abs(snap.v_projected[i] / mass));
  }
  if (!(u_max > 0)) return {nan, nan};
  return {du / u_max, s.material.travel_time() * v_max / u_max};
}

// Mode 2 closed form. With c = L = 1 and u = F(t + x) - F(t - x), let H(t) = F'(t - 1) be the
// wave arriving at x = L. Free end: H(t + 2) = -H(t) and the end moves at -2 H(t); closed
// contact: H(t + 2) = H(t) while H(t) <= 0. v0 = 0 makes H symmetric about t = 1 on [0, 2],
// H(1 +- x) = u0'(x) / 2. Take H = +h on (1 - b, 1 + b), -h elsewhere (the tent u0 of slopes
// s = 2h, -2h with crest at b). The end approaches for 2b, sticks for 1 - 3b, recedes for 2b:
// the pattern is periodic with T = 1 + b iff the approach from u0(1) = s (2b - 1) reaches g0
// in 2b, i.e. b = (1 + g0 / s) / 4, in [1/4, 1/3] (grazing at s = 3 g0). E = s^2 / 2 (EA = 1).
double mode2_frequency(const bar::Material& material, double gap, double energy) {
  const double length = material.length, ea = material.axial_stiffness();
  const double slope = std::sqrt(2 * energy / (ea * length));
  if (!(slope * length >= 3 * gap)) return std::nan("");
  const double period = (5 * length + gap / slope) / (4 * material.wave_speed());
  return 2 * std::numbers::pi / period;
}

double mode1_frequency(const bar::Material& material, double gap, double energy) {
  const double length = material.length, ea = material.axial_stiffness();
  const double slope = std::sqrt(2 * energy / (ea * length));
  if (!(slope * length >= gap)) return std::nan("");
  return 2 * std::numbers::pi * material.wave_speed() / (3 * length + gap / slope);
}

}  // namespace backbone::contact_bar
