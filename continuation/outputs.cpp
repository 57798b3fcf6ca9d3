#include "continuation/outputs.hpp"

namespace backbone::continuation {

core::Table orbit_table(const core::PeriodicOrbitProblem& problem, const Branch& branch) {
  core::Table t({"point", "x", "u0"});
  core::Vector coordinates, values;
  for (const auto& p : branch.points) {
    problem.initial_state_samples(p.x, coordinates, values);
    for (Eigen::Index i = 0; i < values.size(); ++i)
      t.add_row({static_cast<double>(p.index), coordinates[i], values[i]});
  }
  return t;
}

}  // namespace backbone::continuation
