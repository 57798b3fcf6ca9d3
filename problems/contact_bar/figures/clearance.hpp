// The bar in a clearance (problems/contact_bar/orbits/README.md, section 'Modes in a
// clearance'), from the main job's traces OUT/clearance_<name>/ (modes 1 and 2, a symmetric and
// an asymmetric clearance) and its long simulations OUT/clearance_drift_<name>/:
//   clearance   clearance_backbones.png: frequency against energy of the four branches, every
//               traced point over its closed form (ClearanceMode), the one-sided modes 1 and 2
//               dashed; clearance_summary.csv: per branch its points, energy range, worst
//               closed-form and exact-oracle errors, the points with one front phase and with
//               a back phase, and where no orbit reaches the back wall the worst difference
//               from the one-sided mode; clearance_energy_drift.csv: per long simulation the
//               largest relative energy change over its history.
//
//   for (const cli::ProblemJob& job : contact_bar::clearance_figure_jobs()) job.run("results");
#pragma once

#include <filesystem>
#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::contact_bar {

std::vector<cli::ProblemJob> clearance_figure_jobs();

// 0 when written, or skipped with a line when OUT holds no clearance branch.
int draw_clearance(const std::filesystem::path& out);

}  // namespace backbone::contact_bar
