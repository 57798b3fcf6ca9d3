#include "problems/contact_bar/orbits/grazing_limits.hpp"

#include <fmt/format.h>
#include <nlopt.h>

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/solvers/newton.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {

void GrazingLimitOptions::validate() const {
  if (elements < 4)
    throw core::InputError("elements", fmt::format("must be >= 4 (got {})", elements));
  if (steps_per_period < 2 || steps_per_period % 2 != 0)
    throw core::InputError("steps_per_period",
                           fmt::format("must be even and >= 2 (got {})", steps_per_period));
  if (!(start_distance > 0 && start_distance < 0.5))
    throw core::InputError("start_distance",
                           fmt::format("must be in (0, 0.5) (got {})", start_distance));
  if (!(tolerance > 0) || !(constraint_tolerance > 0))
    throw core::InputError("tolerance", "tolerances must be > 0");
  if (max_evaluations < 1)
    throw core::InputError("max_evaluations",
                           fmt::format("must be >= 1 (got {})", max_evaluations));
  if (mode < 2 || mode % 2 != 0)
    throw core::InputError("mode", fmt::format("must be even and >= 2 (got {})", mode));
  if (elements < 2 * mode)
    throw core::InputError("elements",
                           fmt::format("must be >= 2 mode = {} (got {})", 2 * mode, elements));
}

namespace {

// One limit's optimisation: the chart, the phase it minimises, the evaluation counts.
struct LimitProblem {
  const ContactBarOrbitProblem* problem = nullptr;
  core::Vector scale;        // x = scale .* z
  double energy = 0;         // of the energy row
  bool around_half = false;  // the phase measured: around T/2, or around t = 0
  double sign = 1;           // objective = sign * that phase's duration / (L / c)
  int evaluations = 0;
  double step = 1e-7;        // forward-difference step in z
  core::Matrix range;        // m x r: the leading left singular vectors of the rows' Jacobian
  std::vector<double> last;  // the last iterate SLSQP evaluated (NLopt itself returns the best
                             // point within the constraint tolerance, which may be the start)

  core::Vector unknowns(const double* z) const {
    core::Vector x(scale.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = scale[i] * z[i];
    return x;
  }
  // Duration of the phase [s]: closing instants within (T/4, 3T/4) or outside it. NaN when
  // the state is outside the chart or the exact simulation fails.
  double phase(const core::Vector& x) const {
    const double period = x[problem->period_index()];
    core::Vector r;
    if (!(period > 0)) return std::nan("");
    bar::BarSetup s;
    try {
      s = problem->setup_at(x);
    } catch (const core::InputError&) {
      return std::nan("");
    }
    if (s.u0(s.material.length) > s.right.gap * (1 + 1e-12)) return std::nan("");
    const exact_bar::ExactBarSolution sol(s, period);
    if (!sol.ok()) return std::nan("");
    double total = 0;
    for (const auto& c : sol.contact_intervals(exact_bar::Side::right)) {
      const double release = std::min(c.t_release, period);
      const bool middle = c.t_close > 0.25 * period && c.t_close < 0.75 * period;
      if (middle == around_half) total += release - c.t_close;
    }
    return total;
  }
  // Periodicity rows, then the energy row; false outside the chart.
  bool constraints(const core::Vector& x, core::Vector& c) const {
    core::Vector r;
    if (problem->residual(x, r) != core::EvalStatus::ok) return false;
    c.resize(r.size() + 1);
    c.head(r.size()) = r;
    c[r.size()] = (problem->energy(x) - energy) / energy;
    return c.allFinite();
  }
};

double objective(unsigned n, const double* z, double* grad, void* data) {
  auto& p = *static_cast<LimitProblem*>(data);
  ++p.evaluations;
  p.last.assign(z, z + n);
  const double tau = p.problem->setup_template().material.travel_time();
  const core::Vector x = p.unknowns(z);
  const double f = p.sign * p.phase(x) / tau;
  if (!std::isfinite(f)) return 1e3;  // outside the chart: a wall the line search backs off
  if (grad) {
    std::vector<double> w(z, z + n);
    for (unsigned j = 0; j < n; ++j) {
      w[j] += p.step;
      const double fj = p.sign * p.phase(p.unknowns(w.data())) / tau;
      grad[j] = std::isfinite(fj) ? (fj - f) / p.step : 0.0;
      w[j] = z[j];
    }
  }
  return f;
}

// All rows c(z) = [F; energy row] and their forward-difference Jacobian (row-major m x n).
bool rows(LimitProblem& p, unsigned n, const double* z, core::Vector& c, core::Matrix* jacobian) {
  if (!p.constraints(p.unknowns(z), c)) return false;
  if (!jacobian) return true;
  jacobian->resize(c.size(), n);
  std::vector<double> w(z, z + n);
  core::Vector cj;
  for (unsigned j = 0; j < n; ++j) {
    w[j] += p.step;
    const bool ok = p.constraints(p.unknowns(w.data()), cj);
    jacobian->col(j) = ok ? core::Vector((cj - c) / p.step) : core::Vector::Zero(c.size());
    w[j] = z[j];
  }
  return true;
}

// The equality constraints SLSQP sees: Q^T c(z), Q the leading left singular vectors of the
// rows' Jacobian at the start (rank r: n - 1 where the members form a curve). The rows are
// consistent but redundant (2 N test rows for N unknowns; rank n - 1 along the curve), which
// SLSQP's equality-constrained subproblem cannot take; their projection on the Jacobian's range
// has the same solutions near the start, and every limit is checked on all rows afterwards.
void equalities(unsigned m, double* result, unsigned n, const double* z, double* grad, void* data) {
  auto& p = *static_cast<LimitProblem*>(data);
  core::Vector c;
  core::Matrix J;
  if (!rows(p, n, z, c, grad ? &J : nullptr)) {
    std::fill(result, result + m, 1e3);
    if (grad) std::fill(grad, grad + static_cast<std::size_t>(m) * n, 0.0);
    return;
  }
  const core::Vector projected = p.range.transpose() * c;
  std::copy(projected.data(), projected.data() + m, result);
  if (!grad) return;
  const core::Matrix projected_jacobian = p.range.transpose() * J;
  for (unsigned i = 0; i < m; ++i)
    for (unsigned j = 0; j < n; ++j)
      grad[static_cast<std::size_t>(i) * n + j] = projected_jacobian(i, j);
}

// The rows (F and the energy row) plus the vanishing phase itself, phase / (L / c) = 0: the
// last polish of a shape-1 limit that NLopt left with a sliver of its phase. Inside the
// continuum the phase is linear in the member's position along the curve (piecewise-linear
// orbits), so Newton from that side lands on its end.
class RowsAndPhase : public core::Problem {
 public:
  RowsAndPhase(const core::Problem& rows, const LimitProblem& limit) : rows_(rows), limit_(limit) {}
  int num_unknowns() const override { return rows_.num_unknowns(); }
  int num_equations() const override { return rows_.num_equations() + 1; }
  core::Vector typical_scale() const override { return rows_.typical_scale(); }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    core::Vector f;
    const core::EvalStatus status = rows_.residual(x, f);
    if (status != core::EvalStatus::ok) return status;
    const double phase = limit_.phase(x);
    if (!std::isfinite(phase)) return core::EvalStatus::failed;
    r.resize(f.size() + 1);
    r.head(f.size()) = f;
    r[f.size()] = phase / limit_.problem->setup_template().material.travel_time();
    return core::EvalStatus::ok;
  }

 private:
  const core::Problem& rows_;
  const LimitProblem& limit_;
};

const char* nlopt_result_name(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS:
      return "success";
    case NLOPT_STOPVAL_REACHED:
      return "stopval_reached";
    case NLOPT_FTOL_REACHED:
      return "ftol_reached";
    case NLOPT_XTOL_REACHED:
      return "xtol_reached";
    case NLOPT_MAXEVAL_REACHED:
      return "maxeval_reached";
    case NLOPT_MAXTIME_REACHED:
      return "maxtime_reached";
    case NLOPT_ROUNDOFF_LIMITED:
      return "roundoff_limited";
    case NLOPT_FORCED_STOP:
      return "forced_stop";
    case NLOPT_OUT_OF_MEMORY:
      return "out_of_memory";
    case NLOPT_INVALID_ARGS:
      return "invalid_args";
    default:
      return "failure";
  }
}

OrbitOptions chart(const GrazingLimitOptions& o, const bar::Material& material,
                   const SubharmonicMember& start, int knots) {
  OrbitOptions chart;
  chart.elements = o.elements;
  chart.steps_per_period = o.steps_per_period;
  chart.start_on_wall = true;
  chart.free_knots = knots;
  chart.subharmonic_mode = o.mode;
  // As the continuum: knots on the nodes nearest the first J - 1 kinks, the last on N - 1.
  chart.knot_nodes = nearest_knot_nodes(
      o.elements, material.length,
      std::vector<double>(start.kinks.begin(), start.kinks.begin() + (o.mode - 1)));
  if (knots == o.mode) chart.knot_nodes.push_back(o.elements - 1);
  chart.test_elements = 2 * chart.state_size();
  return chart;
}

// The start in the chart's unknowns: the closed-form member (shape 1), or the member sampled on
// the one-knot chart, its first kink on the knot (shape 0).
core::Vector start_unknowns(const ContactBarOrbitProblem& problem, const SubharmonicMember& start,
                            double energy, const GrazingLimitOptions& o, bool shape_one) {
  core::Vector x0(problem.num_unknowns());
  if (shape_one) return problem.subharmonic_guess(energy, 1 - o.start_distance);
  for (int j = 0; j + 1 < o.mode; ++j)
    x0[problem.knot_index(j)] = start.kinks[static_cast<std::size_t>(j)];
  const core::Vector y = problem.node_positions(x0);
  for (int i = 1; i <= problem.options().nodal_unknowns(); ++i) x0[i - 1] = start.u0(y[i - 1]);
  x0[problem.period_index()] = start.period;
  return x0;
}

// A box around the start z (scaled units: g0, L, L/c) keeps SLSQP's first steps, taken on a
// linearisation of a piecewise-smooth map, near the curve; the limit lies well inside it (the
// knots move by start_distance (1 - 3b) L <= 0.25 start_distance L to reach it). The knots stay
// inside (0, L).
struct Box {
  std::vector<double> lower, upper;
};

Box start_box(const ContactBarOrbitProblem& problem, const core::Vector& x0,
              const std::vector<double>& z, const GrazingLimitOptions& o, int knots) {
  const std::size_t n = z.size();
  Box box{std::vector<double>(n, -HUGE_VAL), std::vector<double>(n, HUGE_VAL)};
  for (unsigned i = 0; i < n; ++i) {
    const double half_width =
        static_cast<int>(i) == problem.period_index() ? 1e-2
        : static_cast<int>(i) >= problem.options().nodal_unknowns()
            ? 2 * o.start_distance
            : 0.5 + 20 * o.start_distance * x0.cwiseAbs().maxCoeff() / problem.displacement_scale();
    box.lower[i] = z[i] - half_width;
    box.upper[i] = z[i] + half_width;
  }
  for (int j = 0; j < knots; ++j) {  // knots inside (0, L), in units of L
    box.lower[problem.knot_index(j)] = std::max(box.lower[problem.knot_index(j)], 1e-6);
    box.upper[problem.knot_index(j)] = std::min(box.upper[problem.knot_index(j)], 1 - 1e-6);
  }
  return box;
}

// One SLSQP run from z in `box`, the projection Q from the rows' Jacobian at z; `from` becomes
// the last iterate. False when z is outside the chart.
bool run_slsqp(LimitProblem& p, const GrazingLimitOptions& o, std::vector<double>& from,
               const Box& box, nlopt_result& result) {
  const unsigned n = static_cast<unsigned>(from.size());
  core::Vector c0;
  core::Matrix J0;
  if (!rows(p, n, from.data(), c0, &J0)) return false;
  const Eigen::JacobiSVD<core::Matrix> svd(J0, Eigen::ComputeThinU);
  const auto& sigma = svd.singularValues();
  int rank = 0;
  while (rank < sigma.size() && sigma[rank] > 1e-6 * sigma[0]) ++rank;
  p.range = svd.matrixU().leftCols(rank);
  p.last.clear();
  const unsigned m = static_cast<unsigned>(rank);
  nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, n);
  nlopt_set_min_objective(opt, objective, &p);
  const std::vector<double> tolerances(m, o.constraint_tolerance);
  nlopt_add_equality_mconstraint(opt, m, equalities, &p, tolerances.data());
  nlopt_set_lower_bounds(opt, box.lower.data());
  nlopt_set_upper_bounds(opt, box.upper.data());
  nlopt_set_xtol_rel(opt, o.tolerance);
  nlopt_set_maxeval(opt, o.max_evaluations);
  double value = 0;
  result = nlopt_optimize(opt, from.data(), &value);
  nlopt_destroy(opt);
  if (!p.last.empty()) from = p.last;
  return true;
}

// The polish onto all rows (least-squares Newton on F plus the energy row): NLopt stops within
// constraint_tolerance of them; the polish moves the point by about that much.
struct Polish {
  const LimitProblem& p;
  const ContactBarOrbitProblem& on_rows;  // the chart with the energy row
  core::NewtonOptions newton;
  Polish(const LimitProblem& limit, const ContactBarOrbitProblem& rows) : p(limit), on_rows(rows) {
    newton.residual_tolerance = 1e-12;
  }
  // Moves `at` (scaled) onto the rows when Newton converges.
  core::NewtonSummary operator()(std::vector<double>& at) const {
    core::Vector y = p.unknowns(at.data());
    const core::NewtonSummary s = core::make_corrector("eigen", newton)->solve(on_rows, y);
    if (s.converged())
      for (std::size_t i = 0; i < at.size(); ++i) at[i] = y[i] / p.scale[i];
    return s;
  }
};

// Shape 1's second pass from the first one's limit z, with a 100x smaller difference step in a
// box of 1e-3: the first locates the kink at the end of the curve only to the resolution of its
// gradients. Then, if a sliver of the phase around T/2 is left (two contact phases instead of
// one plus a grazing instant), Newton on the rows plus the phase.
void refine_shape_one(LimitProblem& p, const GrazingLimitOptions& o, const Box& box,
                      const Polish& polish, std::vector<double>& z, nlopt_result& result,
                      core::NewtonSummary& polished) {
  const std::size_t n = z.size();
  p.step = 1e-9;
  Box near{std::vector<double>(n), std::vector<double>(n)};
  for (unsigned i = 0; i < n; ++i)
    near.lower[i] = std::max(box.lower[i], z[i] - 1e-3),
    near.upper[i] = std::min(box.upper[i], z[i] + 1e-3);
  std::vector<double> again = z;
  nlopt_result second = NLOPT_FAILURE;
  if (run_slsqp(p, o, again, near, second)) {
    const core::NewtonSummary s = polish(again);
    if (s.converged() && second > 0) z = again, result = second, polished = s;
  }
  p.step = 1e-7;
  p.around_half = true;
  const core::Vector at = p.unknowns(z.data());
  if (p.phase(at) > 0) {
    const RowsAndPhase closing(polish.on_rows, p);
    core::Vector y = at;
    const core::NewtonSummary s = core::make_corrector("eigen", polish.newton)->solve(closing, y);
    // It stalls near the rows' round-off, the kink making the last steps oscillate: its point
    // is kept when the rows hold to 1e-10 (inside the trace's newton_tolerance, 3e-9) and the
    // phase shrank.
    core::Vector f;
    if (polish.on_rows.residual(y, f) == core::EvalStatus::ok && f.cwiseAbs().maxCoeff() <= 1e-10 &&
        p.phase(y) < p.phase(at)) {
      for (unsigned i = 0; i < n; ++i) z[i] = y[i] / p.scale[i];
      polished = s;
    }
  }
  p.around_half = false;
}

// The limit at z: its orbit, vanishing phase, residual, exact return and contact structure.
GrazingLimit describe_limit(const ContactBarOrbitProblem& problem, LimitProblem& p,
                            const std::vector<double>& z, bool shape_one, nlopt_result result,
                            int first_pass, const core::NewtonSummary& polished) {
  GrazingLimit limit;
  limit.name = shape_one ? "shape_1" : "shape_0";
  limit.free_knots = problem.options().free_knots;
  limit.x = p.unknowns(z.data());
  limit.evaluations = p.evaluations;
  limit.period = limit.x[problem.period_index()];
  limit.energy = problem.energy(limit.x);
  limit.u0 = problem.initial_displacement(limit.x);
  p.around_half = shape_one;
  limit.phase_duration = p.phase(limit.x);
  core::Vector r;
  limit.residual = problem.residual(limit.x, r) == core::EvalStatus::ok
                       ? r.cwiseAbs().maxCoeff()
                       : std::numeric_limits<double>::infinity();
  limit.return_error = return_error(problem, limit.x, exact_bar::ExactBarSolver()).worst();
  limit.structure = contact_structure(problem.setup_at(limit.x), limit.period);
  limit.ok = result > 0 && std::isfinite(limit.return_error) && limit.return_error < 1e-6;
  limit.message =
      fmt::format("nlopt slsqp: {} after {} evaluations ({} in the first pass); polish: {}",
                  nlopt_result_name(result), limit.evaluations, first_pass, polished.message);
  return limit;
}

GrazingLimit locate(const bar::BarSetup& setup, const bar::BarSolver& solver, double energy,
                    const GrazingLimitOptions& o, bool shape_one) {
  const auto started = std::chrono::steady_clock::now();
  const bar::Material& material = setup.material;
  const SubharmonicMember start =
      subharmonic_member(material, setup.right.gap, energy,
                         shape_one ? 1 - o.start_distance : o.start_distance, o.mode);
  const int knots = shape_one ? o.mode : o.mode - 1;
  const ContactBarOrbitProblem problem(setup, solver, chart(o, material, start, knots));
  const core::Vector x0 = start_unknowns(problem, start, energy, o, shape_one);
  LimitProblem p;
  p.problem = &problem;
  p.scale = problem.typical_scale().cwiseAbs();
  p.energy = energy;
  // Shape 1: maximise the phase around t = 0, which grows smoothly up to the limit and beyond
  // it (where the rows stop having solutions), rather than minimise the one around T/2, which
  // is flat (0) beyond the limit and let SLSQP stop there. Shape 0: the one-knot chart holds
  // the limit alone; minimise the phase around t = 0.
  p.around_half = false;
  p.sign = shape_one ? -1.0 : 1.0;
  const unsigned n = static_cast<unsigned>(x0.size());
  std::vector<double> z(n);
  for (unsigned i = 0; i < n; ++i) z[i] = x0[i] / p.scale[i];
  const Box box = start_box(problem, x0, z, o, knots);
  OrbitOptions polished_chart = problem.options();
  polished_chart.fixed_energy = energy;
  const ContactBarOrbitProblem on_rows(setup, solver, polished_chart);
  const Polish polish(p, on_rows);

  nlopt_result result = NLOPT_FAILURE;
  if (!run_slsqp(p, o, z, box, result)) {
    GrazingLimit failed;
    failed.name = shape_one ? "shape_1" : "shape_0";
    failed.message = "the start is outside the chart";
    return failed;
  }
  core::NewtonSummary polished = polish(z);
  const int first_pass = p.evaluations;
  if (shape_one) refine_shape_one(p, o, box, polish, z, result, polished);
  GrazingLimit limit = describe_limit(problem, p, z, shape_one, result, first_pass, polished);
  limit.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return limit;
}

}  // namespace

GrazingLimits grazing_limits(const bar::BarSetup& setup, const bar::BarSolver& solver,
                             double energy, const GrazingLimitOptions& options) {
  options.validate();
  if (setup.right.type != bar::EndType::contact || !(setup.right.gap > 0))
    throw core::InputError("right", "the grazing limits need right = contact and gap > 0");
  ContactFamily(setup.material, setup.right.gap, options.mode);
  GrazingLimits g;
  for (const bool shape_one : {true, false}) {
    // A start that SLSQP leaves for another root (the shape-0 start, its second kink cut off,
    // is not itself a solution) is retried from nearer the limit.
    GrazingLimitOptions o = options;
    GrazingLimit limit = locate(setup, solver, energy, o, shape_one);
    for (int retry = 0; retry < 2 && !limit.ok; ++retry) {
      o.start_distance /= 4;
      GrazingLimit again = locate(setup, solver, energy, o, shape_one);
      again.evaluations += limit.evaluations;
      again.seconds += limit.seconds;
      again.message += fmt::format(" (start_distance {:g} after a failed start)", o.start_distance);
      limit = std::move(again);
    }
    g.limits.push_back(std::move(limit));
  }
  // The shape-1 limit simulated by T2 against the shape-0 limit's u0.
  const GrazingLimit& one = g.limits[0];
  const GrazingLimit& zero = g.limits[1];
  g.half_period = 0.5 * one.period;
  bar::BarSetup s = setup;
  s.u0 = one.u0;
  s.v0 = bar::PiecewiseLinear::zero(setup.material.length);
  const exact_bar::ExactBarSolution sol(s, g.half_period);
  g.shift_distance = std::numeric_limits<double>::infinity();
  if (sol.ok()) {
    double du = 0, u_max = 0;
    const int samples = 2000;
    for (int i = 0; i <= samples; ++i) {
      const double x = setup.material.length * i / samples;
      u_max = std::max(u_max, std::abs(zero.u0(x)));
      du = std::max(du, std::abs(sol.u(x, g.half_period) - zero.u0(x)));
    }
    if (u_max > 0) g.shift_distance = du / u_max;
  }
  return g;
}

core::Table grazing_limit_table(const GrazingLimits& g) {
  core::Table t({"limit", "ok", "free_knots", "energy", "period", "contact_phases",
                 "grazing_instants", "min_gap", "phase_duration", "residual", "return_error",
                 "shift_distance", "evaluations"});
  for (const GrazingLimit& l : g.limits)
    t.add_row({l.name == "shape_1" ? 1.0 : 0.0, l.ok ? 1.0 : 0.0, double(l.free_knots), l.energy,
               l.period, double(l.structure.contact_phases), double(l.structure.grazing_instants),
               l.structure.min_gap, l.phase_duration, l.residual, l.return_error, g.shift_distance,
               double(l.evaluations)});
  return t;
}

}  // namespace backbone::contact_bar
