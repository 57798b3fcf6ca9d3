#include "problems/contact_bar/orbits/subharmonic.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "continuation/dimension_evidence.hpp"
#include "core/errors.hpp"
#include "core/io/table.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {

ContactStructure contact_structure(const bar::BarSetup& setup, double period) {
  if (!setup.right.has_wall() || !(setup.right.gap > 0))
    throw core::InputError("right",
                           "the contact structure needs right = contact or clearance "
                           "and gap > 0");
  ContactStructure result;
  const exact_bar::ExactBarSolution sol(setup, period);
  if (!sol.ok()) return result;
  result.ok = true;
  result.closings_on_fronts = static_cast<int>(sol.closings_on_fronts().size());
  const double g0 = setup.right.gap, tol = 1e-9 * period;
  const auto intervals = sol.contact_intervals(exact_bar::Side::right);
  // The phases on one wall; a phase through t = 0 = T appears as [0, a) and [T - a', T): one
  // phase. Returns the count, the duration of the phase that contains t = 0 and the total.
  auto phases_on = [&](bool back, double& first_contact, double& total) {
    std::vector<std::pair<double, double>> phases;
    for (const auto& c : intervals) {
      const double release = std::min(c.t_release, period);
      if (c.back_wall == back && release - c.t_close > tol) {
        phases.emplace_back(c.t_close, release);
        total += release - c.t_close;
      }
    }
    if (phases.size() >= 2 && phases.front().first <= tol && phases.back().second >= period - tol) {
      first_contact = phases.front().second + (period - phases.back().first);
      phases.pop_back();
    } else if (!phases.empty() && phases.front().first <= tol) {
      first_contact = phases.front().second;
    }
    return static_cast<int>(phases.size());
  };
  result.contact_phases = phases_on(false, result.first_contact, result.contact_time);
  double unused = 0;
  result.back_contact_phases = phases_on(true, unused, result.back_contact_time);
  // Closed during a phase; a closed interval shorter than tol is a grazing instant.
  auto closed_at = [&](double t) {
    for (const auto& c : intervals)
      if (!c.back_wall && std::min(c.t_release, period) - c.t_close > tol && t >= c.t_close - tol &&
          t <= std::min(c.t_release, period) + tol)
        return true;
    return false;
  };
  const int samples = 4000;
  std::vector<double> u(samples + 1);
  result.min_gap = std::numeric_limits<double>::infinity();
  const bool back_wall = setup.right.has_back_wall();
  if (back_wall) result.min_back_gap = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= samples; ++i) {
    u[i] = sol.u_end(exact_bar::Side::right, period * i / samples);
    result.min_gap = std::min(result.min_gap, g0 - u[i]);
    if (back_wall) result.min_back_gap = std::min(result.min_back_gap, setup.right.gap_back + u[i]);
  }
  // Local maxima of the (periodic) end displacement, refined by ternary search.
  for (int i = 0; i < samples; ++i) {
    const double before = u[(i + samples - 1) % samples], after = u[i + 1];
    if (!(u[i] >= before && u[i] >= after)) continue;
    double a = period * (i - 1) / samples, b = period * (i + 1) / samples;
    auto at = [&](double t) {
      const double w = std::fmod(t + period, period);
      return sol.u_end(exact_bar::Side::right, w);
    };
    for (int it = 0; it < 100; ++it) {
      const double m1 = a + (b - a) / 3, m2 = b - (b - a) / 3;
      if (at(m1) < at(m2))
        a = m1;
      else
        b = m2;
    }
    const double t = std::fmod(0.5 * (a + b) + period, period);
    const double gap = g0 - at(t);
    result.min_gap = std::min(result.min_gap, gap);
    if (std::abs(gap) <= 1e-9 * g0 && !closed_at(t) && !closed_at(t + 1e-6 * period) &&
        !closed_at(t - 1e-6 * period))
      ++result.grazing_instants;
    // Skip the rest of a flat stretch at this maximum (a plateau counts once).
    while (i + 1 < samples && u[i + 1] == u[i]) ++i;
  }
  return result;
}

void write_subharmonic_outputs(const ContactBarOrbitProblem& problem, const ContactFamily& mode2,
                               const continuation::Branch& branch, const std::filesystem::path& out,
                               double rank_threshold) {
  // The periodicity residual F without path rows.
  const ContactBarOrbitProblem alone = problem.without_path_rows();
  const exact_bar::ExactBarSolver oracle;
  core::RankOptions rank;
  const bool check = std::isfinite(rank_threshold);
  if (check) rank.relative_threshold = rank_threshold;
  core::Table table({"point", "energy", "period", "period_closed_form", "relative_error", "shape",
                     "contact_phases", "grazing_instants", "min_gap", "return_error", "dimension_F",
                     "nullity_F", "gap_F"});
  std::vector<double> dimensions;
  std::vector<bool> beside;  // the dimension came from J beside the point (rechecked)
  std::vector<ContactStructure> structures;
  for (const auto& point : branch.points) {
    structures.push_back(
        contact_structure(problem.setup_at(point.x), point.x[problem.period_index()]));
    const ContactStructure& c = structures.back();
    const double energy = point.observable("energy"), period = point.observable("period");
    const double exact = 2 * mode2.period(energy);
    const ReturnError re = return_error(problem, point.x, oracle);
    const double nan = std::nan("");
    continuation::DimensionEvidence e;
    // The neighbouring member: at a grazing limit F is not differentiable (a contact phase
    // vanishes) and J there misses a direction that J a step into the continuum shows.
    const std::size_t i = static_cast<std::size_t>(&point - branch.points.data());
    const std::size_t j = i + 1 < branch.points.size() ? i + 1 : (i > 0 ? i - 1 : i);
    if (check)
      e = continuation::dimension_evidence(alone, point.x, rank, core::VerifyOptions{},
                                           j != i ? branch.points[j].x : core::Vector{});
    dimensions.push_back(check ? e.report.verified_dimension : nan);
    beside.push_back(check && e.beside);
    table.add_row(
        {static_cast<double>(point.index), energy, period, exact, std::abs(period / exact - 1),
         point.observable("shape"), c.ok ? c.contact_phases : nan, c.ok ? c.grazing_instants : nan,
         c.ok ? c.min_gap : nan, re.worst(),
         check ? static_cast<double>(e.report.verified_dimension) : nan,
         check ? static_cast<double>(e.report.nullity) : nan, check ? e.report.gap : nan});
  }
  table.write_csv(out / "subharmonic_check.csv");
  // branch.csv gains the contact structure (columns contact_phases, grazing_instants, min_gap)
  // and, with the check, F's dimension in its dimension column.
  const core::Table saved = core::Table::read_csv(out / "branch.csv");
  const auto& names = saved.columns();
  const auto column =
      static_cast<std::size_t>(std::find(names.begin(), names.end(), "dimension") - names.begin());
  const auto flag_column = static_cast<std::size_t>(
      std::find(names.begin(), names.end(), "dimension_flag") - names.begin());
  std::vector<std::string> columns = names;
  for (const char* name : {"contact_phases", "grazing_instants", "min_gap"})
    columns.emplace_back(name);
  core::Table rewritten(columns);
  for (std::size_t i = 0; i < saved.rows(); ++i) {
    std::vector<core::Table::Cell> cells = saved.cells(i);
    if (check && column < names.size() && i < dimensions.size()) {
      cells[column] = dimensions[i];
      // Every member lies on the traced curve in F's zero set, so F's dimension is at least 1:
      // a verified 0 (the probes left the two-knot chart near shape 0) is flagged unconfirmed
      // (dimension_flag 2, continuation/README.md), never reported as an isolated orbit.
      if (dimensions[i] < 1 && flag_column < names.size()) cells[flag_column] = 2.0;
      if (beside[i] && flag_column < names.size()) cells[flag_column] = 1.0;
    }
    const bool known = i < structures.size() && structures[i].ok;
    const double nan = std::nan("");
    cells.emplace_back(known ? structures[i].contact_phases : nan);
    cells.emplace_back(known ? structures[i].grazing_instants : nan);
    cells.emplace_back(known ? structures[i].min_gap : nan);
    rewritten.add_cells(std::move(cells));
  }
  rewritten.write_csv(out / "branch.csv");
  if (check) {
    std::map<int, int> counts;  // F's verified dimension -> points
    for (double d : dimensions)
      if (std::isfinite(d)) ++counts[static_cast<int>(d)];
    std::string list;
    for (const auto& [dimension, points] : counts)
      list += fmt::format("{}{} at {} point{}", list.empty() ? "" : ", ", dimension, points,
                          points == 1 ? "" : "s");
    fmt::print(
        "dimension of the periodicity residual F alone (branch.csv's dimension column; the "
        "point lines give the traced curve's): {}\n",
        list.empty() ? "not checked" : list);
  }
}

}  // namespace backbone::contact_bar
