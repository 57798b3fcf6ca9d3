#include "continuation/branch.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <complex>
#include <limits>

namespace backbone::continuation {

double BranchPoint::observable(const std::string& name) const {
  return core::observable_value(observables, name);
}

const char* to_string(StopReason r) {
  switch (r) {
    case StopReason::max_points:
      return "max_points";
    case StopReason::bound_reached:
      return "bound_reached";
    case StopReason::boundary_reached:
      return "boundary_reached";
    case StopReason::step_floor:
      return "step_floor";
    case StopReason::newton_failed:
      return "newton_failed";
    case StopReason::evaluation_failed:
      return "evaluation_failed";
    case StopReason::singular_tangent:
      return "singular_tangent";
    case StopReason::cancelled:
      return "cancelled";
  }
  return "?";
}

std::string dimension_warning(const BranchPoint& p) {
  const int candidates = p.rank ? p.rank->nullity : -1;
  switch (p.dimension_flag) {
    case DimensionFlag::as_verified:
      return {};
    case DimensionFlag::rechecked:
      return fmt::format(
          "verified dimension 0 of {} candidates contradicts the curve; re-checked "
          "along its tangent: dimension {} (dimension_flag 1)",
          candidates, p.dimension);
    case DimensionFlag::unconfirmed:
      return fmt::format(
          "verified dimension {} of {} candidates contradicts the curve, and a "
          "probe along its tangent failed too (dimension_flag 2: not to be "
          "trusted)",
          p.dimension, candidates);
    case DimensionFlag::inside:
      return fmt::format(
          "on the boundary of its solution set, where J is one side's: dimension {} verified at "
          "a neighbour just inside (dimension_flag 3)",
          p.dimension);
  }
  return {};
}

core::Table branch_table(const Branch& branch) {
  std::vector<std::string> names;
  if (!branch.points.empty())
    for (const auto& [key, value] : branch.points.front().observables) names.push_back(key);
  std::vector<std::string> columns{"point"};
  columns.insert(columns.end(), names.begin(), names.end());
  const bool floquet = !branch.points.empty() && branch.points.front().floquet.has_value();
  if (floquet)
    for (const char* c : {"stable", "unstable_multipliers", "max_multiplier_modulus",
                          "trivial_multiplier_distance", "monodromy_determinant"})
      columns.push_back(c);
  for (const char* c : {"dimension", "dimension_flag", "nullity", "sigma_zero", "sigma_kept",
                        "residual", "newton_iterations", "step_size", "arclength",
                        "jacobian_evaluations", "residual_evaluations"})
    columns.push_back(c);
  core::Table table(columns);
  for (const BranchPoint& p : branch.points) {
    std::vector<double> row{static_cast<double>(p.index)};
    for (const std::string& n : names) row.push_back(p.observable(n));
    if (floquet) {
      const core::Floquet f = p.floquet ? *p.floquet : core::undecided_floquet(0);
      row.insert(row.end(), {static_cast<double>(f.stable), static_cast<double>(f.unstable),
                             f.max_modulus, f.trivial_distance, f.determinant});
    }
    row.push_back(p.dimension);
    row.push_back(static_cast<double>(p.dimension_flag));
    row.push_back(p.rank ? p.rank->nullity : -1);
    // sigma_zero: largest singular value counted as zero, sigma_kept: smallest one kept, both
    // relative to the largest (NaN when there is none or the rank was not checked): how far
    // the rank decision is from its threshold on either side.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    double zero = nan, kept = nan;
    if (p.rank && p.rank->singular_values.size() > 0 && p.rank->singular_values[0] > 0) {
      const auto& sv = p.rank->singular_values;
      const Eigen::Index rank = static_cast<Eigen::Index>(p.x.size()) - p.rank->nullity;
      if (rank < sv.size()) zero = sv[rank] / sv[0];
      if (rank >= 1 && rank - 1 < sv.size()) kept = sv[rank - 1] / sv[0];
    }
    row.push_back(zero);
    row.push_back(kept);
    row.push_back(p.residual);
    row.push_back(p.newton_iterations);
    row.push_back(p.step_size);
    row.push_back(p.arclength);
    row.push_back(static_cast<double>(p.jacobian_evaluations));
    row.push_back(static_cast<double>(p.residual_evaluations));
    table.add_row(row);
  }
  return table;
}

core::Table multiplier_table(const Branch& branch) {
  core::Table table({"point", "index", "re", "im", "modulus", "trivial"});
  for (const BranchPoint& p : branch.points) {
    if (!p.floquet) continue;
    const core::Floquet& f = *p.floquet;
    for (std::size_t i = 0; i < f.multipliers.size(); ++i)
      table.add_row({static_cast<double>(p.index), static_cast<double>(i), f.multipliers[i].real(),
                     f.multipliers[i].imag(), std::abs(f.multipliers[i]),
                     f.trivial[i] ? 1.0 : 0.0});
  }
  return table;
}

core::Table branch_point_table(const Branch& branch, const core::Observables& template_point) {
  std::vector<std::string> observables, described;
  const auto add_name = [](std::vector<std::string>& names, const std::string& name) {
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  };
  for (const auto& [key, value] : template_point) add_name(observables, key);
  for (const BranchPointReport& r : branch.branch_points) {
    for (const auto& [key, value] : r.observables) add_name(observables, key);
    for (const auto& [key, value] : r.attached_description) add_name(described, key);
  }
  std::vector<std::string> columns = observables;
  columns.push_back("dimension");
  columns.insert(columns.end(), described.begin(), described.end());
  for (const char* c : {"tangent_angle", "verified", "nullity", "candidates", "probed",
                        "after_point", "arclength", "test_value", "sign_change", "location_steps",
                        "jacobian_evaluations", "residual_evaluations"})
    columns.push_back(c);
  core::Table table(columns);
  for (const BranchPointReport& r : branch.branch_points) {
    std::vector<double> row;
    for (const std::string& n : observables)
      row.push_back(core::observable_value(r.observables, n));
    row.push_back(r.attached_dimension);
    for (const std::string& n : described)
      row.push_back(core::observable_value(r.attached_description, n));
    row.insert(
        row.end(),
        {r.tangent_angle, r.verified() ? 1.0 : 0.0, static_cast<double>(r.nullity),
         static_cast<double>(r.candidates), static_cast<double>(r.probed),
         static_cast<double>(r.after_point), r.arclength, r.test_value, r.sign_change ? 1.0 : 0.0,
         static_cast<double>(r.location_steps), static_cast<double>(r.jacobian_evaluations),
         static_cast<double>(r.residual_evaluations)});
    table.add_row(row);
  }
  return table;
}

}  // namespace backbone::continuation
