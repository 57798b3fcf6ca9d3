#include "problems/exact_bar/exact_bar_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"

namespace backbone::exact_bar {

using core::InputError;

bar::History ExactBarSolver::simulate(const bar::BarSetup& setup,
                                      const bar::SimulationOptions& options) const {
  options.validate();
  setup.validate();
  const double L = setup.material.length;
  for (double p : options.probes)
    if (p < 0 || p > L)
      throw InputError("probes", fmt::format("must lie in [0, {}] (got {})", L, p));
  const ExactBarSolution solution(setup, options.t_end);

  const double steps = std::max(1.0, std::round(options.t_end / options.dt));
  const auto rows =
      static_cast<std::size_t>(std::min(static_cast<double>(options.history_samples), steps + 1));
  bar::History h;
  h.probes = options.probes;
  h.probe_u.assign(options.probes.size(), {});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < rows; ++i) {
    // The last row is t_end itself (t_end * n / n can be one ulp below it).
    const double t = i + 1 == rows
                         ? options.t_end
                         : options.t_end * static_cast<double>(i) / static_cast<double>(rows - 1);
    h.t.push_back(t);
    if (!solution.ok()) {
      h.u_contact.push_back(nan);
      h.contact_force.push_back(nan);
      if (options.energy) h.energy.push_back(nan);
      for (auto& column : h.probe_u) column.push_back(nan);
      continue;
    }
    h.u_contact.push_back(solution.u_end(t));
    h.contact_force.push_back(solution.contact_force(t));
    if (options.energy) h.energy.push_back(solution.energy(t));
    for (std::size_t k = 0; k < options.probes.size(); ++k)
      h.probe_u[k].push_back(solution.u(options.probes[k], t));
  }
  return h;
}

bar::FieldSnapshot ExactBarSolver::snapshot(const bar::BarSetup& setup, double t,
                                            const bar::SnapshotRequest& request) const {
  if (!std::isfinite(t) || t < 0)
    throw InputError("t", fmt::format("must be finite and >= 0 (got {})", t));
  return ExactBarSolution(setup, t).snapshot(t, request);
}

}  // namespace backbone::exact_bar
