// The exact characteristics solver behind the shared bar::BarSolver interface.
//
// Each call solves the setup exactly (ExactBarSolution) and samples it: simulate() records
// min(history_samples, round(t_end / dt) + 1) instants evenly spaced over [0, t_end] (dt only
// sets the default density, there is no time step); snapshot() returns nodal values and exact
// hat-function projections at one instant. Cost: the number of characteristic segments,
// independent of dt. For repeated queries on one setup keep an ExactBarSolution instead.
//
//   exact_bar::ExactBarSolver solver;
//   bar::SimulationOptions o; o.t_end = 3.1; o.history_samples = 311;
//   bar::History h = solver.simulate(setup, o);           // u_contact, contact_force, energy
//   bar::SnapshotRequest r; r.elements = 40; r.projected_v = true;
//   bar::FieldSnapshot f = solver.snapshot(setup, 1.55, r);  // f.v_projected: exact
#pragma once

#include <string>

#include "problems/bar/bar.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::exact_bar {

class ExactBarSolver : public bar::BarSolver {
 public:
  std::string name() const override { return "exact"; }
  // Throws core::InputError for a bad setup or options (probes outside [0, L]: key "probes").
  // If the event march fails, every sampled value is NaN.
  bar::History simulate(const bar::BarSetup& setup,
                        const bar::SimulationOptions& options) const override;
  bar::FieldSnapshot snapshot(const bar::BarSetup& setup, double t,
                              const bar::SnapshotRequest& request) const override;
};

}  // namespace backbone::exact_bar
