// The files a traced branch is written to, beside branch.csv (branch_table, branch.hpp).
//
// orbits.csv holds, for every point of a branch of a core::PeriodicOrbitProblem, the initial
// state of its orbit as (coordinate, value) rows: `point,x,u0`. It is also the restart format
// (a point of it is a whole orbit).
//
//   continuation::orbit_table(problem, branch).write_csv(out / "orbits.csv");
#pragma once

#include "continuation/branch.hpp"
#include "core/periodic_orbit.hpp"
#include "core/table.hpp"

namespace backbone::continuation {

core::Table orbit_table(const core::PeriodicOrbitProblem& problem, const Branch& branch);

}  // namespace backbone::continuation
