// The stability study of the bar's modes (problems/contact_bar/orbits/README.md, section
// 'Stability'), from the traces with --stability true that the main job writes into
// OUT/stability/<run>/ (plugin.cpp, stability_steps).
//   stability_summary  stability/summary.csv: per run its branch, representation, grid, time
//                      step, points, the multipliers' worst and median distances from the circle
//                      and from +1, |det - 1|, the fronts' count, Jordan defects, structure and
//                      return errors (fronts.csv), and a verdict; stability_backbones.png (the
//                      fronts' runs coloured by Jordan defect), multipliers.png (the fronts'
//                      multipliers against the projected grid's) and max_modulus.png (the
//                      projected grid's largest non-trivial |mu| against energy)
//   perturbation_growth  stability/perturbation_growth.csv: the closed-form orbits of modes 1
//                      to 3 at 2, 20 and 200 times their grazing energy, perturbed at random by
//                      1e-6 and simulated by the exact solver for 1000 periods
//                      (orbits/monodromy.hpp, perturbation_growth): the largest distance to the
//                      orbit (drift along it removed), at k <= 500 and at the end, and the
//                      bound largest^(1/1000) on an excited multiplier's modulus
//
//   for (const cli::ProblemJob& job : contact_bar::stability_figure_jobs()) job.run("results");
#pragma once

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::contact_bar {

std::vector<cli::ProblemJob> stability_figure_jobs();

// summary.csv's verdict of one run: the fronts' K decides; the projected grid's ("grid") gives
// none. unstable (of them unstable_on_kinks) and undecided count points; kinks: points where
// the TD-BEM's one-sided differences of K disagree, where a multiplier off the circle is one
// side's and decides nothing; defect_min/max: the fronts' Jordan defects.
// kink_growth: at those unstable points on a kink, the perturbed orbits' check (fronts.csv,
// growth_*; orbits/README.md, 'Stability'), the worst of each; NaN when not run. With a power
// of k up to 1.5 (a linear drift reads 0.95 to 1.05 on the kinks of the main job) the verdict
// gives the bound the check proves, every excited |mu| <= largest^(1 / periods), against one
// side's multiplier; a faster growth, or none measured, leaves the point unresolved.
struct KinkGrowth {
  double periods = std::numeric_limits<double>::quiet_NaN();
  double largest = std::numeric_limits<double>::quiet_NaN();  // growth_largest
  double power = std::numeric_limits<double>::quiet_NaN();    // growth_power
  double modulus = std::numeric_limits<double>::quiet_NaN();  // one side's largest |mu|
};
std::string stability_verdict(const std::string& representation, int unstable,
                              int unstable_on_kinks, int undecided, double defect_min,
                              double defect_max, double kinks, const KinkGrowth& growth = {});

// 0 when written, or skipped with a line when OUT/stability holds no run.
int write_stability_summary(const std::filesystem::path& out);
int write_perturbation_growth(const std::filesystem::path& out);

}  // namespace backbone::contact_bar
