// Figures of the internal resonances of mode 1 (problems/contact_bar/orbits/README.md, section
// 'Dimension changes'), drawn from the outputs of `backbone trace --branch mode1
// --follow all` into OUT/mode1_resonances (the main job's step of that name: 40 intervals, E up
// to 3e-5 J): its branch.csv and the followed branches branch_point_K/.
//   attached_branches  attached_branches.png (paper Fig. 4, label d): frequency-energy plot of
//                      mode 1 with every followed attached branch (vertical: they leave at
//                      constant frequency) and the branch points of branch_points.csv
//   resonant_end       resonant_end.png (Fig. 11): the contacting-end displacement over one
//                      period of the highest-energy orbit of each followed branch beside mode 1's
//                      closed-form orbit at the same period, both by the exact oracle (CSV
//                      beside it); the scene is the paper's
//   resonant_spacetime resonant_spacetime.png (Fig. 10): u(x, t) over one period of the
//                      highest-energy orbit of the first followed branch (exact oracle)
//
//   for (const cli::ProblemJob& job : contact_bar::resonance_figure_jobs())
//     status = std::max(status, job.run("results"));  // after trace --out results/mode1 --follow
//     all
#pragma once

#include <filesystem>
#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::contact_bar {

std::vector<cli::ProblemJob> resonance_figure_jobs();

// 0 when drawn or skipped with a line (no OUT/mode1_resonances, or no followed branch in it).
int draw_attached_branches(const std::filesystem::path& out);
int draw_resonant_spacetime(const std::filesystem::path& out, const std::filesystem::path& scene);
int draw_resonant_end(const std::filesystem::path& out, const std::filesystem::path& scene);

}  // namespace backbone::contact_bar
