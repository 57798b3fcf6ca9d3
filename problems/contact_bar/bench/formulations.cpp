// Benchmark formulations (bench.hpp): the paper's shooting residual f = u0 - u(T) against the
// regular half-period velocity residual (problems/contact_bar/README.md), on the same exact
// orbits of the contact family.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "continuation/methods/natural.hpp"
#include "core/io/plot.hpp"
#include "core/io/table.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "core/orbits/periodic_orbit.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/newton.hpp"
#include "problems/contact_bar/bench/cases.hpp"
#include "problems/contact_bar/bench/metrics.hpp"
#include "problems/contact_bar/bench/support.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"

namespace backbone::contact_bar {

namespace {

const double nan = std::numeric_limits<double>::quiet_NaN();

// End amplitudes (ratio * g0) along each branch, from grazing to E ~ 1e-2 J, the top of the
// traced range: mode 1 E = (ratio g0)^2 / 2 (5e-3 J at 100), mode 2 E = ((2 ratio + 1) g0)^2 / 2
// (9.9e-3 J at 70).
struct FormulationBranch {
  int mode;
  std::vector<double> ratios;
};
const std::vector<FormulationBranch> formulation_branches{{1, {1.05, 2, 10, 100}},
                                                          {2, {1.05, 2, 10, 70}}};
const std::vector<std::pair<std::string, core::ShootingFormulation>> formulation_names{
    {"regular", core::ShootingFormulation::half_period_velocity},
    {"paper", core::ShootingFormulation::displacement_periodicity}};
// The start of both formulations: x* plus start_u0_perturbation g0 sin(3 i) on u0 entry i
// (a fixed pattern, alternating from node to node) and start_period_perturbation relative on T;
// the knot stays. 1e-3 g0 keeps the pattern's strain, 2 * 1e-3 g0 / dx = 0.04 g0 / L, small
// against the grazing strain g0 / L: ten times larger, it is 40% of it, and both formulations
// leave the family at A = 1.05 g0.
const double start_u0_perturbation = 1e-3, start_period_perturbation = 1e-3;
const double formulation_tolerance_metres = 1e-13;  // Newton: ||F||_inf in metres
const int formulation_max_iterations = 30;
// The trace's contact-bar settings (problems/contact_bar/README.md, shooting keys): residual
// sampled on 2x as many test functions as unknowns, rank threshold 1e-5 relative.
constexpr int formulation_oversampling = 2;
constexpr double formulation_rank_threshold = 1e-5;

// Newton on [F; E - E*] (energy fixed: both formulations aim at x* itself), one iteration per
// solve() so that every iterate is measured. The eigen corrector keeps no state between calls
// and applies the same tests after each iteration, so the iterates are those of one solve().
struct NewtonTrace {
  core::NewtonStatus status = core::NewtonStatus::max_iterations;
  int iterations = 0;
  std::vector<double> shooting_residual;  // ||F||_inf [m] at the start and after each iteration
  std::vector<double> energy_error;       // |E - E*| [J]
  std::vector<double> u0_error;           // relative_u0_distance to x*
  double seconds = 0;
};

NewtonTrace trace_newton(const ContactBarOrbitProblem& problem, const core::Vector& exact,
                         double unit, core::Vector& x) {
  const double energy = problem.energy(exact);
  const continuation::ParameterConstraintSystem system(
      problem, continuation::NaturalParameter::of_observable("energy"), energy);
  core::NewtonOptions options;
  options.residual_tolerance = formulation_tolerance_metres / unit;  // problem's units
  options.max_iterations = 1;
  const auto newton = core::make_corrector("eigen", options);
  NewtonTrace trace;
  auto record = [&] {
    core::Vector r;
    trace.shooting_residual.push_back(
        problem.residual(x, r) == core::EvalStatus::ok ? unit * r.lpNorm<Eigen::Infinity>() : nan);
    trace.energy_error.push_back(std::abs(problem.energy(x) - energy));
    trace.u0_error.push_back(relative_u0_distance(problem, x, exact));
  };
  record();
  trace.seconds = bench::seconds_of([&] {
    while (trace.iterations < formulation_max_iterations) {
      const core::NewtonSummary s = newton->solve(system, x);
      if (s.iterations == 0) {  // already converged at the start
        trace.status = s.status;
        return;
      }
      ++trace.iterations;
      record();
      if (s.status != core::NewtonStatus::max_iterations) {
        trace.status = s.status;
        return;
      }
    }
  });
  return trace;
}

// Rank report of the shooting Jacobian (2N equations, N + 1 unknowns) as the continuation makes
// it (continuation/internal/point_recorder.cpp: the problem's forward-difference Jacobian, relative
// threshold 1e-8, candidate null directions verified by re-correction), and the same with an
// absolute floor at the measured uncertainty of that Jacobian, ||J_forward - J_central||_2
// (Weyl: singular values below it cannot be told from zero), and the central-difference
// Jacobian at the relative threshold (problems/contact_bar/README.md). At the
// paper's double root the period column is that uncertain: v(., T) jumps at T, so one-sided
// differences give -v(T+), central ones its mean, zero (rank_report.hpp on absolute_threshold).
struct RankColumns {
  core::RankReport relative, absolute, central;  // central: relative threshold, J_central
  double period_column_forward = nan, period_column_central = nan, uncertainty = nan;
  double sigma_min(int k) const {  // k-th smallest singular value, 1-based
    const Eigen::Index m = relative.singular_values.size();
    return m >= k ? relative.singular_values[m - k] : nan;
  }
  double central_sigma_min_relative() const {
    const Eigen::Index m = central.singular_values.size();
    return m > 0 ? central.singular_values[m - 1] / central.singular_values[0] : nan;
  }
};

RankColumns rank_columns(const core::PeriodicOrbitProblem& problem, const core::Vector& x) {
  RankColumns c;
  core::Matrix forward, central;
  core::FiniteDifferenceOptions central_differences;
  central_differences.scheme = core::FiniteDifferenceOptions::Scheme::central;
  if (problem.jacobian(x, forward) != core::EvalStatus::ok ||
      core::finite_difference_jacobian(problem, x, central, central_differences) !=
          core::EvalStatus::ok)
    return c;
  const int period = problem.period_index();
  c.period_column_forward = forward.col(period).lpNorm<Eigen::Infinity>();
  c.period_column_central = central.col(period).lpNorm<Eigen::Infinity>();
  c.uncertainty = Eigen::JacobiSVD<core::Matrix>(forward - central).singularValues()[0];
  // The continuation's verifier (continuation/internal/point_recorder.cpp): default VerifyOptions,
  // its cut-off the rank threshold.
  const core::VerifyOptions verify;
  core::RankOptions absolute;
  absolute.absolute_threshold = c.uncertainty;
  core::RankOptions relative;
  relative.relative_threshold = formulation_rank_threshold;
  absolute.relative_threshold = formulation_rank_threshold;
  const auto verifier = core::make_verifier(verify, relative);
  c.relative = core::rank_report(forward, relative);
  c.absolute = core::rank_report(forward, absolute);
  c.central = core::rank_report(central, relative);
  for (core::RankReport* report : {&c.relative, &c.absolute, &c.central})
    core::verify_null_directions(problem, x, *verifier, verify, *report);
  return c;
}

// The three tables of the case: formulations.csv (one row per orbit and formulation),
// formulations_history.csv (one row per Newton iterate) and the screen's summary.
struct FormulationTables {
  core::Table table, history, screen;
  FormulationTables();
};

FormulationTables::FormulationTables()
    : history({"mode", "amplitude_ratio", "formulation", "iteration", "residual", "energy_error",
               "u0_error"}),
      screen({"mode", "A/g0", "form", "status", "it", "|F| [m]", "order_F", "order_err", "u0_err",
              "T_err", "return_err", "smin/smax", "null/ver", "abs", "central", "x*: smin/smax"}) {
  // Columns by group: the orbit and the start; the Newton run; where it ended; rank reports.
  std::vector<std::string> columns;
  for (const std::vector<std::string>& group :
       {std::vector<std::string>{"formulation", "status", "mode", "amplitude_ratio", "energy",
                                 "exact_residual", "exact_sigma_min_relative", "exact_nullity",
                                 "start_residual", "start_u0_error"},
        {"iterations", "final_residual", "energy_error", "residual_order", "residual_ratio"},
        {"u0_error", "error_order", "error_ratio", "period_error", "knot_error", "return_error_u",
         "return_error_v"},
        {"period_column_forward", "period_column_central", "jacobian_uncertainty"},
        {"sigma_min_1", "sigma_min_2", "sigma_min_3", "sigma_max", "threshold", "nullity",
         "verified"},
        {"threshold_absolute", "nullity_absolute", "verified_absolute"},
        {"central_sigma_min_relative", "nullity_central", "verified_central"},
        {"residual_unit", "seconds"}})
    columns.insert(columns.end(), group.begin(), group.end());
  table = core::Table(columns);
}

// The shooting problem of one branch: 20 elements, 40 steps per period, the residual on
// formulation_oversampling times as many test functions as unknowns.
OrbitOptions formulation_orbit_options(int mode) {
  OrbitOptions options;
  options.elements = 20;
  options.steps_per_period = 40;
  options.free_knots = mode == 2 ? 1 : 0;  // mode 2: its crest is a free knot
  options.test_elements = formulation_oversampling * (options.elements + options.free_knots);
  return options;
}

// One exact orbit x* of a branch, the perturbed start both formulations begin from, and the
// round-off floors of its observed rates.
struct ExactOrbit {
  int mode = 0;
  double ratio = 0;
  core::Vector exact, start;
  double energy = 0, unit = 0;  // unit: metres per residual unit
  double residual_floor = 0, error_floor = 0;
};

ExactOrbit exact_orbit(ContactBarOrbitProblem& problem, int mode, double ratio, double gap) {
  const OrbitOptions& options = problem.options();
  ExactOrbit o;
  o.mode = mode;
  o.ratio = ratio;
  o.exact = problem.contact_family_guess(mode, ratio);
  o.energy = problem.energy(o.exact);
  o.unit = residual_unit(problem, o.exact);
  o.start = o.exact;
  for (int i = 0; i < options.elements; ++i)
    o.start[i] += start_u0_perturbation * gap * std::sin(3.0 * (i + 1));
  o.start[problem.period_index()] *= 1 + start_period_perturbation;
  double u_max = 0;
  for (int i = 0; i < options.elements; ++i) u_max = std::max(u_max, std::abs(o.exact[i]));
  // Round-off of a residual or error of size u_max after O(steps) operations.
  const double eps = std::numeric_limits<double>::epsilon();
  o.residual_floor = 100 * eps * u_max, o.error_floor = 100 * eps;
  return o;
}

// One formulation's Newton run from the start of an exact orbit, and what is measured at x*
// and where the run ends.
struct FormulationRun {
  std::string label, status;
  double exact_residual = nan, exact_sigma_min = nan;  // at x* itself
  core::RankReport at_exact;
  NewtonTrace trace;
  ObservedRate residual_rate, error_rate;
  double period_error = nan, knot_error = nan;
  ReturnError returned;
  RankColumns rank;
  double sigma_max = nan;
};

FormulationRun run_formulation(ContactBarOrbitProblem& problem, const ContactFamily& family,
                               const exact_bar::ExactBarSolver& oracle, const ExactOrbit& orbit,
                               const std::string& label, core::ShootingFormulation formulation) {
  const OrbitOptions& options = problem.options();
  const int period = problem.period_index();
  const core::Vector& exact = orbit.exact;
  FormulationRun f;
  f.label = label;
  problem.set_formulation(formulation);
  core::Vector r;
  f.exact_residual = problem.residual(exact, r) == core::EvalStatus::ok
                         ? orbit.unit * r.lpNorm<Eigen::Infinity>()
                         : nan;
  // The Jacobian at x* itself (no verification): is the orbit sought a regular root?
  core::Matrix exact_jacobian;
  if (problem.jacobian(exact, exact_jacobian) == core::EvalStatus::ok)
    f.at_exact = core::rank_report(
        exact_jacobian, core::RankOptions{.relative_threshold = formulation_rank_threshold});
  const Eigen::Index m = f.at_exact.singular_values.size();
  f.exact_sigma_min =
      m > 0 ? f.at_exact.singular_values[m - 1] / f.at_exact.singular_values[0] : nan;

  core::Vector x = orbit.start;
  f.trace = trace_newton(problem, exact, orbit.unit, x);
  f.residual_rate = observed_rate(f.trace.shooting_residual, orbit.residual_floor);
  f.error_rate = observed_rate(f.trace.u0_error, orbit.error_floor);
  const double final_energy = problem.energy(x);
  const double closed_form_frequency = family.frequency(final_energy);
  f.period_error = std::abs(x[period] * closed_form_frequency / (2 * std::numbers::pi) - 1);
  f.knot_error =
      options.free_knots == 1 ? std::abs(x[options.elements] - exact[options.elements]) : nan;
  f.returned = return_error(problem, x, oracle);
  f.rank = rank_columns(problem, x);
  f.sigma_max = f.rank.relative.singular_values.size() ? f.rank.relative.singular_values[0] : nan;
  f.status = core::to_string(f.trace.status);
  return f;
}

void add_rows(FormulationTables& t, const ExactOrbit& o, const FormulationRun& f) {
  const NewtonTrace& trace = f.trace;
  const RankColumns& rank = f.rank;
  t.table.add_cells({f.label,
                     f.status,
                     double(o.mode),
                     o.ratio,
                     o.energy,
                     f.exact_residual,
                     f.exact_sigma_min,
                     double(f.at_exact.nullity),
                     trace.shooting_residual.front(),
                     trace.u0_error.front(),
                     double(trace.iterations),
                     trace.shooting_residual.back(),
                     trace.energy_error.back(),
                     f.residual_rate.order,
                     f.residual_rate.ratio,
                     trace.u0_error.back(),
                     f.error_rate.order,
                     f.error_rate.ratio,
                     f.period_error,
                     f.knot_error,
                     f.returned.displacement,
                     f.returned.velocity,
                     rank.period_column_forward,
                     rank.period_column_central,
                     rank.uncertainty,
                     rank.sigma_min(1),
                     rank.sigma_min(2),
                     rank.sigma_min(3),
                     f.sigma_max,
                     rank.relative.threshold,
                     double(rank.relative.nullity),
                     double(rank.relative.verified_dimension),
                     rank.absolute.threshold,
                     double(rank.absolute.nullity),
                     double(rank.absolute.verified_dimension),
                     rank.central_sigma_min_relative(),
                     double(rank.central.nullity),
                     double(rank.central.verified_dimension),
                     o.unit,
                     trace.seconds});
  for (std::size_t k = 0; k < trace.shooting_residual.size(); ++k)
    t.history.add_cells({double(o.mode), o.ratio, f.label, double(k), trace.shooting_residual[k],
                         trace.energy_error[k], trace.u0_error[k]});
  const auto counts = [](const core::RankReport& r) {
    return fmt::format("{}/{}", r.nullity, r.verified_dimension);
  };
  t.screen.add_cells({double(o.mode), o.ratio, f.label, f.status, double(trace.iterations),
                      trace.shooting_residual.back(), f.residual_rate.order, f.error_rate.order,
                      trace.u0_error.back(), f.period_error, f.returned.worst(),
                      rank.sigma_min(1) / f.sigma_max, counts(rank.relative), counts(rank.absolute),
                      counts(rank.central), f.exact_sigma_min});
}

// Residual and u0 error vs iteration: one column per mode, colour per amplitude, dash per
// formulation. The error is the comparable measure: the two residuals differ by definition.
void plot_formulations(const std::filesystem::path& hcsv, const std::filesystem::path& png,
                       double gap) {
  const std::string q = core::gnuplot_quote(hcsv);
  std::string panels;
  for (const auto& [column, label] : {std::pair{5, "shooting residual ||F||_{/Symbol \\245}  [m]"},
                                      std::pair{7, "u_0 error max|u_0 - u_0^*| / max|u_0^*|"}})
    for (const FormulationBranch& branch : formulation_branches) {
      panels += fmt::format("set title 'mode {}'\nset ylabel '{}'\nplot ", branch.mode, label);
      for (std::size_t k = 0; k < branch.ratios.size(); ++k)
        for (std::size_t f = 0; f < formulation_names.size(); ++f)
          panels += fmt::format(
              "{}{} using (($1 == {} && abs($2 - {:.17g}) < 1e-9 && strcol(3) eq '{}') ? $4 "
              ": NaN):(${} > 0 ? ${} : NaN) with linespoints lc {} dt {} pt {} title '{}, A = "
              "{:g} g_0'",
              k + f ? ", " : "", q, branch.mode, branch.ratios[k], formulation_names[f].first,
              column, column, k + 1, f + 1, f ? 6 : 7, formulation_names[f].first,
              branch.ratios[k]);
      if (column == 5)
        panels += fmt::format(", {:g} title 'tolerance' dt 2 lw 2 lc rgb 'black'",
                              formulation_tolerance_metres);
      panels += "\n";
    }
  bench::plot(png,
              fmt::format("set multiplot layout 2,2 title 'Newton from the same "
                          "perturbed exact orbit at fixed energy: regular "
                          "(solid) vs paper (dashed), g_0 = {:g} m'\nset "
                          "logscale y\nset grid\nset format y '10^{{%L}}'\n"
                          "set xlabel 'Newton iteration'\nset key outside right top "
                          "font ',8'\n",
                          gap) +
                  panels + "unset multiplot\n",
              {1600, 1300});
}

}  // namespace

int bench_formulations(const std::filesystem::path& out) {
  const double gap = 1e-3;
  bar::BarSetup setup;  // paper scene: E = rho = L = A = 1 (c = 1)
  setup.left = {bar::EndType::fixed, 0};
  setup.right = {bar::EndType::contact, gap};
  const TdbemSolver tdbem(ContactMethod::event);
  const exact_bar::ExactBarSolver oracle;
  fmt::print(
      "bench formulations: regular (half-period velocity) vs paper (u0 - u(T)) shooting from "
      "the same perturbed exact orbits\n  TD-BEM event contact, 20 elements, 40 steps per "
      "period, residual on {}x as many test functions as unknowns (trace's default); Newton "
      "(eigen) on [F; E - E*], ||F||_inf <= {:g} m, {} iterations\n",
      formulation_oversampling, formulation_tolerance_metres, formulation_max_iterations);

  FormulationTables tables;
  for (const FormulationBranch& branch : formulation_branches) {
    ContactBarOrbitProblem problem(setup, tdbem, formulation_orbit_options(branch.mode));
    const ContactFamily family(setup.material, gap, branch.mode);
    for (double ratio : branch.ratios) {
      const ExactOrbit orbit = exact_orbit(problem, branch.mode, ratio, gap);
      for (const auto& [label, formulation] : formulation_names)
        add_rows(tables, orbit,
                 run_formulation(problem, family, oracle, orbit, label, formulation));
    }
  }
  const std::filesystem::path hcsv = out / "formulations_history.csv";
  tables.table.write_csv(out / "formulations.csv");
  tables.history.write_csv(hcsv);
  fmt::print("{}", tables.screen.aligned());
  fmt::print(
      "  |F|: final ||F||_inf; order_F, order_err: median observed order of the residual and of "
      "u0_err = max|u0 - u0*| / max|u0*| (2 quadratic, 1 linear);\n  T_err: |T / T_closed(E) - "
      "1|; return_err: exact-oracle return error (relative); smin/smax: smallest singular value "
      "of the forward-difference\n  shooting Jacobian at the final point; null/ver: nullity at "
      "relative 1e-5 / verified dimension; abs: absolute floor ||J_fwd - J_cen||_2; central: "
      "J_cen;\n  x*: smin/smax at the exact orbit\n");
  plot_formulations(hcsv, out / "formulations.png", gap);
  return 0;
}

}  // namespace backbone::contact_bar
