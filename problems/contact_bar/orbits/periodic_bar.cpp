#include "problems/contact_bar/orbits/periodic_bar.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "core/errors.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_solution.hpp"

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
  if (free_knots < 0 || free_knots > elements - 1)
    throw InputError("free_knots", fmt::format("must be in 0..elements-1 = 0..{} (got {})",
                                               elements - 1, free_knots));
  if (free_knots == 1 && knot_nodes.empty() && (knot_node < 0 || knot_node >= elements))
    throw InputError("knot_node", fmt::format("must be in 1..elements-1 = 1..{}, or 0 for "
                                              "round(elements/3) (got {})",
                                              elements - 1, knot_node));
  if (!knot_nodes.empty()) {
    if (static_cast<int>(knot_nodes.size()) != free_knots)
      throw InputError("knot_nodes", fmt::format("needs free_knots = {} entries (got {})",
                                                 free_knots, knot_nodes.size()));
    for (std::size_t j = 0; j < knot_nodes.size(); ++j)
      if (knot_nodes[j] < 1 || knot_nodes[j] >= elements ||
          (j > 0 && knot_nodes[j] <= knot_nodes[j - 1]))
        throw InputError("knot_nodes", fmt::format("must increase strictly inside 1..{} (entry "
                                                   "{} is {})",
                                                   elements - 1, j, knot_nodes[j]));
  }
  if (steps_per_period < 2 || steps_per_period % 2 != 0)
    throw InputError(
        "steps_per_period",
        fmt::format("must be even and >= 2 so that T/2 is a step (got {})", steps_per_period));
  if (test_elements != 0 && test_elements < state_size())
    throw InputError("test_elements",
                     fmt::format("must be 0 (square system) or >= elements + free_knots{} = {} "
                                 "(got {})",
                                 start_on_wall ? " - 1" : "", state_size(), test_elements));
  if (!std::isfinite(fixed_energy) || fixed_energy < 0)
    throw InputError("energy",
                     fmt::format("must be > 0, or 0 for no energy row (got {})", fixed_energy));
  if (subharmonic_mode < 2 || subharmonic_mode % 2 != 0)
    throw InputError("subharmonic_mode",
                     fmt::format("must be even and >= 2 (got {})", subharmonic_mode));
  if (fixed_shape >= 0 && (fixed_shape > 1 || !start_on_wall || free_knots < subharmonic_mode))
    throw InputError("shape", fmt::format("must be in [0, 1], with start_on_wall and {} free "
                                          "knots (got {})",
                                          subharmonic_mode, fixed_shape));
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
  if (options_.start_on_wall && !(setup_.right.has_wall() && gap() > 0))
    throw InputError("start_on_wall", "needs right = contact or clearance with a gap > 0");
}

ContactBarOrbitProblem::ContactBarOrbitProblem(bar::BarSetup setup,
                                               std::shared_ptr<const bar::BarSolver> solver,
                                               OrbitOptions options)
    : ContactBarOrbitProblem(std::move(setup), solver_or_throw(solver), options) {
  owned_solver_ = std::move(solver);
}

std::vector<int> ContactBarOrbitProblem::reference_knot_nodes() const {
  const int n = options_.elements, k = options_.free_knots;
  if (!options_.knot_nodes.empty()) return options_.knot_nodes;
  if (k == 1) {
    if (options_.knot_node > 0) return {options_.knot_node};
    return {std::clamp(static_cast<int>(std::lround(n / 3.0)), 1, n - 1)};
  }
  // Evenly spread, strictly increasing (K <= N - 1 leaves room for one node per knot).
  std::vector<int> m(k);
  for (int j = 0; j < k; ++j)
    m[j] = std::clamp(static_cast<int>(std::lround(static_cast<double>(j + 1) * n / (k + 1))),
                      j + 1, n - k + j);
  for (int j = 1; j < k; ++j) m[j] = std::max(m[j], m[j - 1] + 1);
  return m;
}

double ContactBarOrbitProblem::node_value(const Vector& x, int i) const {
  return i <= options_.nodal_unknowns() ? x[i - 1] : gap();
}

double ContactBarOrbitProblem::gap() const {
  return setup_.right.has_wall() ? setup_.right.gap : 0.0;
}

double ContactBarOrbitProblem::displacement_scale() const {
  return gap() > 0 ? gap() : 1e-3 * setup_.material.length;
}

// Segments between consecutive anchors (node 0 at 0, knot nodes at the knots, node N at L):
// f(i, segment, i0, i1) for node i = 1..N in segment `segment` (0..K) from anchor node i0 to i1.
template <class F>
void ContactBarOrbitProblem::for_each_mapped_node(F&& f) const {
  const int n = options_.elements, k = options_.free_knots;
  const std::vector<int> m = reference_knot_nodes();
  int segment = 0;
  for (int i = 1; i <= n; ++i) {
    while (segment < k && i > m[segment]) ++segment;
    f(i, segment, segment == 0 ? 0 : m[segment - 1], segment == k ? n : m[segment]);
  }
}

Vector ContactBarOrbitProblem::node_positions(const Vector& x) const {
  const int n = options_.elements;
  const double length = setup_.material.length;
  const int k = options_.free_knots;
  Vector y(n + k);
  if (k == 0) {
    for (int i = 1; i <= n; ++i) y[i - 1] = length * i / n;
    return y;
  }
  for_each_mapped_node([&](int i, int segment, int i0, int i1) {
    const double y0 = segment == 0 ? 0.0 : x[knot_index(segment - 1)];
    const double y1 = segment == k ? length : x[knot_index(segment)];
    y[i - 1] = i == i1 ? y1 : y0 + (y1 - y0) * (i - i0) / (i1 - i0);
  });
  for (int j = 0; j < k; ++j) y[n + j] = x[knot_index(j)];
  return y;
}

Vector ContactBarOrbitProblem::state_coordinates() const {
  const int n = options_.elements;
  const double length = setup_.material.length;
  Vector y(state_size());
  for (int i = 1; i <= options_.nodal_unknowns(); ++i) y[i - 1] = length * i / n;
  const std::vector<int> m = reference_knot_nodes();
  for (int j = 0; j < options_.free_knots; ++j) y[knot_index(j)] = length * m[j] / n;
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

void ContactBarOrbitProblem::u0_at_nodes(const Vector& x, std::vector<double>& knots,
                                         std::vector<double>& values) const {
  const int n = options_.elements;
  const Vector y = node_positions(x);
  knots.assign(static_cast<std::size_t>(n) + 1, 0.0);
  values.assign(static_cast<std::size_t>(n) + 1, 0.0);
  for (int i = 1; i <= n; ++i) {
    knots[static_cast<std::size_t>(i)] = y[i - 1];
    values[static_cast<std::size_t>(i)] = node_value(x, i);
  }
  knots.back() = setup_.material.length;  // exactly L, whatever the rounding of the map
}

bar::PiecewiseLinear ContactBarOrbitProblem::initial_displacement(const Vector& x) const {
  std::vector<double> knots, values;
  u0_at_nodes(x, knots, values);
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
    const double strain = (node_value(x, i) - u_prev) / h;
    sum += strain * strain * h;
    y_prev = y[i - 1];
    u_prev = node_value(x, i);
  }
  return 0.5 * setup_.material.axial_stiffness() * sum;
}

namespace {

// D / L of the members' contact phases (README.md, 'Subharmonic continuum of mode J') from the
// width B / L = k_J - k_J-1 of the pulse between the last two kinks: (2 - (2J - 1) B) / J
// (J = 2: 1 - 3B/2, the same bits).
double contact_fraction(int mode, double pulse) {
  const double j = mode;
  return 2.0 / j - (2.0 * j - 1) / j * pulse;
}

}  // namespace

double ContactBarOrbitProblem::subharmonic_shape(const Vector& x) const {
  const int j = options_.subharmonic_mode;
  if (options_.free_knots < j) return std::nan("");
  const double length = setup_.material.length;
  const double k1 = x[knot_index(j - 2)] / length, k2 = x[knot_index(j - 1)] / length;
  return (1 - k2) / contact_fraction(j, k2 - k1);
}

double ContactBarOrbitProblem::min_slope(const Vector& x) const {
  // Any x a continuation evaluates, knots out of order (no u0) included: NaN there.
  std::vector<double> coordinates, values;
  u0_at_nodes(x, coordinates, values);
  const double length = setup_.material.length;
  const double s = std::sqrt(2 * energy(x) / (setup_.material.axial_stiffness() * length));
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < coordinates.size(); ++i) {
    const double dx = coordinates[i] - coordinates[i - 1];
    if (!(dx >= 0)) return std::nan("");
    if (dx > 0) smallest = std::min(smallest, std::abs((values[i] - values[i - 1]) / dx));
  }
  return s > 0 ? smallest / s : std::nan("");
}

core::Observables ContactBarOrbitProblem::observables(const Vector& x) const {
  core::Observables o = PeriodicOrbitProblem::observables(x);
  if (options_.free_knots >= 2 && options_.start_on_wall && !setup_.right.has_back_wall())
    o.emplace_back("shape", subharmonic_shape(x));
  o.emplace_back("end_amplitude", std::abs(node_value(x, options_.elements)));
  o.emplace_back("min_slope", min_slope(x));
  if (options_.free_knots == 1) o.emplace_back("knot", x[knot_index(0)]);
  if (options_.free_knots > 1)
    for (int j = 0; j < options_.free_knots; ++j)
      o.emplace_back(fmt::format("knot_{}", j + 1), x[knot_index(j)]);
  return o;
}

Vector ContactBarOrbitProblem::typical_scale() const {
  // Displacements scale with the gap (homogeneity: only E/g0^2 matters), lengths with L,
  // the period with the travel time.
  const double length = setup_.material.length;
  Vector s = Vector::Constant(num_unknowns(), displacement_scale());
  for (int j = 0; j < options_.free_knots; ++j) s[knot_index(j)] = length;
  s[period_index()] = setup_.material.travel_time();
  return s;
}

Vector ContactBarOrbitProblem::step_weights() const {
  // Trapezoid rule on the reference grid: sum_i w_i^2 u0_i^2 = int_0^L u0^2 dx / L for a
  // piecewise-linear u0 up to O(dx^2) (u0(0) = 0 has no unknown; with start_on_wall neither
  // has u0(L) = g0, so every nodal unknown is interior and the knots follow them).
  const int n = options_.elements, nodal = options_.nodal_unknowns();
  Vector w = Vector::Ones(num_unknowns());
  w.head(nodal).setConstant(std::sqrt(1.0 / n));
  if (!options_.start_on_wall) w[n - 1] = std::sqrt(0.5 / n);
  return w;
}

namespace {
// max(1, A / u_s): A = the L2 norm of u0 over the bar / sqrt(L), the step_weights() norm.
double amplitude_ratio(const ContactBarOrbitProblem& p, const Vector& x) {
  const int nodal = p.options().nodal_unknowns();
  const double amplitude = x.head(nodal).cwiseProduct(p.step_weights().head(nodal)).norm();
  const double ratio = amplitude / p.displacement_scale();
  return std::isfinite(ratio) && ratio > 1 ? ratio : 1.0;
}
}  // namespace

Vector ContactBarOrbitProblem::local_scale_factor(const Vector& x) const {
  Vector factor = Vector::Ones(num_unknowns());
  if (options_.amplitude_units)
    factor.head(options_.nodal_unknowns()).setConstant(amplitude_ratio(*this, x));
  return factor;
}

Vector ContactBarOrbitProblem::local_residual_factor(const Vector& x) const {
  if (!options_.amplitude_units) return {};
  const int m = options_.test_elements > 0 ? options_.test_elements : state_size();
  Vector factor = Vector::Ones(num_equations());
  factor.head(m).setConstant(amplitude_ratio(*this, x));
  return factor;
}

namespace {
// Pieces of [a, b] (b - a < 2L) folded into [0, L] by the mirror images at 0 and L: the point
// s of the unfolded line sits at fold(s), period 2L, fold(s) = s on [0, L].
void fold_interval(double a, double b, double length, std::vector<std::pair<double, double>>& out) {
  const double period = 2 * length;
  auto fold = [&](double s) {
    double r = std::fmod(s, period);
    if (r < 0) r += period;
    return r <= length ? r : period - r;
  };
  const double first = std::floor(a / length), last = std::floor(b / length);
  for (double k = first; k <= last; ++k) {
    const double lo = std::max(a, k * length), hi = std::min(b, (k + 1) * length);
    if (lo > hi) continue;
    const double f0 = fold(lo), f1 = fold(hi);  // fold((k + 1) L) is the end piece k reaches
    out.emplace_back(std::min(f0, f1), std::max(f0, f1));
  }
}

// What the Jacobian pattern of the shooting residual is built from: the representation grid,
// the contact events (paper formulation) and the reach of the characteristics over the
// residual's time. Shared with the `wider` pattern, which is built after jacobian_pattern
// returns, when a check asks for it.
struct PatternGeometry {
  std::vector<double> node;  // positions of the nodes 0..N (mapped by the free knots)
  bar::History events;       // paper: the run at x, every step sampled; empty otherwise
  int n = 0, nodal = 0, m = 0, equations = 0;  // elements, nodal unknowns, test rows, rows
  std::vector<int> knot_and_period_columns;    // dense in every row
  double length = 0, c = 0;
  double reach = 0;         // c T (paper) or c T / 2 (regular)
  double test_element = 0;  // L / m
  bool paper = false;
};

// The pattern with every support widened by `margin` on either side.
core::JacobianPattern pattern_with_margin(const PatternGeometry& g, double margin) {
  const std::vector<double>& knot = g.node;
  const bar::History& events = g.events;
  std::vector<std::pair<double, double>> pieces;
  // Unknowns k whose support [node[k], node[k + 2]] meets a folded piece.
  auto columns_meeting = [&](const std::pair<double, double>& piece, auto&& add) {
    const auto [lo, hi] = piece;
    const int first = static_cast<int>(std::lower_bound(knot.begin(), knot.end(), lo) -
                                       knot.begin());  // knot[first] >= lo
    for (int k = std::max(0, first - 2); k < g.nodal; ++k) {
      if (knot[static_cast<std::size_t>(k)] > hi) break;
      if (knot[static_cast<std::size_t>(std::min(k + 2, g.n))] >= lo) add(k);
    }
  };
  core::JacobianPattern pattern;
  pattern.row_columns.resize(static_cast<std::size_t>(g.equations));
  pattern.dense_columns = g.knot_and_period_columns;
  std::vector<char> dense(static_cast<std::size_t>(g.nodal), 0);
  for (std::size_t k = 1; k < events.t.size(); ++k) {
    const bool before = events.contact_force[k - 1] > 0, after = events.contact_force[k] > 0;
    if (before == after) continue;  // closings too: the margin of one step costs little
    pieces.clear();
    fold_interval(g.length - g.c * events.t[k] - margin, g.length - g.c * events.t[k - 1] + margin,
                  g.length, pieces);
    for (const auto& piece : pieces)
      columns_meeting(piece, [&](int col) { dense[static_cast<std::size_t>(col)] = 1; });
  }
  for (int k = 0; k < g.nodal; ++k)
    if (dense[static_cast<std::size_t>(k)]) pattern.dense_columns.push_back(k);
  for (int i = 1; i <= g.m; ++i) {
    // The test function of row i: the hat of node i (regular), the point x_i (paper).
    const double xi = g.length * i / g.m;
    const double a = (g.paper ? xi : xi - g.test_element) - margin;
    const double b = (g.paper ? xi : std::min(xi + g.test_element, g.length)) + margin;
    pieces.clear();
    fold_interval(a + g.reach, b + g.reach, g.length, pieces);
    fold_interval(a - g.reach, b - g.reach, g.length, pieces);
    if (g.paper) fold_interval(a, b, g.length, pieces);  // the u0(x_i) term
    std::vector<int>& columns = pattern.row_columns[static_cast<std::size_t>(i - 1)];
    for (const auto& piece : pieces) columns_meeting(piece, [&](int k) { columns.push_back(k); });
    std::sort(columns.begin(), columns.end());
    columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
  }
  return pattern;
}

// Nodes 0..N of the representation grid from the mapped interior positions y; false when the
// knots are out of order (the residual fails there anyway).
bool grid_nodes(const Vector& y, int n, double length, std::vector<double>& node) {
  node.assign(static_cast<std::size_t>(n) + 1, 0.0);
  for (int i = 1; i < n; ++i) node[static_cast<std::size_t>(i)] = y[i - 1];
  node[static_cast<std::size_t>(n)] = length;
  for (int i = 1; i <= n; ++i)
    if (!(node[static_cast<std::size_t>(i)] > node[static_cast<std::size_t>(i - 1)])) return false;
  return true;
}
}  // namespace

std::optional<core::JacobianPattern> ContactBarOrbitProblem::jacobian_pattern(
    const Vector& x) const {
  const std::string solver = solver_.name();
  const bool tdbem = solver == "tdbem";
  if (!tdbem && solver != "exact") return std::nullopt;
  if (path_rows_enabled_ && options_.path_rows() > 0) return std::nullopt;
  const double period = x[period_index()];
  if (!std::isfinite(period) || !(period > 0)) return std::nullopt;
  auto g = std::make_shared<PatternGeometry>();
  g->n = options_.elements;
  g->nodal = options_.nodal_unknowns();
  g->m = options_.test_elements > 0 ? options_.test_elements : state_size();
  g->equations = num_equations();
  for (int j = 0; j < options_.free_knots; ++j) g->knot_and_period_columns.push_back(knot_index(j));
  g->knot_and_period_columns.push_back(period_index());
  g->length = setup_.material.length;
  g->c = setup_.material.wave_speed();
  if (!grid_nodes(node_positions(x), g->n, g->length, g->node)) return std::nullopt;
  g->test_element = g->length / g->m;
  g->paper = formulation() == core::ShootingFormulation::displacement_periodicity;
  g->reach = g->c * (g->paper ? period : 0.5 * period);
  if (g->paper) {
    // u(x, T) also holds the displacement the free end keeps from each contact release: after
    // a release at t_r the end moves from the wall g0 by the incoming wave since t_r, so every
    // row reached from the end after t_r depends on u0 near fold(L - c t_r), the point that
    // wave started from (the velocity of the regular residual does not see that constant).
    // Those columns are dense; the contact phases come from one simulation at x, sampled at
    // every step, so t_r is known to one step.
    bar::SimulationOptions run;
    run.t_end = period;
    run.dt = time_step(period);
    run.energy = false;
    run.history_samples = static_cast<int>(std::min(1e7, std::ceil(period / run.dt) + 2));
    try {
      g->events = solver_.simulate(setup_at(x), run);
    } catch (const InputError&) {
      return std::nullopt;
    }
  }
  // Margin. The bare supports (plus one test element against the rounding of the folded
  // images at element boundaries) hold every entry where u0 is linear between its kinks, as
  // on the closed-form orbits of the branch: the TD-BEM's interpolation over a step is exact
  // there. Off them (a rough u0: Newton's first iterates, the rank report's probes) the
  // TD-BEM, which takes the end tractions constant over a step and interpolates the end
  // histories between its knots, reads u0 over one step c dt on either side of each image (at
  // 40 steps per period, 13 elements at N = 160), with entries as large as the largest
  // (tests/problems/contact_bar/test_jacobian_pattern.cpp). So the bare supports come first,
  // checked to 1e-4 of each row's size instead of the default 1e-3 (above what the check's
  // finite differences and kinks leave on a complete pattern,
  // problems/contact_bar/orbits/README.md, section 'Jacobian pattern'), and the c dt margin is
  // their `wider` pattern, built only for the Jacobians whose check fails: the bare supports take
  // fewer residuals. The exact solver follows the characteristics exactly: the bare supports are
  // its structural pattern. Without free knots, the exact solver's bare supports and the TD-BEM's c
  // dt margin hold every entry, so a check that fails on them is a kink of F (a contact event moved
  // by the check's step): structural, kept by a corrector (core/problem.hpp), which spares the rank
  // report's probes a column-by-column Jacobian each. With free knots (the subharmonic
  // members) they are not: a kept pattern there stalls the probes of
  // SubharmonicRepresentation.VerifiedDimensionIsTwo where column-by-column Jacobians converge.
  const bool structural = options_.free_knots == 0;
  core::JacobianPattern pattern = pattern_with_margin(*g, g->test_element);
  if (!tdbem) {
    pattern.structural = structural;
    return pattern;
  }
  pattern.check_tolerance = 1e-4;
  const double wide = g->test_element + g->c * time_step(period);
  std::shared_ptr<const PatternGeometry> shared = std::move(g);
  pattern.wider = [shared, wide, structural] {
    core::JacobianPattern margin = pattern_with_margin(*shared, wide);
    margin.structural = structural;
    return margin;
  };
  return pattern;
}

EvalStatus ContactBarOrbitProblem::monodromy(const Vector& x, core::Matrix& M) const {
  if (monodromy_options_.representation == MonodromyOptions::Representation::grid)
    return full_state_monodromy(*this, x, monodromy_options_, M);
  const exact_bar::FrontMonodromy fronts = orbit_front_monodromy(*this, x);
  if (!fronts.ok) return EvalStatus::failed;
  M = fronts.K;
  return EvalStatus::ok;
}

core::FloquetStructure ContactBarOrbitProblem::floquet_structure() const {
  if (monodromy_options_.representation == MonodromyOptions::Representation::grid)
    return {2, true, false};
  return {1, true, true};
}

EvalStatus ContactBarOrbitProblem::admissible(const Vector& x) const {
  const double period = x[period_index()];
  if (!std::isfinite(period) || !(period > 0)) return EvalStatus::failed;
  // Knots stay ordered inside (0, L): a crossing is outside the representation.
  double previous = 0;
  for (int j = 0; j < options_.free_knots; ++j) {
    const double knot = x[knot_index(j)];
    if (!std::isfinite(knot) || !(knot > previous)) return EvalStatus::failed;
    previous = knot;
  }
  if (options_.free_knots > 0 && !(previous < setup_.material.length)) return EvalStatus::failed;
  for (int i = 0; i < options_.nodal_unknowns(); ++i)
    if (!std::isfinite(x[i])) return EvalStatus::non_finite;
  // A u0 through a wall is outside the admissible set: no orbit starts there.
  const double end = node_value(x, options_.elements);
  if (setup_.right.has_wall() && end > setup_.right.gap) return EvalStatus::failed;
  if (setup_.right.has_back_wall() && end < -setup_.right.gap_back) return EvalStatus::failed;
  return EvalStatus::ok;
}

EvalStatus ContactBarOrbitProblem::compute_residual(const Vector& x, Vector& r) const {
  const int m = options_.test_elements > 0 ? options_.test_elements : state_size();  // grid
  const double length = setup_.material.length;
  const double period = x[period_index()];
  if (const EvalStatus status = admissible(x); status != EvalStatus::ok) return status;

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

  const int rows = path_rows_enabled_ ? options_.path_rows() : 0;
  r.resize(m + rows);
  int row = m;
  if (rows > 0 && options_.fixed_energy > 0)
    r[row++] = (energy(x) - options_.fixed_energy) / options_.fixed_energy;
  if (rows > 0 && options_.fixed_shape >= 0) {
    const int j = options_.subharmonic_mode;
    const double k1 = x[knot_index(j - 2)] / length, k2 = x[knot_index(j - 1)] / length;
    // In units of g0 like the residual rows (a knot moved by dk moves u0 by about s dk): in
    // units of L the row weighs 1e-3 of them and the rank report counts it as null.
    r[row++] = (1 - k2 - options_.fixed_shape * contact_fraction(j, k2 - k1)) * length /
               displacement_scale();
  }
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

bool ContactBarOrbitProblem::exact_jacobian_applies() const {
  if (!options_.exact_jacobian) return false;
  if (formulation() != core::ShootingFormulation::half_period_velocity) return false;
  if (path_rows_enabled_ && options_.path_rows() > 0) return false;
  return exact_jacobian_applies_to_solver();
}

bool ContactBarOrbitProblem::exact_jacobian_applies_to_solver() const {
  if (solver_.name() == "exact") return true;
  const auto* tdbem = dynamic_cast<const TdbemSolver*>(&solver_);
  return tdbem && tdbem->method() == ContactMethod::event;
}

bool ContactBarOrbitProblem::tdbem_jacobian_applies() const {
  const auto* tdbem = dynamic_cast<const TdbemSolver*>(&solver_);
  return options_.tdbem_jacobian && tdbem && tdbem->method() == ContactMethod::event &&
         formulation() == core::ShootingFormulation::half_period_velocity &&
         options_.free_knots == 0 && !options_.start_on_wall &&
         !(path_rows_enabled_ && options_.path_rows() > 0);
}

std::string ContactBarOrbitProblem::jacobian_description() const {
  if (tdbem_jacobian_applies()) return "tdbem";
  if (options_.tdbem_jacobian)
    return exact_description() +
           " (tdbem applies to the TD-BEM's event march, the regular formulation and a uniform "
           "grid away from the wall, without path rows)";
  return exact_description();
}

bool ContactBarOrbitProblem::jacobian_exact() const {
  return tdbem_jacobian_applies() || exact_jacobian_applies();
}

std::string ContactBarOrbitProblem::exact_description() const {
  if (exact_jacobian_applies()) return "exact";
  if (!options_.exact_jacobian) return "differences";
  std::vector<std::string> reasons;
  if (formulation() != core::ShootingFormulation::half_period_velocity)
    reasons.emplace_back("exact applies to the regular formulation");
  if (!exact_jacobian_applies_to_solver())
    reasons.emplace_back("exact applies with the exact solver or the TD-BEM's event march");
  if (!reasons.empty()) return fmt::format("differences ({})", fmt::join(reasons, "; "));
  // Only the path rows stand in the way: F alone (without_path_rows) takes the exact one.
  return "differences for the curve (path rows); exact for F alone (rank reports, atlas)";
}

ContactBarOrbitProblem ContactBarOrbitProblem::without_path_rows() const {
  ContactBarOrbitProblem alone = *this;
  alone.set_path_rows(false);
  return alone;
}

EvalStatus ContactBarOrbitProblem::tdbem_jacobian(const Vector& x, core::Matrix& J) const {
  if (!tdbem_jacobian_applies()) return EvalStatus::failed;
  if (const EvalStatus status = admissible(x); status != EvalStatus::ok) return status;
  const int n = options_.elements, unknowns = num_unknowns();
  const int m = options_.test_elements > 0 ? options_.test_elements : state_size();
  const double length = setup_.material.length, period = x[period_index()];
  const double c = setup_.material.wave_speed();
  std::vector<double> nodes, test_nodes;
  for (int i = 0; i <= n; ++i) nodes.push_back(length * i / n);
  for (int i = 0; i <= m; ++i) test_nodes.push_back(length * i / m);
  std::optional<TdbemMarch> march;
  try {
    march.emplace(setup_at(x), time_step(period), ContactMethod::event,
                  TangentDirections{nodes, false});
  } catch (const InputError&) {
    return EvalStatus::failed;
  }
  if (!march->advance_to(0.5 * period)) return EvalStatus::failed;
  const core::Matrix V = march->tangent_projected_velocity(test_nodes);  // (m + 1) x n
  std::vector<double> u(test_nodes.size());
  for (std::size_t i = 0; i < test_nodes.size(); ++i) u[i] = march->displacement(test_nodes[i]);
  const double dx = length / m, end_strain = march->strain(length);
  const double scale = setup_.material.travel_time() / displacement_scale();
  const int rows = path_rows_enabled_ ? options_.path_rows() : 0;
  J = core::Matrix::Zero(m + rows, unknowns);
  for (int i = 1; i <= m; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double mass = i == m ? 0.5 * dx : dx;
    J.row(i - 1).head(n) = scale / mass * V.row(i);
    // int u_x psi_i' dx: psi_i rises over the element before node i and falls over the one after.
    double ux_dpsi = (u[k] - u[k - 1]) / dx;
    if (i < m) ux_dpsi -= (u[k + 1] - u[k]) / dx;
    const double dv_dt = c * c * ((i == m ? end_strain : 0.0) - ux_dpsi);
    J(i - 1, period_index()) = 0.5 * scale / mass * dv_dt;
  }
  return J.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
}

// The regular residual r_i = (L/c) / u_s int v(x, T/2) psi_i dx / m_i differentiated through
// the exact solution (exact_bar, 'Tangent'): the unknowns move u0's knots (the free knots map
// the grid) and values, and T moves the instant T/2.
EvalStatus ContactBarOrbitProblem::compute_jacobian(const Vector& x, core::Matrix& J) const {
  if (tdbem_jacobian_applies()) return tdbem_jacobian(x, J);
  if (!exact_jacobian_applies()) return PeriodicOrbitProblem::compute_jacobian(x, J);
  const int n = options_.elements, k = options_.free_knots, unknowns = num_unknowns();
  const int m = options_.test_elements > 0 ? options_.test_elements : state_size();
  const double length = setup_.material.length, period = x[period_index()];
  if (const EvalStatus status = admissible(x); status != EvalStatus::ok) return status;
  exact_bar::InitialTangent seed;
  seed.d_knot.assign(static_cast<std::size_t>(n) + 1, exact_bar::Sensitivity(unknowns));
  seed.d_value.assign(static_cast<std::size_t>(n) + 1, exact_bar::Sensitivity(unknowns));
  for (int i = 1; i <= options_.nodal_unknowns(); ++i) seed.d_value[i].insert(i - 1) = 1;
  // Node i < N moves with the knots at its anchors (node_positions); node N stays at L.
  for_each_mapped_node([&](int i, int segment, int i0, int i1) {
    if (i == n) return;
    const double w = static_cast<double>(i - i0) / (i1 - i0);
    if (segment > 0 && i != i1) seed.d_knot[i].insert(knot_index(segment - 1)) = 1 - w;
    if (segment < k) seed.d_knot[i].insert(knot_index(segment)) = i == i1 ? 1.0 : w;
  });
  exact_bar::ExactBarSolution solution(setup_at(x), 0.5 * period, std::move(seed));
  if (!solution.ok()) return EvalStatus::failed;
  const exact_bar::ProjectedVelocityTangent d =
      solution.projected_velocity_tangent(0.5 * period, m);
  const double dx = length / m;
  const double scale = setup_.material.travel_time() / displacement_scale();
  const int rows = path_rows_enabled_ ? options_.path_rows() : 0;
  Vector factor = Vector::Constant(m, scale / dx);
  factor[m - 1] *= 2;  // the last hat is half
  J.resize(m + rows, unknowns);
  J.topRows(m) = factor.asDiagonal() * d.d_p.middleCols(1, m).transpose();
  J.col(period_index()).head(m) = 0.5 * factor.cwiseProduct(d.d_t.segment(1, m));
  J.bottomRows(rows).setZero();
  return J.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
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
  const std::vector<int> m = reference_knot_nodes();
  for (int j = 0; j < options_.free_knots; ++j) x[knot_index(j)] = length * m[j] / n;
  if (options_.free_knots == 1) x[knot_index(0)] = length / (2 * mode - 1);  // first crest
  const Vector y = node_positions(x);
  for (int i = 1; i <= options_.nodal_unknowns(); ++i)
    x[i - 1] = amplitude * std::sin(k * y[i - 1]);
  x[period_index()] = 4 * setup_.material.travel_time() / (2 * mode - 1);
  return x;
}

Vector ContactBarOrbitProblem::contact_family_guess(int mode, double amplitude_ratio) const {
  if (mode < 1) throw InputError("mode", fmt::format("must be >= 1 (got {})", mode));
  if (!(amplitude_ratio > 0))
    throw InputError("amplitude_ratio", fmt::format("must be > 0 (got {})", amplitude_ratio));
  const double length = setup_.material.length;
  const double g0 = displacement_scale();
  const double tau = setup_.material.travel_time();
  const int n = options_.elements;
  Vector x(num_unknowns());
  if (options_.start_on_wall)
    throw InputError("start_on_wall", "the modes start at rest away from the wall");
  const std::vector<int> m = reference_knot_nodes();
  for (int j = 0; j < options_.free_knots; ++j) x[knot_index(j)] = length * m[j] / n;
  if (mode == 1) {
    // u0 = eps x, end at -amplitude_ratio g0; T = (3L + g0/|eps|)/c (README.md, 'Mode 1').
    const double slope = amplitude_ratio * g0 / length;
    const Vector y = node_positions(x);
    for (int i = 1; i <= n; ++i) x[i - 1] = -slope * y[i - 1];
    const double ratio = std::max(amplitude_ratio, 1.0);  // below grazing: linear period 4L/c
    x[period_index()] = tau * (3 + 1 / ratio);
    return x;
  }
  if (mode >= 3) return mode_guess(mode, std::max(amplitude_ratio, 1.0), x);
  // Mode 2: tent of slopes +s, -s with crest at b L; |u0(L)| = (s L - g0) / 2 above grazing.
  const double ratio = std::max(amplitude_ratio, 1.0);
  const double slope = (2 * ratio + 1) * g0 / length;
  const double b = 0.25 * (1 + g0 / (slope * length));
  if (options_.free_knots >= 1) {
    // The crest on the knot whose reference position is nearest b L, the others where they are.
    int nearest = 0;
    for (int j = 1; j < options_.free_knots; ++j)
      if (std::abs(x[knot_index(j)] - b * length) < std::abs(x[knot_index(nearest)] - b * length))
        nearest = j;
    x[knot_index(nearest)] = b * length;
    for (int j = 1; j < options_.free_knots; ++j)
      if (!(x[knot_index(j)] > x[knot_index(j - 1)]))
        throw InputError("knot_nodes", "the mode-2 crest does not fit between the other knots");
  }
  const Vector y = node_positions(x);
  for (int i = 1; i <= n; ++i) {
    const double yi = y[i - 1];
    x[i - 1] = yi <= b * length ? slope * yi : slope * (2 * b * length - yi);
  }
  x[period_index()] = tau * (1 + b);
  return x;
}

// Mode J >= 3 (README.md, 'Mode J'): |u0(L)| = (s L - (J - 1) g0) / J = ratio g0, so
// s = (J ratio + J - 1) g0 / L; with J - 1 free knots its kinks sit on them (u0 held exactly),
// with none u0 is sampled at the nodes (to O(dx)). x holds the reference knot positions.
Vector ContactBarOrbitProblem::mode_guess(int mode, double ratio, Vector x) const {
  const double length = setup_.material.length, g0 = gap();
  const double s = (mode * ratio + mode - 1) * g0 / length;
  const double energy = 0.5 * setup_.material.axial_stiffness() * length * s * s;
  const ContactFamily family(setup_.material, g0, mode);
  const std::vector<double> kinks = family.kinks(energy);
  if (options_.free_knots == mode - 1) {
    for (int j = 0; j < options_.free_knots; ++j) x[knot_index(j)] = kinks[j];
  } else if (options_.free_knots > 0) {
    throw InputError("free_knots", fmt::format("mode {} has {} kinks: free_knots {} or 0 (got {})",
                                               mode, mode - 1, mode - 1, options_.free_knots));
  }
  const bar::PiecewiseLinear u0 = family.u0(energy);
  const Vector y = node_positions(x);
  for (int i = 1; i <= options_.elements; ++i) x[i - 1] = u0(y[i - 1]);
  x[period_index()] = family.period(energy);
  return x;
}

Vector ContactBarOrbitProblem::subharmonic_guess(double energy, double shape) const {
  const int mode = options_.subharmonic_mode;
  if (!options_.start_on_wall || options_.free_knots < mode)
    throw InputError("free_knots", fmt::format("the subharmonic members start on the wall "
                                               "(start_on_wall) and have {} kinks (free_knots "
                                               ">= {})",
                                               mode, mode));
  if (!(shape > 0 && shape <= 1))
    throw InputError("shape", fmt::format("must be in (0, 1] (got {}): at 0 the second kink "
                                          "reaches x = L",
                                          shape));
  const SubharmonicMember member = subharmonic_member(setup_.material, gap(), energy, shape, mode);
  const double length = setup_.material.length;
  const int n = options_.elements;
  Vector x(num_unknowns());
  const std::vector<int> m = reference_knot_nodes();
  for (int j = 0; j < options_.free_knots; ++j) x[knot_index(j)] = length * m[j] / n;
  for (int j = 0; j < mode; ++j) x[knot_index(j)] = member.kinks[static_cast<std::size_t>(j)];
  for (int j = 1; j < options_.free_knots; ++j)
    if (!(x[knot_index(j)] > x[knot_index(j - 1)]))
      throw InputError("knot_nodes", "the subharmonic kinks do not fit between the other knots");
  const Vector y = node_positions(x);
  for (int i = 1; i <= options_.nodal_unknowns(); ++i) x[i - 1] = member.u0(y[i - 1]);
  x[period_index()] = member.period;
  return x;
}

Vector ContactBarOrbitProblem::clearance_guess(int mode, double energy) const {
  const bar::End& end = setup_.right;
  if (!end.has_back_wall())
    throw InputError("right_end", "the clearance modes need right_end = clearance");
  const ClearanceMode family(setup_.material, end.gap, end.gap_back, mode);
  if (!options_.start_on_wall || options_.free_knots != mode)
    throw InputError("free_knots", fmt::format("clearance mode {} starts on the front wall "
                                               "(start_on_wall) with {} kinks on {} free knots "
                                               "(got {})",
                                               mode, mode, mode, options_.free_knots));
  const std::vector<double> kinks = family.kinks(energy);  // InputError below grazing
  Vector x(num_unknowns());
  for (int j = 0; j < mode; ++j) x[knot_index(j)] = kinks[static_cast<std::size_t>(j)];
  const bar::PiecewiseLinear u0 = family.u0(energy);
  const Vector y = node_positions(x);
  for (int i = 1; i <= options_.nodal_unknowns(); ++i) x[i - 1] = u0(y[i - 1]);
  x[period_index()] = family.period(energy);
  return x;
}

std::vector<int> nearest_knot_nodes(int elements, double length, const std::vector<double>& at) {
  const int k = static_cast<int>(at.size());
  if (k > elements - 1)
    throw InputError("free_knots", fmt::format("{} knots need at least {} elements (got {})", k,
                                               k + 1, elements));
  std::vector<int> m(at.size());
  for (int j = 0; j < k; ++j)
    m[j] = std::clamp(static_cast<int>(std::lround(at[j] / length * elements)), j + 1,
                      elements - k + j);
  for (int j = 1; j < k; ++j) m[j] = std::max(m[j], m[j - 1] + 1);
  return m;
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

}  // namespace backbone::contact_bar
